"""Tests of gonio.instrument: the cone quadrature and the noise models."""

import math

import numpy as np
import pytest

from gonio.instrument import Instrument, cap_quadrature, cone_directions


def _axes(rng, n):
    w = rng.standard_normal((n, 3))
    w[:, 2] = np.abs(w[:, 2])
    w[0] = [0, 0, 1]
    w[1] = [0, 0, -1]          # the frame must work at both poles
    w[2] = [1, 0, 0]
    return w / np.linalg.norm(w, axis=1, keepdims=True)


@pytest.mark.parametrize("half", [0.5, 5.0, 30.0, 80.0])
def test_cap_rule_points_in_cap_and_weights(half):
    p, w = cap_quadrature(half, 3, 7)
    assert p.shape == (21, 3) and w.shape == (21,)
    assert np.all(w > 0) and math.isclose(w.sum(), 1.0)
    assert np.allclose(np.linalg.norm(p, axis=1), 1)
    assert np.all(p[:, 2] >= math.cos(math.radians(half)) - 1e-15)


def test_point_cone():
    p, w = cap_quadrature(0.0, 4, 9)
    assert p.tolist() == [[0.0, 0.0, 1.0]] and w.tolist() == [1.0]
    assert Instrument().n_source == 1 and Instrument(cone_source=1).n_source == 12


@pytest.mark.parametrize("half", [1.0, 10.0, 45.0])
def test_cap_rule_exact_for_linear_functions(half):
    """Uniform cap average of w is axis (1 + cos a) / 2: the rule reproduces it about any axis."""
    rng = np.random.default_rng(0)
    axes = _axes(rng, 40)
    p, w = cap_quadrature(half, 1, 2)          # even the smallest rule
    d = cone_directions(axes, p)               # (40, 2, 3)
    assert np.allclose(np.linalg.norm(d, axis=-1), 1)
    mean = np.einsum("nkx,k->nx", d, w)
    c = math.cos(math.radians(half))
    assert np.allclose(mean, axes * (1 + c) / 2, atol=1e-14)
    # and any affine function a + b . w
    b = np.array([0.3, -1.2, 2.0])
    assert np.allclose(np.einsum("nk,k->n", 0.7 + d @ b, w), 0.7 + axes @ b * (1 + c) / 2)


def test_cap_rule_exact_for_quadratic_in_cos_and_converges_for_smooth():
    half = 20.0
    c = math.cos(math.radians(half))
    p, w = cap_quadrature(half, 2, 3)
    # uniform average of cos^3 over the cap: int_c^1 x^3 dx / (1 - c)
    exact = (1 - c ** 4) / (4 * (1 - c))
    assert math.isclose(w @ p[:, 2] ** 3, exact, rel_tol=1e-14)
    # exp(k cos t): (e^k - e^{k c}) / (k (1 - c)), not a polynomial; Gauss converges fast
    k = 40.0
    exact = (math.exp(k) - math.exp(k * c)) / (k * (1 - c))
    errs = [abs(w2 @ np.exp(k * p2[:, 2]) / exact - 1)
            for p2, w2 in (cap_quadrature(half, r, 3) for r in (1, 2, 3, 4))]
    assert errs[-1] < 1e-6 and all(a > b for a, b in zip(errs, errs[1:]))


def test_cap_rule_is_uniform_in_solid_angle_not_in_theta():
    """A function of azimuth x polar angle, against a Monte Carlo uniform-cap average."""
    half = 30.0
    rng = np.random.default_rng(1)
    n = 400_000
    c = math.cos(math.radians(half))
    cos_t = 1 - rng.uniform(0, 1 - c, n)                 # uniform in solid angle
    phi = rng.uniform(0, 2 * np.pi, n)
    sin_t = np.sqrt(1 - cos_t ** 2)

    def f(x, y, z):
        return np.exp(3 * x) * (1 + y * y) / (0.2 + z)

    mc = f(sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t)
    p, w = cap_quadrature(half, 6, 16)
    q = w @ f(*p.T)
    assert abs(q - mc.mean()) < 5 * mc.std() / math.sqrt(n)


@pytest.mark.parametrize("kwargs, match", [
    ({"cone_source": -1}, "cone_source"),
    ({"cone_detector": 90}, "cone_detector"),
    ({"cone_detector": "wide"}, "cone_detector"),
    ({"snr": 0}, "snr"),
    ({"snr": -5}, "snr"),
    ({"snr": float("nan")}, "snr"),
    ({"floor": -0.1}, "floor"),
    ({"floor": float("inf")}, "floor"),
    ({"noise": "gaussian"}, "noise must be one of"),
    ({"snr_reference": 0}, "snr_reference"),
    ({"rings": 0}, "rings"),
    ({"azimuths": 2.5}, "azimuths"),
])
def test_instrument_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Instrument(**kwargs)


