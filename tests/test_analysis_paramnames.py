"""Tests of analysis.paramnames: the fit's names, bounds and units follow brdf.schema."""

import pytest

import brdf
from analysis.paramnames import (BASE_PARAMS, MODEL_PARAM_NAMES, PARAM_NAMES, base_of,
                                 defaults_from_fabric, entry)
from brdf import schema


@pytest.mark.parametrize("name", MODEL_PARAM_NAMES)
def test_model_parameter_bounds_lie_where_a_thread_accepts_them(name):
    lo, hi, prior, unit, fallback = entry(name)
    base, thread = base_of(name)
    info = schema.THREAD[base.split("_")[0] if base.startswith("albedo") else base]
    assert thread in (1, 2) and unit == info.unit
    assert info.contains(lo) and info.contains(hi) and lo < fallback < hi
    assert (prior == "log-uniform") == info.log_scale


def test_names_cover_every_thread_parameter_but_the_curve():
    scalars = schema.SCALAR_PARAMS
    expect = [f"{q}{j}" for j in (1, 2) for q in scalars]
    assert set(expect) <= set(MODEL_PARAM_NAMES)
    assert {f"albedo{j}_{c}" for j in (1, 2) for c in "rgb"} <= set(MODEL_PARAM_NAMES)
    assert len(MODEL_PARAM_NAMES) == 2 * (len(scalars) + 3)
    assert {"tangent_scale", "albedo_r"} <= set(BASE_PARAMS)
    assert PARAM_NAMES[-2:] == ("scale", "log_noise")


def test_defaults_from_fabric_reads_every_model_parameter():
    fab = brdf.fabric("silk_crepe_de_chine")
    d = defaults_from_fabric(fab)
    assert tuple(d) == MODEL_PARAM_NAMES
    t1, t2 = fab.threads
    assert d["gamma_v2"] == t2.gamma_v == 32 and d["area1"] == t1.area == 0.75
    assert d["albedo1_b"] == pytest.approx(0.12 * 0.05, rel=1e-15)
