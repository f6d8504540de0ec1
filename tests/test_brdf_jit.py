"""brdf.jit, the Dr.Jit backend: its f_r against the NumPy kernel's (the reference) for every
preset and variant at random and edge-case pairs, in Fabric.eval, eval_threads and the
batched Prepared.eval; its gradients against central differences of the NumPy kernel; and
the choice of backend (MICROCYL_BACKEND, the fallback said once)."""

import warnings

import numpy as np
import pytest

import brdf
from brdf import jit
from spec_reference import random_pairs
from test_brdf_fabric import CASES, IDS

needs_drjit = pytest.mark.skipif(not jit.available()[0],
                                 reason=f"Dr.Jit does not run here: {jit.available()[1]}")
#: The agreement asked of the two backends, relative, in float64.
RTOL = 1e-6


@pytest.fixture(autouse=True)
def every_call_on_drjit(monkeypatch):
    """The drjit backend shades every call here, however few its pairs (below
    brdf.jit.MIN_ELEMENTS it would leave them to NumPy)."""
    monkeypatch.setattr(jit, "MIN_ELEMENTS", 0)


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    with np.errstate(invalid="ignore"):             # the zero and NaN directions
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def edge_pairs():
    """Pairs at the kernel's edges: normal incidence and view, grazing (n . w from 1e-3
    down to 1e-200, opposite and along each thread), below and on the horizon, retro
    (wo = wi) and mirror (wo = wi turned 180 degrees about n), directions along the warp,
    the weft and the tangent samples of the presets (offsets -90..90 degrees), a zero and a
    NaN direction."""
    rng = np.random.default_rng(5)
    up = random_pairs(40, rng)[0]
    ws = [[0, 0, 1], [1, 0, 1e-3], [0, 1, 1e-9], [0.6, -0.8, 1e-200], [-1, 0, 1e-160],
          [0.8, 0.6, 1e-60], [0, -1, 1e-70], [1, 1e-40, 1e-40],
          [np.cos(0.4), 0, np.sin(0.4)], [0, np.cos(0.96), np.sin(0.96)],
          [np.cos(1.2), 0, np.sin(1.2)], [1, 1e-200, 1e-200], [1e-200, 0, 1]]
    ws = _unit(ws)
    mirror = ws * [-1, -1, 1]
    pairs = [(a, b) for a in ws for b in ws]                       # incl. retro (a = b)
    pairs += list(zip(ws, mirror)) + list(zip(mirror, ws))
    pairs += list(zip(up, up)) + list(zip(up, up * [-1, -1, 1]))  # retro, mirror
    pairs += [(up[0], [0.3, 0.2, -0.5]), ([0.3, 0.2, -0.5], up[1]), (up[2], [1, 0, 0]),
              ([0, 0, 0], up[3]), (up[4], [np.nan, 0, 1])]       # below, on, bad
    wi, wo = (np.array([p[k] for p in pairs], dtype=np.float64) for k in (0, 1))
    return wi, wo


@pytest.fixture(scope="module")
def pairs():
    wi, wo = random_pairs(300, np.random.default_rng(23))
    ei, eo = edge_pairs()
    return np.concatenate([wi, ei]), np.concatenate([wo, eo])


def with_backend(monkeypatch, name, fn):
    monkeypatch.setenv(jit.BACKEND_ENV, name)
    try:
        return fn()
    finally:
        monkeypatch.delenv(jit.BACKEND_ENV)


def ill_conditioned(wi, wo):
    """Opposite pairs both within 1e-20 of the horizon: there cos^2(theta_d) of samples
    along the pair is rounding noise and MODEL.md's f_s, which divides by it, diverges
    (f_r ~ 1e52 at n . w = 1e-60, 1e192 at 1e-200 for the charmeuse without masking and
    reweighting, its digits those of the rounding: brdf.kernel.thread_geometry's notes).
    Both backends give finite f_r >= 0 there, and nothing more is asked."""
    wi, wo = _unit(wi), _unit(wo)
    return (wi[:, 2] < 1e-20) & (wo[:, 2] < 1e-20) & ((wi * wo).sum(axis=-1) < -0.99)


