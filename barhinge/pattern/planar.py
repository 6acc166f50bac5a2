"""Faces of a planar straight-line graph (placeholder: the foundation work replaces this)."""

from __future__ import annotations

import numpy as np

from barhinge.errors import PatternError


def planar_faces(vertices: np.ndarray, edges: np.ndarray) -> list[list[int]]:
    """Counter-clockwise bounded faces of the planar graph (vertices (n, 2), edges (m, 2))."""
    raise PatternError("faces are missing and face finding is not available yet")
