"""Tests of analysis.params: names, ties, priors, bounds, TOML."""

import numpy as np
import pytest

from analysis.params import (DEFAULT_FREE, DEFAULT_TIES, PARAM_NAMES, ParamSpec, parse_free,
                             parse_ties)

D = {"eta1": 1.5, "eta2": 1.4, "kd1": 0.2, "kd2": 0.3, "gamma_s1": 5.0, "gamma_s2": 18.0,
     "gamma_v1": 10.0, "gamma_v2": 32.0, "area1": 0.75, "area2": 0.25,
     "albedo1_r": 0.1, "albedo1_g": 0.2, "albedo1_b": 0.3,
     "albedo2_r": 0.4, "albedo2_g": 0.5, "albedo2_b": 0.6}


def test_names_and_aliases():
    assert len([n for n in PARAM_NAMES if n.endswith("1") or "1_" in n]) == 9
    assert parse_free("albedo1,eta2") == ("albedo1_r", "albedo1_g", "albedo1_b", "eta2")
    with pytest.raises(ValueError, match="unknown free parameter 'etta1'.*eta1, kd1"):
        parse_free("etta1")
    with pytest.raises(ValueError, match="none given"):
        parse_free(" , ")


def test_ties_equal_complement_and_swap():
    assert parse_ties("eta2=eta1,area2=1-area1") == {"eta2": ("eta1", "equal"),
                                                      "area2": ("area1", "complement")}
    with pytest.raises(ValueError, match="tie"):
        parse_ties("eta1==eta2")
    with pytest.raises(ValueError, match="unknown tied parameter 'foo'"):
        parse_ties("foo=eta1")
    spec = ParamSpec(DEFAULT_FREE, defaults=D, ties=DEFAULT_TIES)
    assert spec.ndim == 8 and "eta2" not in spec.free and "area2" not in spec.free
    x = spec.to_natural(spec.start()[None].repeat(2, 0))
    x[1, spec.free.index("eta1")] = 1.7
    x[1, spec.free.index("area1")] = 0.6
    v = spec.values(spec.to_internal(x))
    assert v["eta2"][1] == v["eta1"][1] == pytest.approx(1.7, rel=1e-12)
    assert v["area2"][1] == pytest.approx(0.4, rel=1e-12)
    # --free eta2 --tie eta2=eta1: only eta2 is free, so eta1 follows eta2 (swapped)
    s2 = ParamSpec("eta2", defaults=D, ties="eta2=eta1")
    assert s2.free == ("eta2",) and s2.ties == {"eta1": ("eta2", "equal")}
    assert s2.values(s2.to_internal(np.array([1.33])))["eta1"] == pytest.approx(1.33, rel=1e-12)


def test_internal_coordinates_are_logits_of_the_position_within_the_bounds():
    spec = ParamSpec("gamma_s1,kd1", defaults=D)      # gamma_s log-uniform [0.3, 60] deg
    u = spec.start()
    q = (np.log(5.0) - np.log(0.3)) / (np.log(60.0) - np.log(0.3))
    assert u[0] == pytest.approx(np.log(q / (1 - q)), rel=1e-12)
    assert u[1] == pytest.approx(np.log(0.2 / 0.8), rel=1e-12)
    x = np.array([[7.0, 0.5], [0.31, 0.999], [59.0, 1e-6]])
    np.testing.assert_allclose(spec.to_natural(spec.to_internal(x)), x, rtol=1e-9)
    assert spec.values(spec.to_internal(x))["gamma_s1"][0] == pytest.approx(7.0, rel=1e-12)
    # outside the bounds there is no internal value
    assert np.isnan(spec.to_internal(np.array([100.0, 0.5]))[0])


def test_log_prior_is_flat_in_the_natural_value():
    """Prior mass of an interval of kd (uniform) and of gamma_s (log-uniform), integrated in
    the internal coordinate, equals its share of the range."""
    spec = ParamSpec("gamma_s1,kd1", defaults=D)
    u = np.linspace(-40, 40, 400001)
    th = np.stack([np.zeros_like(u), u], -1)
    w = np.exp(spec.log_prior(th))                    # gamma_s at its mid-point, kd varies
    kd = spec.to_natural(th)[:, 1]
    share = np.trapezoid(w * ((kd > 0.2) & (kd < 0.5)), u) / np.trapezoid(w, u)
    assert share == pytest.approx(0.3, abs=1e-4)
    th = np.stack([u, np.zeros_like(u)], -1)
    w = np.exp(spec.log_prior(th))
    g = spec.to_natural(th)[:, 0]
    share = np.trapezoid(w * ((g > 1.0) & (g < 10.0)), u) / np.trapezoid(w, u)
    assert share == pytest.approx(np.log(10) / np.log(200), abs=1e-4)
    assert np.isneginf(spec.log_prior(np.array([[0.0, 41.0]]))[0])


def test_area_sum_constraint():
    spec = ParamSpec("area1,area2", defaults=D)
    lp = spec.log_prior(spec.to_internal(np.array([[0.5, 0.4], [0.7, 0.4]])))
    assert np.isfinite(lp[0]) and np.isneginf(lp[1])