def assert_agree(got, ref, skip=None, axis=0):
    """Same NaNs, same zeros, and ``got`` within RTOL of ``ref`` elementwise; but where
    ``skip`` (a mask of the pairs, along ``axis``), finite and >= 0."""
    assert got.shape == ref.shape
    np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))
    ok = ~np.isnan(ref)
    if skip is not None:
        shape = [1] * ref.ndim
        shape[axis] = skip.size
        skipped = np.broadcast_to(skip.reshape(shape), ref.shape)
        assert np.all(np.isfinite(got[skipped])) and np.all(got[skipped] >= 0)
        ok &= ~skipped
    np.testing.assert_array_equal(got[ok] == 0, ref[ok] == 0)
    np.testing.assert_allclose(got[ok], ref[ok], rtol=RTOL, atol=0)


@needs_drjit
@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_eval_agrees_with_numpy(monkeypatch, pairs, preset, options):
    """Fabric.eval and eval_threads of both backends agree to 1e-6 relative, zeros and NaNs
    where the NumPy kernel has them (below the horizon, bad directions)."""
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    ref = with_backend(monkeypatch, "numpy", lambda: fab.eval(wi, wo))
    assert np.isnan(ref).any() and (ref == 0).any() and (ref > 0).sum() > 300
    skip = ill_conditioned(wi, wo)
    assert 0 < skip.sum() <= 20              # of 570 pairs
    assert_agree(with_backend(monkeypatch, "drjit", lambda: fab.eval(wi, wo)), ref, skip)
    # each thread's share: to 1e-6 of itself or 1e-12 of the pair's f_r (where a grazing
    # n . wi of 1e-160 divides a share of 1e-316, Dr.Jit's kernels, which flush subnormal
    # numbers to 0, give 0 where NumPy gives 6e-156 beside the other thread's 4e-7)
    split = with_backend(monkeypatch, "drjit", lambda: fab.eval_threads(wi, wo))
    ref_split = with_backend(monkeypatch, "numpy", lambda: fab.eval_threads(wi, wo))
    assert_agree(split.sum(axis=-2), ref_split.sum(axis=-2), skip)
    ok = ~(np.isnan(ref) | skip[:, None])[:, None, :].repeat(2, axis=1)
    bound = RTOL * np.abs(ref_split) + 1e-12 * np.abs(ref)[:, None, :]
    assert np.all(np.abs(split - ref_split)[ok] <= bound[ok])


def _batch(fab, nb, rng):
    """A batch of nb parameter sets about the fabric's (a fit's walkers)."""
    th = fab.threads
    spread = lambda v: np.asarray(v) * rng.uniform(0.8, 1.2, (nb,) + np.shape(v))  # noqa: E731
    kw = {name: spread([getattr(t, name) for t in th])
          for name in ("gamma_s", "gamma_v", "albedo")}
    kw["kd"] = np.clip(spread([t.kd for t in th]), 0, 1)
    kw["eta"] = 1.0 + spread([t.eta - 1.0 for t in th])
    kw["area"] = spread([t.area for t in th]) * 0.8
    return kw


@needs_drjit
@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_batched_eval_agrees_with_numpy(monkeypatch, pairs, preset, options):
    """Prepared.eval of a batch (and of the fabric's own parameters) agrees to 1e-6."""
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    kw = _batch(fab, 5, np.random.default_rng(len(preset) + len(options)))
    preps = {b: with_backend(monkeypatch, b, lambda: fab.prepare(wi, wo))
             for b in ("numpy", "drjit")}
    skip = ill_conditioned(wi, wo)
    for args in (kw, {}):
        ref = preps["numpy"].eval(**args)
        assert_agree(preps["drjit"].eval(**args), ref, skip, axis=ref.ndim - 2)
    assert preps["drjit"]._jit is not None and preps["numpy"]._jit is None
    assert_agree(preps["drjit"].eval(), with_backend(monkeypatch, "numpy",
                                                      lambda: fab.eval(wi, wo)), skip)


@needs_drjit
@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_float32_batches_agree_with_numpy_float64(monkeypatch, pairs, preset, options):
    """Prepared.eval(dtype=float32) on Dr.Jit (samples shaded and summed in float32, the
    threads combined in float64) keeps f_r of a batch within 5e-6 relative of the NumPy
    kernel's float64 wherever it is at least 1e-3 of the channel's largest value, and within
    2e-6 of that largest value everywhere (the NumPy float32 shading's bounds,
    tests/test_brdf_prepared.py)."""
    wi, wo = pairs
    keep = ~ill_conditioned(wi, wo)
    wi, wo = wi[keep], wo[keep]
    fab = brdf.fabric(preset, **options)
    kw = _batch(fab, 4, np.random.default_rng(len(preset) * 7 + len(options)))
    ref = with_backend(monkeypatch, "numpy", lambda: fab.prepare(wi, wo).eval(**kw))
    prep = with_backend(monkeypatch, "drjit", lambda: fab.prepare(wi, wo))
    got = prep.eval(**kw, dtype=np.float32)
    assert got.dtype == np.float64 and np.array_equal(np.isnan(got), np.isnan(ref))
    ok = ~np.isnan(ref)
    top = np.nanmax(ref, axis=1, keepdims=True)
    big = ok & (ref >= 1e-3 * top)
    np.testing.assert_allclose(got[big], ref[big], rtol=5e-6, atol=0)
    assert np.all(np.abs(got - ref)[ok] <= 2e-6 * np.broadcast_to(top, ref.shape)[ok])
    assert not np.array_equal(got[big], ref[big])        # shaded in float32 indeed


