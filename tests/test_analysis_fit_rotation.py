"""``rotation`` as a fit parameter: a fabric rotated about n by a hidden angle, measured on a
full grid with noise, fitted from the unrotated preset with ``rotation`` free."""

from __future__ import annotations

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import FabricModel, fit
from analysis.params import ParamSpec, defaults_from_fabric

INSTRUMENT = gonio.Instrument(snr=20.0, floor=1e-4, max_theta=80.0, min_separation=0.0)


def test_rotation_is_degrees_in_values_and_radians_in_the_option():
    fab = brdf.fabric("velvet").with_values({"rotation": -25.0})
    assert fab.values()["rotation"] == pytest.approx(-25.0)
    assert fab.options["rotation"] == pytest.approx(np.radians(-25.0))
    # the forward model's slow path (a rotation per batch row) is the rotated fabric's f_r
    wi = brdf.directions.from_angles(np.radians([10, 40, 60]), np.radians([0, 70, 200]))
    wo = brdf.directions.from_angles(np.radians([30, 50, 20]), np.radians([180, 10, 95]))
    base = brdf.fabric("velvet")
    fwd = base.forward(wi, wo)
    kw = base.batch_kwargs({n: np.array([v, v]) for n, v in base.values().items()}
                           | {"rotation": np.array([-25.0, 0.0])})
    out = fwd(**kw)
    np.testing.assert_allclose(out[0], fab.eval(wi, wo), rtol=1e-5)
    np.testing.assert_allclose(out[1], base.eval(wi, wo), rtol=1e-5)
    assert not np.allclose(out[0], out[1], rtol=1e-2)     # the rotation changes f_r here


@pytest.mark.slow
def test_a_rotated_satin_is_recovered_within_its_95_interval(tmp_path):
    start = brdf.fabric("polyester_satin_charmeuse")
    truth = start.with_values({"rotation": 25.0, "kd1": 0.1})
    table = gonio.measure(truth, gonio.full_grid(30.0, 60.0), INSTRUMENT, seed=4,
                          progress=False)
    spec = ParamSpec(("rotation", "kd1"), defaults=defaults_from_fabric(start))
    r = fit(table, spec, FabricModel(start, table.wi, table.wo), seed=2, progress=False,
            max_steps=200, n_starts=2, out_dir=tmp_path)
    s = r.summary["rotation"]
    assert s["unit"] == "deg"
    assert s["lo95"] <= 25.0 <= s["hi95"], s
    assert s["hi95"] - s["lo95"] < 2.0          # the table tells it: well under a degree
    assert r.summary["kd1"]["lo95"] <= 0.1 <= r.summary["kd1"]["hi95"]
