"""Validation of crease patterns (placeholder: the foundation work replaces this)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from barhinge.pattern.crease import CreasePattern


def check(cp: CreasePattern) -> None:
    """Raise PatternError for the first problem found in ``cp``."""
    return None
