"""Periodic unit cells: the effective stiffness of an infinite tessellation from one cell.

A tessellation is periodic with two lattice vectors ``t1``, ``t2`` (in the state analysed).
Its displacement under a uniform macroscopic deformation is a macroscopic field plus a
periodic fluctuation (first-order homogenisation of a plate; e.g. Schenk & Guest 2013, and
the Kirchhoff-Love kinematics of any plate text)::

    u(X) = Phi(X) g + w(X),   w(X + t1) = w(X + t2) = w(X),

with ``g = (eps_11, eps_22, gamma_12, kappa_11, kappa_22, 2 kappa_12)`` in the cell frame
(``e1`` along ``t1``, ``e2`` in the lattice plane, ``n = e1 x e2``; ``(x, y, z)`` the node
coordinates in that frame, ``z`` from the reference plane ``z0``)::

    u_1 = eps_11 x + gamma_12 y / 2 - z (kappa_11 x + kappa_12 y)
    u_2 = gamma_12 x / 2 + eps_22 y - z (kappa_12 x + kappa_22 y)
    u_3 = kappa_11 x^2 / 2 + kappa_12 x y + kappa_22 y^2 / 2

(``kappa = d^2 u_3 / dx dx``: positive curvature bends the sheet up, towards ``n``). The
fluctuation is eliminated (static condensation of the tangent) and the energy per unit
projected area is ``W = g^T ABD g / 2``: the classical 6 x 6 ``[[A, B], [B, D]]`` stiffness
of a laminate (A: force / length, B: force, D: force x length).

The cell is given as a model of a small *sheet* of at least 2 x 2 periods (for example
``miura(2, 2, fold=theta)``): nodes one lattice vector apart share their fluctuation, and
each class of periodic images of an element (bar, hinge) counts once, through its copy
nearest the sheet's centre. A single cell would not do: its boundary creases have no fold
hinges and its boundary bars only one adjacent panel's stiffness. The chosen copy must be
the stiffest of its class (checked); 2 x 2 periods suffice when no element spans more than
one period.

The result is linear: the tangent at the state (default ``model.X0``, stress-free). Rigid
rotations are not in the ansatz; they cost no energy at a stress-free state.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.errors import ConfigError

__all__ = ["PeriodicCell", "kinematic_abd", "periodic_cell"]

#: names of the six macroscopic components, in the order of ``PeriodicCell.ABD``
COMPONENTS = ("eps_11", "eps_22", "gamma_12", "kappa_11", "kappa_22", "kappa_12x2")


@dataclasses.dataclass(frozen=True)
class PeriodicCell:
    """Effective stiffness of a periodic tessellation.

    Attributes
    ----------
    ABD : (6, 6) float
        Energy per unit projected area ``W = g^T ABD g / 2`` for
        ``g = (eps_11, eps_22, gamma_12, kappa_11, kappa_22, 2 kappa_12)`` in the cell frame.
    frame : (3, 3) float
        Rows ``e1, e2, n`` of the cell frame (global coordinates).
    area : float
        Projected cell area ``|t1 x t2|``.
    z0 : float
        Reference plane (frame ``z``) of the curvatures.
    classes : (n_nodes,) int
        Periodic class of each model node (nodes one lattice vector apart share one).
    weights_bars, weights_hinges : (n_bars,), (n_hinges,) float
        1 for the element that stands for its class in the cell energy, else 0.
    modes : (n_nodes, 3, 6) float
        Displacement of every node (global axes) for a unit value of each component.
    """

    ABD: np.ndarray
    frame: np.ndarray
    area: float
    z0: float
    classes: np.ndarray
    weights_bars: np.ndarray
    weights_hinges: np.ndarray
    modes: np.ndarray

    @property
    def A(self) -> np.ndarray:
        """(3, 3) in-plane stiffness (force / length), curvatures held zero."""
        return self.ABD[:3, :3]

    @property
    def B(self) -> np.ndarray:
        """(3, 3) in-plane / bending coupling (force)."""
        return self.ABD[:3, 3:]

    @property
    def D(self) -> np.ndarray:
        """(3, 3) bending stiffness (force x length), strains held zero."""
        return self.ABD[3:, 3:]

    def in_plane_compliance(self, free_curvature: bool = False) -> np.ndarray:
        """(3, 3) in-plane compliance ``eps = a N`` (N: force per length), with the
        curvatures held zero (default) or free (stress-resultant-free moments)."""
        if free_curvature:
            return np.linalg.inv(self.ABD)[:3, :3]
        return np.linalg.inv(self.A)

    def bending_compliance(self, free_strain: bool = True) -> np.ndarray:
        """(3, 3) bending compliance ``kappa = d M``, with the in-plane strains free
        (default: no in-plane force) or held zero."""
        if free_strain:
            return np.linalg.inv(self.ABD)[3:, 3:]
        return np.linalg.inv(self.D)

    def poisson_in_plane(self, free_curvature: bool = False) -> float:
        """``nu_12 = -eps_22 / eps_11`` under in-plane force along ``e1`` only."""
        a = self.in_plane_compliance(free_curvature)
        return float(-a[1, 0] / a[0, 0])

    def poisson_bending(self, free_strain: bool = True) -> float:
        """``nu_b = -kappa_22 / kappa_11`` under a bending moment about ``e2`` only
        (> 0: saddle)."""
        d = self.bending_compliance(free_strain)
        return float(-d[1, 0] / d[0, 0])

    def moduli(self) -> dict[str, float]:
        """In-plane engineering constants (curvatures held zero): ``E1, E2`` (force /
        length: a membrane modulus times thickness), ``G12``, ``nu12``, ``nu21``."""
        a = self.in_plane_compliance()
        return {
            "E1": float(1 / a[0, 0]),
            "E2": float(1 / a[1, 1]),
            "G12": float(1 / a[2, 2]),
            "nu12": float(-a[1, 0] / a[0, 0]),
            "nu21": float(-a[0, 1] / a[1, 1]),
        }


def _frame(lattice: np.ndarray) -> np.ndarray:
    t1, t2 = lattice
    e1 = t1 / np.linalg.norm(t1)
    n = np.cross(t1, t2)
    nn = np.linalg.norm(n)
    if nn <= 1e-12 * np.linalg.norm(t1) * np.linalg.norm(t2):
        raise ConfigError("the two lattice vectors are parallel")
    n /= nn
    return np.vstack([e1, np.cross(n, e1), n])


def _macro_field(X: np.ndarray, R: np.ndarray, z0: float) -> np.ndarray:
    """(n, 3, 6) displacement of every node (global axes) for a unit value of each
    macroscopic component (frame rows ``R``; in-plane origin at the centroid, ``z`` from the
    plane ``z0``)."""
    p = (X - X.mean(0)) @ R.T
    x, y = p[:, 0], p[:, 1]
    z = X @ R[2] - z0
    o = np.zeros_like(x)
    loc = np.stack(
        [
            np.stack([x, o, o], 1),  # eps_11
            np.stack([o, y, o], 1),  # eps_22
            np.stack([y / 2, x / 2, o], 1),  # gamma_12
            np.stack([-z * x, o, x * x / 2], 1),  # kappa_11
            np.stack([o, -z * y, y * y / 2], 1),  # kappa_22
            np.stack([-z * y / 2, -z * x / 2, x * y / 2], 1),  # 2 kappa_12
        ],
        axis=2,
    )  # (n, 3, 6) in the frame
    return np.einsum("ai,nag->nig", R, loc)


def _node_classes(X: np.ndarray, lattice: np.ndarray, tol: float):
    """Class id and integer cell index (n, 2) of each node: nodes whose positions differ by
    an integer combination of the lattice vectors share a class."""
    t1, t2 = lattice
    n = np.cross(t1, t2)
    M = np.column_stack([t1, t2, n / np.linalg.norm(n)])
    c = np.linalg.solve(M, (X - X[0]).T).T  # lattice coordinates, normal offset
    k = np.floor(c[:, :2] + tol)
    frac = c[:, :2] - k
    lat = c[:, :2]
    scale = np.linalg.norm(lattice, axis=1).max()
    key = np.column_stack([frac, c[:, 2] / scale])
    q = np.round(key / tol).astype(np.int64)
    _, cls = np.unique(q, axis=0, return_inverse=True)
    cls = cls.ravel()
    # check the grouping: members of a class really are lattice translates
    first = np.full(cls.max() + 1, -1)
    first[cls[::-1]] = np.arange(len(cls))[::-1]
    d = X - X[first[cls]] - (k - k[first[cls]]) @ lattice
    if np.abs(d).max() > 10 * tol * scale:
        raise ConfigError(
            "nodes could not be grouped into lattice translates (largest mismatch "
            f"{np.abs(d).max():.2e}); check the lattice vectors and the state"
        )
    return cls, k.astype(np.int64), lat


def _element_weights(
    elems: np.ndarray,
    stiff: np.ndarray,
    cls: np.ndarray,
    k: np.ndarray,
    frac: np.ndarray,
    unordered: list,
    what: str,
) -> np.ndarray:
    """Weight 1 for one copy of each element class (the copy nearest the sheet's centre in
    lattice coordinates), 0 for the others. ``unordered`` lists groups of columns whose
    order does not matter (the two ends of a bar; a hinge is (axis pair, wing pair)).
    Copies at the sheet's edge carry less stiffness (one adjacent panel instead of two, no
    fold hinge on a boundary crease), so the chosen copy must be the stiffest of its class."""
    w = np.zeros(len(elems))
    if len(elems) == 0:
        return w
    keys = []
    for e in elems:  # setup only: a cell sheet has a few hundred elements
        best = None
        for p in e:
            parts = tuple(
                tuple(sorted((int(cls[v]), *(k[v] - k[p]).tolist()) for v in e[list(g)]))
                for g in unordered
            )
            best = parts if best is None or parts < best else best
        keys.append(best)
    ids: dict[tuple, int] = {}
    inv = np.array([ids.setdefault(x, len(ids)) for x in keys])
    centre = frac.mean(0)
    dist = np.linalg.norm(frac[elems].mean(1) - centre, axis=1)
    order = np.lexsort((dist, inv))
    first = order[np.r_[True, inv[order][1:] != inv[order][:-1]]]
    w[first] = 1.0
    top = np.zeros(len(ids))
    np.maximum.at(top, inv, stiff)
    if (stiff[first] < top[inv[first]] * (1 - 1e-9)).any():
        raise ConfigError(
            f"the sheet is too small for a periodic cell: the central copy of a {what} is "
            "softer than another copy; use a sheet of more periods"
        )
    return w


def periodic_cell(
    model: Any,
    lattice: Any,
    X: np.ndarray | None = None,
    *,
    z0: float | None = None,
    tol: float = 1e-7,
) -> PeriodicCell:
    """Effective ``ABD`` stiffness of the infinite tessellation a sheet model repeats.

    Parameters
    ----------
    model : BarHingeModel
        Model of a sheet of at least 2 x 2 periods (see the module docstring).
    lattice : (2, 3) float
        Lattice vectors ``t1``, ``t2`` in the state ``X`` (length; e.g. Miura ``(2 L, 0, 0)``
        and ``(0, 2 S, 0)``); ``e1`` of the cell frame is along ``t1``.
    X : (n_nodes, 3) float, optional
        State (default ``model.X0``).
    z0 : float, optional
        Reference plane of the curvatures: its ``n`` coordinate (``X @ n``; default the mean
        over node classes).
    tol : float
        Relative tolerance of the periodic node matching.

    Returns
    -------
    PeriodicCell

    Raises
    ------
    ConfigError
        Bad lattice, nodes that are not lattice translates, a sheet of fewer than 2 x 2
        periods, a central copy softer than another copy of its class, or a singular cell
        (a mechanism of the periodic fluctuation).
    """
    X = model.X0 if X is None else np.asarray(X, float)
    if X.shape != (model.n_nodes, 3):
        raise ConfigError(f"X must have shape ({model.n_nodes}, 3), got {X.shape}")
    T = np.asarray(lattice, float)
    if T.shape != (2, 3) or not np.isfinite(T).all():
        raise ConfigError(f"lattice must be two finite 3-vectors, shape (2, 3), got {T.shape}")
    R = _frame(T)
    cls, k, lat = _node_classes(X, T, tol)
    n_cls = int(cls.max()) + 1
    span = np.zeros((n_cls, 2))
    for d in (0, 1):
        lo = np.full(n_cls, np.inf)
        hi = np.full(n_cls, -np.inf)
        np.minimum.at(lo, cls, k[:, d])
        np.maximum.at(hi, cls, k[:, d])
        span[:, d] = hi - lo
    if (span.max(0) < 1).any():
        raise ConfigError(
            "no two nodes of the sheet are one lattice vector apart along "
            f"{'t1' if span[:, 0].max() < 1 else 't2'}: check the lattice vectors"
        )
    if (span.max(0) < 2).any():
        raise ConfigError(
            f"the sheet spans {span.max(0).astype(int).tolist()} periods along (t1, t2); a "
            "periodic cell needs a sheet of at least 2 x 2 periods (a single cell has no fold "
            "hinges on its boundary creases)"
        )
    if len(getattr(model, "bar_pairs", ())):
        raise ConfigError(
            "the periodic cell weighs bars one by one; the CST membrane couples the sides of "
            "its triangles: build the model with a bar calibration ('fit', 'filipov' or "
            "'dilation')"
        )
    wb = _element_weights(model.bars, model.bar_EA, cls, k, lat, [[0, 1]], "bar")
    wh = _element_weights(model.hinges, model.hinge_k, cls, k, lat, [[0, 1], [2, 3]], "hinge")
    cell = model.with_(bar_EA=model.bar_EA * wb, hinge_k=model.hinge_k * wh)
    K = sp.csr_matrix(cell.tangent(X))

    zc = float((np.bincount(cls, X @ R[2]) / np.bincount(cls)).mean())
    z_ref = zc if z0 is None else float(z0)
    Phi_n = _macro_field(X, R, z_ref)
    Phi = Phi_n.reshape(-1, 6)
    # periodic fluctuation: node dof (3 n + a) <- class dof (3 c + a); class 0 fixed
    rows = np.arange(3 * len(X))
    cols = (3 * cls[:, None] + np.arange(3)).ravel()
    P = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(3 * len(X), 3 * n_cls))
    P = P[:, 3:]
    Kww = (P.T @ K @ P).tocsc()
    Kwg = P.T @ (K @ Phi)
    Kgg = Phi.T @ (K @ Phi)
    try:
        lu = spla.splu(Kww)
        W = lu.solve(np.asarray(Kwg))
    except RuntimeError as exc:
        raise ConfigError(
            "the periodic cell has a mechanism (singular condensed tangent); add fold "
            f"stiffness ({exc})"
        ) from None
    Keff = Kgg - Kwg.T @ W
    area = float(np.linalg.norm(np.cross(T[0], T[1])))
    ABD = 0.5 * (Keff + Keff.T) / area
    modes = Phi_n - (P @ W).reshape(len(X), 3, 6)
    return PeriodicCell(
        ABD=ABD,
        frame=R,
        area=area,
        z0=z_ref,
        classes=cls,
        weights_bars=wb,
        weights_hinges=wh,
        modes=modes,
    )


def kinematic_abd(
    model: Any,
    area: float,
    frame: np.ndarray,
    z0: float,
    X: np.ndarray | None = None,
    boundary: np.ndarray | None = None,
) -> np.ndarray:
    """(6, 6) ``ABD`` of a finite sheet with the macroscopic field prescribed on its boundary
    nodes and the others free (kinematic uniform boundary conditions): the condensed tangent
    divided by ``area``. An upper bound of the periodic ``ABD`` (Hill 1963) that closes as
    the sheet grows.

    Parameters
    ----------
    model : BarHingeModel of the sheet
    area : float
        Projected area the sheet stands for (e.g. cells x ``PeriodicCell.area``).
    frame, z0 : as in :class:`PeriodicCell` (use the cell's, to compare).
    X : (n_nodes, 3) float, optional (default ``model.X0``)
    boundary : (k,) int, optional
        Nodes that follow the macroscopic field (default the pattern's boundary vertices).
    """
    X = model.X0 if X is None else np.asarray(X, float)
    bnd = model.pattern.boundary_vertices if boundary is None else np.asarray(boundary, int)
    if len(bnd) == 0:
        raise ConfigError("kinematic_abd needs boundary nodes")
    K = sp.csr_matrix(model.tangent(X))
    Phi = _macro_field(X, np.asarray(frame, float), float(z0)).reshape(-1, 6)
    free = np.ones(len(X), bool)
    free[bnd] = False
    f = np.flatnonzero(np.repeat(free, 3))
    KP = np.asarray((K @ Phi)[f])
    Keff = Phi.T @ (K @ Phi) - KP.T @ spla.splu(K[f][:, f].tocsc()).solve(KP)
    return 0.5 * (Keff + Keff.T) / float(area)
