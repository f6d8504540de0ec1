"""Tests of brdf.schema: the one parameter table, and that Thread and TangentCurve use it."""

import dataclasses

import pytest

import brdf
from brdf import schema


def test_table_matches_the_thread_fields():
    assert schema.THREAD_FIELDS == tuple(f.name for f in dataclasses.fields(brdf.Thread))
    assert schema.SCALAR_PARAMS == ("eta", "kd", "gamma_s", "gamma_v", "area")
    assert schema.THREAD["gamma_s"].unit == schema.THREAD["gamma_v"].unit == "deg"
    assert schema.THREAD["offsets"].unit == "deg" and schema.THREAD["eta"].unit == "1"


@pytest.mark.parametrize("info", [p for p in schema.THREAD_PARAMS if p.typical])
def test_typical_range_lies_inside_the_validated_range(info):
    lo, hi = info.typical
    assert lo < hi <= (hi if info.hi is None else info.hi)
    assert info.contains(lo) and info.contains(hi)
    assert lo <= info.typical_value <= hi
    if info.log_scale:
        assert lo > 0


@pytest.mark.parametrize("name, inside, outside", [
    ("eta", 1.0001, 1.0), ("kd", 1.0, 1.0001), ("kd", 0.0, -1e-9), ("gamma_s", 1e-6, 0.0),
    ("area", 0.0, 1.5), ("offsets", -90.0, 90.5), ("lengths", 0.0, -0.1),
])
def test_every_range_is_what_thread_accepts(name, inside, outside):
    info = schema.THREAD[name]
    assert info.contains(inside) and not info.contains(outside)
    good = dict(eta=1.46, albedo=(0.1, 0.2, 0.3), kd=0.3, gamma_s=12, gamma_v=24, area=0.33,
                offsets=(-25, 25), lengths=(1,))
    value = {"offsets": (inside, 0.0), "lengths": (inside, 1.0)}.get(name, inside)
    brdf.Thread(**dict(good, **{name: value}, **({"offsets": (0, 0, 0)} if name == "lengths"
                                                 else {})))
    value = {"offsets": (outside, 0.0), "lengths": (outside, 1.0)}.get(name, outside)
    with pytest.raises(ValueError, match=name):
        brdf.Thread(**dict(good, **{name: value}, **({"offsets": (0, 0, 0)} if name == "lengths"
                                                     else {})))


def test_headings_and_text():
    assert [p.heading for p in schema.THREAD_PARAMS] == [
        "η", "A (RGB)", "k_d", "γs (deg)", "γv (deg)", "area a", "offsets (deg)", "lengths"]
    assert schema.THREAD["offsets"].text((-32.0, 0.0, 18.0)) == "[-32, 0, 18]"
    assert schema.THREAD["albedo"].text((0.06, 0.24, 0.3)) == "0.06, 0.24, 0.3"
    assert schema.THREAD["eta"].text(1.539) == "1.539"


def test_area_sum_and_rotation():
    schema.check_areas(0.5, 0.5)
    with pytest.raises(ValueError, match=r"areas must sum to at most 1; got 0.6 \+ 0.5"):
        schema.check_areas(0.6, 0.5)
    with pytest.raises(ValueError, match="rotation must be a finite angle in radians"):
        schema.FABRIC["rotation"].check(float("nan"))


def test_thread_docstring_lists_every_parameter():
    for info in schema.THREAD_PARAMS:
        assert f"\n    {info.name} " in brdf.Thread.__doc__
