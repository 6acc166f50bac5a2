"""Tachi's generalised Miura-ori designed from a target section curve.

Source: T. Tachi, "Generalization of rigid-foldable quadrilateral-mesh origami", J. IASS
50(3):173-179, 2009, and "One-DOF cylindrical deployable structures with rigid quadrilateral
panels", Proc. IASS Symposium 2009: a cylindrical Miura-like surface is built in its folded
state from a zig-zag section polyline and mirror reflections; a flat-foldable quad mesh that
has one such intermediate folded state is rigid-foldable with one degree of freedom.

Construction used here (derived for this module; checked in the tests)
---------------------------------------------------------------------
1. The zig-zag section ``P_i`` (i = 0..n, in the xz plane) is the target curve ``c_i`` with
   alternate points pushed by +-depth/2 along the curve normal (depth = 0: ``curve`` is used
   as the zig-zag itself).
2. Even rows ``j`` are copies of P at y = j s; odd rows are ``Q_i = P_i + v_i`` at y = j s,
   so every strip is the mirror image of its neighbour in the plane between them.
3. ``v_i = lambda_i t_i`` with ``t_i`` the unit bisector of the section's edge directions at
   P_i. This makes the sector angles at every interior vertex (a, pi - a, pi - a, a), so each
   vertex is developable *and* flat-foldable (Kawasaki), and the rows are straight in the
   flat pattern.
4. Faces are planar trapezoids iff ``v_{i+1} - v_i`` is parallel to ``P_{i+1} - P_i``, which
   fixes ``lambda_{i+1} = lambda_i (t_i . n_i) / (t_{i+1} . n_i)`` (n_i the normal of edge i)
   from the user's ``offset`` = lambda_1; the end vertices copy their neighbour's offset.

The flat pattern is the isometric unfolding of this folded state.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
    fold_angles_of,
    mv_assignment,
    unfold,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["default_arch_curve", "miura_tachi", "tachi_section"]


def default_arch_curve(radius: float = 4.0, angle: float = 120.0, n: int = 8) -> np.ndarray:
    """(n + 1, 2) points (x, z) of a circular arch of the given radius and opening angle."""
    phi = np.radians(np.linspace(-angle / 2, angle / 2, n + 1))
    return np.column_stack([radius * np.sin(phi), radius * np.cos(phi)])


def tachi_section(curve: np.ndarray, depth: float) -> np.ndarray:
    """(n + 1, 2) zig-zag section: ``curve`` points pushed alternately by +-depth/2 along the
    curve normal (left normal of the tangent in the xz plane)."""
    C = np.asarray(curve, float)
    if depth == 0:
        return C.copy()
    T = np.gradient(C, axis=0)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    N = np.column_stack([-T[:, 1], T[:, 0]])
    sgn = np.where(np.arange(len(C)) % 2 == 0, 0.5, -0.5)
    return C + (sgn * depth)[:, None] * N


def _offsets(P: np.ndarray, offset: float, fam: str) -> np.ndarray:
    """(n + 1, 3) zig-zag offset vectors v_i (3-D, y = 0)."""
    n = len(P) - 1
    E = np.diff(P, axis=0)
    lengths = np.linalg.norm(E, axis=1)
    if (lengths <= 1e-12 * max(float(np.ptp(P, axis=0).max()), 1e-300)).any():
        k = int(np.flatnonzero(lengths <= 0)[0]) if (lengths <= 0).any() else 0
        raise PatternError(f"{fam}: section points {k} and {k + 1} coincide")
    U = E / lengths[:, None]
    Nrm = np.column_stack([-U[:, 1], U[:, 0]])
    v = np.zeros((n + 1, 2))
    if n == 1:
        v[:] = offset * U[0]
    else:
        T = U[:-1] + U[1:]
        tn = np.linalg.norm(T, axis=1)
        if (tn < 1e-9).any():
            k = int(np.flatnonzero(tn < 1e-9)[0]) + 1
            raise PatternError(f"{fam}: the section turns back on itself at point {k}")
        T /= tn[:, None]
        lam = np.zeros(n - 1)
        lam[0] = offset
        for i in range(1, n - 1):
            num = float(T[i - 1] @ Nrm[i])
            den = float(T[i] @ Nrm[i])
            if abs(den) < 1e-12 or num / den <= 0:
                raise PatternError(
                    f"{fam}: the section does not zig-zag at point {i + 1} (offsets would "
                    "change sign); expected alternating turns (use depth > 0)"
                )
            lam[i] = lam[i - 1] * num / den
        v[1:n] = lam[:, None] * T
        v[0], v[n] = v[1], v[n - 1]
    mu = 1.0 + np.einsum("ij,ij->i", np.diff(v, axis=0), U) / lengths
    if (mu <= 0.05).any():
        k = int(np.flatnonzero(mu <= 0.05)[0])
        raise PatternError(
            f"{fam}: offset = {offset:g} collapses facet column {k} (odd-row edge would be "
            f"{mu[k]:.3g} x the even-row edge); expected a smaller offset"
        )
    return np.column_stack([v[:, 0], np.zeros(n + 1), v[:, 1]])


def miura_tachi(
    curve: Sequence[Sequence[float]] | None = None,
    ny: int = 3,
    depth: float = 0.4,
    offset: float = 0.3,
    spacing: float = 0.6,
    folded: bool = False,
) -> CreasePattern:
    """Generalised Miura-ori (Tachi 2009) whose folded section follows ``curve``.

    Parameters
    ----------
    curve : (k, 2) sequence of (x, z) points or None
        Target section curve, k >= 2 points, one facet column per segment; default
        :func:`default_arch_curve` (radius 4, 120 deg, 8 segments).
    ny : int
        Cells along the cylinder axis y (2 ny strips), >= 1.
    depth : float
        Zig-zag depth added across the curve (>= 0; 0 uses ``curve`` as the zig-zag).
    offset : float
        Zig-zag offset lambda of the odd rows at the first interior section point (> 0,
        like Miura's V).
    spacing : float
        Distance s between rows along y (> 0, like Miura's S).
    folded : bool
        Return the designed folded state ((n, 3) vertices) instead of the flat pattern.

    Returns
    -------
    CreasePattern
        Grid layout as :func:`miura` (``meta['barhinge:grid']``); target fold angles = the
        designed state's fold angles.
    """
    fam = "miura_tachi"
    C = default_arch_curve() if curve is None else curve
    try:
        C = np.asarray(C, dtype=float)
    except (TypeError, ValueError):
        raise PatternError(f"{fam}: curve must be a list of (x, z) points") from None
    if C.ndim != 2 or C.shape[1] != 2 or len(C) < 2 or not np.isfinite(C).all():
        raise PatternError(f"{fam}: curve must be a (k, 2) array of finite points with k >= 2")
    ny = check_int("ny", ny, 1, family=fam)
    depth = check_range("depth", depth, 0.0, None, lo_open=False, family=fam)
    offset = check_range("offset", offset, 0.0, None, family=fam)
    spacing = check_range("spacing", spacing, 0.0, None, family=fam)
    P2 = tachi_section(C, depth)
    V = _offsets(P2, offset, fam)
    P = np.column_stack([P2[:, 0], np.zeros(len(P2)), P2[:, 1]])
    lay = GridLayout(len(P), 2 * ny + 1)
    J = np.arange(lay.nj)
    X = (
        P[None, :, :]
        + (J % 2)[:, None, None] * V[None, :, :]
        + (J * spacing)[:, None, None] * np.array([0.0, 1.0, 0.0])
    ).reshape(-1, 3)
    faces = lay.quads()
    edges = lay.edges()
    rho = fold_angles_of(X, faces, edges)
    bnd = lay.boundary_mask()
    A = mv_assignment(rho, bnd)
    rho[bnd] = 0.0
    Xout = X if folded else unfold(X, faces)
    return build_pattern(
        Xout,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=rho,
        family=fam,
        parameters={
            "curve": C.tolist(),
            "ny": ny,
            "depth": depth,
            "offset": offset,
            "spacing": spacing,
            "folded": folded,
        },  # fmt: skip
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )
