"""A fabric symmetric under a half turn has a circular ``rotation``: draws piled at -90 and
+90 degrees are one mode across the wrap, summarized with circular statistics, and no
``at_bound`` warning fires there (analysis.fit.circular)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import fit
from analysis.fit.circular import unwrap
from analysis.fit.results import summarize
from analysis.fit.trust import at_bound
from analysis.fit.workflow import fit_spec
from analysis.params import ParamSpec

INSTRUMENT = gonio.Instrument(snr=20.0, floor=1e-4, max_theta=80.0, min_separation=0.0)


@pytest.mark.parametrize("preset", brdf.PRESETS)
def test_the_period_is_what_a_half_turn_does_to_f_r(preset):
    rng = np.random.default_rng(3)
    v = rng.normal(size=(2, 300, 3))
    v[..., 2] = np.abs(v[..., 2])
    wi, wo = v / np.linalg.norm(v, axis=-1, keepdims=True)
    fab = brdf.fabric(preset, rotation=np.radians(20.0))
    turned = fab.replace(rotation=np.radians(200.0)).eval(wi, wo)
    same = np.allclose(turned, fab.eval(wi, wo), rtol=1e-9, atol=0.0)
    assert fab.periods() == {"rotation": 180.0 if same else 360.0}
    assert fab.periods() == brdf.fabric(preset).periods()


def _wrapped_draws(mode, sd, n=(2, 400, 8), seed=0):
    """Normal draws about ``mode`` (degrees) put back into [-90, 90) as a bounded sampler
    holds them: a mode near the bound is split between its two ends."""
    x = np.random.default_rng(seed).normal(mode, sd, size=n)
    return np.mod(x + 90.0, 180.0) - 90.0


def _diagnosis(spec, natural):
    chains = spec.to_internal(natural)
    nd = natural.shape[-1]
    return SimpleNamespace(chains=chains, taus=np.ones((natural.shape[0], nd)),
                           tau=np.ones(nd), rhat=np.ones(nd), kept=natural.shape[1])


@pytest.mark.parametrize("mode", [89.0, -89.4, 0.0])
def test_a_mode_across_the_wrap_is_summarized_as_one(mode):
    rot = _wrapped_draws(mode, 1.0)
    kd = np.random.default_rng(1).uniform(0.2, 0.4, size=rot.shape)
    natural = np.stack([rot, kd], -1)
    circ = ParamSpec(("rotation", "kd1"), periods={"rotation": 180.0})
    s = summarize(circ, _diagnosis(circ, natural))["rotation"]
    assert s["period"] == 180.0
    assert -90.0 <= s["median"] < 90.0
    # the median within 0.2 degree of the mode, on the circle
    assert abs((s["median"] - mode + 90.0) % 180.0 - 90.0) < 0.2
    # 95% of N(mode, 1): mode -+ 1.96, as one interval (it may cross the bound)
    assert s["hi95"] - s["lo95"] == pytest.approx(2 * 1.96, rel=0.05)
    result = SimpleNamespace(names=circ.free, spec=circ,
                             samples=lambda: natural.reshape(-1, 2))
    assert [w for w in at_bound(result) if "rotation" in w["parameters"]] == []


def test_without_the_period_the_same_draws_read_as_two_bounds():
    """The check above could fail: the same draws, the rotation not known to be circular,
    give the plain summary (a median far from the mode) and the bound warning."""
    natural = np.stack([_wrapped_draws(89.0, 1.0), np.full((2, 400, 8), 0.3)], -1)
    plain = ParamSpec(("rotation", "kd1"), bounds={"rotation": (-90.0, 90.0)},
                      periods={"rotation": 360.0})                     # range < period
    s = summarize(plain, _diagnosis(plain, natural))["rotation"]
    assert "period" not in s and s["hi95"] - s["lo95"] > 100.0
    result = SimpleNamespace(names=plain.free, spec=plain, samples=lambda: natural.reshape(-1, 2))
    assert [w["parameters"] for w in at_bound(result)] == [["rotation"], ["rotation"]]  # both


def test_unwrap_keeps_each_draw_within_whole_periods():
    x = np.random.default_rng(2).uniform(-90.0, 90.0, 1000)
    y = unwrap(x, 180.0, -90.0)
    k = (y - x) / 180.0
    np.testing.assert_allclose(k, np.round(k), atol=1e-9)
    assert -90.0 <= np.median(y) < 90.0


@pytest.mark.slow
def test_a_satin_turned_to_the_wrap_is_recovered_without_a_bound_warning(tmp_path):
    """A symmetric satin at 89.7 degrees, 0.3 from the wrap at +-90: fitted with rotation free
    from the unrotated preset (``fit_spec`` takes the half-turn period from the fabric)."""
    start = brdf.fabric("polyester_satin_charmeuse")
    truth = start.with_values({"rotation": 89.7, "kd1": 0.1})
    table = gonio.measure(truth, gonio.full_grid(30.0, 60.0), INSTRUMENT, seed=4,
                          progress=False)
    spec = fit_spec(start, "rotation,kd1")
    assert spec.period("rotation") == 180.0
    r = fit(table, spec, start.forward(table.wi, table.wo), seed=2, progress=False,
            max_steps=200, n_starts=2, out_dir=tmp_path)
    s = r.summary["rotation"]
    off = (s["median"] - 89.7 + 90.0) % 180.0 - 90.0      # circular distance to the truth
    assert abs(off) < 1.0, s
    assert s["lo95"] - 180.0 <= 89.7 - 180.0 <= s["hi95"] or s["lo95"] <= 89.7 <= s["hi95"], s
    assert not [w for w in r.warnings if w["kind"] == "at_bound"
                and "rotation" in w["parameters"]], r.warnings
    median = r.spec.to_natural(r.median_internal())[0]
    assert abs((median - 89.7 + 90.0) % 180.0 - 90.0) < 1.0


def test_the_measured_datasets_rotation_is_circular_where_the_preset_repeats():
    """polyester's satin is symmetric under a half turn (its -90 and +90 are one orientation);
    velvet's pile is not: its rotation spans a whole turn, [-180, 180], not half of one."""
    from analysis.measured import measured_spec
    assert measured_spec("curet_02_polyester")[0].period("rotation") == 180.0
    assert measured_spec("curet_44_linen")[0].period("rotation") == 180.0
    velvet = measured_spec("curet_07_velvet")[0]
    assert velvet.period("rotation") == 360.0
    assert (velvet.params["rotation"].lo, velvet.params["rotation"].hi) == (-180.0, 180.0)
    assert measured_spec("curet_02_polyester")[0].params["rotation"].hi == 90.0
