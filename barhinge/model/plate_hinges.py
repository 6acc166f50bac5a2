"""Plate-consistent hinge stiffnesses for finely subdivided panels (:func:`consistent_bending`).

A sheet cut into many small flat cells (``barhinge.pattern.subdivide.subdivided``) bends
through its hinges: the bend hinges inside each N5B8 cell (corner to centre) and the fold
hinges of the flat ``F`` lines between cells. The rule here chooses their stiffnesses so that
every *uniform curvature* ``w = (k11 x^2 + k22 y^2) / 2 + k12 x y`` of a cell stores the
Kirchhoff plate energy per unit area

    U = D / 2 (k11^2 + k22^2 + 2 nu k11 k22 + 2 (1 - nu) k12^2)  +  lambda (k11 k22 - k12^2)

(``D = E t^3 / (12 (1 - nu^2))``; the last term, the linearised Gaussian curvature, is a null
Lagrangian: its integral is a boundary term that vanishes wherever ``w = 0`` along straight
supported edges, so ``lambda`` is a free parameter of the fit). This is the patch test of
plate elements: a hinge model that passes it on a regular mesh converges to the plate as the
cells shrink; one that fails it converges to a different (anisotropic) plate.

How (per cell, in the cell's own plane): the linearised dihedral angle of a hinge with axis
``a -> b`` and wing nodes ``p`` is ``sum_p (w_p - w_axis(p)) / dist(p, axis)``; for a uniform
curvature each angle is linear in ``(k11, k22, k12, delta)``, ``delta`` the offset of the
centre nodes from the quadratic (the structure relaxes it: condensed out); the neighbour cell
across a side is taken as the point reflection of the cell through the side's midpoint (exact
for the parallelogram and barycentric-triangle grids of ``subdivided``). Hinge energies
``k theta^2 / 2`` (a side hinge shared by two cells counts half per cell). Stiffnesses per
hinge group (opposite sides, the two halves of a diagonal; the three sides of a triangle) and
``lambda`` by bounded least squares (``k >= 0``), relative to ``D``. The fit is exact
(residual ~1e-12) for squares (every hinge ``4 D / 3``, ``lambda = -(1/3 + nu) D``),
rectangles of aspect ratio up to about 1.6, equilateral triangles (``2 D / sqrt 3``) and
the 60-degree rhombus (only as its long-diagonal hinges become near rigid, ~3e4 D); it
leaves a residual for elongated rectangles, oblique parallelograms and right or isosceles
triangles, which is reported (``PlateHinges.residual``): such cells converge to a plate with
the wrong anisotropy, not to the Kirchhoff plate.

Sources: the patch test of nonconforming plate elements (Morley 1968; Irons & Razzaque 1972);
dihedral-angle bending energies and their mesh dependence (Grinspun, Hirani, Desbrun &
Schroeder 2003, "Discrete shells"; Wardetzky, Bergou, Harmon, Zorin & Grinspun 2007,
"Discrete quadratic curvature energies").
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from barhinge.errors import ConfigError
from barhinge.model.model import BarHingeModel
from barhinge.model.triangulate import quad_centres

logger = logging.getLogger(__name__)

__all__ = [
    "PlateHinges",
    "cell_fit",
    "cell_matrix",
    "consistent_bending",
    "consistent_hinge_stiffness",
    "coupled_bending",
]

#: weight of the pull of each hinge group towards 4/3 D in the cell fit (log scale)
REGULARISATION = 1e-3
#: relative rounding of cell shapes (normalised by sqrt(area)) when grouping equal cells
SHAPE_DIGITS = 6


@dataclasses.dataclass(frozen=True)
class PlateHinges:
    """Result of :func:`consistent_hinge_stiffness`.

    Attributes
    ----------
    hinge_k : (n_hinges,) float, moment per radian: the model's stiffnesses with the bend
        hinges and the ``F``-line fold hinges replaced (creases keep theirs)
    residual : (n_faces,) float, largest entry of the cell's energy mismatch over ``D``
        (0 = the cell passes the uniform-curvature patch test)
    changed : (n_hinges,) bool, hinges whose stiffness the rule set (every hinge inside or
        between cells; creases get their spring in series with the plate strip)
    """

    hinge_k: np.ndarray
    residual: np.ndarray
    changed: np.ndarray


def _coef(p: np.ndarray) -> np.ndarray:
    """Coefficients of (k11, k22, k12) in w at the points p (..., 2)."""
    x, y = p[..., 0], p[..., 1]
    return np.stack([x * x / 2, y * y / 2, x * y], axis=-1)


def _angle_row(a, b, wings, da: float = 0.0, db: float = 0.0) -> np.ndarray:
    """(..., 4) linearised dihedral angle of the hinge a -> b (points (..., 2)) per
    (k11, k22, k12, delta); wings is a list of (point (..., 2), centre flag); da, db: centre
    flags of the axis ends. Vectorised over the leading axes (one hinge of many cells)."""
    u = b - a
    uu = np.einsum("...i,...i->...", u, u)
    g = np.zeros(np.shape(a)[:-1] + (4,))
    for p, dp in wings:
        s = np.einsum("...i,...i->...", p - a, u) / uu
        d = np.linalg.norm(p - a - s[..., None] * u, axis=-1)
        g[..., :3] += (_coef(p) - (1 - s)[..., None] * _coef(a) - s[..., None] * _coef(b)) / d[
            ..., None
        ]
        g[..., 3] += (dp - (1 - s) * da - s * db) / d
    return g


def _cell_rows(P: np.ndarray, wings: np.ndarray | None = None):
    """Angle rows, energy weights and groups of a cell's hinges, in the order: quad: side i
    (P_i -> P_i+1) for i = 0..3, then half-diagonal P_i -> centre; triangle: side i.

    ``P`` (k, 2) or, for many cells of one size at once, (nc, k, 2); the rows are then
    (nc, n, 4) (the weights and groups are the same for every cell of a size).
    ``wings`` (k, 2) or (nc, k, 2): the neighbour cell's wing node across each side, in the
    cell's plane (quads: its centre node; triangles: its corner opposite the side); by
    default (and where a row is NaN) the point reflection of the cell's own centre (quads) or
    opposite corner (triangles) through the side's midpoint (exact on a grid of equal
    parallelograms and on a barycentric grid of equal triangles)."""
    P = np.asarray(P, float)
    rows, w, grp = [], [], []
    if P.shape[-2] == 4:
        c = quad_centres(P)  # the model's centre node (triangulate: where the diagonals cross)
        for i in range(4):
            a, b = P[..., i, :], P[..., (i + 1) % 4, :]
            nb = a + b - c
            if wings is not None:
                wi = np.asarray(wings, float)[..., i, :]
                nb = np.where(np.isfinite(wi).all(axis=-1)[..., None], wi, nb)
            rows.append(_angle_row(a, b, [(c, 1.0), (nb, 1.0)]))
            w.append(0.5)
            grp.append(i % 2)
        for i in range(4):
            wings_i = [(P[..., (i + 1) % 4, :], 0.0), (P[..., i - 1, :], 0.0)]
            rows.append(_angle_row(P[..., i, :], c, wings_i, 0.0, 1.0))
            w.append(1.0)
            grp.append(2 + i % 2)
    else:
        for i in range(3):
            a, b, o = P[..., i, :], P[..., (i + 1) % 3, :], P[..., (i + 2) % 3, :]
            nb = a + b - o
            if wings is not None:
                wi = np.asarray(wings, float)[..., i, :]
                nb = np.where(np.isfinite(wi).all(axis=-1)[..., None], wi, nb)
            rows.append(_angle_row(a, b, [(o, 0.0), (nb, 0.0)]))
            w.append(0.5)
            grp.append(i)
    return np.stack(rows, axis=-2), np.array(w), np.array(grp)


def _condensed(k: np.ndarray, rows: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(3, 3) energy form in (k11, k22, k12) with the centre offset condensed out."""
    M = np.einsum("hi,h,hj->ij", rows, w * k, rows)
    if M[3, 3] > 1e-300:
        return M[:3, :3] - np.outer(M[:3, 3], M[3, :3]) / M[3, 3]
    return M[:3, :3]


