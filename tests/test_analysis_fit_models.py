"""Fits of every model (analysis.families): the parameter catalogue each baseline derives from
its PARAMS, the identifiability choices on grey and relative tables, the forward model against
the model's own eval, and the issue's acceptance criterion on simulated tables: Lambert data
rank `lambert` first (or within its se), microcylinder data put `microcylinder` first by more
than 4 se over every sheen model. (The heavier version: bench/bench_models.py.)"""

import json
import math

import numpy as np
import pytest

import brdf
from _fitmodels import random_pairs
from analysis.families import MICROCYLINDER, family, family_of, model_names
from analysis.fit import LogPosterior, fit, fit_fabric, fit_spec, forward_model
from analysis.fit.compare import compare_fits
from analysis.fit.medians import median_fabric
from analysis.params import ParamSpec
from brdf import MODELS
from brdf.baselines import BaselineModel, Lambert
from gonio.table import Table

BASELINES = tuple(n for n, c in MODELS.items() if issubclass(c, BaselineModel))
SHEEN = tuple(m for m in BASELINES if m != "lambert")


def test_every_baseline_catalogue_comes_from_its_params():
    for name in BASELINES:
        cls, fam = MODELS[name], family(name)
        expected = []
        for p in cls.PARAMS:
            expected += [f"{p.name}_{c}" for c in "rgb"] if p.kind == "rgb" else [p.name]
        assert fam.model_names == tuple(expected)
        assert fam.names == tuple(expected) + ("scale", "log_noise")
        spec = ParamSpec(fam.model_names, family=fam)
        for p in cls.PARAMS:
            n = f"{p.name}_g" if p.kind == "rgb" else p.name
            assert (spec.params[n].lo, spec.params[n].hi) == tuple(map(float, p.typical))
            assert spec.params[n].prior == ("log-uniform" if p.log_scale else "uniform")
        # the alias names the three channels; a microcylinder name is refused, naming the model's
        rgb = [p.name for p in cls.PARAMS if p.kind == "rgb"]
        assert ParamSpec(rgb[0], family=fam).free == tuple(f"{rgb[0]}_{c}" for c in "rgb")
        with pytest.raises(ValueError, match="unknown free parameter 'eta1'.*base_r"):
            ParamSpec("eta1", family=fam)
    assert family(None) is family(MICROCYLINDER)
    with pytest.raises(ValueError, match="unknown model 'phong'; models: microcylinder"):
        family("phong")


@pytest.mark.parametrize("name", BASELINES)
def test_default_free_sets_are_identifiable_on_grey_and_relative_tables(name):
    fam = family(name)
    rgb = [q for q in fam.aliases]
    free, ties, notes = fam.default_free()
    assert free == fam.model_names and ties == () and notes == ()
    free, ties, notes = fam.default_free(grey=True)
    assert set(ties) == {f"{q}_{c}={q}_r" for q in rgb for c in "gb"}
    assert set(free) == set(fam.model_names) - {f"{q}_{c}" for q in rgb for c in "gb"}
    assert "grey table" in notes[0]
    # relative: the scale carries the level; the base is fixed (Lambert) or 1 - the sheen's
    # share (a sheen model); grey: all three channels, RGB: the red one
    free, ties, notes = fam.default_free(grey=True, relative=True)
    assert "scale" in free and not any(n.startswith("base_") for n in free)
    mixed = {f"base_{c}=1-sheen_r" for c in "rgb"} if "sheen" in rgb else set()
    assert {t for t in ties if t.startswith("base_")} == mixed
    free, ties, _ = fam.default_free(relative=True)
    assert "base_r" not in free and {"base_g", "base_b", "scale"} <= set(free)
    assert {t for t in ties if t.startswith("base_")} == ({"base_r=1-sheen_r"} if mixed
                                                          else set())
    # every choice leaves a valid spec, whose values follow the ties
    for grey in (False, True):
        for relative in (False, True):
            free, ties, _ = fam.default_free(grey=grey, relative=relative)
            spec = ParamSpec(free, ties=ties, family=fam)
            v = spec.values(np.full((1, spec.ndim), 0.3))
            if grey:
                for q in rgb:
                    assert v[f"{q}_g"] == v[f"{q}_b"] == v[f"{q}_r"]
            if relative and mixed:
                assert v["base_r"] == pytest.approx(1.0 - v["sheen_r"])


