"""Tests of analysis.albedo: known answers, error bounds, the per-thread rule, seeds."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import brdf  # noqa: E402
from _analytic_brdfs import Lambert, Phong, SeparableLobe, TwoLambertThreads  # noqa: E402
from spec_reference import ReferenceFabric  # noqa: E402

from analysis import albedo, albedo_curve, albedo_hemispherical  # noqa: E402


def dirs(theta_deg, phi_deg=0.0):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack(np.broadcast_arrays(np.sin(t) * np.cos(p), np.sin(t) * np.sin(p),
                                        np.cos(t)), axis=-1)


@pytest.mark.parametrize("swap", [False, True])
def test_lambert_albedo_is_its_reflectance(swap):
    w = dirs(np.array([0.0, 30.0, 60.0, 89.0, 89.999]), 37.0)
    r = albedo(Lambert(), w, swap=swap)
    # Gauss-Legendre in mu is exact for f cos(theta) = rho mu / pi; phi is constant
    np.testing.assert_allclose(r.value, np.broadcast_to([0.2, 0.5, 0.8], (5, 3)),
                               rtol=0, atol=1e-12)
    assert r.value.shape == r.error.shape == (5, 3)
    assert np.all(r.error < 1e-3)


def test_below_horizon_direction_gives_zero():
    r = albedo(Lambert(), [[0.0, 0.6, -0.8]])
    assert np.all(r.value == 0)


@pytest.mark.parametrize("theta", [0.0, 20.0, 50.0, 75.0])
def test_separable_lobe_closed_form(theta):
    b = SeparableLobe(n=20)
    for swap in (False, True):
        r = albedo(b, dirs(theta, 10.0), swap=swap, tol=1e-6, rtol=0)
        exact = b.albedo(np.radians(theta))
        assert np.all(np.abs(r.value - exact) <= r.error)
        assert np.all(np.abs(r.value - exact) < 1e-6)


def test_normalized_phong_at_normal_incidence():
    # the lobe about the normal: integral of ks (n+2)/(2 pi) cos^n cos dw = ks exactly
    r = albedo(Phong(n=50, ks=0.7), [0.0, 0.0, 1.0], tol=1e-7, rtol=0, max_level=5)
    assert abs(r.value[0] - 0.7) <= r.error[0]
    assert abs(r.value[0] - 0.7) < 1e-6


def test_rqmc_same_seed_same_bytes_and_contains_exact():
    b = SeparableLobe(n=5)
    w = dirs(np.array([10.0, 60.0]))
    r1 = albedo(b, w, method="rqmc", seed=42, m=10)
    r2 = albedo(b, w, method="rqmc", seed=42, m=10)
    r3 = albedo(b, w, method="rqmc", seed=43, m=10)
    assert r1.value.tobytes() == r2.value.tobytes()
    assert r1.error.tobytes() == r2.error.tobytes()
    assert r1.value.tobytes() != r3.value.tobytes()
    exact = b.albedo(np.radians([10.0, 60.0]))
    assert np.all(np.abs(r1.value - exact) <= r1.error)


def test_thread_rule_on_fake_threads_is_exact_sum():
    fake = TwoLambertThreads(0.25, 0.5)
    r = albedo(fake, dirs(np.array([0.0, 45.0, 85.0]), 20.0), tol=1e-9)
    assert r.method == "threads"
    np.testing.assert_allclose(r.value, 0.75, atol=1e-9)


def test_threads_agree_with_independent_transliteration():
    """brdf's fabric and tests/spec_reference.py (written from MODEL.md) give the same albedo."""
    w = dirs(np.array([0.0, 70.0]), np.array([0.0, 90.0]))
    ours = albedo(brdf.fabric("polyester_satin_charmeuse"), w)
    ref = albedo(ReferenceFabric(brdf.fabric("polyester_satin_charmeuse")), w, max_level=1)
    np.testing.assert_allclose(ours.value, ref.value, atol=1e-6)


