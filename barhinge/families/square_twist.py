"""Square-twist tessellation: a grid of twisted squares joined by pleats.

Sources: Fujimoto's square twist tessellation (S. Fujimoto, *Souzou suru origami asobi e no
shoutai*, 1982); Lang, *Twists, Tilings, and Tessellations*, CRC 2018, ch. 3 (twist folds
and their flat-foldability); the single twist is the FOLD spec example ``squaretwist.fold``.

Geometry: twist (i, j) is centred at (i p, j p) (pitch p) with a central square of side ``a``
turned by ``+twist`` when i + j is even and ``-twist`` when odd (so that the pleats between
neighbours are straight). From every corner of a square two pleat lines leave parallel to
the grid axes towards the neighbouring twists (or the sheet boundary, half a pitch beyond the
outer twists). At each corner the sectors are (90, 90 + twist, 90, 90 - twist): developable
and Kawasaki-flat-foldable. The square sides are valleys; at each corner the pleat line that
bounds the small sector (90 - twist) with a square side is a mountain and the other a valley
(big-little-big rule), giving 3 V + 1 M at every vertex (Maekawa).
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import SegmentBuilder, check_int, check_range
from barhinge.pattern.crease import CreasePattern

__all__ = ["square_twist"]


def square_twist(
    nx: int = 3,
    ny: int = 3,
    pitch: float = 2.0,
    a: float = 0.8,
    twist: float = 30.0,
    target: float = 90.0,
) -> CreasePattern:
    """Square-twist tessellation of ``nx`` x ``ny`` twists (flat pattern).

    Parameters
    ----------
    nx, ny : int
        Twists along x and y, >= 1.
    pitch : float
        Distance between neighbouring twist centres, > 0.
    a : float
        Side of the twisted central squares, > 0, with ``a (cos t + sin t) < pitch``.
    twist : float
        Twist angle t of the central squares, degrees in (0, 45).
    target : float
        Target fold angle magnitude (degrees, (0, 180]).
    """
    fam = "square_twist"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    pitch = check_range("pitch", pitch, 0.0, None, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    twist = check_range("twist", twist, 0.0, 45.0, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    t = math.radians(twist)
    if a * (math.cos(t) + math.sin(t)) >= pitch:
        raise PatternError(
            f"{fam}: a = {a:g} is too large for pitch = {pitch:g} and twist = {twist:g} "
            f"(squares would overlap); expected a < {pitch / (math.cos(t) + math.sin(t)):.4g}"
        )
    half = pitch / 2
    x0, x1 = -half, (nx - 1) * pitch + half
    y0, y1 = -half, (ny - 1) * pitch + half
    sb = SegmentBuilder(max(x1 - x0, y1 - y0))
    rays: dict[tuple[int, int], list[float]] = {}  # boundary splits: side -> coordinates
    for i in range(nx):
        for j in range(ny):
            sg = 1.0 if (i + j) % 2 == 0 else -1.0
            c = np.array([i * pitch, j * pitch])
            R = np.array(
                [[math.cos(sg * t), -math.sin(sg * t)], [math.sin(sg * t), math.cos(sg * t)]]
            )
            corners = [c + R @ (a / 2 * np.array(d)) for d in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
            for k in range(4):
                sb.add(corners[k], corners[(k + 1) % 4], "V", target)
            for k, p in enumerate(corners):
                sides = [corners[(k + 1) % 4] - p, corners[(k - 1) % 4] - p]
                sides = [d / np.linalg.norm(d) for d in sides]
                # the two axis directions pointing away from the square at this corner
                out = p - c
                dirs = [np.array([np.sign(out[0]), 0.0]), np.array([0.0, np.sign(out[1])])]
                small = [min(math.acos(np.clip(d @ s, -1, 1)) for s in sides) for d in dirs]
                for d, sm, other in zip(dirs, small, small[::-1], strict=True):
                    asg = "M" if sm < other else "V"
                    ang = -target if asg == "M" else target
                    if d[0] != 0:  # horizontal pleat line: to the neighbour or the boundary
                        ii = i + int(d[0])
                        if 0 <= ii < nx:
                            if d[0] > 0:  # add each shared pleat line once, from the left twist
                                q = np.array([ii * pitch + (p[0] - c[0]) * -1, p[1]])
                                sb.add(p, q, asg, ang)
                        else:
                            xb = x1 if d[0] > 0 else x0
                            sb.add(p, (xb, p[1]), asg, ang)
                            rays.setdefault((0, int(d[0])), []).append(p[1])
                    else:
                        jj = j + int(d[1])
                        if 0 <= jj < ny:
                            if d[1] > 0:
                                q = np.array([p[0], jj * pitch + (p[1] - c[1]) * -1])
                                sb.add(p, q, asg, ang)
                        else:
                            yb = y1 if d[1] > 0 else y0
                            sb.add(p, (p[0], yb), asg, ang)
                            rays.setdefault((1, int(d[1])), []).append(p[0])
    # boundary, split where pleat lines arrive
    for (axis, side), coords in {
        (0, -1): rays.get((0, -1), []),
        (0, 1): rays.get((0, 1), []),
        (1, -1): rays.get((1, -1), []),
        (1, 1): rays.get((1, 1), []),
    }.items():
        if axis == 0:
            xb = x1 if side > 0 else x0
            ys = sorted([y0, y1, *coords])
            for ya, yb_ in zip(ys, ys[1:], strict=False):
                sb.add((xb, ya), (xb, yb_), "B")
        else:
            yb = y1 if side > 0 else y0
            xs = sorted([x0, x1, *coords])
            for xa, xb_ in zip(xs, xs[1:], strict=False):
                sb.add((xa, yb), (xb_, yb), "B")
    return sb.build(
        family=fam,
        parameters={"nx": nx, "ny": ny, "pitch": pitch, "a": a, "twist": twist, "target": target},
    )
