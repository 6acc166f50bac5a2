"""Miura-ori: flat pattern, exact rigidly folded states and the closed forms of Schenk & Guest.

Source: M. Schenk and S. D. Guest, "Geometry of Miura-folded metamaterials", PNAS 110(9):
3276-3281, 2013 (unit cell of four parallelogram facets with sides a, b and sector angle
gamma; facet angle theta in [0, pi/2] between the facets and the xy plane; cell dimensions
H, S, L, V, their Eq. 1, and in-plane Poisson's ratio nu_SL, their Eq. 2).

Geometry used here (shared by :func:`miura` and :func:`miura_geometry`)
----------------------------------------------------------------------
Vertex ``(i, j)``, ``i = 0..2 nx`` (x, the "L" direction), ``j = 0..2 ny`` (y, the "S"
direction), has id ``j * (2 nx + 1) + i`` (see :func:`miura_layout`). Its folded position is

    X(i, j) = (i L + (j mod 2) V,  j S,  (i mod 2) H),

which for theta = 0 is the flat pattern x = i a + (j mod 2) b cos(gamma), y = j b sin(gamma).

* "straight" creases: the row edges ``(i, j)-(i+1, j)`` of length ``a``; each row is a straight
  line in the flat pattern and a zig-zag in a vertical plane once folded;
* "zig-zag" creases: the column edges ``(i, j)-(i, j+1)`` of length ``b``; each column is a
  zig-zag in the flat pattern that stays in a horizontal plane (z = 0 for even ``i``, z = H for
  odd ``i``) while folding.

Fold angles (FOLD convention, valley > 0; derived from the facet normals of the geometry
above and checked against ``CreasePattern.state_fold_angles`` in the tests):

* zig-zag crease in column ``i``: ``rho_z = +2 theta`` for even ``i`` (valley), ``-2 theta`` for
  odd ``i`` (mountain);
* straight crease ``(i, j)-(i+1, j)``: ``|rho_s| = 2 arctan(cos(gamma) tan(theta))``, valley
  when ``i + j`` is odd and mountain when it is even.

Every interior vertex has three creases of one kind and one of the other (Maekawa) and
sector angles gamma, pi - gamma, pi - gamma, gamma (Kawasaki).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
    grid_layout,
    mv_assignment,
)
from barhinge.pattern.crease import CreasePattern

__all__ = [
    "MiuraGeometry",
    "MiuraLayout",
    "miura",
    "miura_fold_angles",
    "miura_geometry",
    "miura_grid_coords",
    "miura_layout",
    "miura_layout_of",
]

#: default facet angle theta (deg) whose fold angles become the flat pattern's targets
DEFAULT_TARGET_THETA = 60.0


@dataclasses.dataclass(frozen=True)
class MiuraGeometry:
    """Closed-form geometry of a folded Miura-ori unit cell (Schenk & Guest 2013, Eq. 1-2).

    Attributes
    ----------
    a, b : float
        Facet side lengths (a along the straight creases, b along the zig-zag creases).
    alpha : float
        Sector angle gamma in degrees.
    theta : float
        Facet angle in degrees (0 flat, 90 fully folded).
    H : float
        Height of the cell: ``a sin(theta) sin(gamma)``.
    S : float
        Half width (y) of the cell: ``b cos(theta) tan(gamma) / sqrt(1 + cos^2 theta tan^2 gamma)``.
    L : float
        Half length (x) of the cell: ``a sqrt(1 - sin^2 theta sin^2 gamma)``.
    V : float
        Zig-zag offset (x) of the cell: ``b / sqrt(1 + cos^2 theta tan^2 gamma)``.
    rho_zigzag : float
        Magnitude of the zig-zag creases' fold angle in degrees: ``2 theta``.
    rho_straight : float
        Magnitude of the straight creases' fold angle in degrees:
        ``2 arctan(cos(gamma) tan(theta))``.
    nu_SL : float
        In-plane Poisson's ratio ``-(dL/L)/(dS/S) = -cos^2(theta) tan^2(gamma)`` (S&G Eq. 2).
    """

    a: float
    b: float
    alpha: float
    theta: float
    H: float
    S: float
    L: float
    V: float
    rho_zigzag: float
    rho_straight: float
    nu_SL: float

    @property
    def cell_size(self) -> tuple[float, float, float]:
        """(2 L, 2 S, H): footprint and height of one unit cell (x, y, z)."""
        return (2 * self.L, 2 * self.S, self.H)

    def sheet_size(self, nx: int, ny: int) -> tuple[float, float, float]:
        """Bounding box (x, y, z) of an ``nx`` x ``ny`` sheet made by :func:`miura`:
        ``(2 nx L + V, 2 ny S, H)`` (``V`` only when ny >= 1 shifts odd rows)."""
        return (2 * nx * self.L + self.V, 2 * ny * self.S, self.H)


def miura_geometry(a: float, b: float, alpha: float, theta: float) -> MiuraGeometry:
    """Closed forms of a folded Miura-ori cell (Schenk & Guest 2013, PNAS 110(9), Eq. 1-2).

    Parameters
    ----------
    a, b : float
        Facet side lengths (> 0).
    alpha : float
        Sector angle gamma, degrees in (0, 90).
    theta : float
        Facet angle, degrees in [0, 90].

    Returns
    -------
    MiuraGeometry
    """
    fam = "miura_geometry"
    a = check_range("a", a, 0.0, None, family=fam)
    b = check_range("b", b, 0.0, None, family=fam)
    al = check_range("alpha", alpha, 0.0, 90.0, family=fam)
    th_deg = check_range("theta", theta, 0.0, 90.0, lo_open=False, hi_open=False, family=fam)
    g = math.radians(al)
    th = math.radians(th_deg)
    c2t2 = math.cos(th) ** 2 * math.tan(g) ** 2
    D = math.sqrt(1.0 + c2t2)
    H = a * math.sin(th) * math.sin(g)
    S = b * math.cos(th) * math.tan(g) / D
    L = a * math.sqrt(1.0 - math.sin(th) ** 2 * math.sin(g) ** 2)
    V = b / D
    rho_z = 2.0 * th_deg
    rho_s = math.degrees(2.0 * math.atan(math.cos(g) * math.tan(th))) if th_deg < 90 else 180.0
    return MiuraGeometry(
        a=a, b=b, alpha=al, theta=th_deg, H=H, S=S, L=L, V=V,
        rho_zigzag=rho_z, rho_straight=rho_s, nu_SL=-c2t2,
    )  # fmt: skip


@dataclasses.dataclass(frozen=True)
class MiuraLayout(GridLayout):
    """Index map of a Miura sheet (a :class:`GridLayout` of (2 nx + 1) x (2 ny + 1) vertices).

    ``straight_edges`` are the row edges (length a), ``zigzag_edges`` the column edges
    (length b); the ``left/right/bottom/top`` vertex and edge groups come from GridLayout.
    """

    @property
    def straight_edges(self) -> np.ndarray:
        """(n,) int: all straight-family edges (row edges, including the two boundary rows)."""
        return self.row_edges

    @property
    def zigzag_edges(self) -> np.ndarray:
        """(n,) int: all zig-zag-family edges (column edges, including the boundary columns)."""
        return self.column_edges

    @property
    def interior_straight_edges(self) -> np.ndarray:
        """(n,) int: straight creases that fold (rows 1 .. 2 ny - 1)."""
        i, j = np.meshgrid(np.arange(self.ni - 1), np.arange(1, self.nj - 1), indexing="xy")
        return np.asarray(self.row_edge(i.ravel(), j.ravel()))

    @property
    def interior_zigzag_edges(self) -> np.ndarray:
        """(n,) int: zig-zag creases that fold (columns 1 .. 2 nx - 1)."""
        i, j = np.meshgrid(np.arange(1, self.ni - 1), np.arange(self.nj - 1), indexing="xy")
        return np.asarray(self.column_edge(i.ravel(), j.ravel()))


def miura_layout(nx: int, ny: int) -> MiuraLayout:
    """The :class:`MiuraLayout` of ``miura(nx, ny, ...)``."""
    nx = check_int("nx", nx, 1, family="miura")
    ny = check_int("ny", ny, 1, family="miura")
    return MiuraLayout(2 * nx + 1, 2 * ny + 1)


def miura_layout_of(cp: CreasePattern) -> MiuraLayout:
    """The :class:`MiuraLayout` of a pattern made by :func:`miura` or a grid-based variation
    (``miura_arc``, ``miura_nonuniform``, ``miura_tachi``, ``russo_pleat``), read from
    ``cp.meta['barhinge:grid']`` (also after a FOLD round trip)."""
    g = grid_layout(cp)
    return MiuraLayout(g.ni, g.nj)


def miura_fold_angles(layout: GridLayout, alpha: float, theta: float) -> np.ndarray:
    """(m,) float degrees: signed fold angle of every edge of a Miura sheet at facet angle
    ``theta`` (0 on boundary edges), in the edge order of ``layout.edges()``."""
    geo = miura_geometry(1.0, 1.0, alpha, theta)
    ni, nj = layout.ni, layout.nj
    I, J = np.meshgrid(np.arange(ni - 1), np.arange(nj), indexing="xy")
    s_row = np.where((I + J) % 2 == 1, 1.0, -1.0)
    s_row[[0, -1], :] = 0.0
    I, J = np.meshgrid(np.arange(ni), np.arange(nj - 1), indexing="xy")
    s_col = np.where(I % 2 == 0, 1.0, -1.0)
    s_col[:, [0, -1]] = 0.0
    return np.concatenate([s_row.ravel() * geo.rho_straight, s_col.ravel() * geo.rho_zigzag])


def miura_grid_coords(a: np.ndarray, b: np.ndarray, alpha: float, theta: float) -> np.ndarray:
    """(n, 3) folded coordinates of a Miura grid with panel lengths ``a[i]`` (columns, x) and
    ``b[j]`` (rows, y), sector angle ``alpha`` and facet angle ``theta`` (degrees).

    Every facet is a Miura parallelogram with the same angles, so each step uses the Schenk &
    Guest cell dimensions of its own lengths: ``x = sum L_k + sum (-1)^k V_k``,
    ``y = sum S_k``, ``z = sum (-1)^k H_k``.
    """
    ga = miura_geometry(1.0, 1.0, alpha, theta)
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    sa = np.where(np.arange(len(a)) % 2 == 0, 1.0, -1.0)
    sb = np.where(np.arange(len(b)) % 2 == 0, 1.0, -1.0)
    cx = np.concatenate([[0.0], np.cumsum(a * ga.L)])
    cz = np.concatenate([[0.0], np.cumsum(sa * a * ga.H)])
    cy = np.concatenate([[0.0], np.cumsum(b * ga.S)])
    off = np.concatenate([[0.0], np.cumsum(sb * b * ga.V)])
    ni, nj = len(a) + 1, len(b) + 1
    I, J = np.meshgrid(np.arange(ni), np.arange(nj), indexing="xy")
    I, J = I.ravel(), J.ravel()
    return np.column_stack([cx[I] + off[J], cy[J], cz[I]])


def miura(
    nx: int = 4,
    ny: int = 4,
    a: float = 1.0,
    b: float = 1.0,
    alpha: float = 60.0,
    fold: float | None = None,
    target: float = DEFAULT_TARGET_THETA,
) -> CreasePattern:
    """Miura-ori sheet of ``nx`` x ``ny`` unit cells (Miura 1985; Schenk & Guest 2013).

    Parameters
    ----------
    nx, ny : int
        Unit cells along x (straight creases) and y (zig-zag creases); each cell has 2 x 2
        parallelogram facets, so the sheet has (2 nx + 1)(2 ny + 1) vertices.
    a, b : float
        Facet side lengths: ``a`` along the straight creases (x), ``b`` along the zig-zag creases.
    alpha : float
        Sector angle gamma in degrees, in (0, 90).
    fold : float or None
        Facet angle theta of Schenk & Guest in degrees, in [0, 90]. None: the flat pattern with
        (n, 2) vertices. A value: the exact rigidly folded state with (n, 3) vertices and
        ``fold_angles`` equal to that state's fold angles.
    target : float
        For the flat pattern: the facet angle (degrees, in (0, 90]) whose fold angles become the
        target ``fold_angles`` (default 60).

    Returns
    -------
    CreasePattern
        Quad faces ``(i,j),(i+1,j),(i+1,j+1),(i,j+1)`` counter-clockwise from +z; vertex and
        edge ids as documented in the module docstring and :class:`MiuraLayout` (edges: row /
        straight edges first, then column / zig-zag edges). Boundary edges are ``B``.
        ``meta['barhinge:grid'] = [2 nx + 1, 2 ny + 1]``.

    Notes
    -----
    Zig-zag crease fold angle ``+-2 theta``; straight crease ``+-2 arctan(cos gamma tan theta)``;
    see the module docstring for which are valleys.
    """
    fam = "miura"
    lay = miura_layout(nx, ny)
    a = check_range("a", a, 0.0, None, family=fam)
    b = check_range("b", b, 0.0, None, family=fam)
    alpha = check_range("alpha", alpha, 0.0, 90.0, family=fam)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, 90.0, lo_open=False, hi_open=False, family=fam)
    target = check_range("target", target, 0.0, 90.0, hi_open=False, family=fam)
    theta = 0.0 if fold is None else fold
    X = miura_grid_coords(np.full(lay.ni - 1, a), np.full(lay.nj - 1, b), alpha, theta)
    if fold is None:
        X = X[:, :2]
    rho = miura_fold_angles(lay, alpha, target if fold is None else fold)
    A = mv_assignment(miura_fold_angles(lay, alpha, 45.0), lay.boundary_mask())
    params = {"nx": lay.ni // 2, "ny": lay.nj // 2, "a": a, "b": b, "alpha": alpha, "fold": fold}
    if fold is None:
        params["target"] = target
    return build_pattern(
        X,
        lay.quads(),
        edges=lay.edges(),
        assignment=A,
        fold_angles=rho,
        family=fam,
        parameters=params,
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )


def miura_line_creases(cp: CreasePattern) -> np.ndarray:
    """Edge ids of the M/V creases on the longest straight crease line through the vertex
    nearest the centroid of a flat Miura sheet (edge ids are the same in folded states)."""
    V = np.asarray(cp.vertices, float)
    E = np.asarray(cp.edges)
    crease = np.flatnonzero(np.isin(np.asarray(cp.assignment), ["M", "V"]))
    c = int(np.argmin(np.linalg.norm(V - V.mean(0), axis=1)))
    size = float(np.linalg.norm(np.ptp(V, axis=0)))
    best = np.zeros(0, np.int64)
    for e in crease[(E[crease] == c).any(1)]:
        u = V[E[e, 1]] - V[E[e, 0]]
        u /= np.linalg.norm(u)
        # creases collinear with e: both end points on the line through c along u
        ok = np.ones(len(crease), bool)
        for k in (0, 1):
            off = V[E[crease, k]] - V[c]
            ok &= np.linalg.norm(off - np.outer(off @ u, u), axis=1) <= 1e-6 * size
        line = crease[ok]
        if len(line) > len(best):
            best = line
    return np.sort(best)
