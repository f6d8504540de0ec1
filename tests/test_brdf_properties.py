"""Property tests (hypothesis) of brdf's public API over random valid and invalid inputs.

The rule: a call either returns a result with the documented properties, or raises
ValueError or TypeError whose message names the offending parameter. Nothing else escapes
(no IndexError, ZeroDivisionError, RuntimeWarning: the suite turns brdf's warnings into
errors). Valid ranges are written here from MODEL.md and the paper's Table II, not read from
brdf.schema. About 6,000 examples in all, each cheap.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import brdf
from brdf import Fabric, TangentCurve, Thread, frames, terms
from tests._properties import call as _call
from tests._properties import raises_naming as _raises_naming

ALLOWED = (ValueError, TypeError)
FAST = settings(max_examples=400, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])


def fast(n):
    return settings(FAST, max_examples=n)


# -- strategies ---------------------------------------------------------------------------------
any_float = st.floats(allow_nan=True, allow_infinity=True)
#: Components that stress a direction: huge, tiny (their squares underflow), subnormal, signed 0.
component = st.one_of(
    st.floats(-1.0, 1.0), st.sampled_from([0.0, -0.0, 1e-200, -1e-200, 5e-324, 1e-160, 1e300,
                                           -1e300, np.nan, np.inf, -np.inf, 1.0, -1.0]),
    st.floats(allow_nan=True, allow_infinity=True))
direction = st.tuples(component, component, component)
directions = st.lists(direction, min_size=1, max_size=6)
junk = st.one_of(st.none(), st.text(max_size=4), st.booleans(), st.lists(st.integers(), max_size=4),
                 st.dictionaries(st.text(max_size=2), st.integers(), max_size=2),
                 st.complex_numbers(allow_nan=False, max_magnitude=10))
presets = st.sampled_from(sorted(brdf.PRESETS))


def raises_naming(exc, *names):
    _raises_naming(exc, *names, allowed=ALLOWED)


def call(fn, *names):
    return _call(fn, *names, allowed=ALLOWED)


# -- Thread and TangentCurve --------------------------------------------------------------------
def thread_valid(kw):
    """MODEL.md / Table II: eta > 1, A >= 0 (1 or 3), k_d and area in [0, 1], gammas > 0,
    offsets in [-90, 90] one more than lengths >= 0 summing > 0; all finite."""
    def fin(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)

    alb = kw["albedo"]
    alb = alb if isinstance(alb, tuple) else (alb,)
    offs, lens = kw["offsets"], kw["lengths"]
    return (fin(kw["eta"]) and kw["eta"] > 1 and fin(kw["kd"]) and 0 <= kw["kd"] <= 1
            and fin(kw["gamma_s"]) and kw["gamma_s"] > 0 and fin(kw["gamma_v"])
            and kw["gamma_v"] > 0 and fin(kw["area"]) and 0 <= kw["area"] <= 1
            and len(alb) in (1, 3) and all(fin(a) and a >= 0 for a in alb)
            and len(offs) == len(lens) + 1 and all(fin(a) and -90 <= a <= 90 for a in offs)
            and all(fin(x) and x >= 0 for x in lens) and (not lens or sum(lens) > 0))


def maybe(valid, extra=any_float):
    return st.one_of(valid, extra)


thread_kwargs = st.fixed_dictionaries({
    "eta": maybe(st.floats(1.0001, 3.0)),
    "albedo": st.one_of(st.tuples(*[st.floats(0, 2)] * 3), st.floats(0, 1),
                        st.tuples(any_float, any_float, any_float), st.tuples(st.floats(0, 1))),
    "kd": maybe(st.floats(0, 1)),
    "gamma_s": maybe(st.floats(0.5, 60)),
    "gamma_v": maybe(st.floats(0.5, 90)),
    "area": maybe(st.floats(0, 1)),
    "offsets": st.lists(maybe(st.floats(-90, 90)), min_size=0, max_size=4).map(tuple),
    "lengths": st.lists(maybe(st.floats(0, 3)), min_size=0, max_size=3).map(tuple),
})


@fast(800)
@given(thread_kwargs)
def test_thread_accepts_exactly_the_valid_parameters(kw):
    t = call(lambda: Thread(**kw), *kw)
    assert (t is not None) == thread_valid(kw), kw
    if t is not None:
        assert t.curve.offsets == tuple(float(a) for a in kw["offsets"])
        assert Thread(**t.as_dict()) == t


@fast(300)
@given(st.sampled_from(["eta", "albedo", "kd", "gamma_s", "gamma_v", "area", "offsets",
                        "lengths"]), junk)
def test_thread_junk_names_the_parameter(name, value):
    base = dict(eta=1.46, albedo=(0.1, 0.2, 0.3), kd=0.3, gamma_s=12, gamma_v=24, area=0.3,
                offsets=(-25, 25), lengths=(1,))
    base[name] = value
    call(lambda: Thread(**base), name)


@fast(600)
@given(st.lists(st.floats(-90, 90), min_size=1, max_size=5), st.data(),
       st.integers(1, 64), st.sampled_from(["midpoint", "control_points"]))
def test_tangent_curve_samples(offsets, data, n, method):
    lengths = data.draw(st.lists(st.floats(0, 5), min_size=len(offsets) - 1,
                                 max_size=len(offsets) - 1))
    curve = call(lambda: TangentCurve(offsets, lengths), "lengths")
    if curve is None:
        assert sum(lengths) <= 0
        return
    alpha, weight = curve.samples(n, method)
    assert np.all(np.diff(alpha) > 0) and np.all(weight > 0)
    assert math.isclose(weight.sum(), 1.0, rel_tol=1e-12)
    assert alpha.min() >= min(offsets) and alpha.max() <= max(offsets)


@fast(300)
@given(st.one_of(junk, st.lists(any_float, max_size=3)), st.one_of(junk, st.integers(-3, 0)),
       st.one_of(junk, st.text(max_size=6)))
def test_tangent_curve_bad_input(lengths, n, method):
    curve = call(lambda: TangentCurve((0.0, 10.0), lengths), "lengths", "offsets")
    if curve is not None:
        call(lambda: curve.samples(n, method), "tangent_samples", "tangent_sampling")


# -- Fabric.eval, eval_threads ------------------------------------------------------------------
def check_eval(fab, wi, wo):
    out = fab.eval(wi, wo)
    wi_a, wo_a = np.asarray(wi, float), np.asarray(wo, float)
    shape = np.broadcast_shapes(wi_a.shape[:-1], wo_a.shape[:-1])
    assert out.shape == shape + (3,)
    with np.errstate(all="ignore"):
        big_i = np.max(np.abs(wi_a), axis=-1)
        big_o = np.max(np.abs(wo_a), axis=-1)
    bad = ~(np.isfinite(big_i) & (big_i > 0)) | ~(np.isfinite(big_o) & (big_o > 0))
    bad = np.broadcast_to(bad, shape)
    below = ~bad & np.broadcast_to((wi_a[..., 2] <= 0) | (wo_a[..., 2] <= 0), shape)
    assert np.isnan(out[bad]).all()
    assert (out[below] == 0).all()
    good = out[~bad & ~below]
    assert np.isfinite(good).all() and (good >= 0).all()
    threads = fab.eval_threads(wi, wo)
    assert threads.shape == shape + (2, 3)
    # (atol: subnormal components leave sums of a few subnormal bits, ~1e-24 / sr)
    np.testing.assert_allclose(threads.sum(axis=-2)[~bad], out[~bad], rtol=1e-9, atol=1e-15)
    return out


@fast(900)
@given(presets, directions, directions)
def test_fabric_eval_any_directions(name, wi, wo):
    """NaN exactly for zero or non-finite vectors, 0 below the horizon, else finite >= 0 --
    however tiny or huge the components."""
    n = min(len(wi), len(wo))
    check_eval(brdf.fabric(name), np.array(wi[:n]), np.array(wo[:n]))


@fast(500)
@given(presets, direction, directions, st.sampled_from([
    {}, {"masking": False}, {"reweighting": False}, {"gap": "outgoing"}, {"rotation": 0.7},
    {"transmission": "longitudinal"}, {"tangent_sampling": "control_points"},
    {"tangent_samples": 3}]))
def test_fabric_eval_broadcast_and_variants(name, wi, wo, options):
    fab = brdf.fabric(name).replace(**options)
    out = check_eval(fab, np.array(wi), np.array(wo))
    prep = fab.prepare(np.array(wi), np.array(wo)).eval()
    # atol: Dr.Jit's kernels (brdf.jit) flush subnormal intermediates to 0, and eval and
    # the batched eval form them in different orders: an f_r of 1e-307 may be 0 in one of
    # them (pairs with a component below 2^-250 are NumPy's in both, brdf.jit.tiny_pairs)
    np.testing.assert_allclose(prep, out, rtol=1e-10, atol=1e-300, equal_nan=True)


@fast(400)
@given(st.one_of(junk, st.lists(any_float, max_size=5), st.just(np.zeros((2, 3, 2)))),
       st.sampled_from(["wi", "wo"]))
def test_fabric_eval_bad_arrays(value, which):
    fab = brdf.fabric("linen_plain")
    good = [0.0, 0.6, 0.8]
    args = (value, good) if which == "wi" else (good, value)
    for fn in (fab.eval, fab.eval_threads, fab.prepare):
        out = call(lambda: fn(*args), which)
        if out is not None:
            assert np.asarray(value, dtype=float).shape[-1:] == (3,)


@fast(400)
@given(st.sampled_from(list(brdf.OPTIONS)), st.one_of(junk, any_float, st.integers(-2, 40),
                                                      st.sampled_from(["on", "off", "incident"])))
def test_fabric_options(option, value):
    fab = call(lambda: brdf.fabric("velvet").replace(**{option: value}), option)
    if fab is not None:
        check_eval(fab, np.array([[0.3, 0.1, 0.9]]), np.array([[-0.2, 0.5, 0.8]]))


@fast(200)
@given(st.floats(0, 1), st.floats(0, 1), st.one_of(junk, st.lists(st.none(), max_size=3)))
def test_fabric_threads(a1, a2, extra):
    t = brdf.preset_threads("linen_plain")
    ok = call(lambda: Fabric((t[0].replace(area=a1), t[1].replace(area=a2))), "area")
    assert (ok is not None) == (a1 + a2 <= 1 + 1e-12)
    call(lambda: Fabric(extra), "threads")


# -- Prepared.eval ------------------------------------------------------------------------------
RANGES = {"eta": (1.0, None, True), "kd": (0.0, 1.0, False), "gamma_s": (0.0, None, True),
          "gamma_v": (0.0, None, True), "area": (0.0, 1.0, False)}


def in_range(name, v):
    lo, hi, open_lo = RANGES[name]
    ok = np.isfinite(v) & ((v > lo) if open_lo else (v >= lo))
    return ok & (v <= hi) if hi is not None else ok


param_value = st.one_of(st.floats(1.01, 2.5), st.floats(0.0, 1.0), st.floats(0.5, 40.0),
                        st.sampled_from([-1.0, 0.0, 1.0, 5.0, np.nan, np.inf, -np.inf]))


@fast(800)
@given(presets, st.dictionaries(st.sampled_from(list(RANGES) + ["albedo"]),
                                st.lists(param_value, min_size=2, max_size=2), max_size=3),
       st.integers(1, 3))
def test_prepared_eval_parameters(name, params, batch):
    """In range: finite f_r >= 0 equal to a Fabric with those parameters. Out of range: one
    ValueError naming the parameter, before any shading."""
    fab = brdf.fabric(name)
    wi = np.array([[0.3, 0.1, 0.9], [0.0, 0.0, 1.0], [0.5, -0.5, 1e-200]])
    wo = np.array([[-0.2, 0.5, 0.8], [0.7, 0.0, 0.7], [0.0, 0.6, 0.8]])
    kw = {k: np.tile(v, (batch, 1)) for k, v in params.items() if k != "albedo"}
    if "albedo" in params:
        kw["albedo"] = np.repeat(np.array(params["albedo"])[None, :, None], batch, 0) \
            * np.ones(3)
    valid = all(in_range(k, np.asarray(v)).all() for k, v in kw.items() if k != "albedo")
    valid &= all(np.isfinite(v) and v >= 0 for v in params.get("albedo", []))
    area = kw.get("area", np.array([[t.area for t in fab.threads]]))
    valid = valid and bool(np.all(area.sum(axis=-1) <= 1 + 1e-12))
    out = call(lambda: fab.prepare(wi, wo).eval(**kw), *kw)
    assert (out is not None) == valid, kw
    if out is not None:
        assert out.shape == ((batch,) if kw else ()) + (3, 3)
        assert np.isfinite(out).all() and (out >= 0).all()
        out = out.reshape(-1, 3, 3)
        changes = {k: float(v[0, j]) for k, v in kw.items() if k != "albedo" for j in [0]}
        threads = [t.replace(**{k: float(v[0, j]) for k, v in kw.items() if k != "albedo"},
                             **({"albedo": tuple(kw["albedo"][0, j])} if "albedo" in kw
                                else {}))
                   for j, t in enumerate(fab.threads)]
        assert changes is not None
        ref = fab.replace(threads=threads).eval(wi, wo)
        np.testing.assert_allclose(out[0], ref, rtol=1e-9, atol=1e-300)


@fast(300)
@given(st.sampled_from(list(RANGES) + ["albedo"]),
       st.one_of(junk, st.lists(any_float, max_size=3), st.just(np.ones((2, 3)))))
def test_prepared_eval_bad_shapes(name, value):
    prep = brdf.fabric("silk_shot").prepare([0.0, 0.0, 1.0], [0.6, 0.0, 0.8])
    call(lambda: prep.eval(**{name: value}), name)


# -- frames -------------------------------------------------------------------------------------
angle = st.floats(-10.0, 10.0)


@fast(500)
@given(st.floats(0.0, math.pi), angle)
def test_frames_angles_round_trip(theta, phi):
    w = frames.from_angles(theta, phi)
    assert math.isclose(np.linalg.norm(w), 1.0, rel_tol=1e-12)
    th, ph = frames.to_angles(w)
    assert abs(float(th) - theta) < 2e-15      # to the last digits, near the poles too
    assert abs(math.sin(theta)) < 1e-7 or abs(math.remainder(float(ph) - phi, 2 * math.pi)) < 1e-6
    for a in (0.3, -2.0):
        np.testing.assert_allclose(frames.rotate_z(frames.rotate_z(w, a), -a), w, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(frames.rotate_y(w, a)), 1.0, rtol=1e-12)


@fast(500)
@given(st.floats(0.01, 1.5), st.floats(-3.1, 3.1), st.floats(0.01, 1.5), st.floats(-3.1, 3.1))
def test_frames_half_diff_round_trip(th, ph, td, pd):
    wi, wo = frames.half_diff_to_directions(th, ph, td, pd)
    back = frames.directions_to_half_diff(wi, wo)
    np.testing.assert_allclose(back[0], th, atol=1e-7)
    np.testing.assert_allclose(back[2], td, atol=1e-7)
    wi2, wo2 = frames.half_diff_to_directions(*back)
    np.testing.assert_allclose(wi2, wi, atol=1e-7)
    np.testing.assert_allclose(wo2, wo, atol=1e-7)


@fast(400)
@given(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.floats(-3.0, 3.0))
def test_frames_plane_round_trip(ti, to, az):
    wi, wo = frames.plane_to_directions(ti, to, az)
    a, b = frames.directions_to_plane(wi, wo, az)
    assert abs(float(a) - ti) < 1e-9 and abs(float(b) - to) < 1e-9
    call(lambda: frames.directions_to_plane(wi, wo, az + 0.5), "wi", "wo")


@fast(400)
@given(st.one_of(junk, st.lists(any_float, max_size=4), directions))
def test_frames_bad_directions(value):
    for fn in (frames.to_angles, frames.normalize, lambda w: frames.flat_pairs(w, w)):
        out = call(lambda: fn(value), "w")
        if out is not None:
            assert np.asarray(value, dtype=float).shape[-1] == 3


# -- terms --------------------------------------------------------------------------------------
@fast(500)
@given(st.floats(1.0001, 4.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0),
       st.floats(1e-3, 2.0), st.floats(-3.0, 3.0), st.sampled_from(["half_angle", "longitudinal"]))
def test_terms_ranges(eta, c, ci, cr, gamma, x, method):
    f = float(terms.fresnel(eta, c))
    assert 0.0 <= f <= 1.0 + 1e-12
    assert 0.0 <= float(terms.transmission(eta, c, ci, cr, method)) <= 1.0 + 1e-12
    g = float(terms.gaussian(gamma, x))
    assert 0.0 <= g <= 1.0 / (gamma * math.sqrt(2 * math.pi)) * (1 + 1e-12)
    assert 0.0 < float(terms.u(x)) <= 1.0
    w = float(terms.pair_weight(ci, cr, x))
    assert ci * cr - 1e-12 <= w <= min(ci, cr) + 1e-12
    assert float(terms.visibility(x)) == max(x, 0.0)


@fast(400)
@given(st.sampled_from(["fresnel", "gaussian", "u", "visibility", "pair_weight",
                        "transmission"]), junk)
def test_terms_bad_input_names_the_parameter(name, value):
    fn = getattr(terms, name)
    args = {"fresnel": ("eta", "cos_i"), "gaussian": ("gamma", "x"), "u": ("x",),
            "visibility": ("cos_angle",), "pair_weight": ("m_i", "m_o", "delta"),
            "transmission": ("eta", "cos_g", "cos_theta_i", "cos_theta_r")}[name]
    for k in range(len(args)):
        vals = [1.2] * len(args)
        vals[k] = value
        with np.errstate(all="ignore"):
            call(lambda: fn(*vals), args[k])


def test_transmission_method_named():
    with pytest.raises(ValueError, match="transmission must be one of"):
        terms.transmission(1.5, 1, 1, 1, "both")
