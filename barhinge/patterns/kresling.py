"""Kresling pattern: the flat crease pattern of a twisted (Kresling) tube, and the related
triangulated "diagonal" sheets.

Sources: B. Kresling, "Natural twist buckling in shells: from the hawkmoth's bellows to the
deployable Kresling-pattern and cylindrical Miura-ori", IASS-APCS 2008; S. D. Guest and
S. Pellegrino, "The folding of triangulated cylinders, Part I: geometric considerations",
J. Appl. Mech. 61:773-777, 1994 (the flat pattern of congruent triangles).

Flat pattern: ``stories`` rows of ``n`` parallelograms with horizontal sides ``a`` (the polygon
sides of the tube), slanted sides from (i a + j s, j h) to (i a + (j + 1) s, (j + 1) h) and the
diagonal from (i, j) to (i + 1, j + 1) in each parallelogram. Column ``n`` is the seam: rolled
into a tube, its slanted edges coincide with column 0 (so they are boundary edges of the flat
sheet). Polygon sides and slanted creases are mountains, the diagonals valleys (the common
drawing; Maekawa 4 M + 2 V, Kawasaki holds at every lattice vertex).
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern
from barhinge.patterns._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
)

__all__ = ["kresling", "triangulated_lattice"]


def triangulated_lattice(
    ni: int, nj: int, a: float, s: float, h: float, target: float, diag_assignment: str = "V"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (n, 2), faces (k, 3), edges (m, 2), assignment and target angles of a
    parallelogram lattice of ni x nj cells (cell sides a and (s, h)) split by the diagonals
    (i, j)-(i+1, j+1). Row and column edges are mountains, diagonals ``diag_assignment``."""
    lay = GridLayout(ni + 1, nj + 1)
    I, J = np.meshgrid(np.arange(ni + 1), np.arange(nj + 1), indexing="xy")
    I, J = I.ravel(), J.ravel()
    X = np.column_stack([I * a + J * s, J * h])
    Q = lay.quads()  # (i,j),(i+1,j),(i+1,j+1),(i,j+1)
    faces = np.vstack([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    grid_edges = lay.edges()
    diag = Q[:, [0, 2]]
    edges = np.vstack([grid_edges, diag])
    A = np.concatenate([np.full(len(grid_edges), "M"), np.full(len(diag), diag_assignment)])
    sign = np.where(A == "V", 1.0, -1.0)
    A[: len(grid_edges)][lay.boundary_mask()] = "B"
    F = np.where(A == "B", 0.0, sign * target)
    return X, faces, edges, A.astype("<U1"), F


def kresling(
    n: int = 6,
    stories: int = 3,
    a: float = 1.0,
    height: float = 0.8,
    shift: float = 0.6,
    target: float = 60.0,
) -> CreasePattern:
    """Flat crease pattern of a Kresling tube with an ``n``-gon cross-section.

    Parameters
    ----------
    n : int
        Polygon sides (columns of parallelograms), >= 3.
    stories : int
        Rows of parallelograms, >= 1.
    a : float
        Polygon side (horizontal crease length), > 0.
    height : float
        Flat height h of a story, > 0.
    shift : float
        Horizontal shift s of one story over the next, as a fraction of ``a``, in [0, 1).
    target : float
        Target fold angle magnitude (degrees, (0, 180]).

    Returns
    -------
    CreasePattern
        Vertex (i, j), i = 0..n, j = 0..stories, has id ``j (n + 1) + i``; triangles
        counter-clockwise; the seam columns i = 0 and i = n are boundary edges.
    """
    fam = "kresling"
    n = check_int("n", n, 3, family=fam)
    stories = check_int("stories", stories, 1, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    height = check_range("height", height, 0.0, None, family=fam)
    shift = check_range("shift", shift, 0.0, 1.0, lo_open=False, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    # the tube closes only if the polygon (side a, n sides) fits: always true in the flat
    # pattern; warn through an error only for degenerate triangles
    if math.hypot(shift * a, height) <= 1e-12:
        raise PatternError(f"{fam}: height and shift give zero-length slanted creases")
    X, faces, edges, A, F = triangulated_lattice(n, stories, a, shift * a, height, target)
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=F,
        family=fam,
        parameters={
            "n": n,
            "stories": stories,
            "a": a,
            "height": height,
            "shift": shift,
            "target": target,
        },  # fmt: skip
        extra_meta={"barhinge:grid": [n + 1, stories + 1], "barhinge:seam": [0, n]},
    )
