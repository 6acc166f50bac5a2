"""Shared test fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: real crease patterns drawn by others (Origami Simulator, FOLD spec), copied into the
#: repository with their licences and sources (tests/data/crease-patterns/SOURCES.md)
SHARED_PATTERNS = REPO / "tests" / "data" / "crease-patterns"


@pytest.fixture(scope="session")
def shared_patterns() -> Path:
    """The folder of real crease patterns kept with the tests."""
    assert SHARED_PATTERNS.is_dir(), f"{SHARED_PATTERNS} is missing from the repository"
    return SHARED_PATTERNS
