"""Ron Resch's triangular pattern.

Sources: R. D. Resch, US patent 3,407,558 (1968) and Resch & Christiansen, "The design and
analysis of kinematic folded plate systems", IASS Symposium 1970; T. Tachi, "Designing freeform
origami tessellations by generalizing Resch's patterns", J. Mech. Des. 135(11), 2013. Drawn as
in Origami Simulator's ``reschTriTessellation.svg`` (Ghassaei 2018, MIT licence; edge length
ratios and vertex degrees compared in the tests).

Geometry: a triangular lattice of side ``t`` (points i e1 + j e2, e1 = (t, 0),
e2 = (t/2, t sqrt(3)/2)). The downward triangles with (i - j) mod 3 = 0 are *stars*: each lattice
point is a corner of exactly one of them. A star loses its three sides; its centroid joins its
three corners by short mountain spokes (length t / sqrt 3) and the apexes of the three upward
neighbour triangles by long valleys (length 2 t / sqrt 3) that cut those triangles in half. All
remaining lattice edges are mountains; the other downward triangles are the flat tiles. Every
interior vertex has degree 6 (lattice points) or 6 (star centres: 3 spokes + 3 long valleys).
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import SegmentBuilder, check_int, check_range
from barhinge.pattern.crease import CreasePattern

__all__ = ["resch"]


def resch(nx: int = 6, ny: int = 6, t: float = 1.0, target: float = 90.0) -> CreasePattern:
    """Resch triangular pattern on a roughly rectangular patch of the lattice (flat pattern).

    Parameters
    ----------
    nx : int
        Lattice triangles' sides per row, >= 2.
    ny : int
        Rows of lattice triangles, >= 2.
    t : float
        Lattice (tile) side, > 0.
    target : float
        Target fold angle magnitude (degrees, (0, 180]).

    Notes
    -----
    Row r of lattice points holds i = -floor(r/2) .. nx - floor(r/2), which keeps the patch
    close to a rectangle. Only whole units (a star with its three upward neighbours, a big
    upward triangle of side 2t) inside that patch are kept, plus the tiles between them, so
    every interior vertex is complete.
    """
    fam = "resch"
    nx = check_int("nx", nx, 2, family=fam)
    ny = check_int("ny", ny, 2, family=fam)
    t = check_range("t", t, 0.0, None, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    e1 = np.array([t, 0.0])
    e2 = np.array([t / 2, t * math.sqrt(3) / 2])

    def inside(i: int, j: int) -> bool:
        return 0 <= j <= ny and -(j // 2) <= i <= nx - (j // 2)

    def pos(i: int, j: int) -> np.ndarray:
        return i * e1 + j * e2

    def down(i: int, j: int) -> tuple[tuple[int, int], ...]:  # downward, bottom vertex (i, j)
        return ((i, j), (i, j + 1), (i - 1, j + 1))

    sb = SegmentBuilder(max(nx, ny) * t)
    points: set[tuple[int, int]] = set()
    stars: set[tuple[int, int]] = set()
    for j in range(ny + 1):
        for i in range(-(j // 2) - 2, nx - (j // 2) + 3):
            if (i - j) % 3 != 0:
                continue
            tri = down(i, j)
            apexes = ((i + 1, j), (i - 1, j), (i - 1, j + 2))
            if not all(inside(*p) for p in tri + apexes):
                continue  # keep whole units only: star + its three upward neighbours
            stars.add((i, j))
            points.update(tri + apexes)
            c = sum(pos(*p) for p in tri) / 3
            for p in tri:
                sb.add(c, pos(*p), "M", -target)
            for p in apexes:
                sb.add(c, pos(*p), "V", target)
            # outer sides of the unit (a big upward triangle of side 2t), split at the corners
            a, b, d = (i - 1, j), (i + 1, j), (i - 1, j + 2)
            for p, q in ((a, (i, j)), ((i, j), b), (b, (i, j + 1)), ((i, j + 1), d),
                         (d, (i - 1, j + 1)), ((i - 1, j + 1), a)):  # fmt: skip
                sb.add(pos(*p), pos(*q), "M", -target)
    # tiles: the other downward triangles whose corners all belong to kept units
    for j in range(ny + 1):
        for i in range(-(j // 2) - 2, nx - (j // 2) + 3):
            tri = down(i, j)
            if (i, j) in stars or (i - j) % 3 == 0 or not all(p in points for p in tri):
                continue
            for p, q in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
                sb.add(pos(*p), pos(*q), "M", -target)
    if not stars:
        raise PatternError(
            f"{fam}: nx = {nx}, ny = {ny} hold no complete Resch unit; expected a larger patch "
            "(nx >= 4 with ny >= 2, or nx >= 3 with ny >= 3)"
        )
    return sb.build(family=fam, parameters={"nx": nx, "ny": ny, "t": t, "target": target})