def cell_fit(P: np.ndarray, nu: float) -> tuple[np.ndarray, float, float]:
    """Hinge stiffnesses over D of one flat cell (module docstring).

    Parameters
    ----------
    P : (4, 2) or (3, 2) float, corners counter-clockwise in the cell's plane
    nu : Poisson's ratio

    Returns
    -------
    k : (8,) or (3,) float, stiffness / D per hinge in the order of ``_cell_rows``
    lam : float, the null-Lagrangian coefficient / D
    residual : float, largest |entry| of the energy-form mismatch / D
    """
    from scipy.optimize import least_squares  # lazy: scipy.optimize is slow to import

    rows, w, grp = _cell_rows(np.asarray(P, float))
    area = 0.5 * abs(float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1])))
    plate = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 2.0 * (1.0 - nu)]])
    null = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -2.0]])
    ng = int(grp.max()) + 1

    def mismatch(x: np.ndarray) -> np.ndarray:
        return (_condensed(x[:ng][grp], rows, w) / area - plate - x[ng] * null).ravel()

    def objective(x: np.ndarray) -> np.ndarray:
        # the energy rows, and a weak pull of every stiffness towards the square cell's
        # 4/3: where the energy does not fix a group (a family of exact fits) the fit
        # takes the moderate member instead of a near-rigid hinge, which would lock
        return np.concatenate([mismatch(x), REGULARISATION * np.log(x[:ng] / (4.0 / 3.0))])

    x0 = np.append(np.full(ng, 4.0 / 3.0), -(1.0 / 3.0 + nu))
    lo = np.append(np.full(ng, 1e-6), -np.inf)
    sol = least_squares(objective, x0, bounds=(lo, np.inf), xtol=1e-14, ftol=1e-14, gtol=1e-14)
    # polish without the pull: the exact fit next to the moderate one
    sol = least_squares(mismatch, sol.x, bounds=(lo, np.inf), xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return sol.x[:ng][grp], float(sol.x[ng]), float(np.abs(mismatch(sol.x)).max())


def _cell_frames(X: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin, e1, e2), each (nf, 3): the planes of the faces F (nf, k): origin corner 0,
    first axis along side 0."""
    P = X[F]
    n = np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)
    n /= np.linalg.norm(n, axis=1)[:, None]
    e1 = P[:, 1] - P[:, 0]
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    return P[:, 0], e1, np.cross(n, e1)


def _cells_2d(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(nf, k, 2) corners of the faces F (nf, k) in their own planes (:func:`_cell_frames`)."""
    origin, e1, e2 = _cell_frames(X, F)
    R = X[F] - origin[:, None]
    return np.stack([np.einsum("fki,fi->fk", R, e1), np.einsum("fki,fi->fk", R, e2)], axis=-1)


def _cell_groups(cp, X: np.ndarray):
    """Per face size (3, 4): the face ids, their corners ``F`` (nf, size), the cells in their
    own planes ``P2`` (nf, size, 2), their areas, and the distinct shapes (``first``: one
    representative per shape, ``inv``: the shape of every cell), shapes being equal up to
    translation, rotation and scale."""
    sizes = np.array([len(f) for f in cp.faces])
    for size in (3, 4):
        fids = np.flatnonzero(sizes == size)
        if not len(fids):
            continue
        F = np.array([cp.faces[f] for f in fids], np.int64)
        P2 = _cells_2d(X, F)
        area = 0.5 * np.abs(
            np.sum(
                P2[..., 0] * np.roll(P2[..., 1], -1, 1) - np.roll(P2[..., 0], -1, 1) * P2[..., 1], 1
            )
        )
        key = np.round(P2 / np.sqrt(area)[:, None, None], SHAPE_DIGITS).reshape(len(fids), -1)
        _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
        yield size, fids, F, P2, area, first, inv.ravel()


def _diagonal_hinges(model: BarHingeModel, fids: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(nf, 4) model index of the half-diagonal hinge at every corner of the N5B8 cells."""
    nv = model.pattern.n_vertices
    h = np.asarray(model.hinges)
    bend = np.asarray(model.hinge_kind) == "bend"
    hkey = np.where(bend, np.asarray(model.hinge_face) * nv + np.minimum(h[:, 0], h[:, 1]), -1)
    horder = np.argsort(hkey)
    hk = fids[:, None] * nv + F
    pos = np.searchsorted(hkey, hk, sorter=horder)
    hid = horder[np.minimum(pos, len(h) - 1)]
    if not np.array_equal(hkey[hid], hk):
        raise ConfigError("N5B8 model and pattern disagree on the cells' diagonals")
    return hid


def consistent_hinge_stiffness(model: BarHingeModel) -> PlateHinges:
    """Plate-consistent stiffnesses of the bend hinges and the ``F``-line fold hinges of an
    N5B8 model of a (subdivided) pattern with triangular or quadrilateral faces (module
    docstring). A crease (M, V, U) hinge gets its spring ``k_c`` in series with the plate
    strip ``k_s`` of the two half-cells beside it, ``k_c k_s / (k_c + k_s)``: its angle is the
    crease's own rotation plus the bending of that strip."""
    cp = model.pattern
    if model.scheme != "N5B8":
        raise ConfigError(f"consistent bending needs an N5B8 model, got {model.scheme}")
    sizes = np.array([len(f) for f in cp.faces])
    if not np.isin(sizes, (3, 4)).all():
        raise ConfigError("consistent bending needs triangular or quadrilateral faces")
    mat = model.material
    D, nu = mat.bending_rigidity, mat.nu
    X = np.asarray(model.X0, float)
    nv = cp.n_vertices
    E = np.asarray(cp.edges, np.int64)
    ekey = np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])
    eorder = np.argsort(ekey)
    side_k = np.zeros(len(E))  # summed half contributions of the cells on each edge
    residual = np.zeros(cp.n_faces)
    bend = np.asarray(model.hinge_kind) == "bend"
    k_new = np.array(model.hinge_k, float)
    for size, fids, F, P2, _, first, inv in _cell_groups(cp, X):
        fits = [cell_fit(P2[f], nu) for f in first]
        kc = np.array([f[0] for f in fits])[inv] * D  # (nf, n hinges of the cell)
        residual[fids] = np.array([f[2] for f in fits])[inv]
        # sides: half of the cell's side stiffness to the edge
        a, b = F, np.roll(F, -1, axis=1)
        sk = np.minimum(a, b) * nv + np.maximum(a, b)
        e = eorder[np.searchsorted(ekey, sk, sorter=eorder)]
        np.add.at(side_k, e.ravel(), 0.5 * kc[:, :size].ravel())
        if size == 4:
            k_new[_diagonal_hinges(model, fids, F).ravel()] = kc[:, 4:].ravel()
    flat_line = ~bend & (np.asarray(model.hinge_edge) >= 0)
    flat_line &= np.asarray(cp.assignment)[np.maximum(model.hinge_edge, 0)] == "F"
    k_new[flat_line] = side_k[np.asarray(model.hinge_edge)[flat_line]]
    # creases: the crease spring in series with the plate strip of the two half-cells
    # beside it (the hinge's angle is the crease's own rotation plus the strip's bending)
    crease = ~bend & ~flat_line & (np.asarray(model.hinge_edge) >= 0)
    ks = side_k[np.asarray(model.hinge_edge)[crease]]
    kc = k_new[crease]
    with np.errstate(divide="ignore"):
        k_new[crease] = np.where((ks > 0) & (kc > 0), kc * ks / (kc + ks), kc)
    logger.debug(
        "consistent bending: %d bend + %d flat-line hinges, largest cell residual %.2g",
        int(bend.sum()),
        int(flat_line.sum()),
        float(residual.max(initial=0.0)),
    )
    changed = bend | flat_line
    changed[np.flatnonzero(crease)[(ks > 0) & (kc > 0)]] = True
    return PlateHinges(hinge_k=k_new, residual=residual, changed=changed)


