"""A worker process that dies with its parent, even a SIGKILLed one (the render's pool)."""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import threading
import time

__all__ = ["exit_with_parent"]


#: prctl(2) option: the signal a process gets when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def exit_with_parent(parent: int) -> None:
    """Make this worker die with its parent, even a SIGKILLed one: PR_SET_PDEATHSIG on Linux,
    else a daemon thread that polls the parent's pid every second."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        ok = libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        ok = False
    if os.getppid() != parent:          # the parent died before the request took effect
        os._exit(1)
    if not ok:
        def watch():
            while os.getppid() == parent:
                time.sleep(1.0)
            os._exit(1)
        threading.Thread(target=watch, daemon=True, name="parent-watchdog").start()
