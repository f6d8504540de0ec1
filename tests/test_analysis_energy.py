"""Tests of analysis.energy: the white furnace finds violations, reports serialize."""

import json
import math

import numpy as np
import pytest

import brdf
from analysis import energy_report, white_furnace
from analysis.energy import directions_grid


def test_white_furnace_finds_a_set_built_to_exceed_one():
    # A = 1, k_d = 1 (all volume scattering isotropic, no absorption) on linen's curves:
    # f_rv = F_T / (cos_i + cos_r) / cos^2(theta_d) grows without the 1/pi a Lambertian has.
    rows = white_furnace(["linen_plain"], scan={"kd": (1.0,)}, theta_deg=(0.0,), phi_deg=(0.0,),
                         modes=("furnace",), workers=1)
    assert [(r["parameter"], r["value"]) for r in rows] == [("none", None), ("kd", 1.0)]
    for r in rows:
        assert r["curves"] == "linen_plain"
        m = r["furnace"]
        assert m["value"] - m["error"] > 1.0
        assert m["exceeds_one"]


def test_white_furnace_value_independent_monte_carlo():
    """The quadrature's furnace albedo of white linen at normal incidence vs plain MC."""
    fab = brdf.fabric("linen_plain")
    white = fab.replace(threads=tuple(t.replace(albedo=(1.0, 1.0, 1.0)) for t in fab.threads))
    rows = white_furnace(["linen_plain"], scan={}, theta_deg=(0.0,), phi_deg=(0.0,),
                         modes=("furnace",), workers=1, tol=1e-4)
    rng = np.random.default_rng(5)
    n = 200_000
    z = rng.random(n)                         # uniform in solid angle on the hemisphere
    p = 2 * np.pi * rng.random(n)
    s = np.sqrt(1 - z * z)
    wi = np.stack([s * np.cos(p), s * np.sin(p), z], axis=-1)
    g = white.eval(wi, np.array([0.0, 0.0, 1.0]))[:, 1] * z * 2 * np.pi
    mc, se = g.mean(), g.std(ddof=1) / math.sqrt(n)
    q = rows[0]["furnace"]["value"]
    assert abs(q - mc) < 5 * se + rows[0]["furnace"]["error"]
    assert mc > 1.0


def test_energy_report_small_serializes_and_is_consistent():
    rep = energy_report(["silk_shot"], ["default", "gap_outgoing"], theta_deg=(0.0, 60.0),
                        phi_deg=(0.0, 90.0), hemispherical=False, furnace=False, workers=1)
    d = json.loads(json.dumps(rep.to_dict()))
    assert len(d["curves"]) == 2 * 2
    for c in d["curves"]:
        v = np.array(c["value"])
        assert v.shape == (2, 2, 3)
        assert c["max"]["value"] == pytest.approx(v.max())
        assert np.all(np.array(c["error"]) <= 1e-3 + 1e-3 * np.abs(v))
    # silk_shot has a1 + a2 = 1: the gap term vanishes, so gap variants agree exactly
    a = [c for c in d["curves"] if c["variant"] == "default"]
    b = [c for c in d["curves"] if c["variant"] == "gap_outgoing"]
    for x, y in zip(a, b):
        assert x["mode"] == y["mode"]
        np.testing.assert_allclose(x["value"], y["value"], rtol=1e-12)


def test_reflectance_grows_at_grazing_incidence():
    """rho'(wi) carries the 1/(n . wi) of f_r: at 89 degrees it is far above the furnace."""
    rep = energy_report(["linen_plain"], ["default"], theta_deg=(89.0,), phi_deg=(0.0,),
                        hemispherical=False, furnace=False, workers=1)
    by = {c["mode"]: c for c in rep.curves}
    assert by["reflectance"]["max"]["value"] > 1.0
    assert by["reflectance"]["exceeds_one"]
    assert by["furnace"]["max"]["value"] < 1.0


def test_bad_names():
    with pytest.raises(ValueError, match="unknown fabric"):
        energy_report(["bogus"])
    with pytest.raises(ValueError, match="unknown variant"):
        energy_report(["linen_plain"], ["nope"])
    with pytest.raises(ValueError, match="scan parameter"):
        white_furnace(["linen_plain"], scan={"area": (0.5,)})


def test_directions_grid_units():
    d = directions_grid([0.0, 90.0], [0.0, 90.0])
    np.testing.assert_allclose(d[1, 1], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0)
