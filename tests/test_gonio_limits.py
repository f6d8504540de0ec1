"""Tests of the instrument's limits (gonio/limits.py, Instrument.reachable and
check_reachable) and of gonio.measure's refusal of pairs out of reach."""

import math
import re

import numpy as np
import pytest

from gonio import Instrument, measure, pairs_from_angles
from gonio.limits import ANGLE_TOLERANCE


def _w(theta, phi):
    """Unit direction from theta, phi in degrees (written out, not the library's)."""
    t, p = np.radians(theta), np.radians(phi)
    return np.stack(np.broadcast_arrays(np.sin(t) * np.cos(p), np.sin(t) * np.sin(p),
                                        np.cos(t)), axis=-1)


def _rotated(w, angle_deg):
    """``w`` turned by ``angle_deg`` toward the normal's side: an exact separation."""
    w = np.asarray(w, float)
    axis = np.cross(w, [0.0, 0.0, 1.0]) if abs(w[2]) < 1 else np.array([0.0, 1.0, 0.0])
    axis = axis / np.linalg.norm(axis)
    a = math.radians(angle_deg)       # Rodrigues
    return (w * math.cos(a) + np.cross(axis, w) * math.sin(a)
            + axis * (axis @ w) * (1 - math.cos(a)))


class Boom:
    def eval(self, wi, wo):
        raise AssertionError("evaluated before the reach was checked")


def test_defaults_have_no_limits():
    ins = Instrument()
    assert (ins.max_theta, ins.min_separation, ins.in_plane) == (None, None, False)
    assert not ins.has_limits
    wi, wo = _w(np.full(5, 30.0), 0.0), _w(np.array([30.0, 89.9, 90.0, 0.0, 60.0]),
                                         np.array([0.0, 45.0, 90.0, 0.0, 270.0]))
    assert ins.reachable(wi, wo).all()
    d = ins.describe()
    assert d["max_theta"] is None and d["min_separation"] is None and d["in_plane"] is False


def test_max_theta_limits_either_arm():
    ins = Instrument(max_theta=80)
    ti = np.array([80.0, 80.001, 30.0, 30.0, 0.0])
    to = np.array([30.0, 30.0, 80.0, 80.001, 90.0])
    assert ins.reachable(_w(ti, 0.0), _w(to, 180.0)).tolist() == [True, False, True, False,
                                                                    False]
    # a limit of 90 allows the horizon, not below it
    assert Instrument(max_theta=90).reachable(_w(90.0, 0), _w([90.0, 90.5], 0)).tolist() == [
        True, False]


def test_max_theta_is_the_nominal_direction_whatever_the_cones():
    ins = Instrument(max_theta=60, cone_source=5, cone_detector=5)
    assert ins.reachable(_w(60.0, 0), _w(60.0, 180.0))        # cone edges reach 65


def test_min_separation_point_cones_excludes_retro_reflection():
    ins = Instrument(min_separation=5)
    wi = _w(30.0, 40.0)
    wo = np.array([wi, _rotated(wi, 5.0), _rotated(wi, 4.99), _rotated(wi, -5.0),
                   _rotated(wi, 175.0)])
    assert ins.reachable(wi, wo).tolist() == [False, True, False, True, True]
    # min_separation 0 with point cones: everything reachable, retro-reflection too
    assert Instrument(min_separation=0).reachable(wi, wo).all()


def test_min_separation_counts_between_the_cones_edges():
    """Separation less both half-angles: cones of 2 and 3 degrees 10 apart leave a 5-degree
    gap; with min_separation 0 only overlapping cones are refused."""
    wi = _w(45.0, 10.0)
    wo = np.array([_rotated(wi, 10.0), _rotated(wi, 9.99), _rotated(wi, 5.0),
                   _rotated(wi, 4.9)])
    ins = Instrument(cone_source=2, cone_detector=3, min_separation=5)
    assert ins.reachable(wi, wo).tolist() == [True, False, False, False]
    ins0 = Instrument(cone_source=2, cone_detector=3, min_separation=0)
    assert ins0.reachable(wi, wo).tolist() == [True, True, True, False]


def test_in_plane():
    ins = Instrument(in_plane=True)
    wi = _w(30.0, 20.0)
    wo = _w(np.array([50.0, 50.0, 50.0, 50.0, 50.0, 50.0, 0.0]),
            np.array([200.0, 20.0, 110.0, 200.0 + math.degrees(5e-7),
                      200.0 + math.degrees(5e-6), 20.0 - 360.0, 77.0]))
    assert ins.reachable(wi, wo).tolist() == [True, True, False, True, False, True, True]
    # normal incidence is in every plane
    assert ins.reachable(_w(0.0, 0.0), _w(60.0, np.arange(0.0, 360.0, 30.0))).all()


def test_reachable_broadcasts_and_ignores_the_stage_rotation():
    rng = np.random.default_rng(3)
    ins = Instrument(max_theta=70, min_separation=10, in_plane=True, cone_detector=1)
    wi = _w(rng.uniform(0, 90, (4, 1)), rng.uniform(0, 360, (4, 1)))
    wo = _w(rng.uniform(0, 90, (1, 6)), rng.uniform(0, 360, (1, 6)))
    wo[0, :3] = -wi[0, 0] * [1, 1, -1]                          # mirror: in plane
    ok = ins.reachable(wi, wo)
    assert ok.shape == (4, 6) and ok.dtype == bool and ok.any() and not ok.all()
    c, s = math.cos(1.1), math.sin(1.1)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    assert np.array_equal(ins.reachable(wi @ R.T, wo @ R.T), ok)
    assert ins.reachable(wi[0, 0], wo[0, 0]).shape == ()
    with pytest.raises(ValueError, match=r"^wi and wo must broadcast together; got shapes "
                                         r"\(3, 3\) and \(2, 3\)$"):
        ins.reachable(wi[:3, 0], wo[0, :2])
    with pytest.raises(ValueError, match=r"^wo must be directions of shape \(\.\.\., 3\)"):
        ins.reachable(wi, [1.0, 0.0])


