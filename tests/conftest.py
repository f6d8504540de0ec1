"""Shared test fixtures."""

from pathlib import Path

import pytest

#: ../shared/data, the measured BRDF data kept beside this repository (never copied in).
SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ../shared/data; tests that need it skip cleanly when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"measured data not found at {SHARED_DATA}")
    return SHARED_DATA

