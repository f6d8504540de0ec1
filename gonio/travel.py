"""The order in which a gonioreflectometer measures pairs: one that limits arm travel.

:func:`travel` is the cost an order is judged by: the sum, over consecutive measurements,
of the great-circle angle the source arm moves plus the angle the detector arm moves
(degrees). Great-circle angles are a stand-in that needs no instrument's kinematics (a
theta/phi arm moving near the pole turns its azimuth stage further than this says).
:func:`order_for_travel` groups the pairs by source position (the source is set once per
group), sweeps the detector along a short open path within a group (nearest neighbour then
2-opt; detectors on one great circle, such as an in-plane sweep, are swept monotonically
along it), runs each group's sweep from the end nearer where the detector is (so
consecutive sweeps alternate direction, boustrophedon), and orders the groups by the same
heuristic on the source's move plus the move between the groups' mean detector directions.
Beyond :data:`MAX_TOUR` nodes (source positions, or detectors of one source) 2-opt is
left out, and beyond :data:`MAX_GREEDY` the heuristic gives way to a serpentine order (theta
rows, azimuth alternating).
"""

from __future__ import annotations

import numpy as np

__all__ = ["order_for_travel", "travel", "check_angles", "MAX_TOUR", "MAX_GREEDY"]

#: Largest number of source positions, or of detector positions of one source, ordered by
#: nearest neighbour and 2-opt (O(n^2) memory and time); beyond, by nearest neighbour alone
#: up to MAX_GREEDY (O(n) memory, O(n^2) time), then a serpentine order.
MAX_TOUR = 2000
MAX_GREEDY = 10000
_MAX_PASSES = 100


def check_angles(angles_deg, what: str = "angles_deg") -> np.ndarray:
    """``angles_deg`` as a float (n, 4) array of finite degrees; one-line ValueError naming
    ``what`` otherwise."""
    a = np.asarray(angles_deg, dtype=float)
    if a.ndim != 2 or a.shape[1] != 4:
        raise ValueError(f"{what} must be an (n, 4) array of theta_i, phi_i, theta_o, phi_o "
                         f"in degrees; got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{what}: row {int(np.argmax(~np.isfinite(a).all(axis=1))) + 1} "
                         f"is not finite")
    return a


def _unit(theta_deg, phi_deg) -> np.ndarray:
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def _arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Great-circle angle in degrees between unit directions (broadcast)."""
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


def travel(angles_deg, order=None) -> float:
    """The arm travel of measuring the rows in ``order`` (default: as given), in degrees.

    The sum over consecutive rows of the great-circle angle between the source directions
    plus that between the detector directions (rows theta_i, phi_i, theta_o, phi_o in
    degrees).

    Examples
    --------
    >>> travel([[30, 0, 30, 180], [30, 0, 60, 180], [40, 0, 60, 180]])
    40.0
    """
    a = check_angles(angles_deg)
    if order is not None:
        a = a[np.asarray(order, dtype=np.intp)]
    if len(a) < 2:
        return 0.0
    wi, wo = _unit(a[:, 0], a[:, 1]), _unit(a[:, 2], a[:, 3])
    return float(np.round(np.sum(_arc(wi[1:], wi[:-1]) + _arc(wo[1:], wo[:-1])), 9))


def _two_opt(tour: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """2-opt of a closed tour (best move for each edge in turn, until none gains)."""
    m = len(tour)
    for _ in range(_MAX_PASSES):
        improved = False
        for i in range(m - 2):
            j = np.arange(i + 2, m if i > 0 else m - 1)
            if not len(j):
                continue
            a, b, c, d = tour[i], tour[i + 1], tour[j], tour[(j + 1) % m]
            gain = dist[a, b] + dist[c, d] - dist[a, c] - dist[b, d]
            k = int(np.argmax(gain))
            if gain[k] > 1e-9:
                tour[i + 1:j[k] + 1] = tour[i + 1:j[k] + 1][::-1].copy()
                improved = True
        if not improved:
            break
    return tour


def _open_path(dist: np.ndarray, start: int) -> np.ndarray:
    """A short open path through all nodes of the (m, m) ``dist``: nearest neighbour from
    ``start``, then 2-opt with free ends (a node at distance 0 from all closes the tour)."""
    m = len(dist)
    if m <= 2:
        return np.array([start, 1 - start][:m])
    seen = np.zeros(m, dtype=bool)
    path = [start]
    seen[start] = True
    for _ in range(m - 1):
        row = np.where(seen, np.inf, dist[path[-1]])
        nxt = int(np.argmin(row))
        path.append(nxt)
        seen[nxt] = True
    full = np.zeros((m + 1, m + 1))
    full[:m, :m] = dist
    tour = _two_opt(np.array([m] + path), full)
    cut = int(np.argmax(tour == m))
    return np.concatenate([tour[cut + 1:], tour[:cut]])


def _serpentine(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Rows of equal theta (ascending), azimuth ascending and descending in turn."""
    rows = np.unique(np.round(theta, 6), return_inverse=True)[1]
    ph = np.mod(phi, 360.0)
    return np.lexsort((np.where(rows % 2 == 0, ph, -ph), rows))


def _greedy(units: np.ndarray, extra, start: int) -> np.ndarray:
    """Nearest-neighbour path from ``start``, each row of distances made when needed (O(m)
    memory)."""
    m = len(units)
    seen = np.zeros(m, dtype=bool)
    path = [start]
    seen[start] = True
    for _ in range(m - 1):
        k = path[-1]
        row = np.arccos(np.clip(units @ units[k], -1.0, 1.0))
        if extra is not None:
            row += np.arccos(np.clip(extra @ extra[k], -1.0, 1.0))
        nxt = int(np.argmin(np.where(seen, np.inf, row)))
        path.append(nxt)
        seen[nxt] = True
    return np.array(path)


def _sequence(units: np.ndarray, theta, phi, extra=None) -> np.ndarray:
    """An order of the nodes at ``units`` (m, 3) that keeps moves short (see module notes);
    ``extra`` (m, 3) more unit directions whose moves count too."""
    m, start = len(units), int(np.argmin(theta))
    if m > MAX_GREEDY:
        return _serpentine(theta, phi)
    if m > MAX_TOUR:
        return _greedy(units, extra, start)
    dist = _arc(units[:, None, :], units[None, :, :])
    if extra is not None:
        dist = dist + _arc(extra[:, None, :], extra[None, :, :])
    return _open_path(dist, start)


def order_for_travel(angles_deg) -> np.ndarray:
    """A measurement order of the pairs that limits arm travel (see the module notes).

    Parameters
    ----------
    angles_deg : array_like, shape (n, 4)
        Rows theta_i, phi_i, theta_o, phi_o in degrees.

    Returns
    -------
    ndarray of int, shape (n,)
        A permutation of ``range(n)``: measure row ``order[0]`` first. The same input gives
        the same order.

    Examples
    --------
    >>> a = [[30, 0, 10, 0], [0, 0, 10, 0], [30, 0, 60, 0], [0, 0, 60, 0], [30, 0, 40, 0]]
    >>> order_for_travel(a).tolist()   # normal incidence first, then theta_i 30 swept back
    [1, 3, 2, 4, 0]
    """
    a = check_angles(angles_deg)
    n = len(a)
    if n < 2:
        return np.arange(n)
    wi, wo = _unit(a[:, 0], a[:, 1]), _unit(a[:, 2], a[:, 3])
    keys, group = np.unique(np.round(wi, 9), axis=0, return_inverse=True)
    group = group.reshape(-1)
    members = [np.flatnonzero(group == g) for g in range(len(keys))]
    mean_o = np.array([wo[idx].mean(axis=0) for idx in members])
    norm = np.linalg.norm(mean_o, axis=1, keepdims=True)
    mean_o = np.where(norm > 1e-9, mean_o / np.maximum(norm, 1e-300), [0.0, 0.0, 1.0])
    first = [idx[0] for idx in members]
    tour = _sequence(wi[first], a[first, 0], a[first, 1], mean_o)
    out, here = [], None
    for g in tour:
        idx = members[g]
        sweep = idx[_sequence(wo[idx], a[idx, 2], a[idx, 3])]
        if here is not None and _arc(wo[sweep[-1]], here) < _arc(wo[sweep[0]], here):
            sweep = sweep[::-1]
        out.append(sweep)
        here = wo[sweep[-1]]
    return np.concatenate(out).astype(np.intp)