@needs_drjit
def test_tiny_components_agree(monkeypatch):
    """Pairs with subnormal or nearly zero components (Dr.Jit's kernels flush subnormal
    inputs and intermediates to 0) give the NumPy kernel's f_r in both eval and the batched
    eval, beside ordinary pairs: at n . wi = 5e-301 f_r is 3.56e-6 / sr (linen_plain),
    whose sample terms pass through subnormal numbers."""
    tiny = [1e-310, 5e-324, 5e-301, 1e-80]
    ws = _unit([v for z in tiny for v in ([1.0, 0.0, z], [0.0, 1.0, z], [z, 0.0, 1.0])]
               + [[0.3, 0.4, 0.8]])
    wi = np.repeat(ws, len(ws), axis=0)
    wo = np.tile(ws, (len(ws), 1))
    assert jit.tiny_pairs(wi, wo).sum() == len(wi) - 1
    for name in ("velvet", "polyester_satin_charmeuse", "linen_plain"):
        fab = brdf.fabric(name)
        ref = with_backend(monkeypatch, "numpy", lambda: fab.eval(wi, wo))
        assert np.all(np.isfinite(ref)) and (ref > 0).any()
        assert_agree(with_backend(monkeypatch, "drjit", lambda: fab.eval(wi, wo)), ref)
        prep = with_backend(monkeypatch, "drjit", lambda: fab.prepare(wi, wo))
        assert_agree(prep.eval(), ref)


GRAD_CASES = [("silk_shot", {}), ("velvet", {"transmission": "longitudinal"}),
              ("linen_plain", {"gap": "outgoing", "masking": False}),
              ("polyester_satin_charmeuse", {"reweighting": False})]


@needs_drjit
@pytest.mark.parametrize("preset, options", GRAD_CASES,
                         ids=[f"{p}-{'-'.join(o) or 'default'}" for p, o in GRAD_CASES])
def test_gradients_match_central_differences(monkeypatch, preset, options):
    """eval_and_grad's derivatives (Dr.Jit's AD) of every parameter of every thread match
    central differences of the NumPy kernel's batched f_r, set by set; its f_r is eval's."""
    fab = brdf.fabric(preset, **options)
    wi, wo = random_pairs(60, np.random.default_rng(9))
    wi, wo = np.concatenate([wi, [[0, 0, 1.0], [0.3, 0.1, -0.9]]]), np.concatenate(
        [wo, [[0.6, 0, 0.8], [0, 0, 1.0]]])            # + normal incidence, below
    kw = _batch(fab, 3, np.random.default_rng(2))
    kw["area"] = kw["area"] * 0.9                       # room to step both areas up
    prep = with_backend(monkeypatch, "drjit", lambda: fab.prepare(wi, wo))
    f, grads = prep.eval_and_grad(**kw)
    np.testing.assert_array_equal(f, prep.eval(**kw))
    assert set(grads) == set(brdf.prepared.GRAD_PARAMS)
    ref = with_backend(monkeypatch, "numpy", lambda: fab.prepare(wi, wo))
    for name, g in grads.items():
        assert g.shape == f.shape + (2,)
        assert np.all(g[:, -1] == 0)                    # below the horizon
        for j in range(2):
            if name == "albedo":     # each channel its own; f_r is linear in it (and an
                h = 1e-3             # albedo of 0 has no left side): a forward difference
                fd = sum(_central(ref, kw, name, (slice(None), j, ch), h, forward=True)
                         [..., ch, None] * np.eye(3)[ch] for ch in range(3))
            else:
                h = 1e-6 * max(1.0, float(np.abs(kw[name][:, j]).max()))
                fd = _central(ref, kw, name, (slice(None), j), h)
            scale = np.abs(fd).max() + np.abs(f).max() * 1e-9
            np.testing.assert_allclose(g[..., j], fd, rtol=0, atol=2e-6 * scale,
                                       err_msg=f"d f / d {name}{j + 1}")
    assert np.abs(grads["eta"]).max() > 0 and np.abs(grads["gamma_s"]).max() > 0