def consistent_bending(model: BarHingeModel) -> BarHingeModel:
    """The model with the plate-consistent bend and flat-line hinge stiffnesses of
    :func:`consistent_hinge_stiffness`."""
    return model.with_(hinge_k=consistent_hinge_stiffness(model).hinge_k)


def cell_matrix(
    P: np.ndarray, nu: float, wings: np.ndarray | None = None
) -> tuple[np.ndarray, float | np.ndarray]:
    """Energy matrix over D of one flat cell's hinge angles, with couplings (the sheet's nu).

    The cell stores ``theta^T K theta D / 2`` (``theta`` its hinge angles in the order of
    ``_cell_rows``; a side hinge shared with the neighbour cell counts in both cells). For
    every uniform curvature ``kappa`` (and the centre offset relaxed) it equals the Kirchhoff
    plate energy ``area kappa^T P kappa / 2`` with the sheet's ``nu`` and *no* null
    Lagrangian, so it holds at free and crease-bounded edges too.

    Triangles: three angles and three curvatures, ``K = R^-T (area P) R^-1`` (``R`` the
    angle rows), the only such form. Quadrilaterals: ``K = alpha K_d + L C L^T`` with ``L``
    the dual rows (``L^T R = I`` on the
    curvatures, ``L^T R_delta = 0``) and ``C = area P - alpha cond(K_d)``, where ``K_d`` gives
    every hinge the square cell's ``4/3`` (no near-rigid hinge, so no locking); ``alpha`` is the
    largest value that keeps ``C`` positive semi-definite, so ``K`` is positive definite
    wherever ``K_d`` is (no zero-energy mode beyond the rigid ones).

    ``P`` (k, 2) is one cell; (nc, k, 2) are many cells of one size at once (``wings``
    then (nc, k, 2)), computed together.

    Returns
    -------
    K : (n, n) or (nc, n, n) float, symmetric positive semi-definite
    residual : float or (nc,) float, largest |entry| of the condensed mismatch / D
        (round-off when exact)
    """
    P = np.asarray(P, float)
    rows, w, _ = _cell_rows(P, wings)
    x, y = P[..., 0], P[..., 1]
    area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, -1) - np.roll(x, -1, -1) * y, axis=-1))
    unit = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 2.0 * (1.0 - nu)]])
    plate = area[..., None, None] * unit
    if P.shape[-2] == 3:
        Rinv = np.linalg.inv(rows[..., :3])
        K = np.swapaxes(Rinv, -1, -2) @ plate @ Rinv
    else:
        Kd = np.diag(w * (4.0 / 3.0))  # the square cell's hinges, scaled by alpha below
        Md = _condensed_form(Kd, rows)
        # largest alpha with plate - alpha Md >= 0: the smallest generalised eigenvalue
        Li = np.linalg.inv(np.linalg.cholesky(Md))
        alpha = np.linalg.eigvalsh(Li @ plate @ np.swapaxes(Li, -1, -2))[..., 0]
        C = plate - alpha[..., None, None] * Md
        ev, V = np.linalg.eigh(0.5 * (C + np.swapaxes(C, -1, -2)))
        C = (V * np.clip(ev, 0.0, None)[..., None, :]) @ np.swapaxes(V, -1, -2)
        RtR = np.swapaxes(rows, -1, -2) @ rows
        L = (rows @ np.linalg.inv(RtR))[..., :3]
        K = alpha[..., None, None] * Kd + L @ C @ np.swapaxes(L, -1, -2)
    K = 0.5 * (K + np.swapaxes(K, -1, -2))
    mismatch = np.abs(_condensed_form(K, rows) - plate).max(axis=(-1, -2)) / area
    return K, (float(mismatch) if P.ndim == 2 else mismatch)


