"""Per-thread scratch buffers, reused across calls of one object (a Prepared, a Likelihood).

A fit evaluates the same shapes thousands of times from two threads. Fresh temporaries of a
few MiB each cost page faults on every call (the allocator hands such blocks back to the
system when they are freed), about a quarter of a log-posterior evaluation on a virtual
machine, and threads take those faults in turn. A :class:`Scratch` keeps one buffer per name
and thread instead.
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["Scratch", "SCRATCH_MAX_BYTES"]

#: Buffers larger than this (bytes) are not kept: a rare large batch allocates afresh.
SCRATCH_MAX_BYTES = 64 << 20


class Scratch(threading.local):
    """Named buffers, one set per thread (a :class:`threading.local`).

    Examples
    --------
    >>> s = Scratch()
    >>> a = s.array("x", (2, 3), np.float32)
    >>> a.shape, a.dtype.name
    ((2, 3), 'float32')
    >>> s.array("x", (3, 2), np.float32).base is a.base   # the same memory, reshaped
    True
    >>> import pickle
    >>> pickle.loads(pickle.dumps(s)).buffers              # a copy starts empty
    {}
    """

    def __init__(self):
        self.buffers: dict[tuple[str, np.dtype], np.ndarray] = {}

    def __reduce__(self):               # pickled (e.g. sent to a worker) as a new, empty one
        return (Scratch, ())

    def __deepcopy__(self, memo):
        return Scratch()

    def array(self, name: str, shape: tuple[int, ...], dtype=np.float64) -> np.ndarray:
        """An uninitialized C-contiguous array of ``shape``; the buffer ``name`` of this
        thread when it fits (it grows as needed), else a fresh array."""
        dtype = np.dtype(dtype)
        size = math.prod(shape)
        if size * dtype.itemsize > SCRATCH_MAX_BYTES:
            return np.empty(shape, dtype)
        key = (name, dtype)
        buf = self.buffers.get(key)
        if buf is None or buf.size < size:
            buf = self.buffers[key] = np.empty(max(size, 1), dtype)
        return buf[:size].reshape(shape)
