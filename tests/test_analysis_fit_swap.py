"""Two threads that can trade places (analysis.fit.swap): linen's (area1, rotation) and
(1 - area1, rotation + 90) are one fabric, so a fit keeps area1 to [0, 0.5] and reports one
mode; 0.5 is a fold, not a bound."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import fit
from analysis.fit.swap import fold_thread_swap
from analysis.fit.trust import at_bound
from analysis.fit.workflow import fit_spec
from analysis.measured import measured_spec
from analysis.params import ParamSpec, defaults_from_fabric


def _pairs(n=300, seed=5):
    v = np.random.default_rng(seed).normal(size=(2, n, 3))
    v[..., 2] = np.abs(v[..., 2]) + 0.05
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize("area, rot", [(0.3, 10.0), (0.8, -60.0), (0.45, 85.0)])
def test_swapped_threads_turned_a_quarter_are_the_same_fabric(area, rot):
    """The symmetry the fold rests on, by evaluation: equal f_r at 300 random pairs."""
    wi, wo = _pairs()
    fab = brdf.fabric("linen_plain")
    one = fab.with_values({"area1": area, "area2": 1 - area, "rotation": rot}).eval(wi, wo)
    two = fab.with_values({"area1": 1 - area, "area2": area, "rotation": rot + 90.0})
    np.testing.assert_allclose(two.eval(wi, wo), one, rtol=1e-12, atol=0.0)
    other = fab.with_values({"area1": 1 - area, "area2": area, "rotation": rot})
    assert np.max(np.abs(other.eval(wi, wo) / one - 1)) > 1e-3   # area alone is another


def test_which_fabrics_can_swap():
    """Only two threads with one tangent curve that a half turn keeps: linen's."""
    swaps = {p: brdf.fabric(p).thread_swap() for p in brdf.PRESETS}
    assert swaps == {p: (90.0 if p == "linen_plain" else None) for p in brdf.PRESETS}


def test_the_linen_type_measured_fits_are_folded_and_the_others_not():
    for name in ("curet_01_felt", "curet_44_linen", "curet_46_cotton"):
        spec = measured_spec(name)[0]
        assert (spec.params["area1"].lo, spec.params["area1"].hi) == (0.0, 0.5), name
        assert spec.folds == {"area1": 0.5}
        assert any("area1 kept to [0, 0.5]" in n for n in spec.notes)
    for name in ("curet_07_velvet", "curet_02_polyester", "rgl_white_felt"):
        spec = measured_spec(name)[0]          # another curve, or rotation fixed
        assert spec.params["area1"].hi == 1.0 and spec.folds == {}, name


def test_a_start_in_the_other_half_moves_to_the_same_fabric_in_the_kept_half():
    fab = brdf.fabric("linen_plain", rotation=np.radians(30.0)).with_values(
        {"area1": 0.7, "area2": 0.3})
    spec = fit_spec(fab, "kd1,area1,rotation", ["kd2=kd1,area2=1-area1"])
    assert spec.folds == {"area1": 0.5}
    start = dict(zip(spec.free, spec.to_natural(spec.start())))
    assert start["area1"] == pytest.approx(0.3) and start["rotation"] == pytest.approx(-60.0)
    wi, wo = _pairs(100)
    moved = fab.with_values({"area1": 0.3, "area2": 0.7, "rotation": start["rotation"]})
    np.testing.assert_allclose(moved.eval(wi, wo), fab.eval(wi, wo), rtol=1e-12)


@pytest.mark.parametrize("free, ties, why", [
    ("kd1,kd2,area1,rotation", "area2=1-area1", "kd2 free apart from kd1"),
    ("kd1,area1", "kd2=kd1,area2=1-area1", "rotation fixed"),
    ("kd1,area1,area2,rotation", "kd2=kd1", "areas not complementary"),
])
def test_no_fold_where_the_threads_differ_or_cannot_turn(free, ties, why):
    fab = brdf.fabric("linen_plain")
    spec = ParamSpec(free, defaults=defaults_from_fabric(fab), ties=ties,
                     periods=fab.periods())
    assert fold_thread_swap(spec, fab) is spec, why


def test_a_user_bound_on_the_area_is_kept():
    fab = brdf.fabric("linen_plain")
    spec = ParamSpec("kd1,area1,rotation", defaults=defaults_from_fabric(fab),
                     ties="kd2=kd1,area2=1-area1", bounds={"area1": (0.2, 0.9)},
                     periods=fab.periods())
    assert fold_thread_swap(spec, fab) is spec