def _condensed_form(K: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(..., 3, 3) form ``R^T K R`` in (k11, k22, k12), the centre offset (4th row entry, if
    any) condensed out (``K`` (..., n, n), ``rows`` (..., n, 3 or 4))."""
    M = np.swapaxes(rows, -1, -2) @ K @ rows
    if M.shape[-1] == 4:
        m33 = M[..., 3, 3]
        ok = m33 > 1e-300
        corr = M[..., :3, 3, None] * M[..., 3, None, :3] / np.where(ok, m33, 1.0)[..., None, None]
        return M[..., :3, :3] - np.where(ok[..., None, None], corr, 0.0)
    return M[..., :3, :3]


#: a uniform curvature (k11, k22, k12) that moves every hinge of a cell (sign test)
_TEST_CURVATURES = np.array([[1.0, 0.6, 0.35], [-0.4, 1.0, 0.8]])


def coupled_bending(model: BarHingeModel) -> BarHingeModel:
    """The model with plate-consistent hinges *and* couplings: every cell stores the
    Kirchhoff plate energy of every uniform curvature with the sheet's Poisson ratio
    (:func:`cell_matrix`), the crease springs in series with the plate strip beside them.

    Couplings stay inside cells and never involve a crease hinge: a crease's angle holds its
    own rotation, which the plate energy must not see. Cells on a crease or a free edge keep
    the principal part of their matrix (positive semi-definite); their crease hinge gets the
    cell's diagonal entry as its plate strip. Needs N5B8 quadrilateral or triangular faces.
    A cell takes its neighbours' wing nodes across its flat sides where they are (a
    quadrilateral its neighbours' centre nodes, a triangle their opposite corners): any grid,
    e.g. a bilinear grid of a trapezoid or a graded grid
    (``barhinge.pattern.subdivide.subdivided`` with ``grading``); across a crease or a free
    edge it takes the point reflection of its own. Where the model's hinge angles disagree
    with the cells' rows, a warning names the largest mismatch.
    """
    from barhinge.kernels.geometry import hinge_angle_derivatives

    cp = model.pattern
    if model.scheme != "N5B8":
        raise ConfigError(f"coupled bending needs an N5B8 model, got {model.scheme}")
    sizes = np.array([len(f) for f in cp.faces])
    if not np.isin(sizes, (3, 4)).all():
        raise ConfigError("coupled bending needs triangular or quadrilateral faces")
    mat = model.material
    D, nu = mat.bending_rigidity, mat.nu
    X = np.asarray(model.X0, float)
    nv = cp.n_vertices
    h = np.asarray(model.hinges)
    bend = np.asarray(model.hinge_kind) == "bend"
    edge_of = np.asarray(model.hinge_edge)
    asg = np.asarray(cp.assignment)
    flat_line = ~bend & (edge_of >= 0)
    flat_line &= asg[np.maximum(edge_of, 0)] == "F"
    crease = ~bend & ~flat_line & (edge_of >= 0)
    hinge_of_edge = np.asarray(model.fold_hinge_of_edge)
    E = np.asarray(cp.edges, np.int64)
    ekey = np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])
    eorder = np.argsort(ekey)
    _, grad, _ = hinge_angle_derivatives(X, h)  # (nh, 12) at the reference
    diag = np.zeros(model.n_hinges)
    pair_i, pair_j, pair_c = [], [], []
    residual = np.zeros(cp.n_faces)
    worst = 0.0
    for size, fids, F, P2, area, first, inv in _cell_groups(cp, X):
        # model hinge of every cell hinge: sides, then (quads) the half-diagonals
        a, b = F, np.roll(F, -1, axis=1)
        e = eorder[np.searchsorted(ekey, np.minimum(a, b) * nv + np.maximum(a, b), sorter=eorder)]
        hid = hinge_of_edge[e]  # (nf, size), -1 on boundary edges
        # the neighbour's wing node across every flat side, in the cell's plane (quads:
        # its centre node; triangles: its corner opposite the side): the grid need not be
        # point-symmetric (graded grids; quads' centres sit where their diagonals cross)
        side = np.maximum(hid, 0)
        if size == 4:
            diag_hid = _diagonal_hinges(model, fids, F)
            own = np.maximum(h[diag_hid[:, 0], 0], h[diag_hid[:, 0], 1])[:, None]  # centre
        else:
            own = np.roll(F, -2, axis=1)  # the corner opposite side i (F_i -> F_i+1)
        wing = np.where(h[side, 2] == own, h[side, 3], h[side, 2])  # (nf, size)
        origin, e1, e2 = _cell_frames(X, F)
        R = X[wing] - origin[:, None]
        wings = np.stack([np.einsum("fki,fi->fk", R, e1), np.einsum("fki,fi->fk", R, e2)], -1)
        wings[~((hid >= 0) & flat_line[side])] = np.nan
        scale = np.sqrt(area)[:, None, None]
        key = np.round(np.concatenate([P2, np.nan_to_num(wings, nan=1e9)], 1) / scale, SHAPE_DIGITS)
        _, first, inv = np.unique(
            key.reshape(len(fids), -1), axis=0, return_index=True, return_inverse=True
        )
        inv = inv.ravel()
        if size == 4:
            hid = np.concatenate([hid, diag_hid], axis=1)
        # the distinct shapes together (one batched computation, not one per shape)
        rep_wings = wings[first]
        K_rep, res_rep = cell_matrix(P2[first], nu, rep_wings)
        K = K_rep[inv]  # (nf, n, n) / D
        residual[fids] = np.asarray(res_rep)[inv]
        # angle rows per cell: the representative's, scaled to the cell (rows ~ length)
        rows = _cell_rows(P2[first], rep_wings)[0][inv]
        rows = rows * np.sqrt(area / area[first][inv])[:, None, None]
        valid = hid >= 0
        plate_like = valid & ~crease[np.maximum(hid, 0)]
        sign, mismatch = _angle_signs(X, F, h, grad, np.where(plate_like, hid, -1), rows)
        worst = max(worst, mismatch)
        # diagonal entries: every valid hinge (creases: their plate strip)
        np.add.at(diag, hid[valid], D * np.einsum("fii->fi", K)[valid])
        n = hid.shape[1]
        ia, ib = np.triu_indices(n, 1)
        ok = plate_like[:, ia] & plate_like[:, ib]
        c = D * K[:, ia, ib] * sign[:, ia] * sign[:, ib]
        pair_i.append(hid[:, ia][ok])
        pair_j.append(hid[:, ib][ok])
        pair_c.append(c[ok])
    if worst > 1e-6:
        logger.warning(
            "coupled bending: hinge angles differ from the cells' rows by up to "
            "%.2g (relative); those cells do not pass the patch test exactly",
            worst,
        )
    k_new = np.array(model.hinge_k, float)
    k_new[bend | flat_line] = diag[bend | flat_line]
    ks, kc = diag[crease], k_new[crease]
    with np.errstate(divide="ignore", invalid="ignore"):
        k_new[crease] = np.where((ks > 0) & (kc > 0), kc * ks / (kc + ks), kc)
    pi, pj = np.concatenate(pair_i), np.concatenate(pair_j)
    lo, hi = np.minimum(pi, pj), np.maximum(pi, pj)
    keys, where = np.unique(lo * model.n_hinges + hi, return_inverse=True)
    pk = np.bincount(where.ravel(), weights=np.concatenate(pair_c), minlength=len(keys))
    pairs = np.stack([keys // model.n_hinges, keys % model.n_hinges], axis=1)
    keep = np.abs(pk) > 1e-14 * D
    logger.debug(
        "coupled bending: %d pairs, largest cell residual %.2g",
        int(keep.sum()),
        float(residual.max(initial=0.0)),
    )
    out = model.with_(hinge_k=k_new, hinge_pairs=pairs[keep], pair_k=pk[keep])
    out.meta["bending_rule"] = "coupled"
    out.meta["cell_residual"] = float(residual.max(initial=0.0))
    return out


def _angle_signs(
    X: np.ndarray, F: np.ndarray, h: np.ndarray, grad: np.ndarray, hid: np.ndarray, rows
) -> tuple[np.ndarray, float]:
    """(nf, n) sign of each model hinge angle against the cell's linearised angle row, and
    the largest relative mismatch of their magnitudes (0 where the rows use the model's own
    wing nodes)."""
    P = X[F]
    nrm = np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    e1 = P[:, 1] - P[:, 0]
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(nrm, e1)
    H = h[np.maximum(hid, 0)]  # (nf, n, 4) nodes
    R = X[H] - P[:, None, None, 0]  # (nf, n, 4, 3)
    x = np.einsum("fhpk,fk->fhp", R, e1)
    y = np.einsum("fhpk,fk->fhp", R, e2)
    coef = np.stack([x * x / 2, y * y / 2, x * y], axis=-1)  # (nf, n, 4, 3)
    g = grad[np.maximum(hid, 0)].reshape(*hid.shape, 4, 3)
    gn = np.einsum("fhpk,fk->fhp", g, nrm)  # angle per unit normal displacement of a node
    model_d = np.einsum("fhp,fhpc,tc->tfh", gn, coef, _TEST_CURVATURES)
    row_d = np.einsum("fhc,tc->tfh", rows[..., :3], _TEST_CURVATURES)
    best = np.argmax(np.abs(row_d), axis=0)  # the test curvature that moves each hinge most
    md = np.take_along_axis(model_d, best[None], 0)[0]
    rd = np.take_along_axis(row_d, best[None], 0)[0]
    ratio = np.where(hid >= 0, md / rd, 1.0)
    return np.sign(ratio), float(np.abs(np.abs(ratio) - 1.0).max(initial=0.0))