def _table(brdf_obj, n=120, seed=0, rel=0.05, meta=None, grey=False):
    wi, wo = random_pairs(n, seed)
    f = np.asarray(brdf_obj.eval(wi, wo), dtype=float)
    if grey:
        f = np.repeat(f.mean(axis=-1, keepdims=True), 3, axis=-1)
    sig = rel * f + 1e-4
    noise = np.random.default_rng(seed + 1).normal(size=f.shape)
    vals = f + sig * (np.repeat(noise[:, :1], 3, axis=-1) if grey else noise)
    return Table(wi, wo, vals, sigma=sig, meta=meta or {"source": "simulated"})


def test_fit_spec_reads_grey_and_relative_from_the_table():
    t = _table(Lambert(base=0.4), grey=True, meta={"source": "s", "relative": True})
    spec = fit_spec(Lambert(), table=t)
    assert spec.free == ("scale",) and spec.model == "lambert"
    assert any("relative table" in n for n in spec.notes)
    rgb = _table(Lambert(base=(0.2, 0.4, 0.6)))
    assert fit_spec(Lambert(), table=rgb).free == ("base_r", "base_g", "base_b")
    # the microcylinder's default is unchanged
    assert fit_spec(brdf.fabric("velvet"), table=rgb).free[:3] == ("eta1", "kd1", "kd2")


@pytest.mark.parametrize("name", BASELINES)
def test_forward_model_is_the_models_eval_at_the_spec_values(name):
    cls = MODELS[name]
    fam = family(name)
    wi, wo = random_pairs(40, 3)
    spec = ParamSpec(fam.model_names, family=fam, defaults=fam.defaults(cls()))
    rng = np.random.default_rng(5)
    theta = rng.normal(0, 1.0, (3, spec.ndim))
    post = LogPosterior(spec, None, forward_model(cls(), wi, wo))
    pred = post.predict(theta)
    for b in range(3):
        values = {n: float(v[b]) for n, v in spec.values(theta).items()}
        model = fam.build(values)
        assert isinstance(model, cls)
        np.testing.assert_allclose(pred[b], model.eval(wi, wo), rtol=1e-12, atol=0)
    # Lambert independently: base / pi
    if name == "lambert":
        base = np.stack([spec.values(theta)[f"base_{c}"] for c in "rgb"], -1)
        np.testing.assert_allclose(pred, np.broadcast_to(base[:, None, :] / math.pi,
                                                         pred.shape), rtol=1e-12)


def test_the_posterior_is_proper_on_a_grey_relative_lambert_table():
    """Scale free, base fixed: the scale is found (truth 2 x the base's 0.5 -> data 1/pi)."""
    t = _table(Lambert(base=1.0), grey=True, meta={"source": "s", "relative": True})
    spec = fit_spec(Lambert(), table=t)
    r = fit(t, spec, forward_model(Lambert(), t.wi, t.wo), max_steps=200, check_every=50,
            progress=False)
    med = r.summary["scale"]["median"]
    assert med == pytest.approx(2.0, rel=0.03)
    assert r.summary["scale"]["hi95"] / r.summary["scale"]["lo95"] < 1.1


def test_a_sheen_five_times_its_base_is_not_boxed_in_on_a_relative_table():
    """Ashikhmin's plain sum: scale (sheen L + base / pi) is linear, so a relative table
    tells the ratio sheen / base alone. Truth 0.75 / 0.15 = 5, beyond the ratio 2 that a base
    fixed at 0.5 allowed: with base = 1 - sheen the sheen is the share 0.75 / 0.9 = 0.833
    and the scale the sum 0.9, neither at a bound."""
    truth = MODELS["ashikhmin"](base=0.15, sheen=0.75, roughness=0.5)
    t = _table(truth, n=150, grey=True, meta={"source": "s", "relative": True}, seed=4)
    start = MODELS["ashikhmin"]()
    spec = fit_spec(start, table=t)
    assert spec.ties["base_r"][0] == "sheen_r" and spec.ties["base_r"][1] != "equal"
    r = fit(t, spec, forward_model(start, t.wi, t.wo), max_steps=300, check_every=50,
            progress=False, seed=2)
    sheen, scale = r.summary["sheen_r"], r.summary["scale"]
    assert sheen["lo95"] <= 0.75 / 0.9 <= sheen["hi95"], sheen
    assert sheen["hi95"] < 0.95                                 # far from the bound 1
    assert scale["lo95"] <= 0.9 <= scale["hi95"], scale
    assert not [w for w in r.warnings if w["kind"] == "at_bound"]


