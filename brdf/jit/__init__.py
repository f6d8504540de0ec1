"""brdf's compiled backend: the microcylinder kernel in Dr.Jit (:mod:`brdf.jit.kernel`),
written once for every Dr.Jit float type, behind the same :class:`brdf.FabricPlan` as the
NumPy kernel (:mod:`brdf.kernel`, :mod:`brdf.shading`), which stays the reference.

``Fabric.eval``, ``Fabric.eval_threads`` and ``Prepared.eval`` run on Dr.Jit's LLVM backend
in float64 (``Prepared.eval(dtype=float32)`` in float32; :mod:`brdf.jit.llvm`) when
:func:`backend` says ``"drjit"``; the Mitsuba
plugin (:mod:`reports.mitsuba.bsdf`) runs the same kernel in its variant's float32.
``MICROCYL_BACKEND=numpy|drjit`` chooses; unset, the default is ``drjit`` where it runs
(Dr.Jit importable, its LLVM backend initialised with an LLVM of version 16 or later: LLVM 14
and 15 abort the process on Dr.Jit's ``fmaximum``), else ``numpy`` with the reason written
once per process (a :class:`BackendWarning`, a UserWarning: the test suite's filters make
brdf's RuntimeWarnings errors, and this one must not fail a machine without Dr.Jit).

Dr.Jit's LLVM kernels flush subnormal numbers (below 2.2e-308) to zero, inputs and
intermediates alike, where NumPy keeps them: pairs with a component nearly 0 (:func:`tiny_pairs`,
0 < |w_k| < 2^-250, about 5.5e-76: products of up to four such factors stay normal) are left to
the NumPy kernel, so that both backends give the same f_r everywhere (at n . wi = 5e-301 a
flushed sample term had moved f_r by 5%).

This package imports no Dr.Jit: :func:`compiled` loads it on first use (about a second).
:func:`limit_threads` caps Dr.Jit's pool of worker threads (by default one a core) for a
process that shares the cores with others: each of N batch workers on C cores takes C // N.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import sys
import threading
import warnings

import numpy as np

__all__ = ["BackendWarning", "backend", "available", "compiled", "ctrl_c_held", "tiny_pairs",
           "use_jit", "worth_a_call", "limit_threads", "thread_limit", "share_cores",
           "MIN_ELEMENTS", "BACKENDS", "BACKEND_ENV", "MIN_LLVM", "TINY_COMPONENT"]

#: The kernels ``MICROCYL_BACKEND`` chooses between.
BACKENDS = ("numpy", "drjit")
#: The environment variable that chooses.
BACKEND_ENV = "MICROCYL_BACKEND"
#: The least LLVM major version Dr.Jit's LLVM backend runs the kernel with.
MIN_LLVM = 16
#: Pairs with a nonzero component below this (2^-250) are shaded by the NumPy kernel.
TINY_COMPONENT = 2.0 ** -250
#: Calls of fewer (pair, tangent sample) elements than this run the NumPy kernel even under
#: the drjit backend: Dr.Jit's tracing of a call (about 0.5 ms) costs more than it saves
#: there (velvet, one thread: 1 pair 0.48 ms NumPy against 0.68 ms Dr.Jit, 1,000 pairs
#: 8.2 against 3.6 ms; 2026-12-07).
MIN_ELEMENTS = 1 << 14
_LIMIT: list[int | None] = [None]      # limit_threads' cap, applied when Dr.Jit loads


def limit_threads(n: int | None) -> None:
    """Cap Dr.Jit's worker threads in this process at ``n`` (None: its default, one a
    core), now if Dr.Jit is loaded, else when :func:`compiled` loads it (this imports no
    Dr.Jit).

    Raises
    ------
    ValueError
        ``n`` is not None nor an integer >= 1.

    Examples
    --------
    >>> limit_threads(1); thread_limit()
    1
    >>> limit_threads(None)
    >>> limit_threads(0)
    Traceback (most recent call last):
    ...
    ValueError: Dr.Jit's thread count must be an integer >= 1 (or None); got 0
    """
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 1):
        raise ValueError(f"Dr.Jit's thread count must be an integer >= 1 (or None); got {n!r}")
    _LIMIT[0] = n
    if "brdf.jit.llvm" in sys.modules:              # loaded already: apply now
        sys.modules["brdf.jit.llvm"].apply_thread_limit(restore=True)


def thread_limit() -> int | None:
    """The cap :func:`limit_threads` set (None: Dr.Jit's default)."""
    return _LIMIT[0]


def share_cores(workers: int) -> int:
    """Run in each of ``workers`` worker processes sharing this machine's cores: caps
    Dr.Jit's threads at cores // workers (at least 1), so that the workers' kernels do not
    oversubscribe the cores; returns the cap.

    >>> share_cores(10 ** 6)
    1
    >>> limit_threads(None)
    """
    n = max(1, (os.cpu_count() or 1) // max(1, int(workers)))
    limit_threads(n)
    return n


def compiled():
    """:mod:`brdf.jit.llvm` (the LLVM float64 driver), imported on first use: the one place
    brdf loads Dr.Jit.

    Raises
    ------
    ImportError
        Dr.Jit is not installed.
    KeyboardInterrupt
        Ctrl-C came while Dr.Jit imported (raised once the import has ended).
    """
    with ctrl_c_held():
        # optional dependency, loaded on use (drjit, about a second): llvm imports it at its top
        from brdf.jit import llvm
    return llvm


@contextlib.contextmanager
def ctrl_c_held():
    """Ctrl-C held back until the block has run, then acted on: for the imports of Dr.Jit
    and Mitsuba, whose extensions crash the process when a KeyboardInterrupt comes while
    they initialise (nanobind's std::terminate, a segfault, or a half-registered module
    whose next import aborts; Dr.Jit 1.5.0, 2026-12-08). In the main thread, where Python
    runs its handler (no other thread receives the interrupt), and where the handler is
    Python's (an ignored or default SIGINT is left as it is).

    Examples
    --------
    >>> with ctrl_c_held():
    ...     done = True            # an interrupt here would be raised after the block
    >>> done
    True
    """
    handler = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(handler):
        yield
        return
    came = []
    signal.signal(signal.SIGINT, lambda *args: came.append(args))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)
    for args in came[:1]:
        handler(*args)


@functools.cache
def available() -> tuple[bool, str]:
    """Whether the Dr.Jit backend runs in this process, and why not (asked once).

    Returns
    -------
    (bool, str)
        True and "" where Dr.Jit imports, its LLVM backend initialised with LLVM >=
        :data:`MIN_LLVM`, and a small kernel gives the right answer; else False and the
        reason.
    """
    try:
        llvm = compiled()
    except ImportError as exc:
        return False, f"Dr.Jit is not importable ({exc})"
    return llvm.probe(MIN_LLVM)


def backend() -> str:
    """The kernel that ``Fabric.eval`` and ``Prepared.eval`` run: ``"numpy"`` or
    ``"drjit"`` (read from ``MICROCYL_BACKEND`` at each call; the probe of Dr.Jit is made
    once).

    Raises
    ------
    ValueError
        ``MICROCYL_BACKEND`` is set to something else than ``numpy`` or ``drjit``.
    RuntimeError
        ``MICROCYL_BACKEND=drjit`` where Dr.Jit does not run (the reason given).

    Examples
    --------
    >>> import os
    >>> os.environ[BACKEND_ENV] = "numpy"
    >>> backend()
    'numpy'
    >>> del os.environ[BACKEND_ENV]
    >>> backend() == ("drjit" if available()[0] else "numpy")
    True
    """
    choice = os.environ.get(BACKEND_ENV, "").strip()
    if choice == "numpy":
        return "numpy"
    if choice not in ("", "drjit"):
        raise ValueError(f"{BACKEND_ENV} must be one of {', '.join(BACKENDS)} (or unset); "
                         f"got {choice!r}")
    ok, why = available()
    if ok:
        return "drjit"
    if choice == "drjit":
        raise RuntimeError(f"{BACKEND_ENV}=drjit, but Dr.Jit does not run here: {why}")
    _fallback(why)
    return "numpy"


class BackendWarning(UserWarning):
    """The Dr.Jit backend does not run here; the NumPy kernel does (said once a process)."""


@functools.cache
def _fallback(why: str) -> None:
    """Say once per process why the NumPy kernel runs."""
    warnings.warn(f"microcyl: the Dr.Jit backend does not run here ({why}); using the "
                  f"NumPy kernel (set {BACKEND_ENV}=numpy to silence this)", BackendWarning,
                  stacklevel=3)


def use_jit(plan, pairs: int) -> bool:
    """Whether ``pairs`` pairs of ``plan`` (a :class:`brdf.FabricPlan`) run on Dr.Jit: the
    backend is drjit and they make at least :data:`MIN_ELEMENTS` (pair, sample) elements.

    >>> import brdf, os
    >>> os.environ[BACKEND_ENV] = "numpy"
    >>> use_jit(brdf.fabric("velvet").plan, 10 ** 6)
    False
    >>> del os.environ[BACKEND_ENV]
    """
    return backend() == "drjit" and worth_a_call(plan, pairs)


def worth_a_call(plan, pairs: int) -> bool:
    """Whether ``pairs`` pairs of ``plan`` (of one parameter set, or a batch's sets times its
    pairs) make the :data:`MIN_ELEMENTS` (pair, sample) elements that pay for a Dr.Jit call
    (its tracing, about 0.5 ms), whichever backend is chosen.

    >>> import brdf
    >>> plan = brdf.fabric("velvet").plan              # 32 + 32 distinct samples
    >>> worth_a_call(plan, 255), worth_a_call(plan, 256)
    (False, True)
    """
    return pairs * sum(t.ca.size for t in plan.threads) >= MIN_ELEMENTS


def tiny_pairs(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """The pairs of unit (n, 3) ``wi``, ``wo`` with a nonzero component below
    :data:`TINY_COMPONENT`, which the NumPy kernel shades (module notes): a bool array (n,).

    >>> w = np.array([[0.6, 0.0, 0.8], [1.0, 0.0, 1e-310], [1.0, 1e-80, 0.0]])
    >>> tiny_pairs(w, w[::-1]).tolist()
    [True, True, True]
    >>> tiny_pairs(w[:1], w[:1]).tolist()
    [False]
    """
    def sub(w):
        a = np.abs(w)
        flag = (a < TINY_COMPONENT) & (a != 0.0)
        return (flag[:, 0] | flag[:, 1] | flag[:, 2]) if flag.any() else None

    out = [f for f in (sub(wi), sub(wo)) if f is not None]
    if not out:                     # the usual case, at the cost of one pass
        return np.zeros(wi.shape[0], dtype=bool)
    return out[0] | out[-1]
