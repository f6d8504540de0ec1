"""Shared test fixtures."""

from pathlib import Path

import signal

import pytest

#: ../shared/data, the measured BRDF data kept beside this repository (never copied in).
SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ../shared/data; tests that need it skip cleanly when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"measured data not found at {SHARED_DATA}")
    return SHARED_DATA


def default_sigint():
    """``preexec_fn`` for a CLI subprocess that a test interrupts: SIGINT at its default, as
    a terminal gives it. (A suite run as a background job inherits SIGINT ignored, and an
    ignored SIGINT stays ignored across exec, so Ctrl-C would never reach the command.)"""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