def test_start_outside_bounds_is_an_error():
    with pytest.raises(ValueError, match="start value of gamma_s1 = 5 deg lies outside.*"
                                         r"\[6, 20\]"):
        ParamSpec("gamma_s1", defaults=D, bounds={"gamma_s1": (6, 20)})
    with pytest.raises(ValueError, match="prior"):
        ParamSpec("kd1", defaults=D, priors={"kd1": "gaussian"})
    with pytest.raises(ValueError, match="log-uniform prior of kd1 needs lo > 0"):
        ParamSpec("kd1", defaults=D, priors={"kd1": "log-uniform"})


def test_model_kwargs_layout():
    spec = ParamSpec("kd1", defaults=D)
    kw = spec.model_kwargs(spec.values(spec.to_internal(np.array([[0.9], [0.1]]))))
    assert kw["kd"].shape == (2, 2) and kw["albedo"].shape == (2, 2, 3)
    np.testing.assert_allclose(kw["kd"][0], [0.9, 0.3], rtol=1e-12)
    assert kw["albedo"][1].tolist() == [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]
    assert kw["gamma_s"][0].tolist() == [5.0, 18.0]


def test_from_toml(tmp_path):
    p = tmp_path / "spec.toml"
    p.write_text('free = ["eta1", "gamma_s1"]\ntie = ["eta2=eta1"]\n'
                 '[bounds]\neta1 = [1.2, 1.8]\n[prior]\ngamma_s1 = "uniform"\n'
                 '[start]\neta1 = 1.6\n')
    spec = ParamSpec.from_toml(p, defaults=D, free="kd2")
    assert spec.free == ("eta1", "gamma_s1", "kd2")
    assert spec.params["eta1"].lo == 1.2 and spec.params["eta1"].default == 1.6
    q = (5.0 - 0.3) / (60.0 - 0.3)           # uniform prior now: linear position in [0.3, 60]
    assert spec.start()[1] == pytest.approx(np.log(q / (1 - q)), rel=1e-12)
    bad = tmp_path / "bad.toml"
    bad.write_text("free = [\n")
    with pytest.raises(ValueError, match="bad.toml: not valid TOML"):
        ParamSpec.from_toml(bad, defaults=D)


def test_contradictory_ties_are_refused():
    with pytest.raises(ValueError, match="tie eta2=eta1: both eta2 and eta1 are listed free"):
        ParamSpec("eta1,eta2", defaults=D, ties="eta2=eta1")
    with pytest.raises(ValueError, match="tie eta2=eta1: neither eta2 nor eta1 is free"):
        ParamSpec("kd1", defaults=D, ties="eta2=eta1")
    with pytest.raises(ValueError, match="eta2 is already tied to eta1"):
        parse_ties("eta2=eta1,eta2=kd1")
    with pytest.raises(ValueError, match="already tied"):
        ParamSpec("eta1,kd1", defaults=D, ties="eta2=eta1,kd1=eta2")
    with pytest.raises(ValueError, match=r"ties: item 1 is int 1"):
        parse_ties([1])


def test_from_toml_checks_every_key(tmp_path):
    def spec(text):
        p = tmp_path / "s.toml"
        p.write_text(text)
        return ParamSpec.from_toml(p, defaults=D)

    assert spec('free = ["eta1"]\ntie = "eta2=eta1"\n').ties == {"eta2": ("eta1", "equal")}
    for text, key in [('free = ["eta1"]\ntie = [1]\n', "'tie'"),
                      ('free = 3\n', "'free'"),
                      ('free = ["eta1"]\n[start]\neta1 = {a = 1}\n', "start value of eta1"),
                      ('free = ["eta1"]\n[bounds]\neta1 = [1, {a = 2}]\n', "upper bound of eta1"),
                      ('free = ["eta1"]\n[bounds]\neta1 = 3\n', "bounds of eta1"),
                      ('free = ["eta1"]\nbounds = 3\n', "'bounds'"),
                      ('free = ["eta1"]\n[prior]\neta1 = 2\n', "prior of eta1"),
                      ('free = ["eta1"]\n[start]\netta = 2\n', "etta"),
                      ('free = ["eta1", "eta2"]\ntie = ["eta2=eta1"]\n', "both eta2 and eta1"),
                      ('fabric = 1\nfree = ["eta1"]\n', "'fabric'")]:
        with pytest.raises(ValueError, match=key) as err:
            spec(text)
        assert "s.toml" in str(err.value)


def test_to_natural_is_each_parameters_own_map_column_by_column():
    """ParamSpec.to_natural (one pass over all columns) gives, bit for bit, what each free
    parameter's Param.to_natural gives its column (log, uniform and circular ones, a NaN
    and an infinity), for a batch and for one vector."""
    spec = ParamSpec(["gamma_s1", "kd1", "eta1", "rotation", "albedo1_g"],
                     periods={"rotation": 180.0})
    assert spec.circular.tolist() == [False, False, False, True, False]
    assert spec.params["gamma_s1"].is_log and not spec.params["kd1"].is_log
    rng = np.random.default_rng(5)
    theta = rng.normal(size=(40, spec.ndim)) * np.array([3.0, 30.0, 0.5, 9.0, 800.0])
    theta[0, 1], theta[1, 4] = np.nan, np.inf
    got = spec.to_natural(theta)
    for i, name in enumerate(spec.free):
        if name == "rotation":          # wrapped into [-90, 90): checked by its own test
            assert np.all((got[:, i] >= -90.0) & (got[:, i] < 90.0))
            continue
        want = spec.params[name].to_natural(theta[:, i])
        assert np.array_equal(got[:, i], want, equal_nan=True), name
    assert np.array_equal(spec.to_natural(theta[3]), got[3])
