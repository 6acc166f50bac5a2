"""Crease patterns: the data structure, validation, FOLD and SVG files."""

from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.validate import Finding, check, findings, merged

__all__ = ["CreasePattern", "Finding", "check", "findings", "merged"]
