"""Every model of the registry (brdf.MODELS) against the model protocol (brdf.Model).

One suite, parametrised over the registry: adding a model is its module and its registry
line, and it is checked here. Each check is a function of the model class (``check_*``), run
over every registered model and, by ``test_a_registered_toy_model_flows_through_...``, over a
toy model registered in the test, which also goes through a fit's forward model.

What is checked, each against something computed independently of the model's code:
shapes and broadcasting (against a loop over pairs); f_r >= 0 and finite above the horizon,
0 below; units (f_r in 1/sr: a Lambert of albedo a is a / pi; the toy's analytic albedo); the
model's claim of reciprocity (``reciprocal``); the directional albedo of its start values
by a midpoint rule over (cos theta, phi), at most 1, and the same as analysis.albedo's
quadrature; the sampler's histogram against its pdf (chi-square, tests/_chi2.py), the pdf
integrating to 1 and sample's weight being f_r cos / pdf; the batched forward model and
``prepare().eval`` against single evaluations of ``with_values`` models.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import brdf
from _chi2 import cell_integrals, chi2_pvalue, histogram, sidak
from analysis.albedo import albedo
from analysis.families import family
from analysis.fit import LogPosterior, fit_fabric, fit_spec, forward_model
from analysis.fit.medians import median_fabric
from brdf import MODELS
from brdf.baselines import BaselineModel
from brdf.schema import ParamInfo
from gonio.table import Table

NAMES = list(MODELS)
#: Chi-square tests in this module (each registered model once): the significance of each.
ALPHA = sidak(0.01, len(NAMES) + 1)


def _dirs(n, rng, lo=0.05):
    """n unit directions above the horizon, cos(theta) uniform in [lo, 1]."""
    c = rng.uniform(lo, 1.0, n)
    p = rng.uniform(0.0, 2.0 * math.pi, n)
    s = np.sqrt(1.0 - c * c)
    return np.stack([s * np.cos(p), s * np.sin(p), c], axis=-1)


def _from_angles(theta_deg, phi_deg=0.0):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def _perturbed(cls, model, k, rng):
    """k value sets (flat names) inside each parameter's search range, between the start and
    a random point, drawn nearer the start until the model takes them (a fabric's areas
    sum to at most 1)."""
    schema = cls.param_schema()
    start = model.values()
    out = []
    while len(out) < k:
        far = {}
        for p in schema:
            q = rng.uniform(0.25, 0.75)
            far[p.name] = p.lo + q * (p.hi - p.lo) if p.prior == "uniform" else \
                math.exp(math.log(p.lo) + q * (math.log(p.hi) - math.log(p.lo)))
        for w in (0.5, 0.25, 0.1):
            v = {n: (1 - w) * start[n] + w * far[n] for n in schema.names}
            try:
                model.with_values(v)
            except ValueError:
                continue
            out.append(v)
            break
    return out


# -- the checks, each a function of a model class ----------------------------------------------
def check_protocol(cls):
    model = cls.start()
    assert isinstance(model, brdf.Model) and brdf.model_class(brdf.model_name(model)) is cls
    schema = cls.param_schema()
    assert len(set(schema.names)) == len(schema.names) > 0
    assert tuple(model.values()) == schema.names
    for p in schema:
        assert p.lo < p.hi and p.prior in ("uniform", "log-uniform") and p.unit
        assert p.lo <= model.values()[p.name] <= p.hi, p.name
        assert p.info.contains(p.lo) or p.info.contains(p.hi)
    for group, names in schema.aliases.items():
        assert [schema[n].channel for n in names] == [0, 1, 2] and group not in schema
    assert model.with_values({}).values() == model.values()
    assert set(cls.CONSTRAINED) <= set(schema.names)
    start = {n: np.array([v]) for n, v in model.values().items()}
    assert cls.admissible(start).tolist() == [True]


def check_shapes_and_broadcasting(cls):
    model, rng = cls.start(), np.random.default_rng(1)
    wi, wo = _dirs(4, rng)[:, None, :], _dirs(5, rng)[None, :, :]
    f = model.eval(wi, wo)
    assert f.shape == (4, 5, 3) and f.dtype == np.float64
    loop = np.array([[model.eval(wi[a, 0], wo[0, b]) for b in range(5)] for a in range(4)])
    np.testing.assert_allclose(f, loop, rtol=1e-12, atol=0)
    assert model.eval(wi[0, 0], wo[0, 0]).shape == (3,)
    assert model.pdf(wo[0, :2], wi[:3, 0][:, None]).shape == (3, 2)
    got_wi, weight, pdf = model.sample(wo[0, 0], rng.random((7, 2)))
    assert got_wi.shape == (7, 3) and weight.shape == (7, 3) and pdf.shape == (7,)


def check_nonnegative_finite_and_zero_below(cls):
    model, rng = cls.start(), np.random.default_rng(2)
    wi, wo = _dirs(400, rng, lo=1e-6), _dirs(400, rng, lo=1e-6)
    f = model.eval(wi, wo)
    assert np.all(np.isfinite(f)) and f.min() >= 0.0
    below = wi * np.array([1.0, 1.0, -1.0])
    assert np.all(model.eval(below, wo) == 0.0) and np.all(model.eval(wi, below) == 0.0)


def check_reciprocity_as_claimed(cls):
    model, rng = cls.start(), np.random.default_rng(3)
    wi, wo = _dirs(300, rng, lo=0.1), _dirs(300, rng, lo=0.1)
    a, b = model.eval(wi, wo), model.eval(wo, wi)
    if cls.reciprocal:
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-14)
    else:                           # a model that says it is not: some pair shows it
        assert np.max(np.abs(a - b) / np.maximum(np.maximum(a, b), 1e-300)) > 1e-6


def midpoint_albedo(model, wo, n=96):
    """Integral of f_r(wi, wo) cos(theta_i) over the hemisphere of wi, RGB: the midpoint
    rule on n x 2n cells of (cos theta_i, phi_i) (d omega = d cos theta d phi)."""
    mu = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) * math.pi / n
    m, p = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - m * m)
    wi = np.stack([s * np.cos(p), s * np.sin(p), m], axis=-1).reshape(-1, 3)
    f = model.eval(wi, wo)
    return (f * m.reshape(-1, 1)).sum(axis=0) * (1.0 / n) * (math.pi / n)


def check_albedo_at_most_one(cls):
    model = cls.start()
    for theta in (0.0, 50.0, 80.0):
        wo = _from_angles(theta, 30.0)
        mid = midpoint_albedo(model, wo)
        assert np.all(mid >= 0.0) and np.all(mid <= 1.0), (theta, mid)
        ref = albedo(model, wo).value
        np.testing.assert_allclose(mid, ref, rtol=0.03, atol=2e-3)


def check_sampler_against_pdf(cls, alpha=ALPHA, n=40000):
    model = cls.start()
    wo = _from_angles(40.0, 20.0)
    rng = np.random.default_rng(4)
    wi, weight, pdf = model.sample(wo, rng.random((n, 2)))
    ok = pdf > 0
    assert ok.mean() > 0.99
    # the pdf of what was drawn is pdf(); weight is f_r cos / pdf
    np.testing.assert_allclose(pdf[ok], model.pdf(wo, wi[ok]), rtol=1e-10)
    want = model.eval(wi[ok], wo) * wi[ok, 2:3] / pdf[ok, None]
    np.testing.assert_allclose(weight[ok], want, rtol=1e-9, atol=1e-300)
    expected = cell_integrals(lambda w: model.pdf(wo, w))
    assert expected.sum() == pytest.approx(1.0, abs=2e-3)          # a density of directions
    _, _, p = chi2_pvalue(histogram(wi[ok]), expected * ok.sum())
    assert p > alpha, f"{cls.__name__}: chi-square p = {p:.3g}"


def check_batched_equals_single(cls):
    model, rng = cls.start(), np.random.default_rng(6)
    wi, wo = _dirs(30, rng), _dirs(30, rng)
    np.testing.assert_allclose(model.prepare(wi, wo).eval(), model.eval(wi, wo),
                               rtol=1e-12, atol=0)
    sets = _perturbed(cls, model, 3, rng)
    values = {n: np.array([s[n] for s in sets]) for n in cls.param_schema().names}
    got = model.forward(wi, wo)(**cls.batch_kwargs(values))
    assert got.shape == (3, 30, 3)
    for b, s in enumerate(sets):
        np.testing.assert_allclose(got[b], model.with_values(s).eval(wi, wo),
                                   rtol=1e-11, atol=0)


CHECKS = [check_protocol, check_shapes_and_broadcasting, check_nonnegative_finite_and_zero_below,
          check_reciprocity_as_claimed, check_albedo_at_most_one, check_sampler_against_pdf,
          check_batched_equals_single]


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__[len("check_"):])
@pytest.mark.parametrize("name", NAMES)
def test_every_registered_model_conforms(name, check):
    check(MODELS[name])


def test_the_registry_holds_every_model_once():
    assert NAMES[0] == brdf.DEFAULT_MODEL == "microcylinder" and MODELS["microcylinder"] is \
        brdf.Fabric
    assert len(set(MODELS.values())) == len(MODELS)
    for name, cls in MODELS.items():
        if issubclass(cls, BaselineModel):
            assert cls.name == name
    with pytest.raises(ValueError, match="unknown model 'phong'; models: microcylinder"):
        brdf.model_class("phong")


def test_units_a_lambert_of_albedo_a_is_a_over_pi():
    a = (0.1, 0.45, 0.9)
    lam = MODELS["lambert"].start().with_values(dict(zip(("base_r", "base_g", "base_b"), a)))
    rng = np.random.default_rng(7)
    f = lam.eval(_dirs(50, rng), _dirs(50, rng))
    np.testing.assert_allclose(f, np.broadcast_to(np.array(a) / math.pi, f.shape), rtol=1e-15)
    np.testing.assert_allclose(midpoint_albedo(lam, _from_angles(30.0)), a, rtol=1e-12)


def test_microcylinder_values_round_trip_through_the_fabric():
    fab = brdf.fabric("silk_crepe_de_chine")
    v = fab.values()
    assert v["gamma_s1"] == fab.threads[0].gamma_s and v["albedo2_r"] == pytest.approx(0.16)
    moved = fab.with_values({"kd2": 0.55, "albedo1_g": 0.3, "tangent_scale1": 0.5})
    assert moved.threads[1].kd == 0.55 and moved.threads[0].albedo[1] == 0.3
    assert moved.threads[0].offsets == (-17.5, -17.5, 17.5, 17.5)
    assert moved.options == fab.options and moved.name == fab.name
    with pytest.raises(ValueError, match="thread 2: kd"):
        fab.with_values({"kd2": 1.5})
    # the areas are constrained together: what with_values refuses, admissible says
    areas = {"area1": np.array([0.5, 0.6]), "area2": np.array([0.5, 0.6])}
    assert type(fab).admissible(areas).tolist() == [True, False]
    with pytest.raises(ValueError, match="areas must sum to at most 1"):
        fab.with_values({"area1": 0.6, "area2": 0.6})


# -- a toy model, registered in the test -------------------------------------------------------
#: The toy's exponent k: f_r = base (k + 2) / (2 pi) (cos_i cos_o)^k.
EXPONENT = ParamInfo("k", "scalar", "1", 0.0, 6.0, "k", "exponent of the cosines",
                     typical=(0.0, 3.0), typical_value=1.0)


class Toy(BaselineModel):
    """f_r = base (k + 2) / (2 pi) (cos_i cos_o)^k (1/sr): reciprocal, directional albedo
    base cos_o^k (analytic: the integral of cos^(k+1) over the hemisphere is 2 pi / (k + 2))."""

    name = "toy"
    PARAMS = (brdf.baselines.BASE, EXPONENT)
    reciprocal = True

    @classmethod
    def geometry(cls, wi, wo):
        return {"c": wi[:, 2] * wo[:, 2]}

    @classmethod
    def shade(cls, geom, base, k):
        k = np.asarray(k)[..., None]
        lobe = (k + 2.0) / (2.0 * math.pi) * geom["c"] ** k           # (B..., n)
        return base[..., None, :] * lobe[..., None]


def test_a_registered_toy_model_flows_through_the_checks_and_the_fit(monkeypatch, tmp_path):
    monkeypatch.setitem(MODELS, "toy", Toy)
    for check in CHECKS:
        check(Toy, **({"alpha": 0.01} if check is check_sampler_against_pdf else {}))
    # its albedo is the analytic one
    toy = Toy(base=(0.2, 0.5, 0.8), k=2.0)
    wo = _from_angles(40.0)
    np.testing.assert_allclose(midpoint_albedo(toy, wo, n=256),
                               np.array([0.2, 0.5, 0.8]) * wo[2] ** 2, rtol=1e-4)
    # a fit knows it by its registry name: names, default free set, forward model
    fam = family("toy")
    assert fam.names == ("base_r", "base_g", "base_b", "k", "scale", "log_noise")
    rng = np.random.default_rng(8)
    wi, wo = _dirs(40, rng), _dirs(40, rng)
    table = Table(wi, wo, toy.eval(wi, wo), sigma=np.full((40, 3), 0.01), meta={"source": "toy"})
    spec = fit_spec(Toy(), table=table)
    assert spec.family is fam and spec.free == ("base_r", "base_g", "base_b", "k")
    post = LogPosterior(spec, None, forward_model(Toy(), wi, wo))
    theta = rng.normal(0.0, 1.0, (3, spec.ndim))
    pred = post.predict(theta)
    for b in range(3):
        v = {n: float(x[b]) for n, x in spec.values(theta).items()}
        want = (np.array([v["base_r"], v["base_g"], v["base_b"]]) * (v["k"] + 2.0)
                / (2.0 * math.pi) * ((wi[:, 2] * wo[:, 2]) ** v["k"])[:, None])
        np.testing.assert_allclose(pred[b], want, rtol=1e-12)
    # and a whole fit: results.json names it, its medians make a Toy near the truth
    r = fit_fabric(table, Toy(), spec, tmp_path / "toy", max_steps=120, check_every=60,
                   seed=2, progress=False)
    assert json.loads((tmp_path / "toy" / "results.json").read_text())["model"] == "toy"
    med = median_fabric(tmp_path / "toy")
    assert isinstance(med.fabric, Toy) and med.model_name == "toy" and med.preset is None
    assert r.summary["k"]["lo95"] < 2.0 < r.summary["k"]["hi95"]
    np.testing.assert_allclose(med.fabric.base, (0.2, 0.5, 0.8), rtol=0.05)
