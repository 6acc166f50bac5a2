"""Shared test fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED_PATTERNS = REPO.parent / "shared" / "crease-patterns"


@pytest.fixture(scope="session")
def shared_patterns() -> Path:
    """The folder of real crease patterns beside the repository (skip if absent)."""
    if not SHARED_PATTERNS.is_dir():
        pytest.skip(f"{SHARED_PATTERNS} is absent")
    return SHARED_PATTERNS
