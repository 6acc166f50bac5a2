"""Small crease patterns built in the tests (independent of the pattern library)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from barhinge.pattern.crease import CreasePattern


def single_vertex(sectors_deg: Sequence[float], assignment: Sequence[str] | None = None):
    """Degree-d vertex at the origin: crease i along angle sum(sectors[:i]), unit length;
    triangular panels (0, i, i+1); rim edges B. Sector i lies between creases i and i+1."""
    a = np.radians(np.asarray(sectors_deg, dtype=float))
    d = len(a)
    th = np.concatenate([[0.0], np.cumsum(a)[:-1]])
    V = np.vstack([[0.0, 0.0], np.column_stack([np.cos(th), np.sin(th)])])
    E = [(0, i + 1) for i in range(d)] + [(i + 1, (i + 1) % d + 1) for i in range(d)]
    A = list(assignment) if assignment is not None else ["U"] * d
    A = A + ["B"] * d
    F = [(0, i + 1, (i + 1) % d + 1) for i in range(d)]
    return CreasePattern(V, np.array(E), np.array(A), faces=F)


@pytest.fixture(scope="session")
def vertex_pattern():
    """Factory: ``vertex_pattern(sectors_deg, assignment=None) -> CreasePattern``."""
    return single_vertex
