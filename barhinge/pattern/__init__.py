"""Crease patterns: the data structure, validation, FOLD and SVG files."""

from barhinge.pattern.crease import CreasePattern

__all__ = ["CreasePattern"]
