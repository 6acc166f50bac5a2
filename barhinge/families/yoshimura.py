"""Yoshimura (diamond) pattern and its closed-form rigidly folded arch (barrel vault).

Source: Y. Yoshimura, "On the mechanism of buckling of a circular cylindrical shell under axial
compression", NACA TM 1390, 1955 (the diamond pattern); its use as a folded arch/barrel vault
follows e.g. Tachi, "Rigid-foldable thick origami" (2011) and the thesis that barhinge grew
from (Yoshimura study pattern).

Flat pattern
------------
``ny`` strips of height ``h`` between ``ny + 1`` horizontal crease lines (rows ``j``, y = j h).
Even rows hold vertices at x = i w (i = 0..nx); odd rows at x = (i + 1/2) w plus the two
side vertices x = 0 and x = nx w. Each strip is cut into isosceles triangles (base ``w``,
height ``h``) by diagonal creases, plus half triangles at the sides, so the sheet is the
rectangle [0, nx w] x [0, ny h]. Interior vertices have degree 6. Seen from +z (the outside
of the arch, which bulges towards +z) the horizontal creases (triangle bases, length w) are
valleys and the diagonals (length sqrt(w^2/4 + h^2)) mountains: the diamonds are pushed in
as in Yoshimura's buckled cylinder (4 M + 2 V at every interior vertex).

Folded arch (exact, one parameter)
----------------------------------
``fold`` = 2 beta, the central angle (degrees) subtended by one horizontal crease. Every row
becomes a polygon of circumradius ``R = w / (2 sin beta)`` in a plane y = j d around the axis
(parallel to y) at height -R; odd rows are turned by beta, and the rows are spaced

    d = sqrt(h^2 - (w/2)^2 tan^2(beta/2)),

which keeps every diagonal at its flat length (so all triangles are rigid). The side vertices
of odd rows are the midpoints of the chords of the (virtual) neighbouring triangles, so the half
triangles are exact halves. Valid for 0 <= fold < min(180, 4 arctan(2h/w)) and
nx * fold <= 360 (the arch must not overlap itself).
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import (
    build_pattern,
    check_int,
    check_range,
    edges_from_faces,
    fold_angles_of,
    mv_assignment,
    zip_strip,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["yoshimura", "yoshimura_arch_rows", "yoshimura_max_fold"]

DEFAULT_TARGET = 20.0


def yoshimura_max_fold(w: float, h: float) -> float:
    """Upper bound (degrees, excluded) of ``fold`` for diamonds of width w and half height h:
    ``min(180, 4 arctan(2 h / w))`` (rows collapse onto one plane at the bound)."""
    return min(180.0, math.degrees(4.0 * math.atan(2.0 * h / w)))


def _rows(nx: int, ny: int) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Per row the vertex ids; all vertices' u (x / w) and row index."""
    us, js, rows = [], [], []
    n = 0
    for j in range(ny + 1):
        if j % 2 == 0:
            u = np.arange(nx + 1, dtype=float)
        else:
            u = np.concatenate([[0.0], np.arange(nx) + 0.5, [float(nx)]])
        rows.append(np.arange(n, n + len(u)))
        n += len(u)
        us.append(u)
        js.append(np.full(len(u), j))
    return rows, np.concatenate(us), np.concatenate(js)


def yoshimura_arch_rows(w: float, h: float, fold: float) -> tuple[float, float]:
    """(R, d): circumradius of the row polygons and spacing of the rows of the folded arch
    (R = inf when fold = 0)."""
    beta = math.radians(fold) / 2
    d = math.sqrt(max(h * h - (w / 2) ** 2 * math.tan(beta / 2) ** 2, 0.0))
    R = math.inf if beta == 0 else w / (2 * math.sin(beta))
    return R, d


def _arch_coords(u: np.ndarray, j: np.ndarray, nx: int, w: float, h: float, fold: float):
    beta = math.radians(fold) / 2
    R, d = yoshimura_arch_rows(w, h, fold)
    y = j * d
    if beta == 0:
        return np.column_stack([u * w, y, np.zeros_like(u)])
    phi = (u - nx / 2) * 2 * beta

    def ring(p):  # crown at z = 0, axis at z = -R
        return R * np.sin(p), -2 * R * np.sin(p / 2) ** 2

    x, z = ring(phi)
    side = (j % 2 == 1) & ((u == 0) | (u == nx))
    if side.any():
        x1, z1 = ring(phi[side] - beta)
        x2, z2 = ring(phi[side] + beta)
        x[side], z[side] = (x1 + x2) / 2, (z1 + z2) / 2
    x = x + nx * w / 2  # keep the crown above the middle of the flat sheet
    return np.column_stack([x, y, z])


def yoshimura(
    nx: int = 4,
    ny: int = 3,
    w: float = 1.0,
    h: float = 0.5,
    fold: float | None = None,
    target: float = DEFAULT_TARGET,
) -> CreasePattern:
    """Yoshimura diamond pattern (flat, or the exact folded arch when ``fold`` is given).

    Parameters
    ----------
    nx : int
        Diamonds (triangle bases) per horizontal crease line, >= 1.
    ny : int
        Strips (rows of triangles), >= 1.
    w : float
        Length of a horizontal crease segment (diamond width), > 0.
    h : float
        Strip height (half the diamond height), > 0.
    fold : float or None
        Arch angle per horizontal crease segment (2 beta, degrees); None gives the flat pattern.
    target : float
        For the flat pattern: the ``fold`` whose exact fold angles become the targets
        (default 20 deg, capped at 90 % of the valid range).

    Returns
    -------
    CreasePattern
        Triangle faces, counter-clockwise from +z; vertices row by row (row j at y = j h;
        ``meta['barhinge:rows']`` lists each row's first vertex id and count).
    """
    fam = "yoshimura"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    w = check_range("w", w, 0.0, None, family=fam)
    h = check_range("h", h, 0.0, None, family=fam)
    fmax = yoshimura_max_fold(w, h)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, fmax, lo_open=False, family=fam)
        if nx * fold > 360.0 + 1e-9:
            raise PatternError(
                f"{fam}: fold = {fold:g} with nx = {nx} turns the arch by {nx * fold:g} deg; "
                "expected nx * fold <= 360"
            )
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    target = min(target, 0.9 * fmax)
    rows, u, j = _rows(nx, ny)
    tris: list[tuple[int, int, int]] = []
    for r in range(ny):
        lo, up = rows[r], rows[r + 1]
        tris += zip_strip(lo, u[lo], up, u[up])
    faces = np.array(tris, dtype=np.int64)
    edges, counts = edges_from_faces(faces)
    boundary = counts == 1
    ref = _arch_coords(u, j, nx, w, h, min(10.0, 0.5 * fmax))
    sign = np.sign(fold_angles_of(ref, faces, edges))
    A = mv_assignment(sign, boundary)
    if fold is None:
        X = np.column_stack([u * w, j * h])
        rho = fold_angles_of(_arch_coords(u, j, nx, w, h, target), faces, edges)
    else:
        X = _arch_coords(u, j, nx, w, h, fold)
        rho = fold_angles_of(X, faces, edges)
    params = {"nx": nx, "ny": ny, "w": w, "h": h, "fold": fold}
    if fold is None:
        params["target"] = target
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=np.where(boundary, 0.0, rho),
        family=fam,
        parameters=params,
        extra_meta={"barhinge:rows": [[int(r[0]), len(r)] for r in rows]},
    )