def _central(prep, kw, name, index, h, forward=False):
    """The central (or forward) difference of ``prep.eval`` by ``kw[name][index]``."""
    up, down = dict(kw), dict(kw)
    up[name], down[name] = kw[name].copy(), kw[name].copy()
    up[name][index] += h
    if forward:
        return (prep.eval(**up) - prep.eval(**down)) / h
    down[name][index] -= h
    return (prep.eval(**up) - prep.eval(**down)) / (2 * h)


@needs_drjit
def test_small_calls_stay_on_numpy(monkeypatch):
    """Under the drjit backend, calls of fewer than MIN_ELEMENTS (set, pair, sample)
    elements run the NumPy kernel (Dr.Jit's tracing would cost more): one set of 10 velvet
    pairs makes no Dr.Jit half, one of 1,000 does, and so does a batch of 100 sets of the 10
    pairs (a fit's); eval_and_grad works on either."""
    monkeypatch.setattr(jit, "MIN_ELEMENTS", 1 << 14)
    monkeypatch.setenv(jit.BACKEND_ENV, "drjit")
    plan = brdf.fabric("velvet").plan                  # 32 + 32 distinct samples
    assert not jit.use_jit(plan, 255) and jit.use_jit(plan, 256)
    for n, on in ((10, False), (1000, True)):
        wi, wo = random_pairs(n, np.random.default_rng(n))
        prep = brdf.fabric("velvet").prepare(wi, wo)
        f, g = prep.eval_and_grad(eta=[[1.4, 1.5]])
        np.testing.assert_array_equal(f, prep.eval(eta=[[1.4, 1.5]]))
        assert np.abs(g["eta"]).max() > 0
        assert (prep._jit is not None) is on
    etas = np.linspace(1.3, 1.6, 200).reshape(100, 2)
    small = [p[:10] for p in (wi, wo)]
    prep = with_backend(monkeypatch, "drjit", lambda: brdf.fabric("velvet").prepare(*small))
    ref = with_backend(monkeypatch, "numpy", lambda: brdf.fabric("velvet").prepare(*small))
    assert_agree(prep.eval(eta=etas), ref.eval(eta=etas), np.zeros(10, bool), axis=1)
    assert prep._jit is not None and ref._jit is None   # 100 sets x 10 pairs x 64 samples


def test_backend_choice(monkeypatch):
    """MICROCYL_BACKEND picks the kernel; another value is refused, naming the choices."""
    monkeypatch.setenv(jit.BACKEND_ENV, "numpy")
    assert jit.backend() == "numpy"
    prep = brdf.fabric("velvet").prepare([0, 0, 1.0], [0.6, 0, 0.8])
    assert prep._jit is None
    monkeypatch.setenv(jit.BACKEND_ENV, "cuda")
    with pytest.raises(ValueError, match="MICROCYL_BACKEND must be one of numpy, drjit"):
        jit.backend()
    monkeypatch.delenv(jit.BACKEND_ENV)
    assert jit.backend() == ("drjit" if jit.available()[0] else "numpy")


def test_fallback_is_said_once(monkeypatch):
    """Where Dr.Jit does not run, the default is numpy, with the reason warned once per
    process (a BackendWarning, which the suite's filters leave a warning); asking for drjit
    then is an error naming the reason."""
    why = "a test's stand-in reason (libLLVM 14)"
    monkeypatch.setattr(jit, "available", lambda: (False, why))
    monkeypatch.delenv(jit.BACKEND_ENV, raising=False)
    jit._fallback.cache_clear()
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            assert jit.backend() == "numpy"
            assert jit.backend() == "numpy"
            f = brdf.fabric("velvet").eval([0, 0, 1.0], [0.6, 0, 0.8])
        assert np.all(f > 0)
        said = [w for w in seen if why in str(w.message)]
        assert len(said) == 1 and issubclass(said[0].category, jit.BackendWarning)
        monkeypatch.setenv(jit.BACKEND_ENV, "drjit")
        with pytest.raises(RuntimeError, match=r"MICROCYL_BACKEND=drjit.*libLLVM 14"):
            jit.backend()
        monkeypatch.setenv(jit.BACKEND_ENV, "numpy")
        prep = brdf.fabric("velvet").prepare([0, 0, 1.0], [0.6, 0, 0.8])
        with pytest.raises(RuntimeError, match="eval_and_grad needs Dr.Jit.*libLLVM 14"):
            prep.eval_and_grad()
    finally:
        jit._fallback.cache_clear()


