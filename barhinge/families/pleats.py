"""Pleats (corrugations): straight parallel pleats with an exact folded state, and pleats whose
direction follows a circular arc.

Sources: the accordion / corrugation is the simplest fold pattern (e.g. Jackson, *Folding
Techniques for Designers*, 2011, ch. 1 "Pleats"); arc-following pleats discretised as
concentric polygons with radial facet lines follow Jackson's "curved pleats" and Demaine et al.,
"(Non)existence of pleated folds: how paper folds between creases", Graphs and Combinatorics
27, 2011 (which shows why straight-segment arcs need the extra radial creases).
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
    mv_assignment,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["curved_pleats", "pleats"]


def pleats(
    n: int = 6,
    w: float = 1.0,
    length: float = 4.0,
    fold: float | None = None,
    target: float = 90.0,
) -> CreasePattern:
    """Straight pleats: ``n`` rectangular panels of width ``w`` and length ``length`` joined by
    ``n - 1`` parallel creases (along y), alternating valley (first) and mountain.

    Parameters
    ----------
    n : int
        Number of panels, >= 2.
    w, length : float
        Panel width (x) and crease length (y), > 0.
    fold : float or None
        Fold angle magnitude of every crease (degrees, in [0, 180)); None gives the flat sheet.
        The folded state is exact: panel k is tilted by ``(-1)^(k+1) fold / 2`` about the y axis,
        so valleys open towards +z.
    target : float
        Target fold angle magnitude of the flat pattern (degrees, (0, 180]).

    Returns
    -------
    CreasePattern
        Vertices ``(k, 0)`` and ``(k, 1)`` (crease line k = 0..n, bottom/top) with id
        ``j * (n + 1) + k``; faces counter-clockwise; ``meta['barhinge:grid'] = [n + 1, 2]``.
    """
    fam = "pleats"
    n = check_int("n", n, 2, family=fam)
    w = check_range("w", w, 0.0, None, family=fam)
    length = check_range("length", length, 0.0, None, family=fam)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, 180.0, lo_open=False, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    lay = GridLayout(n + 1, 2)
    k = np.arange(n)
    sign_crease = np.where(np.arange(1, n) % 2 == 1, 1.0, -1.0)  # crease k: V for odd k
    if fold is None:
        xs = np.concatenate([[0.0], np.cumsum(np.full(n, w))])
        X = np.column_stack([np.tile(xs, 2), np.repeat([0.0, length], n + 1)])
    else:
        t = np.radians(fold) / 2 * np.where(k % 2 == 0, -1.0, 1.0)
        xs = np.concatenate([[0.0], np.cumsum(w * np.cos(t))])
        zs = np.concatenate([[0.0], np.cumsum(w * np.sin(t))])
        X = np.column_stack([np.tile(xs, 2), np.repeat([0.0, length], n + 1), np.tile(zs, 2)])
    edges = lay.edges()
    mag = target if fold is None else fold
    rho_row = np.zeros(lay.n_row_edges)
    rho_col = np.zeros(n + 1)
    rho_col[1:n] = sign_crease * mag
    rho = np.concatenate([rho_row, rho_col])
    A = mv_assignment(rho, lay.boundary_mask())
    return build_pattern(
        X,
        lay.quads(),
        edges=edges,
        assignment=A,
        fold_angles=rho,
        family=fam,
        parameters={"n": n, "w": w, "length": length, "fold": fold, "target": target},
        extra_meta={"barhinge:grid": [n + 1, 2]},
    )


def curved_pleats(
    n: int = 6,
    radius: float = 2.0,
    w: float = 0.5,
    sweep: float = 90.0,
    segments: int = 8,
    target: float = 90.0,
) -> CreasePattern:
    """Pleats whose direction follows a circular arc (flat pattern).

    The creases are ``n - 1`` concentric polygonal arcs at radii ``radius + k w`` (k = 1..n-1)
    over the angle ``sweep``, each made of ``segments`` straight segments, alternating valley
    (k odd) and mountain; the radial lines through the polygon corners are facet lines (``F``,
    target 0) that let the trapezoidal panels bend at the corners, as a straight-segment arc
    pleat cannot fold with the arcs alone (Demaine et al. 2011).

    Parameters
    ----------
    n : int
        Number of annular panels, >= 2.
    radius : float
        Inner radius, > 0.
    w : float
        Panel width (radial), > 0.
    sweep : float
        Angle covered by the arcs, degrees in (0, 360).
    segments : int
        Straight segments per arc, >= 1 (the sweep per segment must be < 180 deg).
    target : float
        Target fold angle magnitude of the arc creases, degrees in (0, 180].

    Returns
    -------
    CreasePattern
        Vertex ``(s, k)`` (angular index s = 0..segments, arc k = 0..n) has id
        ``k * (segments + 1) + s``; arcs centred on the origin, symmetric about +y.
    """
    fam = "curved_pleats"
    n = check_int("n", n, 2, family=fam)
    radius = check_range("radius", radius, 0.0, None, family=fam)
    w = check_range("w", w, 0.0, None, family=fam)
    sweep = check_range("sweep", sweep, 0.0, 360.0, family=fam)
    segments = check_int("segments", segments, max(1, math.floor(sweep / 180.0) + 1), family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    lay = GridLayout(segments + 1, n + 1)
    ang = np.radians(90.0 + sweep / 2 - np.arange(segments + 1) * sweep / segments)
    r = radius + np.arange(n + 1) * w
    # i runs clockwise (decreasing angle) and j outwards, so quads are counter-clockwise
    X = np.column_stack([np.outer(r, np.cos(ang)).ravel(), np.outer(r, np.sin(ang)).ravel()])
    edges = lay.edges()
    I, J = np.meshgrid(np.arange(segments), np.arange(n + 1), indexing="xy")
    rho_row = np.where(J % 2 == 1, target, -target).astype(float).ravel()
    rho = np.concatenate([rho_row, np.zeros(lay.ni * (lay.nj - 1))])
    A = np.where(rho > 0, "V", np.where(rho < 0, "M", "F"))
    bnd = lay.boundary_mask()
    A[bnd] = "B"
    rho[bnd] = 0.0
    return build_pattern(
        X,
        lay.quads(),
        edges=edges,
        assignment=A,
        fold_angles=rho,
        family=fam,
        parameters={
            "n": n,
            "radius": radius,
            "w": w,
            "sweep": sweep,
            "segments": segments,
            "target": target,
        },  # fmt: skip
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )
