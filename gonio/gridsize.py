"""Sizes of the grid layouts of :mod:`gonio.layouts`, counted without building them.

The step parsing and the pair counts that the layouts' builders check before allocating
(:func:`check_pairs`: at most :data:`MAX_PAIRS`, and within the memory limit of
:func:`gonio.memory.memory_limit`) and that :func:`gonio.geomspec.spec_pairs` and the memory
budgets use. Every layout's size, from a spec string, a file or the API, passes
:func:`check_pairs` before its arrays are built. Steps are in degrees.
"""

from __future__ import annotations

import math

import numpy as np

from gonio.memory import check_memory
from gonio.numtext import parse_number

__all__ = ["MAX_PAIRS", "full_grid_pairs", "rusinkiewicz_pairs", "merl_pairs", "step_degrees",
           "node_count", "node_range", "side_count", "full_steps", "rus_steps", "merl_stride",
           "check_pairs", "plane_pairs", "GEOMETRY_BYTES_PER_PAIR"]


def step_degrees(name, value, upper=90.0) -> float:
    """``value`` (a number or its text) as a step in (0, ``upper``] degrees, or a ValueError
    naming ``name``."""
    try:
        v = parse_number(value.strip(" \t")) if isinstance(value, str) else float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number of degrees; got {value!r}") from None
    if not (math.isfinite(v) and 0 < v <= upper):
        raise ValueError(f"{name} must be in (0, {upper:g}] degrees; got {value!r}")
    return v


#: The most (wi, wo) pairs a grid layout builds (about 2 GB of float64 arrays): finer steps
#: are refused before any allocation instead of exhausting memory.
MAX_PAIRS = 20_000_000
#: Peak memory of building a layout, bytes a pair (directions, angles, the horizon's
#: selection and their copies; about 250 measured on full:2, rounded up).
GEOMETRY_BYTES_PER_PAIR = 300


def node_count(step, stop) -> int:
    """Size of :func:`_range` (``step``, ``stop``), without building it."""
    return int(math.ceil(stop / step - 1e-9))


def side_count(theta_step, phi_step) -> int:
    """Directions of one side of a full grid: 1 + (n_theta - 1) n_phi."""
    return 1 + (node_count(theta_step, 90.0) - 1) * node_count(phi_step, 360.0)


def full_steps(theta_step, phi_step, theta_o_step, phi_o_step):
    """The four checked steps of a full grid, with their defaults filled in."""
    ti_s = step_degrees("theta_step", theta_step)
    pi_s = step_degrees("phi_step", ti_s if phi_step is None else phi_step, 360.0)
    to_s = step_degrees("theta_o_step", ti_s if theta_o_step is None else theta_o_step)
    po_s = step_degrees("phi_o_step", pi_s if phi_o_step is None else phi_o_step, 360.0)
    return ti_s, pi_s, to_s, po_s


def full_grid_pairs(theta_step: float = 10.0, phi_step: float | None = None, *,
                    theta_o_step: float | None = None, phi_o_step: float | None = None) -> int:
    """Number of pairs :func:`full_grid` builds for these steps (degrees), counted without
    building them (an exact int, however large).

    Examples
    --------
    >>> full_grid_pairs(45, 90)
    25
    """
    ti_s, pi_s, to_s, po_s = full_steps(theta_step, phi_step, theta_o_step, phi_o_step)
    return side_count(ti_s, pi_s) * side_count(to_s, po_s)


def rus_steps(theta_h_step, phi_h_step, theta_d_step, phi_d_step):
    """The four checked steps of a Rusinkiewicz grid, with their defaults filled in."""
    th_s = step_degrees("theta_h_step", theta_h_step)
    ph_s = step_degrees("phi_h_step", th_s if phi_h_step is None else phi_h_step, 360.0)
    td_s = step_degrees("theta_d_step", th_s if theta_d_step is None else theta_d_step)
    pd_s = step_degrees("phi_d_step", th_s if phi_d_step is None else phi_d_step, 360.0)
    return th_s, ph_s, td_s, pd_s


def rusinkiewicz_pairs(theta_h_step: float = 5.0, phi_h_step: float | None = None,
                       theta_d_step: float | None = None,
                       phi_d_step: float | None = None) -> int:
    """Number of (theta_h, phi_h, theta_d, phi_d) nodes :func:`rusinkiewicz` places (before
    it drops those below the horizon), counted without building them."""
    th_s, ph_s, td_s, pd_s = rus_steps(theta_h_step, phi_h_step, theta_d_step, phi_d_step)
    return node_count(th_s, 90.0) * node_count(ph_s, 360.0) * node_count(td_s, 90.0) * node_count(pd_s, 360.0)


def merl_stride(stride) -> int:
    """A checked MERL stride (an integer in [1, 90])."""
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or not 1 <= stride <= 90:
        raise ValueError(f"MERL stride must be an integer in [1, 90]; got {stride!r}")
    return int(stride)


def merl_pairs(stride: int = 1) -> int:
    """Number of MERL bins :func:`merl` places for ``stride`` (before the horizon).

    Examples
    --------
    >>> merl_pairs(30)
    54
    """
    s = merl_stride(stride)
    return node_count(s, 90.0) ** 2 * node_count(s, 180.0)


def plane_pairs(theta_o_step: float = 5.0, n_theta_i: int = 6) -> int:
    """Number of pairs :func:`plane` places for ``n_theta_i`` incidences: each sweeps
    theta_o = k step strictly inside (-90, 90).

    Examples
    --------
    >>> plane_pairs(30, 2)
    10
    """
    k = node_count(step_degrees("theta_o_step", theta_o_step), 90.0) - 1
    return int(n_theta_i) * (2 * k + 1)


def check_pairs(kind, counts) -> None:
    """ValueError if the product of ``counts`` exceeds :data:`MAX_PAIRS`, or the layout's
    arrays (:data:`GEOMETRY_BYTES_PER_PAIR` a pair) exceed the memory limit
    (:func:`gonio.memory.check_memory`).

    Examples
    --------
    >>> check_pairs("plane", (6, 1.8e11))
    Traceback (most recent call last):
    ...
    ValueError: plane: the steps give 1,080,000,000,000 direction pairs, more than
    20,000,000; use coarser steps
    """
    total = math.prod(int(c) for c in counts)
    if total > MAX_PAIRS:
        raise ValueError(f"{kind}: the steps give {total:,} direction pairs, more than "
                         f"{MAX_PAIRS:,}; use coarser steps")
    check_memory(f"{kind}: {total:,} direction pairs", total * GEOMETRY_BYTES_PER_PAIR,
                 "use coarser steps")


def node_range(step, stop) -> np.ndarray:
    """Degrees 0, step, 2 step, ... strictly below ``stop`` (robust to rounding)."""
    return step * np.arange(node_count(step, stop))