def test_kernel_is_generic_over_its_float_type():
    """brdf.jit.kernel on Python floats (the types of Mitsuba's scalar_rgb) gives each
    thread's surface and volume sums and P mean of the NumPy kernel (FabricPlan.geometry
    and shade) at a few pairs, to 1e-12."""
    from brdf.jit import consts, kernel
    fab = brdf.fabric("silk_crepe_de_chine", transmission="longitudinal", rotation=0.4)
    types = consts.Types(float, float, int, lambda *rgb: rgb)
    k = consts.consts(fab.plan, types)
    wi, wo = random_pairs(4, np.random.default_rng(4))
    geoms = fab.plan.geometry(wi, wo)
    shades = fab.plan.shade(geoms, fab.plan.params)

    class Vec:
        def __init__(self, w):
            self.x, self.y, self.z = map(float, w)

    rot = fab.plan.options.rotation
    for c in range(len(wi)):
        sums = kernel.fabric_sums(k, Vec(wi[c]), Vec(wo[c]), float(np.cos(rot)),
                                      float(np.sin(rot)))
        for j in range(2):
            surf, vol, pmean = sums[j]
            np.testing.assert_allclose([surf, vol, pmean],
                                       [shades[j, 0, 0, c], shades[j, 1, 0, c],
                                        geoms[j].pmean[c]], rtol=1e-12, atol=0)


@needs_drjit
def test_one_compiled_kernel_serves_every_preset(monkeypatch):
    """brdf.jit.llvm's kernels take a fabric's numbers, the pair count and the batch size
    as parameters: every preset (same options) and every size launch the same kernels;
    another option compiles another."""
    import drjit as dr
    from brdf.jit import llvm
    monkeypatch.setenv(jit.BACKEND_ENV, "drjit")
    rng = np.random.default_rng(8)

    def hashes(fab, n, nb):
        wi, wo = random_pairs(n, rng)
        dr.kernel_history()                           # clears it
        fab.eval(wi, wo)
        fab.prepare(wi, wo).eval(eta=np.full((nb, 2), 1.4))
        return {e["hash"] for e in dr.kernel_history() if e["type"] == dr.KernelType.JIT}

    with dr.scoped_set_flag(dr.JitFlag.KernelHistory, True):
        seen = [frozenset(hashes(brdf.fabric(name), 30 + 7 * i, 2 + i))
                for i, name in enumerate(brdf.PRESETS)]
        other = hashes(brdf.fabric("velvet", masking=False), 30, 2)
    assert len(set(seen)) == 1 and len(seen[0]) >= 3
    assert other - seen[0]
    assert llvm.plan_consts(brdf.fabric("velvet").plan)[0].masking is True


@needs_drjit
def test_no_pair_to_shade(monkeypatch):
    """Pairs all below the horizon, bad or with subnormal components leave Dr.Jit nothing
    to shade: eval, the batched eval (both precisions) and eval_and_grad give 0 and NaN
    where the NumPy kernel does."""
    monkeypatch.setenv(jit.BACKEND_ENV, "drjit")
    fab = brdf.fabric("linen_plain")
    wi = np.array([[0.0, 0.0, 0.0], [0.3, 0.2, -0.9], [1.0, 0.0, 1e-310]])
    wo = np.array([[0.0, 0.6, 0.8], [0.0, 0.6, 0.8], [0.0, 0.6, 0.8]])
    ref = with_backend(monkeypatch, "numpy", lambda: fab.eval(wi, wo))
    assert np.isnan(ref[0]).all() and (ref[1] == 0).all() and (ref[2] > 0).all()
    for rows in (slice(0, 2), slice(0, 3)):
        prep = fab.prepare(wi[rows], wo[rows])
        for got in (fab.eval(wi[rows], wo[rows]), prep.eval(), prep.eval(dtype=np.float32),
                    prep.eval_and_grad()[0]):
            assert_agree(got, ref[rows])
        eta = [[1.3, 1.4], [1.5, 1.6]]
        assert_agree(prep.eval(eta=eta), with_backend(
            monkeypatch, "numpy", lambda: fab.prepare(wi[rows], wo[rows]).eval(eta=eta)),
            axis=1)
        assert np.isnan(prep.eval_and_grad()[1]["eta"][0]).all()


