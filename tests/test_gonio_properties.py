"""Property tests (hypothesis) of gonio's public API over random valid and invalid inputs.

The rule: a call either returns a result with the documented properties, or raises
ValueError (FormatError is one), TypeError or OSError whose one-line message names the
offending parameter or file. Files go to a temporary folder per example. About 6,000
examples in all, each cheap.
"""

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import brdf
import gonio
from brdf.frames import from_angles
from tests._gonio_helpers import Lambert
from tests._properties import call as _call
from tests._properties import raises_naming as _raises_naming

ALLOWED = (ValueError, TypeError, OSError)


def fast(n):
    return settings(max_examples=n, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


def raises_naming(exc, *names):
    _raises_naming(exc, *names, allowed=ALLOWED)


def call(fn, *names):
    return _call(fn, *names, allowed=ALLOWED)


any_float = st.floats(allow_nan=True, allow_infinity=True)
junk = st.one_of(st.none(), st.text(max_size=4), st.booleans(), st.lists(st.integers(), max_size=4),
                 st.dictionaries(st.text(max_size=2), st.integers(), max_size=2))
component = st.one_of(st.floats(-1.0, 1.0), st.sampled_from(
    [0.0, -0.0, 1e-200, 5e-324, 1e300, -1e300, np.nan, np.inf, -np.inf, 1.0]), any_float)
direction = st.tuples(component, component, component)


# -- Table --------------------------------------------------------------------------------------
@fast(600)
@given(st.one_of(junk, st.lists(st.tuples(any_float, any_float, any_float), max_size=3)),
       st.one_of(junk, st.lists(st.tuples(any_float, any_float, any_float), max_size=3)),
       st.one_of(junk, st.lists(any_float, max_size=3)),
       st.one_of(st.none(), junk, st.lists(any_float, max_size=3)),
       st.one_of(st.just({}), junk))
def test_table_construction(wi, wo, values, sigma, meta):
    t = call(lambda: gonio.Table(wi, wo, values, sigma, meta),
             "wi", "wo", "values", "sigma", "meta")
    if t is not None:
        assert t.wi.shape == t.wo.shape == t.values.shape == (len(t), 3)
        np.testing.assert_allclose(np.linalg.norm(t.wi, axis=1), 1.0, rtol=1e-12)
        assert t.valid.shape == (len(t), 3)


# -- write and read back, every writable format -------------------------------------------------
unit_angles = st.tuples(st.floats(0.0, math.pi), st.floats(-math.pi, math.pi))
value = st.one_of(st.floats(0.0, 1e3), st.sampled_from([np.nan, -0.5, np.inf, 0.0, 1e-300]))


@st.composite
def tables(draw, finite=False):
    n = draw(st.integers(1, 6))
    ang = np.array([draw(unit_angles) + draw(unit_angles) for _ in range(n)])
    vals = st.floats(0.0, 1e3) if finite else value
    grey = draw(st.booleans())
    v = np.array([[draw(vals)] * 3 if grey else [draw(vals) for _ in range(3)]
                  for _ in range(n)])
    sigma = None
    if draw(st.booleans()):
        sigma = np.abs(v) * 0.01 if finite else np.where(np.isfinite(v), np.abs(v) * 0.01, np.nan)
    meta = draw(st.dictionaries(st.sampled_from(["source", "note", "x.y-z", "bad key"]),
                                st.one_of(st.text(max_size=8), st.integers(), st.floats(0, 1)),
                                max_size=2))
    return gonio.Table(from_angles(ang[:, 0], ang[:, 1]), from_angles(ang[:, 2], ang[:, 3]),
                       v, sigma, meta)


def same(a, b, rtol):
    np.testing.assert_allclose(a, b, rtol=rtol, atol=1e-300, equal_nan=True)


@pytest.mark.filterwarnings("ignore::gonio.TableWarning")   # tables near the normal: radians?
@fast(350)
@given(tables(), st.integers(9, 17))
def test_csv_round_trip(t, digits):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "t.csv"
        gonio.write(t, p, digits=digits)
        back = gonio.read(p)
    assert len(back) == len(t)
    same(back.values, t.values, 1e-8)
    np.testing.assert_allclose(back.wi, t.wi, atol=1e-7)
    np.testing.assert_allclose(back.wo, t.wo, atol=1e-7)
    assert (back.sigma is None) == (t.sigma is None)


@fast(300)
@given(tables())
def test_exr_round_trip(t):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "t.exr"
        gonio.write(t, p)
        back = gonio.read(p)
    assert len(back) == len(t)
    finite = np.isfinite(t.values) & (np.abs(t.values) < 3e38) & (np.abs(t.values) > 1e-37)
    same(back.values[finite], t.values[finite], 1e-6)
    np.testing.assert_allclose(back.wi, t.wi, atol=1e-6)


@fast(300)
@given(tables(), st.sampled_from([None, "SPHERICAL_TL_PL_TV_PV", "RUSIN_TH_PH_TD_PD",
                                  "CARTESIAN"]))
def test_alta_round_trip(t, param):
    """Rows with a missing value or sigma are left out; the rest read back (or the writer
    refuses a table without such rows, before writing)."""
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "t.alta"
        ok = call(lambda: gonio.write(t, p, param=param), "write_alta")
        if ok is None and not p.exists():
            keep = np.all(t.valid, axis=1)
            if t.sigma is not None:
                keep &= np.all(np.isfinite(t.sigma), axis=1)
            assert not keep.any() or param is None   # None picks COS_TH only for wi = wo
            return
        back = gonio.read(p)
    keep = np.all(t.valid, axis=1)
    if t.sigma is not None:
        keep &= np.all(np.isfinite(t.sigma) & (t.sigma >= 0), axis=1)
    assert len(back) == int(keep.sum())
    same(back.values, t.values[keep], 0.0)               # 17 digits: the same doubles
    if param is not None:            # directions to the last digits, even 1e-9 off the normal
        # (Rusinkiewicz angles: to 1e-12, below which directions_to_half_diff takes phi = 0)
        atol = 2e-12 if param.startswith("RUSIN") else 2e-15
        np.testing.assert_allclose(back.wi, t.wi[keep], rtol=0, atol=atol)
        np.testing.assert_allclose(back.wo, t.wo[keep], rtol=0, atol=atol)


@fast(100)
@given(st.one_of(junk, tables()), st.sampled_from([".csv", ".alta", ".exr", ".binary", ".txt",
                                                   ""]),
       st.one_of(st.just({}), st.fixed_dictionaries({"digits": st.one_of(junk,
                                                                           st.integers(-2, 3))})))
def test_write_bad_arguments(obj, suffix, options):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / f"t{suffix}"
        if suffix in (".exr", ".binary"):
            options = {}
        call(lambda: gonio.write(obj, p, **options), "write", "digits", "table", "suffix",
             "format", str(p))


# -- reading text files of random content -------------------------------------------------------
token = st.one_of(st.sampled_from(["30", "0", "-45.5", "180", "200", "3_0", "nan", "NaN", "inf",
                                   "", " 1 ", "1e400", "x", "\u0663", ".5", "5.", "+1", "-"]),
                  st.floats(-400, 400).map(lambda x: f"{x:g}"))
header = st.sampled_from(["theta_i,phi_i,theta_o,phi_o,r,g,b",
                          "\ufefftheta_i,phi_i,theta_o,phi_o,value",
                          "theta_i,phi_i,theta_o,phi_o,value,sigma",
                          "theta_i,phi_i,theta_o,r,g,b", "theta_i,theta_i,phi_i,theta_o,phi_o,value"])


@fast(700)
@given(header, st.lists(st.lists(token, min_size=4, max_size=8), max_size=4),
       st.sampled_from(["", "# source: \"x\"\n", "\ufeff# c\n"]))
def test_csv_reader_of_random_text(head, rows, prefix):
    """A table whose angles lie in range and whose fields are numbers, or a FormatError
    naming the file (and, for a bad field, the line)."""
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "r.csv"
        p.write_text(prefix + head + "\n" + "".join(",".join(r) + "\n" for r in rows),
                     encoding="utf-8")
        t = call(lambda: gonio.read(p), str(p))
    if t is not None:
        theta = np.degrees(t.angles[:, [0, 2]])
        assert np.all((theta >= 0) & (theta <= 180 + 1e-9)) and len(t) == len(rows)
        assert all(r[k].strip() not in ("3_0", "x", "\u0663", "1e400", "nan", "")
                   and (k % 2 or r[k] != "200") for r in rows for k in range(4))


alta_head = st.sampled_from(["#DIM 4 3\n#PARAM_IN SPHERICAL_TL_PL_TV_PV\n#PARAM_OUT RGB_COLOR\n",
                             "\ufeff#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n",
                             "#DIM 6 3\n#PARAM_IN CARTESIAN\n#PARAM_OUT RGB_COLOR\n",
                             "#DIM 3 3\n#PARAM_IN RUSIN_TH_TD_PD\n#PARAM_OUT RGB_COLOR\n#VS 2\n",
                             "#DIM 4 3\n#PARAM_IN NOPE\n"])
alta_token = st.one_of(st.sampled_from(["0.5", "0", "1", "-1", "3.2", "7", "nan", "inf", "3_0",
                                        "x", "0.25", "1e-3"]), st.floats(-7, 7).map(repr))


@fast(500)
@given(alta_head, st.lists(st.lists(alta_token, min_size=3, max_size=12), max_size=4))
def test_alta_reader_of_random_text(head, rows):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "r.alta"
        p.write_text(head + "".join(" ".join(r) + "\n" for r in rows), encoding="utf-8")
        t = call(lambda: gonio.read(p), str(p))
    if t is not None:
        assert len(t) == len(rows) and np.isfinite(t.wi).all() and np.isfinite(t.wo).all()


# -- geometry specs -----------------------------------------------------------------------------
spec_arg = st.one_of(st.sampled_from(["30", "45", "90", "0", "-5", "3_0", "nan", "inf", "x",
                                      "1e1", "\u0663\u0660", "", "30,45", "60, 30", "100"]),
                     st.integers(30, 95).map(str))


@fast(900)
@given(st.sampled_from(["full", "plane", "rus", "rusinkiewicz", "merl", "pairs", "nope", "",
                        "FULL"]),
       st.lists(st.one_of(spec_arg, st.sampled_from(["warp", "weft", "45", "12.5"])), max_size=4),
       st.one_of(st.just(0.0), st.floats(-7, 7), junk))
def test_from_spec(kind, args, rotation):
    if kind == "merl":
        args = [a for a in args if a not in ("30", "45", "90", "1e1")][:1] or ["40"]
    spec = ":".join([kind] + args)
    g = call(lambda: gonio.from_spec(spec, rotation=rotation), "geometry spec", "rotation",
             repr(":".join(args)))          # pairs:FILE names the file it cannot read
    if g is not None:
        assert g.wi.shape == g.wo.shape and g.wi.shape[0] > 0
        assert np.all(g.wi[:, 2] > 0) and np.all(g.wo[:, 2] > 0)
        assert gonio.from_spec(g.spec).wi.shape == g.wi.shape


@fast(300)
@given(st.one_of(junk, st.text(max_size=12)))
def test_from_spec_junk(spec):
    if isinstance(spec, str) and any(c.isdigit() for c in spec):
        spec = "".join(c for c in spec if not c.isdigit())   # no accidental fine grids
    call(lambda: gonio.from_spec(spec), "geometry spec")


# -- Instrument and measure ---------------------------------------------------------------------
instrument_kwargs = st.fixed_dictionaries({}, optional={
    "cone_source": st.one_of(st.floats(0, 10), any_float, junk),
    "cone_detector": st.one_of(st.floats(0, 10), any_float, junk),
    "snr": st.one_of(st.none(), st.floats(1, 500), any_float, junk),
    "floor": st.one_of(st.floats(0, 0.1), any_float, junk),
    "noise": st.one_of(st.sampled_from(["multiplicative", "shot"]), junk),
    "snr_reference": st.one_of(st.floats(0.1, 10), any_float, junk),
    "rings": st.one_of(st.integers(1, 3), st.integers(-2, 0), junk),
    "azimuths": st.one_of(st.integers(1, 6), junk),
    "max_theta": st.one_of(st.none(), st.floats(1, 90), any_float, junk),
    "min_separation": st.one_of(st.none(), st.floats(0, 30), any_float, junk),
    "in_plane": st.one_of(st.booleans(), junk),
})


@fast(700)
@given(instrument_kwargs)
def test_instrument(kw):
    ins = call(lambda: gonio.Instrument(**kw), *kw)
    if ins is not None:
        pts, w = ins.source_rule
        assert pts.shape[1] == 3 and math.isclose(w.sum(), 1.0, rel_tol=1e-9)
        sig = ins.sigma(np.array([[0.1, 0.2, 0.0]]))
        assert sig is None or (np.isfinite(sig).all() and (sig >= 0).all())
        ok = ins.reachable(np.array([[0.0, 0.0, 1.0], [np.nan, 0.0, 1.0]]), [0.6, 0.0, 0.8])
        assert ok.dtype == bool and ok.shape == (2,) and (not ins.has_limits or not ok[1])


@fast(120)
@given(st.sampled_from(["plane:warp:30", "full:60", "rus:60", "plane:weft:45:0,30"]),
       st.sampled_from([Lambert(), brdf.fabric("linen_plain")]),
       st.builds(gonio.Instrument, cone_source=st.sampled_from([0.0, 2.0]),
                 cone_detector=st.sampled_from([0.0, 3.0]),
                 snr=st.sampled_from([None, 20.0]), rings=st.integers(1, 2),
                 azimuths=st.integers(1, 3)),
       st.integers(0, 2**32), st.one_of(st.none(), st.integers(1, 50)))
def test_measure_small(spec, model, instrument, seed, chunk):
    t = gonio.measure(model, spec, instrument, seed=seed, chunk=chunk, progress=False)
    assert len(t) == len(gonio.from_spec(spec).wi)
    assert np.isfinite(t.values).all()
    if instrument.snr is None:
        assert (t.values >= 0).all() and t.sigma is None
    again = gonio.measure(model, spec, instrument, seed=seed, chunk=chunk, progress=False)
    assert again.values.tobytes() == t.values.tobytes()


@fast(200)
@given(st.one_of(junk, st.floats()), st.one_of(junk, st.integers(-3, 0)),
       st.one_of(st.none(), junk, st.integers(-5, -1)))
def test_measure_bad_arguments(geometry, chunk, seed):
    call(lambda: gonio.measure(Lambert(), geometry, None, seed=seed, chunk=chunk,
                               progress=False), "geometry", "chunk", "seed")
    call(lambda: gonio.measure(object(), "plane:warp:45", progress=False), "brdf", "eval")


# -- the shared RGL felts -----------------------------------------------------------------------
@pytest.fixture(scope="module")
def felts(shared_data):
    return [gonio.load_rgl(p) for p in sorted((shared_data / "rgl").glob("*.bsdf"))]


def test_rgl_felts_any_directions(felts):
    @fast(900)
    @given(st.integers(0, len(felts) - 1), st.lists(direction, min_size=1, max_size=4),
           direction)
    def check(k, wi, wo):
        wi, wo = np.array(wi), np.array(wo)
        out = felts[k].eval(wi, wo)
        assert out.shape == (len(wi), 3)
        with np.errstate(all="ignore"):
            bad = ~np.isfinite(np.max(np.abs(wi), axis=1)) | (np.max(np.abs(wi), axis=1) == 0)
            bo = np.max(np.abs(wo))
        bad |= not (np.isfinite(bo) and bo > 0)
        below = ~bad & ((wi[:, 2] <= 0) | (wo[2] <= 0))
        assert np.isnan(out[bad]).all() and (out[below] == 0).all()
        good = out[~bad & ~below]
        assert np.isfinite(good).all() and (good >= 0).all()

    check()