@pytest.mark.parametrize("kw, match", [
    ({"max_theta": 0}, r"^max_theta must be None \(no limit\) or degrees in \(0, 90\]; got 0$"),
    ({"max_theta": 90.5}, "^max_theta must be"), ({"max_theta": math.nan}, "^max_theta"),
    ({"max_theta": "high"}, "^max_theta"), ({"max_theta": True}, "^max_theta"),
    ({"min_separation": -1}, r"^min_separation must be None \(no limit\) or degrees in "
                             r"\[0, 180\); got -1$"),
    ({"min_separation": 180}, "^min_separation"), ({"min_separation": math.inf},
                                                    "^min_separation"),
    ({"in_plane": "yes"}, "^in_plane must be True or False; got 'yes'$"),
    ({"in_plane": 1}, "^in_plane"), ({"in_plane": None}, "^in_plane"),
])
def test_bad_limits_are_refused_in_one_line(kw, match):
    with pytest.raises(ValueError, match=match) as exc:
        Instrument(**kw)
    assert "\n" not in str(exc.value)


def test_limits_are_normalized_and_described():
    ins = Instrument(max_theta=np.float32(75), min_separation=3, in_plane=np.bool_(True))
    assert ins.max_theta == 75.0 and type(ins.max_theta) is float
    assert ins.min_separation == 3.0 and ins.in_plane is True
    d = ins.describe()
    assert (d["max_theta"], d["min_separation"], d["in_plane"], d["limit_unit"]) == (
        75.0, 3.0, True, "deg")
    assert ins.describe_limits() == ("max_theta 75 deg, min_separation 3 deg, in the plane "
                                     "of incidence only")


def test_check_reachable_says_how_many_which_limit_and_the_first():
    ins = Instrument(max_theta=70, min_separation=5)
    angles = np.array([[30, 0, 30, 180], [40, 90, 40, 90], [75, 0, 30, 180],
                       [30, 0, 30, 0], [20, 0, 50, 180]], float)
    wi, wo = _w(angles[:, 0], angles[:, 1]), _w(angles[:, 2], angles[:, 3])
    with pytest.raises(ValueError) as exc:
        ins.check_reachable(wi, wo, "plan.csv")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("plan.csv: 3 of 5 pairs out of the instrument's "
                                              "reach (1 beyond max_theta, 2 closer than "
                                              "min_separation)")
    assert re.search(r"the first, pair 2: theta_i 40, phi_i 90, theta_o 40, phi_o 90 deg "
                     r"\(separation 0 deg\); limits: max_theta 70 deg, min_separation 5 deg$",
                     msg), msg
    ins.check_reachable(wi[[0, 4]], wo[[0, 4]])                 # no error


def test_angles_at_a_limit_survive_rounding_through_degrees():
    """Pairs written in degrees and read back sit at the limit within rounding."""
    ins = Instrument(max_theta=80, min_separation=20, in_plane=True)
    g = pairs_from_angles([80.0, 10.0], [33.0, 33.0], [60.0, 30.0], [213.0, 33.0])
    assert ins.reachable(g.wi, g.wo).tolist() == [True, True]
    over = 80 + 100 * ANGLE_TOLERANCE
    g = pairs_from_angles([over], [33.0], [60.0], [213.0])
    assert not ins.reachable(g.wi, g.wo)[0]


def test_measure_refuses_unreachable_pairs_before_any_evaluation():
    ins = Instrument(min_separation=5, snr=20)
    g = pairs_from_angles([30, 30, 45], [0, 0, 10], [30, 60, 45], [180, 0, 10])
    with pytest.raises(ValueError, match=r"^geometry pairs: 1 of 3 pairs out of the "
                                         r"instrument's reach \(1 closer than min_separation\);"
                                         r" the first, pair 3: theta_i 45, phi_i 10"):
        measure(Boom(), g, ins, seed=1)
    with pytest.raises(ValueError, match=r"^geometry full:30:30:30:30: 505 of 625 pairs .*"
                                         r"480 out of the plane of incidence"):
        measure(Boom(), "full:30", Instrument(in_plane=True, min_separation=1))


def test_limits_change_no_value():
    class Lambert:
        def eval(self, wi, wo):
            return np.where((wi[:, 2] > 0) & (wo[:, 2] > 0), 0.3, 0.0)[:, None] * np.ones(3)
    g = pairs_from_angles([30, 30, 0], [0, 0, 0], [30, 60, 40], [180, 180, 90])
    limited = Instrument(cone_detector=2, snr=30, max_theta=70, min_separation=5,
                         in_plane=True)
    free = Instrument(cone_detector=2, snr=30)
    a, b = measure(Lambert(), g, limited, seed=4), measure(Lambert(), g, free, seed=4)
    assert np.array_equal(a.values, b.values) and a.meta["instrument"]["in_plane"] is True


def test_a_direction_with_a_nan_is_out_of_reach_of_every_limit():
    bad = np.array([np.nan, 0.0, 1.0])
    for kw in ({"max_theta": 80}, {"min_separation": 1}, {"in_plane": True}):
        assert not Instrument(**kw).reachable(bad, [0.0, 0.0, 1.0])
        assert not Instrument(**kw).reachable([0.0, 0.0, 1.0], bad)
    assert Instrument().reachable(bad, bad)                      # no limit: nothing checked
