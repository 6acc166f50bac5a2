"""Shared test fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# The tests check what the code computes, not what an earlier run kept: the calibration
# cache (barhinge._disk_cache) is off for the whole session, subprocesses included. The
# tests of the cache turn it on in a temporary folder of their own.
os.environ["BARHINGE_CACHE"] = "off"

REPO = Path(__file__).resolve().parents[1]
#: real crease patterns drawn by others (Origami Simulator, FOLD spec), copied into the
#: repository with their licences and sources (tests/data/crease-patterns/SOURCES.md)
SHARED_PATTERNS = REPO / "tests" / "data" / "crease-patterns"


@pytest.fixture(scope="session")
def shared_patterns() -> Path:
    """The folder of real crease patterns kept with the tests."""
    assert SHARED_PATTERNS.is_dir(), f"{SHARED_PATTERNS} is missing from the repository"
    return SHARED_PATTERNS
