"""Pleated hyperbolic paraboloid (hypar): concentric squares with their diagonals.

Sources: the pleated hypar of the Bauhaus preliminary course (Albers, 1927-28); E. D. Demaine,
M. L. Demaine, V. Hart, G. N. Price, T. Tachi, "(Non)existence of pleated folds: how paper
folds between creases", Graphs and Combinatorics 27(3):377-397, 2011 (which proves the
untriangulated pattern cannot fold with rigid facets: the trapezoids must bend, which the
bar-and-hinge model allows through its bending hinges).

Geometry: squares of half-sides ``size * k / n`` (k = 1..n, the outermost is the sheet
boundary) centred on the origin, and both diagonals. The square creases alternate (the
outermost crease square is a mountain), and the diagonal segment between squares k and k + 1
takes the assignment of square k, so every square corner has three creases of one kind and one
of the other (Maekawa) and sectors 135/45/45/135 (Kawasaki). The four diagonal segments at the
centre take the opposite of the innermost square.
"""

from __future__ import annotations

import numpy as np

from barhinge.families._common import SegmentBuilder, check_int, check_range
from barhinge.pattern.crease import CreasePattern

__all__ = ["hypar"]


def hypar(n: int = 5, size: float = 1.0, target: float = 90.0) -> CreasePattern:
    """Hypar of ``n`` concentric squares (flat pattern).

    Parameters
    ----------
    n : int
        Number of squares including the boundary, >= 2.
    size : float
        Half side of the sheet, > 0.
    target : float
        Target fold angle magnitude (degrees, (0, 180]).
    """
    fam = "hypar"
    n = check_int("n", n, 2, family=fam)
    size = check_range("size", size, 0.0, None, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    sb = SegmentBuilder(2 * size)
    corners = np.array([(1, 1), (-1, 1), (-1, -1), (1, -1)], float)

    def asg_of(k: int) -> str:  # square k (1..n-1); k = n-1 is a mountain
        return "M" if (n - 1 - k) % 2 == 0 else "V"

    for k in range(1, n + 1):
        r = size * k / n
        a = "B" if k == n else asg_of(k)
        ang = 0.0 if a == "B" else (-target if a == "M" else target)
        for c in range(4):
            sb.add(r * corners[c], r * corners[(c + 1) % 4], a, ang)
    for c in corners:
        for k in range(n):
            a = ("V" if asg_of(1) == "M" else "M") if k == 0 else asg_of(k)
            ang = -target if a == "M" else target
            sb.add(size * k / n * c, size * (k + 1) / n * c, a, ang)
    return sb.build(family=fam, parameters={"n": n, "size": size, "target": target})
