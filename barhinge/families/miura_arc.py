"""Arc Miura-ori: sector angle graded from one zig-zag crease line to the next, so the sheet
folds into an arch (exact rigid folding).

Sources: the arc / curved Miura derivative of Gattas, Wu & You, "Miura-base rigid origami:
parameterizations of first-level derivative and piecewise geometries", J. Mech. Des. 135(11),
2013; the mirror-symmetric folded form of straight-row generalised Miura patterns follows
Tachi, "Generalization of rigid-foldable quadrilateral-mesh origami", J. IASS 50(3), 2009.

Flat pattern
------------
Straight rows (the "straight" creases) at y = j h, j = 0..2 ny. Zig-zag line ``i``
(i = 0..2 nx) has its own sector angle ``gamma_i``: it runs from x = i a on even rows to
x = i a + h cot(gamma_i) on odd rows. Here

    gamma_i = alpha - delta / 2   (i even, valley zig-zags)
    gamma_i = alpha + delta / 2   (i odd, mountain zig-zags)
    gamma_i += grade * (i - nx) / nx       (optional linear grading along the arch)

Every interior vertex has sectors (gamma_i, pi - gamma_i, pi - gamma_i, gamma_i): developable
and flat-foldable (Kawasaki), not Miura-periodic when delta != 0.

Exact folded state (derived here, checked in the tests)
-------------------------------------------------------
Every straight crease has the same fold angle magnitude ``fold`` = rho_s. Rows lie in planes
y = j s with ``s = h cos(rho_s / 2)``; even rows form the section polyline P (edges of length
a), odd rows Q_i = P_i + lambda_i t_i with t_i the bisector of P at i, ``lambda_i =
sqrt(b_i^2 - s^2)`` (b_i = h / sin gamma_i the zig-zag edge length) and section turn angle
``tau_i = 2 arccos(b_i cos(gamma_i) / lambda_i)`` (up at valley zig-zags, down at mountain
ones). Face planarity needs ``lambda_i sin(tau_i / 2)`` to be the same for all i, and it is:
it equals ``sqrt(h^2 - s^2)``. Unequal turns at valley and mountain zig-zags bend the section
into an arch (crown towards +z for delta > 0, a trough for delta < 0); the section is turned
so that its two ends are level.
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
    fold_angles_of,
    mv_assignment,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["miura_arc", "miura_arc_angles"]

DEFAULT_TARGET = 90.0


def miura_arc_angles(nx: int, alpha: float, delta: float, grade: float = 0.0) -> np.ndarray:
    """(2 nx + 1,) sector angle gamma_i (degrees) of each zig-zag line."""
    i = np.arange(2 * nx + 1)
    return alpha + np.where(i % 2 == 0, -delta / 2, delta / 2) + grade * (i - nx) / nx


def _folded(a: float, h: float, gam: np.ndarray, ny: int, fold: float) -> np.ndarray:
    """(n, 3) coordinates of the exact folded state with straight-crease fold angle ``fold``."""
    g = np.radians(gam)
    n = len(g) - 1
    s = h * math.cos(math.radians(fold) / 2)
    b = h / np.sin(g)
    lam = np.sqrt(np.maximum(b * b - s * s, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(lam > 0, b * np.cos(g) / np.where(lam > 0, lam, 1.0), 1.0)
    tau = 2 * np.arccos(np.clip(c, -1.0, 1.0))
    turn = np.where(np.arange(n + 1) % 2 == 0, tau, -tau)  # valley zig-zags turn up
    psi = np.concatenate([[0.0], np.cumsum(turn[1:n])])  # direction of edge k = 0..n-1
    U = np.column_stack([np.cos(psi), np.sin(psi)])
    P = np.vstack([[0.0, 0.0], np.cumsum(a * U, axis=0)])
    # bisector offsets at interior points; end points keep the flat trapezoid shape
    T = np.zeros((n + 1, 2))
    T[1:n] = U[:-1] + U[1:]
    T[1:n] /= np.linalg.norm(T[1:n], axis=1, keepdims=True)
    v = lam[:, None] * T
    if n >= 2:
        k0 = h * (1 / math.tan(g[1]) - 1 / math.tan(g[0]))
        kn = h * (1 / math.tan(g[n]) - 1 / math.tan(g[n - 1]))
        v[0] = v[1] - k0 * U[0]
        v[n] = v[n - 1] + kn * U[n - 1]
    # level the ends: rotate the section so that P_n - P_0 is along +x
    chord = P[n] - P[0]
    ang = -math.atan2(chord[1], chord[0])
    R = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])
    P = P @ R.T
    v = v @ R.T
    J = np.arange(2 * ny + 1)
    P3 = np.column_stack([P[:, 0], np.zeros(n + 1), P[:, 1]])
    v3 = np.column_stack([v[:, 0], np.zeros(n + 1), v[:, 1]])
    X = (
        P3[None]
        + (J % 2)[:, None, None] * v3[None]
        + (J * s)[:, None, None] * np.array([0.0, 1.0, 0.0])
    )
    return X.reshape(-1, 3)


def miura_arc(
    nx: int = 4,
    ny: int = 3,
    a: float = 1.0,
    h: float = 0.8,
    alpha: float = 60.0,
    delta: float = 10.0,
    grade: float = 0.0,
    fold: float | None = None,
    target: float = DEFAULT_TARGET,
) -> CreasePattern:
    """Arc Miura-ori: zig-zag lines with alternating (and optionally graded) sector angles.

    Parameters
    ----------
    nx, ny : int
        Cells along x and y (2 x 2 facets each), >= 1.
    a : float
        Length of the straight-crease segments (x), > 0.
    h : float
        Strip height (distance between straight creases), > 0.
    alpha : float
        Mean sector angle, degrees in (0, 90).
    delta : float
        Sector angle of the mountain zig-zags minus that of the valley zig-zags (degrees); the
        arch curvature grows with |delta| (> 0: arch, < 0: trough); 0 gives the Miura-ori.
    grade : float
        Extra sector angle ramp from the first to the middle zig-zag line (degrees).
    fold : float or None
        Fold angle magnitude of the straight creases (degrees, [0, 180)) of the exact folded
        state; None: flat pattern.
    target : float
        Straight-crease fold angle (degrees) whose state gives the flat pattern's targets.

    Returns
    -------
    CreasePattern
        Grid layout as :func:`miura` (``meta['barhinge:grid']``, row edges = straight
        creases, column edges = zig-zags).
    """
    fam = "miura_arc"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    h = check_range("h", h, 0.0, None, family=fam)
    alpha = check_range("alpha", alpha, 0.0, 90.0, family=fam)
    delta = check_range("delta", delta, -180.0, 180.0, family=fam)
    grade = check_range("grade", grade, -90.0, 90.0, family=fam)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, 180.0, lo_open=False, family=fam)
    target = check_range("target", target, 0.0, 180.0, family=fam)
    gam = miura_arc_angles(nx, alpha, delta, grade)
    if gam.min() <= 0 or gam.max() >= 90:
        k = int(np.argmin(gam)) if gam.min() <= 0 else int(np.argmax(gam))
        raise PatternError(
            f"{fam}: alpha, delta and grade give zig-zag line {k} the sector angle "
            f"{gam[k]:g} deg; expected every sector angle in (0, 90)"
        )
    off = h / np.tan(np.radians(gam))
    # odd-row edges must keep a positive length
    odd_len = a + np.diff(off)
    if odd_len.min() <= 0.05 * a:
        raise PatternError(
            f"{fam}: delta = {delta:g} is too large for a = {a:g}, h = {h:g} (a facet collapses); "
            "expected a smaller delta or a longer a"
        )
    lay = GridLayout(2 * nx + 1, 2 * ny + 1)
    I, J = np.meshgrid(np.arange(lay.ni), np.arange(lay.nj), indexing="xy")
    I, J = I.ravel(), J.ravel()
    faces = lay.quads()
    edges = lay.edges()
    ref = fold_angles_of(_folded(a, h, gam, ny, 60.0), faces, edges)
    bnd = lay.boundary_mask()
    A = mv_assignment(ref, bnd)
    if fold is None:
        X = np.column_stack([I * a + (J % 2) * off[I], J * h])
        rho = fold_angles_of(_folded(a, h, gam, ny, target), faces, edges)
    else:
        X = _folded(a, h, gam, ny, fold)
        rho = fold_angles_of(X, faces, edges)
    rho[bnd] = 0.0
    params = {
        "nx": nx, "ny": ny, "a": a, "h": h, "alpha": alpha, "delta": delta, "grade": grade,
        "fold": fold,
    }  # fmt: skip
    if fold is None:
        params["target"] = target
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=rho,
        family=fam,
        parameters=params,
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )
