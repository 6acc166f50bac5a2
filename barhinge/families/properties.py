"""Vertex conditions of flat crease patterns: developability, Maekawa and Kawasaki.

* Developability: the sector angles around an interior vertex sum to 2 pi.
* Maekawa's theorem (Maekawa; Justin 1986; see Demaine & O'Rourke, *Geometric Folding
  Algorithms*, 2007, Thm 12.2.4): at a flat-foldable interior vertex ``|#M - #V| = 2``.
* Kawasaki's theorem (Kawasaki 1989; Demaine & O'Rourke 2007, Thm 12.2.2): at a flat-foldable
  interior vertex of even degree the alternate sector angles each sum to pi.

All functions use the current geometry of the pattern (normally the flat state) and report
one value per vertex (NaN / -1 where the condition does not apply).
"""

from __future__ import annotations

import numpy as np

from barhinge.pattern.crease import CreasePattern

__all__ = ["degree_counts", "kawasaki_error", "maekawa_count", "sector_sum_error"]


def sector_sum_error(cp: CreasePattern) -> np.ndarray:
    """(n,) float radians: ``sum(sector angles) - 2 pi`` at interior vertices, NaN elsewhere."""
    return -np.asarray(cp.angle_defect)


def maekawa_count(cp: CreasePattern) -> np.ndarray:
    """(n,) int: ``#M - #V`` of the creases at each interior vertex, 0 elsewhere."""
    E = cp.edges
    A = cp.assignment
    s = np.where(A == "M", 1, np.where(A == "V", -1, 0))
    out = np.zeros(cp.n_vertices, dtype=np.int64)
    np.add.at(out, E[:, 0], s)
    np.add.at(out, E[:, 1], s)
    mask = np.zeros(cp.n_vertices, bool)
    mask[cp.interior_vertices] = True
    out[~mask] = 0
    return out


def kawasaki_error(cp: CreasePattern) -> np.ndarray:
    """(n,) float radians: ``sum of odd sector angles - pi`` at interior vertices of even
    degree (alternating sum / 2), NaN elsewhere."""
    out = np.full(cp.n_vertices, np.nan)
    for v in cp.interior_vertices:
        sec = cp.sector_angles[v]
        if len(sec) % 2 == 0 and len(sec) >= 2:
            out[v] = float(sec[0::2].sum()) - np.pi
    return out


def degree_counts(cp: CreasePattern, vertices: np.ndarray | None = None) -> dict[int, int]:
    """Histogram {degree: count} of vertex degrees (over ``vertices``; default interior)."""
    vs = cp.interior_vertices if vertices is None else np.asarray(vertices)
    deg = cp.vertex_degree[vs]
    values, counts = np.unique(deg, return_counts=True)
    return {int(d): int(c) for d, c in zip(values, counts, strict=True)}
