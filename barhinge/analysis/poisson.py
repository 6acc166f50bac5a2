"""Poisson's ratios of folded sheets: in-plane along a fold path, out-of-plane from bending.

Definitions (named as such in the results)
------------------------------------------
* ``periodic``: the lengths ``l_1``, ``l_2`` of two lattice vectors of the tessellation, each
  the mean distance of vertex pairs one period apart (e.g. Miura vertices ``(i, j)`` and
  ``(i + 2, j)``: ``2 L``; ``(i, j)`` and ``(i, j + 2)``: ``2 S``). This is the unit-cell ratio
  of Schenk & Guest (2013, PNAS 110(9):3276, Eq. 2), free of boundary effects.
* ``end-to-end``: the sheet's overall dimensions, the extents between two pairs of opposite
  boundary vertex groups (left/right, bottom/top): along the line joining the groups'
  centroids, from the outermost vertex of one end to the outermost vertex of the other (for a
  flat-ish sheet, its bounding-box size). For a Miura sheet of ``n`` cells this is
  ``2 n L + V`` along the zig-zag direction, where the periodic length is ``2 L`` (Schenk &
  Guest 2013, Eq. 1, cell dimensions): the finite-sheet ratio differs from the periodic one
  and tends to it as ``n`` grows (one cell at ``cos^2(theta) tan^2(gamma) = 1``, where the
  periodic ratio is -1: about -1/3). ``measure="centroid"`` keeps the distance between the
  group centroids, which cancels the zig-zag offset and gives the periodic ratio again on a
  uniform sheet.

Both give the tangent ratio along the path ``nu_21 = -(d ln l_2) / (d ln l_1)``: minus the
strain in direction 2 per unit strain in direction 1 (direction 1 is the driving one), with the
derivatives taken along the path by second-order finite differences (``numpy.gradient``).

Out-of-plane (bending) ratio: a quadratic ``w = f + d x + e y + a x^2 + b x y + c y^2`` fitted to
one layer of vertices of a bent sheet gives curvatures ``kappa_x = 2 a``, ``kappa_y = 2 c``;
``nu_b = -kappa_y / kappa_x`` (bent about y by moments on the x ends; ``-kappa_x / kappa_y``
when bent along y). ``nu_b > 0`` means a saddle (anticlastic), ``nu_b < 0`` a dome
(synclastic). For the Miura-ori in the rigid-panel limit (panels bend only along a diagonal),
Schenk & Guest (2013) find the bending ratio equal and opposite to the in-plane one:
``-kappa_L / kappa_S = +cos^2(theta) tan^2(gamma)``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from barhinge.errors import ConfigError

__all__ = [
    "BendingPoisson",
    "InPlanePoisson",
    "bending_poisson",
    "end_to_end_poisson",
    "grid_ends",
    "grid_pairs",
    "periodic_poisson",
]


@dataclasses.dataclass(frozen=True)
class InPlanePoisson:
    """In-plane Poisson's ratio along a path.

    Attributes
    ----------
    definition : str
        ``"periodic"`` or ``"end-to-end"``.
    length_1, length_2 : (n_states,) float
        Measured lengths in the driving direction 1 and the transverse direction 2.
    strain_1, strain_2 : (n_states,) float
        Logarithmic strains ``ln(l / l_0)`` from state 0.
    nu : (n_states,) float
        Tangent ratio ``-(d ln l_2)/(d ln l_1)`` (NaN where ``d l_1 = 0``).
    secant : (n_states,) float
        Secant ratio ``-strain_2 / strain_1`` from state 0 (NaN at state 0).
    """

    definition: str
    length_1: np.ndarray
    length_2: np.ndarray
    strain_1: np.ndarray
    strain_2: np.ndarray
    nu: np.ndarray
    secant: np.ndarray


def _states(path_or_X: Any) -> np.ndarray:
    X = getattr(path_or_X, "X", path_or_X)
    X = np.asarray(X, float)
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] < 3:
        raise ConfigError(
            f"a Poisson's ratio along a path needs at least 3 states of shape (n_states, "
            f"n_nodes, 3), got {X.shape}"
        )
    return X


def _pairs(pairs: Any, n_nodes: int, name: str) -> np.ndarray:
    P = np.asarray(pairs, dtype=np.int64)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) == 0:
        raise ConfigError(f"{name} must be a non-empty (k, 2) array of node ids, got {P.shape}")
    if P.min() < 0 or P.max() >= n_nodes:
        raise ConfigError(f"{name} references node {P.max()}, but there are {n_nodes} nodes")
    return P


def _ratio(definition: str, l1: np.ndarray, l2: np.ndarray, t: np.ndarray | None):
    t = np.arange(len(l1), dtype=float) if t is None else np.asarray(t, float)
    e1, e2 = np.log(l1 / l1[0]), np.log(l2 / l2[0])
    d1, d2 = np.gradient(e1, t, edge_order=2), np.gradient(e2, t, edge_order=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        nu = np.where(d1 != 0, -d2 / d1, np.nan)
        sec = np.where(e1 != 0, -e2 / e1, np.nan)
    return InPlanePoisson(definition, l1, l2, e1, e2, nu, sec)


def periodic_poisson(
    path_or_X: Any, pairs_1: Any, pairs_2: Any, *, parameter: np.ndarray | None = None
) -> InPlanePoisson:
    """Periodic-cell in-plane Poisson's ratio along a path.

    Parameters
    ----------
    path_or_X : FoldPath or (n_states, n_nodes, 3) float
    pairs_1, pairs_2 : (k, 2) int
        Node pairs one lattice period apart in the driving direction 1 and the transverse
        direction 2; each length is the mean distance over its pairs.
    parameter : (n_states,) float, optional
        Path parameter for the derivatives (default: the state index; the ratio does not
        depend on it, only the accuracy does when steps are uneven).
    """
    X = _states(path_or_X)
    p1 = _pairs(pairs_1, X.shape[1], "pairs_1")
    p2 = _pairs(pairs_2, X.shape[1], "pairs_2")
    l1 = np.linalg.norm(X[:, p1[:, 1]] - X[:, p1[:, 0]], axis=2).mean(1)
    l2 = np.linalg.norm(X[:, p2[:, 1]] - X[:, p2[:, 0]], axis=2).mean(1)
    return _ratio("periodic", l1, l2, parameter)


def end_to_end_poisson(
    path_or_X: Any,
    ends_1: tuple[Any, Any],
    ends_2: tuple[Any, Any],
    *,
    parameter: np.ndarray | None = None,
    measure: str = "extent",
) -> InPlanePoisson:
    """End-to-end (finite-sheet) in-plane Poisson's ratio along a path.

    Parameters
    ----------
    path_or_X : FoldPath or (n_states, n_nodes, 3) float
    ends_1, ends_2 : pair of int arrays
        Node groups at the two opposite ends in direction 1 (e.g. left and right boundary
        vertices, :func:`grid_ends`) and in direction 2.
    parameter : (n_states,) float, optional
        Path parameter for the derivatives (as in :func:`periodic_poisson`).
    measure : ``"extent"`` (default) or ``"centroid"``
        ``"extent"``: the length is the sheet's extent between the two ends, along the unit
        vector ``u`` from the first group's centroid to the second's:
        ``max(X_b . u) - min(X_a . u)``. ``"centroid"``: the distance between the group
        centroids (on a uniform Miura sheet this equals whole periods, so it returns the
        periodic ratio of :func:`periodic_poisson`, not the sheet's).
    """
    X = _states(path_or_X)
    if measure not in ("extent", "centroid"):
        raise ConfigError(f"measure = {measure!r}; expected 'extent' or 'centroid'")

    def length(ends: tuple[Any, Any], name: str) -> np.ndarray:
        if len(ends) != 2:
            raise ConfigError(f"{name} must be two node groups (one per end)")
        a, b = (np.asarray(e, np.int64).ravel() for e in ends)
        if a.size == 0 or b.size == 0 or max(a.max(), b.max()) >= X.shape[1]:
            raise ConfigError(f"{name} groups must be non-empty node ids < {X.shape[1]}")
        d = X[:, b].mean(1) - X[:, a].mean(1)  # (n_states, 3)
        dist = np.linalg.norm(d, axis=1)
        if measure == "centroid":
            return dist
        if not (dist > 0).all():
            raise ConfigError(f"{name}: the two end groups have the same centroid")
        u = d / dist[:, None]
        pb = np.einsum("sni,si->sn", X[:, b], u).max(axis=1)
        pa = np.einsum("sni,si->sn", X[:, a], u).min(axis=1)
        return pb - pa

    return _ratio("end-to-end", length(ends_1, "ends_1"), length(ends_2, "ends_2"), parameter)


def _grid(grid: Any) -> tuple[int, int]:
    g = grid.meta.get("barhinge:grid") if hasattr(grid, "meta") else grid
    if g is None or len(g) != 2:
        raise ConfigError("expected a grid (ni, nj) or a pattern with meta['barhinge:grid']")
    return int(g[0]), int(g[1])


def grid_pairs(grid: Any, period: tuple[int, int] = (2, 2)) -> tuple[np.ndarray, np.ndarray]:
    """Vertex pairs one period apart in a grid-numbered pattern (vertex ``(i, j)`` has id
    ``j * ni + i``, as the generators of :mod:`barhinge.families` number them).

    Parameters
    ----------
    grid : (ni, nj) or CreasePattern with ``meta['barhinge:grid']``
    period : (pi, pj)
        Lattice period in vertex steps (Miura-ori: (2, 2)).

    Returns
    -------
    pairs_i, pairs_j : (k, 2) int
        Pairs ``((i, j), (i + pi, j))`` and ``((i, j), (i, j + pj))``.
    """
    ni, nj = _grid(grid)
    pi, pj = period
    I, J = np.meshgrid(np.arange(ni), np.arange(nj), indexing="xy")
    vid = J * ni + I
    return (
        np.column_stack([vid[:, : ni - pi].ravel(), vid[:, pi:].ravel()]),
        np.column_stack([vid[: nj - pj, :].ravel(), vid[pj:, :].ravel()]),
    )


def grid_ends(grid: Any) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """Boundary vertex groups of a grid-numbered pattern: ``((i = 0, i = ni - 1),
    (j = 0, j = nj - 1))`` for :func:`end_to_end_poisson`."""
    ni, nj = _grid(grid)
    vid = np.arange(ni * nj).reshape(nj, ni)
    return (vid[:, 0], vid[:, -1]), (vid[0, :], vid[-1, :])


@dataclasses.dataclass(frozen=True)
class BendingPoisson:
    """Out-of-plane Poisson's ratio of a bent sheet.

    Attributes
    ----------
    nu : float
        ``-kappa_y / kappa_x``: bent along x (> 0: saddle).
    kappa_x, kappa_y, kappa_xy : float
        Second derivatives ``w_xx``, ``w_yy``, ``w_xy`` of the fitted quadratic (1/length);
        for small slopes, the curvatures along x and y and the twist.
    K : float
        Gaussian curvature of the fitted surface at the layer's centroid.
    rms : float
        Root-mean-square residual of the fit (length).
    """

    nu: float
    kappa_x: float
    kappa_y: float
    kappa_xy: float
    K: float
    rms: float

    @property
    def nu_yx(self) -> float:
        """``-kappa_x / kappa_y``: the ratio for a sheet bent along y (``1 / nu``)."""
        return -self.kappa_x / self.kappa_y if self.kappa_y != 0 else float("nan")


def bending_poisson(X: np.ndarray, layer: Any | None = None) -> BendingPoisson:
    """Bending Poisson's ratio from a quadratic fit of one vertex layer (global x, y, z).

    Parameters
    ----------
    X : (n_nodes, 3) float
        Bent state; the sheet lies roughly in the xy plane and is bent about y.
    layer : (m,) int, optional
        Node ids of one layer (e.g. the top vertices of a corrugated sheet; default all).
    """
    X = np.asarray(X, float)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ConfigError(f"X must have shape (n_nodes, 3), got {X.shape}")
    P = X if layer is None else X[np.asarray(layer, np.int64)]
    if len(P) < 6:
        raise ConfigError(f"a quadratic fit needs at least 6 layer nodes, got {len(P)}")
    c = P.mean(0)
    x, y, w = (P - c).T
    s = max(float(np.abs(P[:, :2] - c[:2]).max()), 1e-300)
    u, v = x / s, y / s
    A = np.column_stack([np.ones_like(u), u, v, u * u, u * v, v * v])
    coef, *_ = np.linalg.lstsq(A, w, rcond=None)
    rms = float(np.sqrt(np.mean((A @ coef - w) ** 2)))
    f, d, e, a, b, cc = coef
    wx, wy = d / s, e / s
    kxx, kxy, kyy = 2 * a / s**2, b / s**2, 2 * cc / s**2
    K = (kxx * kyy - kxy**2) / (1 + wx * wx + wy * wy) ** 2
    nu = -kyy / kxx if kxx != 0 else float("nan")
    return BendingPoisson(float(nu), float(kxx), float(kyy), float(kxy), float(K), rms)
