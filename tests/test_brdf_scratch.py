"""brdf.scratch: per-thread buffers."""

import pickle
import threading

import numpy as np

from brdf.scratch import SCRATCH_MAX_BYTES, Scratch


def test_a_buffer_is_reused_and_grows():
    s = Scratch()
    a = s.array("x", (4, 5))
    b = s.array("x", (2, 10))
    assert np.shares_memory(a, b) and b.shape == (2, 10)
    c = s.array("x", (100,))                 # larger: a new buffer, kept from now on
    assert not np.shares_memory(a, c) and np.shares_memory(c, s.array("x", (3,)))
    assert not np.shares_memory(c, s.array("y", (3,)))          # another name
    assert s.array("x", (3,), np.float32).dtype == np.float32    # another dtype


def test_threads_get_their_own_buffers():
    s = Scratch()
    mine = s.array("x", (10,))
    seen = []
    t = threading.Thread(target=lambda: seen.append(s.array("x", (10,))))
    t.start()
    t.join()
    assert not np.shares_memory(mine, seen[0])


def test_huge_arrays_are_not_kept_and_copies_start_empty():
    s = Scratch()
    n = SCRATCH_MAX_BYTES // 8 + 1
    big = s.array("x", (n,))
    assert big.size == n and not s.buffers
    s.array("x", (5,))
    assert pickle.loads(pickle.dumps(s)).buffers == {}
