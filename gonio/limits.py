"""The reach of a gonioreflectometer: which (wi, wo) pairs its arms can take.

A real instrument cannot take every pair of directions. :class:`gonio.Instrument` has three
limits (each off by default), checked here:

- ``max_theta`` (degrees, 0 < x <= 90): the largest polar angle of either arm. It limits the
  arm's *nominal* direction (the axis of its cone): the mechanics stop the arm, not the light,
  and the part of a cone beyond the limit is light the arm still delivers or collects (a part
  below the horizon counts with f_r = 0, as everywhere in :func:`gonio.measure`).
- ``min_separation`` (degrees, 0 <= x < 180): the smallest angle between the source and the
  detector *cones*, edge to edge: with s the angle between the nominal directions and
  ``cone_source``, ``cone_detector`` the half-angles, a pair is reachable when
  s - cone_source - cone_detector >= min_separation. The detector's head subtends at least
  its acceptance cone seen from the sample and the source at least its own cone, so when the
  two overlap the detector shadows the source (or looks into it); ``min_separation`` is the
  margin the heads need beyond their apertures. With point cones it is the smallest angle
  between the arms, so any ``min_separation > 0`` makes exact retro-reflection (wo = wi)
  unreachable; ``min_separation = 0`` with open cones refuses overlapping cones only.
- ``in_plane`` (bool): the instrument measures in the plane of incidence only: the
  detector's azimuth equals the source's or its opposite, within :data:`IN_PLANE_TOLERANCE`
  radians (|sin(phi_o - phi_i)| <= 1e-6). A direction within 1e-6 rad of the normal lies in
  every plane through it, so normal incidence (or a detector at the normal) is in plane.

The limits are rotations about the normal alike (theta, the angle between the arms and the
plane through the normal all stay), so the sample's rotation on the stage does not change
which pairs are reachable: directions in the lab frame and in the sample frame give the same
answer. Angles at a limit are reachable within :data:`ANGLE_TOLERANCE` degrees (angles that
went through degrees, cosines and back are not exact).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["check_limits", "limit_violations", "reachable", "check_reachable",
           "describe_limits", "ANGLE_TOLERANCE", "IN_PLANE_TOLERANCE", "LIMIT_NAMES"]

#: Degrees by which a pair may pass ``max_theta`` or fall short of ``min_separation`` and
#: still count as reachable (rounding of angles written in degrees).
ANGLE_TOLERANCE = 1e-6
#: Radians: the largest |sin(phi_o - phi_i)| of an in-plane pair, and the largest polar angle
#: of a direction that counts as the normal (in every plane).
IN_PLANE_TOLERANCE = 1e-6
#: The names of the limits, in the order messages give them.
LIMIT_NAMES = ("max_theta", "min_separation", "in_plane")


def _degrees(name: str, value, lo: float, hi: float, lo_open: bool, hi_open: bool):
    """``value`` as a float in the interval, None for None; one-line ValueError otherwise."""
    if value is None:
        return None
    allowed = (f"None (no limit) or degrees in {'(' if lo_open else '['}{lo:g}, "
               f"{hi:g}{')' if hi_open else ']'}")
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {allowed}; got {value!r}") from None
    inside = (math.isfinite(v) and (v > lo if lo_open else v >= lo)
              and (v < hi if hi_open else v <= hi))
    if not inside:
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    return v


def check_limits(max_theta=None, min_separation=None, in_plane=False):
    """The limits checked and normalized: ``(max_theta, min_separation, in_plane)``.

    Raises
    ------
    ValueError
        One line naming the limit, its value and what is allowed: ``max_theta`` None or
        degrees in (0, 90], ``min_separation`` None or degrees in [0, 180), ``in_plane`` a
        bool.

    Examples
    --------
    >>> check_limits(80, 5, True)
    (80.0, 5.0, True)
    >>> check_limits(max_theta=0)
    Traceback (most recent call last):
    ...
    ValueError: max_theta must be None (no limit) or degrees in (0, 90]; got 0
    """
    max_theta = _degrees("max_theta", max_theta, 0.0, 90.0, True, False)
    min_separation = _degrees("min_separation", min_separation, 0.0, 180.0, False, True)
    if not isinstance(in_plane, (bool, np.bool_)):
        raise ValueError(f"in_plane must be True or False; got {in_plane!r}")
    return max_theta, min_separation, bool(in_plane)


def _directions(name: str, w) -> np.ndarray:
    w = np.asarray(w, dtype=float)
    if w.ndim == 0 or w.shape[-1] != 3:
        raise ValueError(f"{name} must be directions of shape (..., 3); got shape {w.shape}")
    return w


def _polar(w: np.ndarray) -> np.ndarray:
    """Polar angle from +z in degrees, accurate near the pole (no arccos)."""
    return np.degrees(np.arctan2(np.hypot(w[..., 0], w[..., 1]), w[..., 2]))


def _between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between directions in degrees, accurate near 0 and 180 (no arccos)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1),
                                 np.sum(a * b, axis=-1)))


def limit_violations(wi, wo, *, max_theta=None, min_separation=None, in_plane=False,
                     cone_source=0.0, cone_detector=0.0) -> dict[str, np.ndarray]:
    """Which pairs break each limit that is on: ``{name: bool array}`` (broadcast shape of
    ``wi[..., 0]`` and ``wo[..., 0]``), names in :data:`LIMIT_NAMES` order, a limit that is
    off left out. Directions (..., 3) in the local frame (z up; need not be unit; one with a
    NaN breaks every limit); cone half-angles in degrees; see the module notes for the
    readings."""
    wi, wo = _directions("wi", wi), _directions("wo", wo)
    try:
        wi, wo = np.broadcast_arrays(wi, wo)
    except ValueError:
        raise ValueError(f"wi and wo must broadcast together; got shapes {wi.shape} and "
                         f"{wo.shape}") from None
    out = {}
    if max_theta is not None:
        top = np.maximum(_polar(wi), _polar(wo))                  # NaN stays NaN: refused
        out["max_theta"] = ~(top <= max_theta + ANGLE_TOLERANCE)
    if min_separation is not None:
        gap = _between(wi, wo) - cone_source - cone_detector
        out["min_separation"] = ~(gap >= min_separation - ANGLE_TOLERANCE)
    if in_plane:
        ri, ro = np.hypot(wi[..., 0], wi[..., 1]), np.hypot(wo[..., 0], wo[..., 1])
        cross = wi[..., 0] * wo[..., 1] - wi[..., 1] * wo[..., 0]
        pole = ((ri <= IN_PLANE_TOLERANCE * np.linalg.norm(wi, axis=-1))
                | (ro <= IN_PLANE_TOLERANCE * np.linalg.norm(wo, axis=-1)))
        finite = np.isfinite(wi).all(axis=-1) & np.isfinite(wo).all(axis=-1)
        out["in_plane"] = ~(finite & (pole | (np.abs(cross) <= IN_PLANE_TOLERANCE * ri * ro)))
    return out


def reachable(wi, wo, **limits) -> np.ndarray:
    """Whether each pair is within every limit: a bool array of the broadcast shape.

    ``limits`` are :func:`limit_violations`'s keywords (the instrument's limits and cones).

    Examples
    --------
    >>> wi = np.array([0.5, 0.0, 0.75 ** 0.5])            # theta 30, phi 0
    >>> wo = np.array([[0.5, 0.0, 0.75 ** 0.5],            # retro-reflection
    ...                [-0.5, 0.0, 0.75 ** 0.5],           # mirror, in plane
    ...                [0.0, 0.5, 0.75 ** 0.5]])           # out of plane
    >>> reachable(wi, wo, min_separation=5, in_plane=True).tolist()
    [False, True, False]
    """
    bad = limit_violations(wi, wo, **limits)
    shape = np.broadcast_shapes(np.shape(wi)[:-1], np.shape(wo)[:-1])
    ok = np.ones(shape, dtype=bool)
    for v in bad.values():
        ok &= ~v
    return ok


def describe_limits(max_theta=None, min_separation=None, in_plane=False, cone_source=0.0,
                    cone_detector=0.0) -> str:
    """The limits in words, one line (what the messages and the CLI print).

    Examples
    --------
    >>> describe_limits(80, 5, False, 1, 0)
    'max_theta 80 deg, min_separation 5 deg between the cones (half-angles 1 and 0 deg)'
    >>> describe_limits()
    'no limits'
    """
    parts = []
    if max_theta is not None:
        parts.append(f"max_theta {max_theta:g} deg")
    if min_separation is not None:
        cones = (f" between the cones (half-angles {cone_source:g} and {cone_detector:g} "
                 f"deg)" if cone_source or cone_detector else "")
        parts.append(f"min_separation {min_separation:g} deg{cones}")
    if in_plane:
        parts.append("in the plane of incidence only")
    return ", ".join(parts) if parts else "no limits"


_BROKEN = {"max_theta": "beyond max_theta", "min_separation": "closer than min_separation",
           "in_plane": "out of the plane of incidence"}


def _deg(x: float) -> str:
    """Degrees for a message: rounded to 1e-6, 7 significant digits, no ``-0``."""
    return f"{round(float(x), 6) + 0.0:.7g}"


def _angles(w: np.ndarray) -> tuple[str, str]:
    """(theta, phi) of one direction in words (degrees; phi in [0, 360), 0 at the normal)."""
    phi = math.degrees(math.atan2(w[1], w[0])) if np.hypot(w[0], w[1]) > 0 else 0.0
    return _deg(_polar(w)), _deg(round(phi, 6) % 360.0)


def check_reachable(wi, wo, what: str = "geometry", **limits) -> None:
    """Raise a one-line ValueError when some pair is out of reach.

    The message says how many pairs break which limit, the first such pair's angles in
    degrees (theta_i, phi_i, theta_o, phi_o; its position, 1-based, in the flattened
    pairs) and the limits. ``limits`` are :func:`limit_violations`'s keywords.

    Examples
    --------
    >>> wi = np.array([[0.5, 0.0, 0.75 ** 0.5]] * 2)
    >>> wo = wi * [[1, 1, 1], [-1, 1, 1]]
    >>> check_reachable(wi, wo, "plan.csv", min_separation=5)  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    ValueError: plan.csv: 1 of 2 pairs out of the instrument's reach (1 closer than
    min_separation); the first, pair 1: theta_i 30, phi_i 0, theta_o 30, phi_o 0 deg
    (separation 0 deg); limits: min_separation 5 deg
    """
    bad = limit_violations(wi, wo, **limits)
    if not bad:
        return
    shape = np.broadcast_shapes(np.shape(wi)[:-1], np.shape(wo)[:-1])
    flat = {k: np.broadcast_to(v, shape).reshape(-1) for k, v in bad.items()}
    anyb = np.zeros(int(np.prod(shape)), dtype=bool)
    for v in flat.values():
        anyb |= v
    n_bad = int(anyb.sum())
    if not n_bad:
        return
    k = int(np.argmax(anyb))
    a = np.broadcast_to(np.asarray(wi, float), shape + (3,)).reshape(-1, 3)[k]
    b = np.broadcast_to(np.asarray(wo, float), shape + (3,)).reshape(-1, 3)[k]
    (ti, pi_), (to, po) = _angles(a), _angles(b)
    counts = ", ".join(f"{int(v.sum())} {_BROKEN[n]}" for n, v in flat.items() if v.any())
    sep = _deg(_between(a, b))
    limit_words = describe_limits(limits.get("max_theta"), limits.get("min_separation"),
                                  limits.get("in_plane", False),
                                  limits.get("cone_source", 0.0),
                                  limits.get("cone_detector", 0.0))
    raise ValueError(
        f"{what}: {n_bad} of {anyb.size} pairs out of the instrument's reach ({counts}); "
        f"the first, pair {k + 1}: theta_i {ti}, phi_i {pi_}, theta_o {to}, phi_o {po} deg "
        f"(separation {sep} deg); limits: {limit_words}")