@needs_drjit
def test_threads_sharing_a_prepared(monkeypatch):
    """Python threads sharing one Dr.Jit-backed Prepared (a fit's ensemble may) each get
    their own batch's f_r, in both precisions, as when called one after another."""
    import concurrent.futures
    monkeypatch.setenv(jit.BACKEND_ENV, "drjit")
    fab = brdf.fabric("velvet")
    wi, wo = random_pairs(200, np.random.default_rng(12))
    prep = fab.prepare(wi, wo)
    batches = [_batch(fab, 3, np.random.default_rng(s)) for s in range(8)]
    dtypes = [np.float64, np.float32] * 4
    serial = [prep.eval(**kw, dtype=dt) for kw, dt in zip(batches, dtypes)]
    assert prep._jit is not None
    with concurrent.futures.ThreadPoolExecutor(4) as ex:
        got = list(ex.map(lambda a: prep.eval(**a[0], dtype=a[1]), zip(batches, dtypes)))
    for g, s in zip(got, serial):
        np.testing.assert_array_equal(g, s)
    assert not np.array_equal(serial[0], serial[2])


@needs_drjit
def test_thread_limit_applies_to_a_loaded_drjit():
    """limit_threads caps the pool of a Dr.Jit already loaded; None gives back a thread a
    core; share_cores(N) gives cores // N (at least 1)."""
    import os
    import drjit as dr
    jit.compiled()
    try:
        jit.limit_threads(1)
        assert dr.thread_count() == 1
        assert jit.share_cores(1) == (os.cpu_count() or 1) == dr.thread_count()
        assert jit.share_cores(4 * (os.cpu_count() or 1)) == 1 == dr.thread_count()
    finally:
        jit.limit_threads(None)
    assert dr.thread_count() == (os.cpu_count() or 1)


@needs_drjit
@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_rotated_batches_agree_with_numpy(monkeypatch, pairs, preset, options):
    """Prepared.eval_rotated (a set a rotation; on Dr.Jit one fused kernel where no pair
    has a nearly zero component, else each set prepared under its rotation) agrees to
    1e-6 with the NumPy kernel's eval of the fabric turned by each set's rotation."""
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    rng = np.random.default_rng(len(preset) + 7 * len(options))
    kw = _batch(fab, 3, rng)
    rot = np.array([-70.0, 0.0, 135.0])
    unit = _unit(wi), _unit(wo)
    with np.errstate(invalid="ignore"):
        plain = ~jit.tiny_pairs(*unit) | np.isnan(unit[0]).any(axis=-1)
    skip = ill_conditioned(wi, wo)
    for rows in (plain, np.ones(len(wi), bool)):      # the fused kernel, then per set
        prep = with_backend(monkeypatch, "drjit", lambda: fab.prepare(wi[rows], wo[rows]))
        fused = with_backend(monkeypatch, "drjit", lambda: prep._fused(len(rot)))
        assert fused == (rows is plain)                          # which path runs
        got = with_backend(monkeypatch, "drjit", lambda: prep.eval_rotated(rot, **kw))
        for b, deg in enumerate(rot):
            turned = fab.replace(rotation=np.radians(deg))
            row = {k: v[b] for k, v in kw.items()}
            ref = with_backend(monkeypatch, "numpy", lambda: turned.prepare(
                wi[rows], wo[rows]).eval(**row))
            assert_agree(got[b], ref, skip[rows])


@needs_drjit
def test_rotated_batches_of_few_pairs_run_fused(monkeypatch):
    """A few pairs (too few for Dr.Jit alone, as a CUReT fit's 200) times many sets run the
    fused kernel, and agree with the per-set NumPy path."""
    monkeypatch.setattr(jit, "MIN_ELEMENTS", 1 << 14)
    fab = brdf.fabric("velvet")
    wi, wo = random_pairs(60, np.random.default_rng(4))
    rot = np.linspace(-90.0, 90.0, 16)
    calls = []
    real = jit.compiled().eval_rotated
    monkeypatch.setattr(jit.compiled(), "eval_rotated",
                        lambda *a: calls.append(1) or real(*a))
    prep = with_backend(monkeypatch, "drjit", lambda: fab.prepare(wi, wo))
    got = with_backend(monkeypatch, "drjit", lambda: prep.eval_rotated(rot))
    assert calls                                    # 60 pairs x 16 sets x 40 samples
    ref = with_backend(monkeypatch, "numpy", lambda: fab.prepare(wi, wo).eval_rotated(rot))
    assert_agree(got, ref)
