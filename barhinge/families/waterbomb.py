"""Waterbomb tessellation: rows of waterbomb bases, alternate rows offset by half a base.

Sources: the traditional waterbomb base tessellation (Resch's "waterbomb pattern"; Hanna,
Lund, Lang, Magleby, Howell, "Waterbomb base: a symmetric single-vertex bistable origami
mechanism", Smart Mater. Struct. 23, 2014; Tachi 2010 "Geometric considerations for the
design of rigid origami structures"), drawn as in Origami Simulator's ``waterbomb.svg``
(Ghassaei 2018, MIT licence; compared in the tests).

Geometry: squares of side ``s``; row r (y in [r s, (r + 1) s]) has square centres at
x = (k + 1/2 + (r mod 2)/2) s. Creases: both diagonals of every square (valleys), vertical
lines every s/2 (mountains: the square sides and the vertical midlines through the centres)
and the horizontal row lines (mountains). Every interior vertex has degree 6 (4 V + 2 M at
the centres, 2 V + 4 M at the corners) with sector angles 45/45/90 that satisfy Kawasaki.
"""

from __future__ import annotations

import numpy as np

from barhinge.families._common import SegmentBuilder, check_int, check_range
from barhinge.pattern.crease import CreasePattern

__all__ = ["waterbomb"]


def waterbomb(nx: int = 4, ny: int = 4, s: float = 1.0, target: float = 90.0) -> CreasePattern:
    """Waterbomb tessellation of ``ny`` rows of ``nx`` bases (flat pattern).

    Parameters
    ----------
    nx : int
        Bases (squares) per row, >= 1; odd rows have nx - 1 full squares and two halves.
    ny : int
        Rows, >= 1.
    s : float
        Side of a base square, > 0. The sheet is nx s by ny s.
    target : float
        Target fold angle magnitude (degrees, (0, 180]): valleys +target, mountains -target.
    """
    fam = "waterbomb"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    s = check_range("s", s, 0.0, None, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    W, H = nx * s, ny * s
    sb = SegmentBuilder(max(W, H))
    h = s / 2
    # horizontal lines at every row boundary, split at every s/2
    for r in range(ny + 1):
        y = r * s
        asg = "B" if r in (0, ny) else "M"
        for k in range(2 * nx):
            sb.add((k * h, y), ((k + 1) * h, y), asg, 0.0 if asg == "B" else -target)
    # vertical lines every s/2 inside every row, split at the square centres' height
    for r in range(ny):
        y0, ym, y1 = r * s, r * s + h, (r + 1) * s
        for k in range(2 * nx + 1):
            x = k * h
            asg = "B" if k in (0, 2 * nx) else "M"
            ang = 0.0 if asg == "B" else -target
            if k % 2 == (1 + r) % 2:  # a square centre lies on this line
                sb.add((x, y0), (x, ym), asg, ang)
                sb.add((x, ym), (x, y1), asg, ang)
            else:
                sb.add((x, y0), (x, y1), asg, ang)
        # diagonals: centres at x = (k + 1/2 + (r mod 2)/2) s, clipped to the sheet
        off = 0.5 * (r % 2)
        for k in range(-1, nx + 1):
            cx = (k + 0.5 + off) * s
            if cx < -1e-12 or cx > W + 1e-12:
                continue
            c = np.array([cx, ym])
            for dx in (-h, h):
                for dy in (-h, h):
                    p = c + (dx, dy)
                    if -1e-12 <= p[0] <= W + 1e-12:
                        sb.add(c, p, "V", target)
    return sb.build(family=fam, parameters={"nx": nx, "ny": ny, "s": s, "target": target})