def _fit_all(table, starts, out):
    """Short fits of ``table`` by each start model into out/<name>; their folders."""
    folders = {}
    for name, (obj, free) in starts.items():
        spec = fit_spec(obj, free, ("none",) if free else None, table=table)
        fit_fabric(table, obj, spec, out / name, max_steps=80, check_every=40, seed=1,
                   progress=False)
        folders[name] = out / name
    return folders


def test_lambert_data_rank_lambert_first_or_within_its_se(tmp_path):
    table = _table(Lambert(base=(0.25, 0.45, 0.65)), n=100, seed=11)
    starts = {m: (MODELS[m](), None) for m in BASELINES}
    folders = _fit_all(table, starts, tmp_path)
    rows = compare_fits(list(folders.values()), names=list(folders))
    assert {r["model"] for r in rows} == set(BASELINES)
    lam = next(r for r in rows if r["fit"] == "lambert")
    assert lam["d_elpd"] <= 2 * lam["d_se"] + 1e-9, rows
    # results.json names the model; the median model of the folder is a Lambert near truth
    doc = json.loads((folders["lambert"] / "results.json").read_text())
    assert doc["model"] == "lambert" and doc["identifiability"] == []
    med = median_fabric(folders["lambert"])
    assert med.model_name == "lambert" and med.preset is None
    np.testing.assert_allclose(med.fabric.base, (0.25, 0.45, 0.65), rtol=0.03)


def test_microcylinder_data_put_microcylinder_first_by_more_than_4_se(tmp_path):
    fab = brdf.fabric("silk_crepe_de_chine")
    table = _table(fab, n=100, seed=21)
    starts = {MICROCYLINDER: (fab, "kd1,gamma_s1"),
              **{m: (MODELS[m](), None) for m in BASELINES}}
    folders = _fit_all(table, starts, tmp_path)
    rows = compare_fits(list(folders.values()), names=list(folders))
    assert rows[0]["fit"] == MICROCYLINDER and rows[0]["model"] == MICROCYLINDER
    for r in rows[1:]:
        assert r["d_elpd"] > 4 * r["d_se"] > 0, r
    assert {r["fit"] for r in rows[1:]} >= set(SHEEN)


def test_family_of_refuses_what_is_no_model():
    assert family_of(Lambert()).name == "lambert"
    assert family_of(brdf.fabric("velvet")).is_default
    with pytest.raises(ValueError, match="not a model a fit knows: str"):
        family_of("velvet")
    assert model_names()[0] == MICROCYLINDER and set(BASELINES) <= set(model_names())


def test_a_spec_and_start_of_different_models_are_refused(tmp_path):
    t = _table(Lambert())
    spec = fit_spec(brdf.fabric("velvet"), "kd1")
    with pytest.raises(ValueError, match="the spec is of model microcylinder, the start of "
                                         "model lambert"):
        fit_fabric(t, Lambert(), spec, tmp_path / "x", max_steps=10, progress=False)
    assert not (tmp_path / "x" / "fit_config.json").exists()


def test_folders_written_before_models_read_as_microcylinder_and_resume(tmp_path):
    """A fit_config.json and results.json without "model" (written before models were named)
    read as microcylinder: the same fit resumes there, another model is refused in one line."""
    from analysis.fit.results import read_results
    fab = brdf.fabric("silk_crepe_de_chine")
    table = _table(fab, n=60, seed=31)
    spec = fit_spec(fab, "kd1", ("none",))
    out = tmp_path / "old"
    fit_fabric(table, fab, spec, out, max_steps=20, check_every=10, progress=False)
    for name in ("fit_config.json", "results.json"):
        doc = json.loads((out / name).read_text())
        (doc["config"] if name == "fit_config.json" else doc).pop("model")
        (out / name).write_text(json.dumps(doc))
    assert read_results(out / "results.json")["model"] == MICROCYLINDER
    assert median_fabric(out, preset="silk_crepe_de_chine").model_name == MICROCYLINDER
    r = fit_fabric(table, fab, spec, out, max_steps=40, check_every=10, progress=False)
    assert r.timing.get("resumed_from") == 20
    lam = fit_spec(Lambert(), table=table)
    with pytest.raises(ValueError) as info:
        fit_fabric(table, Lambert(), lam, out, max_steps=40, progress=False)
    assert "holds a fit of model microcylinder, not lambert" in str(info.value)
    assert "\n" not in str(info.value)