def test_infinite_snr_is_noiseless():
    ins = Instrument(snr=float("inf"))
    assert ins.snr is None and not ins.is_noisy and ins.sigma(np.ones((2, 3))) is None
    v = np.array([[0.1, 0.2, 0.3]])
    assert np.array_equal(ins.add_noise(v, np.random.default_rng(0)), v)


def _check_moments(samples, mean, std, excess_kurtosis=0.0):
    """Sample mean and variance within 5 standard errors of the model's."""
    n = samples.shape[0]
    m = samples.mean(axis=0)
    var = samples.var(axis=0, ddof=1)
    assert np.all(np.abs(m - mean) <= 5 * std / math.sqrt(n) + 1e-15)
    se_var = std ** 2 * np.sqrt(2 / (n - 1) + excess_kurtosis / n)
    assert np.all(np.abs(var - std ** 2) <= 5 * se_var + 1e-15)


def test_multiplicative_noise_moments():
    v = np.array([[0.0, 0.05, 1.0], [3.0, 20.0, 0.5]])
    ins = Instrument(snr=25, floor=0.01)
    n = 20_000
    draws = ins.add_noise(np.broadcast_to(v, (n, 2, 3)), np.random.default_rng(7))
    std = np.sqrt((v / 25) ** 2 + 0.01 ** 2)              # the model, by hand
    assert np.allclose(ins.sigma(v), std)
    _check_moments(draws, v, std)
    assert np.any(draws[:, 0, 0] < 0)                    # negatives are kept


def test_shot_noise_moments_and_quantization():
    v = np.array([0.02, 0.3, 1.0, 4.0])
    snr, ref = 10.0, 0.5
    ins = Instrument(snr=snr, noise="shot", snr_reference=ref)
    n = 40_000
    draws = ins.add_noise(np.broadcast_to(v, (n, 4)), np.random.default_rng(8))
    k = snr ** 2 / ref                                     # counts per unit f_r
    std = np.sqrt(v * ref / snr ** 2)
    assert np.allclose(ins.sigma(v), std)
    assert np.allclose(draws * k, np.round(draws * k))     # photon counts
    _check_moments(draws, v, std, excess_kurtosis=1 / (v * k))
    # at v = snr_reference the SNR is snr
    assert math.isclose(ins.sigma(np.array([ref]))[0], ref / snr)


def test_noise_keeps_nonfinite_and_negative_truth():
    ins = Instrument(snr=10, floor=0.0)
    v = np.array([np.nan, -1.0, 0.5])
    out = ins.add_noise(v, np.random.default_rng(0))
    assert np.isnan(out[0]) and out[1] == -1.0 and out[2] != 0.5
    s = ins.sigma(v)
    assert np.isnan(s[0]) and s[1] == 0 and math.isclose(s[2], 0.05)


def test_describe_is_plain():
    import json
    d = Instrument(cone_source=1, cone_detector=2, snr=50, floor=0.001).describe()
    assert json.loads(json.dumps(d)) == d
    assert d["evaluations_per_pair"] == 144 and d["cone_unit"] == "deg"


@pytest.mark.parametrize("kw, name", [({"snr": 1e-213}, "snr"), ({"snr": 1e200}, "snr"),
                                      ({"floor": 1e300}, "floor"),
                                      ({"snr_reference": 1e-300}, "snr_reference"),
                                      ({"snr_reference": "x"}, "snr_reference")])
def test_noise_parameters_whose_arithmetic_would_overflow_are_refused(kw, name):
    """An snr of 1e-213 made sigma infinite, 1e200 raised OverflowError in snr ** 2."""
    with pytest.raises(ValueError, match=f"^{name} must be"):
        Instrument(**kw)


def test_sizes_are_checked_before_any_quadrature_is_built(monkeypatch):
    """rings and azimuths each at most 256, a pair at most 2^22 evaluations (both cones
    open: (rings x azimuths)^2), refused on construction with the size; no rule built."""
    import gonio.instrument as instrument

    def never(*args, **kw):
        raise AssertionError("quadrature built during the checks")
    monkeypatch.setattr(instrument, "cap_quadrature", never)
    for kwargs, match in (({"rings": 10 ** 7}, r"rings must be an integer in 1\.\.256; got "
                                               r"10000000"),
                          ({"azimuths": 257}, r"azimuths must be an integer in 1\.\.256"),
                          ({"cone_source": 2, "cone_detector": 2, "rings": 64,
                            "azimuths": 33},   # 2,112 points a cone: 4,460,544 a pair
                           r"64 x 33 points a cone.*4,460,544 evaluations for each pair "
                           r"\(about [0-9.]+ GiB at once\); at most 4,194,304")):
        with pytest.raises(ValueError, match=match):
            Instrument(**kwargs)
    ok = [Instrument(cone_source=2, cone_detector=2, rings=64, azimuths=32),   # 2^22
          Instrument(cone_detector=2, rings=256, azimuths=256)]                 # one cone
    assert [i.n_source * i.n_detector for i in ok] == [2048 ** 2, 256 * 256]
