"""Tests of analysis.sanity."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from _analytic_brdfs import Lambert  # noqa: E402

from analysis import sanity_scan  # noqa: E402
from analysis.sanity import edge_pairs  # noqa: E402


def test_lambert_passes():
    r = sanity_scan(Lambert())
    assert r.ok and r.violations == []


def test_nan_at_grazing_is_reported_with_inputs():
    class Bad:
        def eval(self, wi, wo):
            wi, wo = np.asarray(wi), np.asarray(wo)
            up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
            f = np.where(up, 0.1 / np.maximum(wi[..., 2] - 1e-6, 0), 0.0)  # inf/nan near 90
            return f[..., None] * np.ones(3)

    with np.errstate(all="ignore"):
        r = sanity_scan(Bad())
    assert not r.ok
    v = [c for c in r.violations if c["directions"] == "grazing_i"][0]
    assert v["n_nonfinite"] > 0 or v["warnings"]
    ex = v["examples"][0]
    assert ex["theta_i"] > 89.9
    assert any(x is None for x in ex["value"]) or v["warnings"]


def test_negative_and_nonzero_below_horizon():
    class Neg:
        def eval(self, wi, wo):
            wi, wo = np.asarray(wi), np.asarray(wo)
            return (wi[..., 2] - 0.5)[..., None] * np.ones(3)   # negative, and not 0 below

    r = sanity_scan(Neg())
    assert not r.ok
    assert any(c["n_negative"] for c in r.checks)
    below = [c for c in r.checks if c["directions"] == "below_horizon"][0]
    assert below["n_nonzero_below_horizon"] > 0 or below["n_negative"] > 0
    json.dumps(r.to_dict())


def test_edge_pairs_are_unit_and_hit_the_edges():
    sets = edge_pairs()
    for wi, wo in sets.values():
        np.testing.assert_allclose(np.linalg.norm(wi, axis=-1), 1.0, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(wo, axis=-1), 1.0, atol=1e-12)
    wi, wo = sets["phi_d_near_pi"]
    pi_, po = np.arctan2(wi[:, 1], wi[:, 0]), np.arctan2(wo[:, 1], wo[:, 0])
    d = np.abs(np.angle(np.exp(1j * (po - pi_))))
    ok = (wi[:, 2] < 1 - 1e-9) & (wo[:, 2] < 1 - 1e-9)
    assert np.all(d[ok] > np.pi - 0.01)


def test_fabric_scan_findings_reproduce():
    """Every reported example really is non-finite or negative when evaluated again."""
    import brdf

    fab = brdf.fabric("polyester_satin_charmeuse")
    r = sanity_scan(fab)
    names = {c["params"] for c in r.checks}
    assert {"as_given", "offsets_-90_90", "gamma_0.1deg"} <= names
    for c in r.violations:
        for ex in c["examples"]:
            if c["params"] != "as_given":
                continue
            with np.errstate(all="ignore"):
                f = fab.eval(np.array(ex["wi"]), np.array(ex["wo"]))
            assert not np.all(np.isfinite(f)) or np.any(f < 0) or c["warnings"]


def test_bad_input():
    with pytest.raises(ValueError, match="unknown fabric"):
        sanity_scan("bogus")
    with pytest.raises(ValueError, match="eval"):
        sanity_scan(object())
