"""Diagonal pattern (Buri & Weinand): a rectangular sheet crossed by straight diagonal creases.

Source: H. Buri and Y. Weinand, "ORIGAMI - Folded plate structures, architecture", 10th World
Conference on Timber Engineering, 2008, and H. U. Buri, *Origami - folded plate structures*,
EPFL thesis 4714, 2010, which list the diagonal pattern beside the diamond (Yoshimura) and
herringbone (Miura) patterns.

Our reading (stated because the sources give pictures, not coordinates): a grid of ``nx`` x
``ny`` rectangles a x b, each cut by its diagonal in the same direction, so the diagonals form
long straight valley lines across the sheet, and the grid lines are mountains. Every interior
vertex has degree 6 with sectors (phi, 90 - phi, 90, phi, 90 - phi, 90) (phi = atan(b/a)):
Kawasaki holds and there are 4 M + 2 V (Maekawa), so the pattern is flat-foldable; folded
partially it twists into a shell like a Kresling strip.
"""

from __future__ import annotations

from barhinge.families._common import build_pattern, check_int, check_range
from barhinge.families.kresling import triangulated_lattice
from barhinge.pattern.crease import CreasePattern

__all__ = ["diagonal"]


def diagonal(
    nx: int = 6, ny: int = 4, a: float = 1.0, b: float = 1.0, target: float = 90.0
) -> CreasePattern:
    """Diagonal pattern of ``nx`` x ``ny`` rectangles (flat pattern).

    Parameters
    ----------
    nx, ny : int
        Rectangles along x and y, >= 1.
    a, b : float
        Rectangle sides (x, y), > 0.
    target : float
        Target fold angle magnitude (degrees, (0, 180]).
    """
    fam = "diagonal"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    b = check_range("b", b, 0.0, None, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    X, faces, edges, A, F = triangulated_lattice(nx, ny, a, 0.0, b, target)
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=F,
        family=fam,
        parameters={"nx": nx, "ny": ny, "a": a, "b": b, "target": target},
        extra_meta={"barhinge:grid": [nx + 1, ny + 1]},
    )