def test_sharp_preset_error_bound_contains_converged_value():
    fab = brdf.fabric("polyester_satin_charmeuse")
    w = dirs(np.array([0.0, 60.0, 80.0, 89.0]), np.array([0.0, 0.0, 0.0, 90.0]))
    r = albedo(fab, w)
    assert np.all(r.error <= 1e-3)
    fine = albedo(fab, w, min_level=3, max_level=3 + 1, tol=1e-12, rel_floor=0, abs_floor=0)
    assert np.all(np.abs(r.value - fine.value) <= r.error + fine.error)
    assert np.all(np.abs(r.value - fine.value) < 1e-3)


@pytest.mark.slow
def test_every_preset_within_1e3_of_converged():
    """Default albedo vs a 4x and 8x finer rule, at directions that stress each preset."""
    w = dirs(np.array([0.0, 60.0, 80.0, 88.0]), np.array([0.0, 90.0, 0.0, 45.0]))
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        r = albedo(fab, w)
        ref = albedo(fab, w, min_level=2, max_level=3, tol=1e-12, rel_floor=0, abs_floor=0)
        d = np.abs(r.value - ref.value)
        assert np.all(d < 1e-3), name
        assert np.all(d <= r.error + ref.error), name


@pytest.mark.slow
def test_thread_rule_agrees_with_sphere_rule():
    """Two independent quadratures of the same fabric agree within their error bounds."""
    fab = brdf.fabric("silk_shot")
    w = dirs(np.array([0.0, 50.0]), 30.0)
    a = albedo(fab, w)
    b = albedo(fab, w, method="sphere", min_level=3, max_level=4, tol=1e-12)
    assert b.method == "sphere"
    assert np.all(np.abs(a.value - b.value) <= a.error + b.error)


def test_curve_parallel_equals_serial_and_serializes():
    fab = brdf.fabric("linen_plain")
    c1 = albedo_curve(fab, [0, 45, 89], [0, 90], workers=1)
    c2 = albedo_curve(fab, [0, 45, 89], [0, 90], workers=2)
    assert c1.value.shape == (3, 2, 3)
    assert c1.value.tobytes() == c2.value.tobytes()
    m = c1.max()
    assert m["value"] == pytest.approx(c1.value.max())
    json.dumps(c1.to_dict())


def test_hemispherical_lambert_and_separable():
    h = albedo_hemispherical(Lambert((0.3, 0.3, 0.3)), workers=1)
    np.testing.assert_allclose(h.value, 0.3, atol=1e-12)
    # separable lobe: (1/pi) int k cos^n(o) cos(o) dwo = k * 2/(n+2)
    b = SeparableLobe(n=4)
    h = albedo_hemispherical(b, workers=1, tol=1e-8, rtol=0)
    exact = b.k * 2 / (b.n + 2)
    assert np.all(np.abs(h.value - exact) <= h.error)
    np.testing.assert_allclose(h.value, exact, atol=1e-7)


@pytest.mark.parametrize("kwargs, match", [
    ({"method": "simpson"}, "method"),
    ({"tol": 0.0}, "tol"),
    ({"min_level": 3, "max_level": 1}, "min_level"),
])
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        albedo(Lambert(), [0, 0, 1.0], **kwargs)


def test_bad_directions_and_brdf():
    with pytest.raises(ValueError, match="shape"):
        albedo(Lambert(), [0, 1.0])
    with pytest.raises(ValueError, match="eval"):
        albedo(object(), [0, 0, 1.0])
    with pytest.raises(ValueError, match="threads"):
        albedo(Lambert(), [0, 0, 1.0], method="threads")
    with pytest.raises(ValueError, match="theta_deg"):
        albedo_curve(Lambert(), [0, 95])


def test_rotated_fabric_uses_its_own_thread_axes():
    """Turning the fabric and the direction together leaves the albedo unchanged."""
    rot = 0.4
    w0 = dirs(np.array([30.0, 75.0]), np.array([0.0, 90.0]))
    w1 = dirs(np.array([30.0, 75.0]), np.degrees(rot) + np.array([0.0, 90.0]))
    a = albedo(brdf.fabric("polyester_satin_charmeuse"), w0)
    b = albedo(brdf.fabric("polyester_satin_charmeuse", rotation=rot), w1)
    np.testing.assert_allclose(a.value, b.value, atol=1e-9)
