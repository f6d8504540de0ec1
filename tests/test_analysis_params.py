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
    theta = spec.start()[None].repeat(2, 0)
    theta[1, spec.free.index("eta1")] = 1.7
    theta[1, spec.free.index("area1")] = 0.6
    v = spec.values(theta)
    assert v["eta2"][1] == 1.7 and v["eta1"][1] == 1.7
    assert v["area2"][1] == pytest.approx(0.4)
    # --free eta2 --tie eta2=eta1: only eta2 is free, so eta1 follows eta2 (swapped)
    s2 = ParamSpec("eta2", defaults=D, ties="eta2=eta1")
    assert s2.free == ("eta2",) and s2.ties == {"eta1": ("eta2", "equal")}
    assert s2.values(np.array([1.33]))["eta1"] == 1.33


def test_log_uniform_internal_coordinates_and_prior():
    spec = ParamSpec("gamma_s1,kd1", defaults=D)
    u = spec.start()
    assert u[0] == pytest.approx(np.log(5.0)) and u[1] == 0.2
    assert spec.values(np.array([np.log(7.0), 0.5]))["gamma_s1"] == pytest.approx(7.0)
    lp = spec.log_prior(np.array([[np.log(7.0), 0.5], [np.log(7.0), 1.2],
                                  [np.log(100.0), 0.5]]))
    assert lp[0] == 0.0 and np.isneginf(lp[1]) and np.isneginf(lp[2])


def test_area_sum_constraint():
    spec = ParamSpec("area1,area2", defaults=D)
    lp = spec.log_prior(np.array([[0.5, 0.4], [0.7, 0.4]]))
    assert lp[0] == 0.0 and np.isneginf(lp[1])


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
    kw = spec.model_kwargs(spec.values(np.array([[0.9], [0.1]])))
    assert kw["kd"].shape == (2, 2) and kw["albedo"].shape == (2, 2, 3)
    assert kw["kd"][0].tolist() == [0.9, 0.3]
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
    assert spec.start()[1] == 5.0          # uniform prior now: internal = natural
    bad = tmp_path / "bad.toml"
    bad.write_text("free = [\n")
    with pytest.raises(ValueError, match="bad.toml: not valid TOML"):
        ParamSpec.from_toml(bad, defaults=D)
