"""brdf.Prepared: float32 shading against MODEL.md's transliteration, and its scratch buffers
(reused between calls and threads without mixing results)."""

import threading

import numpy as np
import pytest

import brdf
from spec_reference import random_pairs, reference_eval
from test_brdf_fabric import CASES, IDS


@pytest.fixture(scope="module")
def pairs():
    return random_pairs(300, np.random.default_rng(11))


@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_float32_shading_matches_the_spec_transliteration(pairs, preset, options):
    """float32 shading keeps f_r within 5e-6 relative wherever it is at least 1e-3 of the
    channel's largest value, and within 2e-6 of that largest value everywhere."""
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    ref = reference_eval(fab, wi, wo)
    got = fab.prepare(wi, wo).eval(dtype=np.float32)
    assert got.dtype == np.float64 and got.shape == ref.shape
    top = ref.max(axis=0)
    big = ref >= 1e-3 * top
    np.testing.assert_allclose(got[big], ref[big], rtol=5e-6, atol=0)
    assert np.all(np.abs(got - ref) <= 2e-6 * top)


def test_float32_batches_match_float64_batches(pairs):
    wi, wo = pairs
    prep = brdf.fabric("silk_crepe_de_chine").prepare(wi, wo)
    rng = np.random.default_rng(3)
    kw = dict(eta=rng.uniform(1.2, 1.8, (7, 2)), kd=rng.uniform(0, 1, (7, 2)),
              gamma_s=rng.uniform(2, 20, (7, 2)), gamma_v=rng.uniform(2, 30, (7, 2)),
              albedo=rng.uniform(0, 1, (7, 2, 3)))
    f64, f32 = prep.eval(**kw), prep.eval(dtype=np.float32, **kw)
    top = f64.max(axis=1, keepdims=True)
    assert np.all(np.abs(f32 - f64) <= 2e-6 * top)


def test_float32_finite_for_tiny_components():
    tiny = [1e-200, 1e-310, 1e-40]
    ws = [np.array(v, float) for z in tiny for v in ([1.0, 0.0, z], [0.0, 1.0, z],
                                                     [z, 0.0, 1.0], [1.0, z, z])]
    wi = np.array([a for a in ws for _ in ws])
    wo = np.array([b for _ in ws for b in ws])
    for name in ("velvet", "linen_plain", "polyester_satin_charmeuse"):
        got = brdf.fabric(name).prepare(wi, wo).eval(dtype=np.float32)
        assert np.all(np.isfinite(got)) and np.all(got >= 0)


@pytest.mark.parametrize("dtype", [np.float16, np.int64, "complex", "nonsense"])
def test_other_dtypes_are_refused(dtype):
    prep = brdf.fabric("velvet").prepare([0.0, 0.0, 1.0], [0.0, 0.6, 0.8])
    with pytest.raises(ValueError, match="dtype must be numpy.float64 or numpy.float32"):
        prep.eval(dtype=dtype)


def test_scratch_reuse_across_batch_sizes_changes_nothing(pairs):
    """Calls of growing and shrinking batch sizes on one Prepared give what a fresh one does."""
    wi, wo = pairs
    fab = brdf.fabric("velvet")
    prep = fab.prepare(wi, wo)
    rng = np.random.default_rng(5)
    for b in (9, 40, 3, 40, 1):
        eta = rng.uniform(1.2, 1.8, (b, 2))
        for dtype in (np.float64, np.float32):
            again = fab.prepare(wi, wo).eval(eta=eta, dtype=dtype)
            np.testing.assert_array_equal(prep.eval(eta=eta, dtype=dtype), again)


def test_threads_sharing_a_prepared_get_their_own_results(pairs):
    """Two threads evaluating different parameter sets on one Prepared at once each get the
    result a serial call gives (each thread has its own buffers)."""
    wi, wo = pairs
    prep = brdf.fabric("silk_crepe_de_chine").prepare(wi, wo)
    etas = [np.full((16, 2), 1.3), np.full((16, 2), 1.7)]
    want = [prep.eval(eta=e, dtype=np.float32) for e in etas]
    got, errors = [[], []], []

    def work(k):
        try:
            for _ in range(20):
                got[k].append(prep.eval(eta=etas[k], dtype=np.float32))
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for k in (0, 1):
        for g in got[k]:
            np.testing.assert_array_equal(g, want[k])