def test_an_interval_reaching_the_fold_is_no_bound_warning():
    """Draws piled against 0.5 give no at_bound on a folded spec, and do on the same spec
    without the fold (so the check could fail)."""
    fab = brdf.fabric("linen_plain")
    spec = measured_spec("curet_44_linen")[0]
    x = np.tile(spec.to_natural(spec.start()), (4000, 1))
    i = spec.free.index("area1")
    x[:, i] = 0.5 - np.abs(np.random.default_rng(0).normal(0.0, 0.02, 4000))
    folded = SimpleNamespace(names=spec.free, spec=spec, samples=lambda: x)
    assert not [w for w in at_bound(folded) if "area1" in w["parameters"]]
    plain = ParamSpec(spec.free, defaults={n: p.default for n, p in spec.params.items()},
                      ties=spec.ties, bounds={"area1": (0.0, 0.5)}, periods=fab.periods())
    unfolded = SimpleNamespace(names=plain.free, spec=plain, samples=lambda: x)
    assert [w["parameters"] for w in at_bound(unfolded)] == [["area1"]]


@pytest.mark.slow
def test_a_linen_with_its_wider_thread_first_is_recovered_as_the_same_fabric(tmp_path):
    """Truth area1 = 0.75 at 20 degrees; the fit reports its twin, 0.25 at -70 degrees, inside
    the 95% intervals, with no at_bound."""
    start = brdf.fabric("linen_plain")
    truth = start.with_values({"area1": 0.75, "area2": 0.25, "rotation": 20.0})
    table = gonio.measure(truth, gonio.full_grid(30.0, 45.0),
                          gonio.Instrument(snr=30.0, floor=1e-4, max_theta=80.0,
                                           min_separation=0.0), seed=3, progress=False)
    spec = fit_spec(start, "area1,rotation", ["area2=1-area1"])
    assert spec.folds == {"area1": 0.5}
    r = fit(table, spec, start.forward(table.wi, table.wo), seed=1, progress=False,
            max_steps=200, n_starts=2, out_dir=tmp_path)
    a, rot = r.summary["area1"], r.summary["rotation"]
    assert a["lo95"] <= 0.25 <= a["hi95"], a
    assert rot["lo95"] <= -70.0 <= rot["hi95"], rot
    assert not [w for w in r.warnings if w["kind"] == "at_bound"], r.warnings


@pytest.mark.parametrize("key, value, field", [
    ("periods", {"rotation": "ninety"}, "config.spec.periods.rotation"),
    ("periods", {"rotation": -180.0}, "config.spec.periods.rotation"),
    ("folds", {"../../etc/passwd": 0.5}, "config.spec.folds"),
    ("folds", {"area1": float("nan")}, "config.spec.folds.area1"),
    ("periods", ["rotation", 180.0], "config.spec.periods"),
    ("folds", {"<script>\x1b[31m": 0.5}, "config.spec.folds"),
])
def test_a_fit_config_from_others_with_bad_periods_or_folds_is_one_line(tmp_path, key, value,
                                                                         field):
    """fit_config.json's periods and folds (what a folder's stored coordinates mean) read as
    a file from others: a value that is not a number >= 0, a name that is not a parameter,
    is one line naming the file and the field, before any ParamSpec is built."""
    import json

    from analysis.fit.checkpoint import CONFIG_FILE
    from analysis.planning.draws import fit_folder_spec
    spec = measured_spec("curet_44_linen")[0]
    doc = {"version": 8, "model": "microcylinder", "spec": spec.describe(), "extra": {}}
    assert doc["spec"]["periods"] == {"rotation": 180.0} and doc["spec"]["folds"]
    folder = tmp_path / "fit"
    folder.mkdir()
    (folder / CONFIG_FILE).write_text(json.dumps({"config": doc}))
    back, _ = fit_folder_spec(folder)                        # the folder as the fit wrote it
    assert back.period("rotation") == 180.0 and back.folds == {"area1": 0.5}
    doc["spec"][key] = value
    (folder / CONFIG_FILE).write_text(json.dumps({"config": doc}))
    with pytest.raises(ValueError) as err:
        fit_folder_spec(folder)
    text = str(err.value)
    assert "\n" not in text and str(folder / CONFIG_FILE) in text and field in text, text
    assert "\x1b" not in text
