"""Stiffness calibration of bars, bending hinges and fold hinges (the sheet's
:class:`~barhinge.model.material.Material` in, stiffnesses out).

Sources
-------
* Filipov, Liu, Tachi, Schenk & Paulino (2017), "Bar and hinge models for scalable analysis
  of origami", IJSS 124:26-45 (``F17`` below): in-plane bar areas of a rectangular W x H
  panel in N5B8 (exact for extension and Poisson coupling)::

      A_W = t (H^2 - nu W^2) / (2 H (1 - nu^2)),   A_H = t (W^2 - nu H^2) / (2 W (1 - nu^2)),
      A_X = nu t (W^2 + H^2)^(3/2) / (2 W H (1 - nu^2))

  (which we recover as the special case of the general fit below); bending hinges
  ``k_B = C_B D (D_L / t)^(1/3)`` with ``D = E t^3 / (12 (1 - nu^2))``, ``D_L`` the panel
  diagonal and ``C_B = 0.55``; fold hinges ``k_F = L_F D / L*`` with ``L*`` a crease length
  scale. (C_B = 0.55 is not confirmed by a readable source; a MERLIN-family code by an F17
  author puts 1.0 D (D_L/t)^(1/3) on each whole diagonal and 0.55 only in a fold-stiffness
  cap: docs/calibration.md, finding 5. The ``"plate"`` rule is the one checked against a
  plate model; the bar areas are re-derived and tested in closed form.)
* Energy matching: a bar of area ``A`` and length ``L`` under a homogeneous in-plane strain
  stores ``E A L (n.eps.n)^2 / 2``. For each face the bar areas are chosen so that the bars'
  3x3 (Mandel) stiffness ``sum_b A_b L_b m_b m_b^T``, ``m = (n1^2, n2^2, sqrt2 n1 n2)``,
  matches the plane-stress membrane ``t Area C / E``. Six entries, generally more or fewer
  bars: solved in the least-squares sense (minimum norm, non-negative areas). ``"filipov"``
  drops the shear-shear entry (so the rectangle reproduces F17 exactly, shear stiffness
  ``2 nu / (1 - nu)`` of the membrane's); ``"fit"`` keeps all six entries with equal weight;
  ``"dilation"`` is ``"fit"`` with the uniform-dilation energy ``eps = I`` imposed (a seventh
  row, ``C11 + C22 + 2 C12``, weighted ``DILATION_WEIGHT``: exact to ~1e-8 relative), so that
  every panel shape stores the right energy under a uniform in-plane expansion (thermal or
  swelling loads) and the rest is spread by least squares. The evidence for the default is
  the table of docs/calibration.md (``scripts/calibration_table.py``).
"""

from __future__ import annotations

import logging

import numpy as np

from barhinge._disk_cache import load_array, make_key, store_array
from barhinge.errors import ConfigError
from barhinge.model.material import Material
from barhinge.model.topology import Topology
from barhinge.model.triangulate import Triangulation
from barhinge.pattern.crease import CreasePattern

logger = logging.getLogger(__name__)

__all__ = [
    "BAR_CALIBRATIONS",
    "BEND_COEFFICIENT_F17",
    "DEFAULT_LSTAR_OVER_T",
    "bar_areas",
    "bend_stiffness",
    "bend_stiffness_kirchhoff",
    "face_areas",
    "face_frames",
    "fold_stiffness",
    "membrane_fit_matrices",
]

#: Filipov et al. (2017) bending coefficient C_B for N5B8 / N4B5 panels.
BEND_COEFFICIENT_F17 = 0.55
#: lower bound of a bar area in the fit, as a fraction of t * face area / total bar length
#: (keeps every bar load-bearing, so no in-plane mechanism appears; see docs/calibration.md)
MIN_AREA_FRACTION = 0.1
#: weight of the ridge that picks the smallest of equally good bounded bar fits, relative to
#: the weakest direction the moduli fix
BOUNDED_FIT_RIDGE = 1.0e-8
#: weight of the dilation row of the ``"dilation"`` bar calibration (relative to the six
#: moduli rows): the row's residual is ~ 1/weight^2 of the others'
DILATION_WEIGHT = 1.0e4
#: bar calibration rules (docs/calibration.md)
BAR_CALIBRATIONS = ("fit", "filipov", "dilation")
#: default crease length scale L* / t when neither fold_stiffness nor L* is given.
DEFAULT_LSTAR_OVER_T = 100.0


def fold_stiffness(
    crease_lengths: np.ndarray,
    material: Material,
    fold_stiffness: float | None = None,
    crease_length_scale: float | None = None,
) -> np.ndarray:
    """(n,) fold-hinge stiffness (moment per radian): ``L_F * k`` with ``k`` the given
    stiffness per unit length, else ``D / L*`` (F17), ``L*`` defaulting to
    ``DEFAULT_LSTAR_OVER_T * t``."""
    if fold_stiffness is not None and crease_length_scale is not None:
        raise ConfigError("give fold_stiffness or crease_length_scale, not both")
    if fold_stiffness is not None:
        if fold_stiffness < 0:
            raise ConfigError(f"fold_stiffness = {fold_stiffness}; expected >= 0")
        k = float(fold_stiffness)
    else:
        Ls = (
            DEFAULT_LSTAR_OVER_T * material.t
            if crease_length_scale is None
            else crease_length_scale
        )
        if not Ls > 0:
            raise ConfigError(f"crease_length_scale = {Ls}; expected > 0")
        k = material.bending_rigidity / Ls
    return k * np.asarray(crease_lengths, dtype=float)


def bend_stiffness(
    diagonal_lengths: np.ndarray, material: Material, coefficient: float = BEND_COEFFICIENT_F17
) -> np.ndarray:
    """(n,) bending-hinge stiffness ``C_B D (D_L / t)^(1/3)`` (F17), ``D_L`` the length of
    the panel diagonal the hinge lies on."""
    DL = np.asarray(diagonal_lengths, dtype=float)
    return coefficient * material.bending_rigidity * np.cbrt(DL / material.t)


def bend_stiffness_kirchhoff(
    face_area: np.ndarray, diagonal_lengths: np.ndarray, material: Material
) -> np.ndarray:
    """(n,) bending-hinge stiffness that reproduces the Kirchhoff twisting energy of a
    rectangular panel exactly: ``k_B = 2 D (1 - nu) A / D_L^2`` per hinge (A the face area,
    D_L its diagonal). Derivation (docs/theory-model.md): corner deflections
    ``+-delta`` rotate each of the 4 half-diagonal hinges of N5B8 (or the one diagonal
    hinge of N4B5, twice as much) so that the hinge energy is ``8 k_B delta^2 D_L^2/(W H)^2``,
    while the plate ``w = kappa x y`` with ``kappa = 4 delta / (W H)`` stores
    ``D (1 - nu) kappa^2 W H`` (Timoshenko & Woinowsky-Krieger 1959, Sec. 11)."""
    A = np.asarray(face_area, dtype=float)
    DL = np.asarray(diagonal_lengths, dtype=float)
    return 2.0 * material.bending_rigidity * (1.0 - material.nu) * A / DL**2


def face_areas(cp: CreasePattern, X: np.ndarray) -> np.ndarray:
    """(n_faces,) area of each face (Newell), in the geometry X (first nodes = vertices)."""
    out = np.zeros(cp.n_faces)
    sizes = np.array([len(f) for f in cp.faces], dtype=np.int64)
    for k in np.unique(sizes):
        sel = np.flatnonzero(sizes == k)
        P = X[np.array([cp.faces[f] for f in sel], dtype=np.int64)]  # (nf, k, 3)
        out[sel] = 0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1), axis=1)
    return out


def face_frames(X: np.ndarray, faces: tuple[tuple[int, ...], ...], fids: np.ndarray):
    """Newell normal, in-plane frame (e1, e2) and area of the faces ``fids``."""
    k = len(faces[fids[0]])
    F = np.array([faces[f] for f in fids], dtype=np.int64)
    P = X[F]  # (nf, k, 3)
    N = np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)  # 2 * area * normal
    twoA = np.linalg.norm(N, axis=1)
    n = N / twoA[:, None]
    e1 = P[:, 1 % k] - P[:, 0]
    e1 -= np.einsum("ni,ni->n", e1, n)[:, None] * n
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(n, e1)
    return e1, e2, 0.5 * twoA


def membrane_fit_matrices(
    X: np.ndarray, bars: np.ndarray, e1: np.ndarray, e2: np.ndarray
) -> np.ndarray:
    """(nf, 6, m) design matrix: column b = upper triangle (rows 11, 22, 33, 12, 13, 23;
    off-diagonals times sqrt 2) of ``L_b m_b m_b^T`` for the bars ``bars`` (nf, m, 2) of each
    face in its frame (e1, e2)."""
    d = X[bars[..., 1]] - X[bars[..., 0]]  # (nf, m, 3)
    L = np.linalg.norm(d, axis=2)
    n1 = np.einsum("nmi,ni->nm", d, e1) / L
    n2 = np.einsum("nmi,ni->nm", d, e2) / L
    m = np.stack([n1 * n1, n2 * n2, np.sqrt(2.0) * n1 * n2], axis=1)  # (nf, 3, mb)
    iu = ([0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2])
    w = np.array([1, 1, 1, np.sqrt(2), np.sqrt(2), np.sqrt(2)])
    G = m[:, iu[0], :] * m[:, iu[1], :] * L[:, None, :] * w[None, :, None]
    return G


def topo_lengths(X: np.ndarray, bars: np.ndarray) -> np.ndarray:
    """(nf,) total length of the bars (nf, m, 2) of each face."""
    return np.linalg.norm(X[bars[..., 1]] - X[bars[..., 0]], axis=-1).sum(axis=-1)


def _bounded_fits(G: np.ndarray, y: np.ndarray, a_min: np.ndarray) -> np.ndarray:
    """Least squares ``G a ~ y`` with ``a >= a_min``, bars of equal direction tied to one
    area (so a symmetric panel gets a symmetric answer).

    The problem is made dimensionless first (areas in units of ``a_min``, rows in units of
    the largest modulus), so the answer scales exactly with the panel: the same shape in
    millimetres or metres gets the same bar stiffnesses ``E A / L`` per unit thickness. Faces
    of the same shape are solved once (keyed on the rounded dimensionless problem), and each
    answer is kept between processes (:mod:`barhinge._disk_cache`, keyed on the exact
    problem), so that a second run of the same sheet does not import ``scipy.optimize``."""
    y_scale = np.abs(y).max(axis=1)
    Gn = G * (a_min / y_scale)[:, None, None]  # unknowns b = a / a_min >= 1
    yn = y / y_scale[:, None]
    key = np.round(np.concatenate([Gn.reshape(len(G), -1), yn], axis=1), 9)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    out = np.empty((len(first), G.shape[2]))
    for u, f in enumerate(first):
        entry = make_key(_BOUNDED_FIT, Gn[f], yn[f], BOUNDED_FIT_RIDGE, libraries=("scipy",))
        b = load_array(_BOUNDED_FIT, entry, (G.shape[2],))
        if b is None:
            b = _bounded_fit(Gn[f], yn[f])
            store_array(_BOUNDED_FIT, entry, b)
        out[u] = b
    return out[inv.ravel()] * a_min[:, None]


#: namespace of the bounded fits in the cache kept between processes
_BOUNDED_FIT = "bounded_bar_fit"


def _bounded_fit(Gf: np.ndarray, yf: np.ndarray) -> np.ndarray:
    """(m,) dimensionless areas ``b >= 1`` of one face: ``Gf b ~ yf`` (Gf (r, m)), bars of
    equal direction tied; of equally good area sets the smallest (a ridge of weight
    ``BOUNDED_FIT_RIDGE`` relative to the weakest direction the moduli fix), the bounded
    counterpart of the minimum-norm ``pinv`` fit used where no bound is active."""
    from scipy.optimize import lsq_linear  # lazy: its import costs more than a small fold

    cols = Gf / np.linalg.norm(Gf, axis=0)
    group = -np.ones(Gf.shape[1], dtype=np.int64)
    ng = 0
    for b in range(Gf.shape[1]):
        if group[b] >= 0:
            continue
        same = (group < 0) & (np.abs(cols - cols[:, [b]]).max(axis=0) < 1e-9)
        group[same] = ng
        ng += 1
    Gt = np.zeros((Gf.shape[0], ng))
    np.add.at(Gt.T, group, Gf.T)
    # |a|^2 = sum over groups of (bars in the group) * b_g^2: the ridge rows, weighted
    # against the weakest direction the moduli fix (so that a heavily weighted row, the
    # dilation rule's, does not let the ridge bend the fit of the others)
    sv = np.linalg.svd(Gt, compute_uv=False)
    ridge = np.sqrt(BOUNDED_FIT_RIDGE) * float(sv[sv > 1e-12 * sv[0]].min())
    R = np.diag(ridge * np.sqrt(np.bincount(group, minlength=ng)))
    A = np.vstack([Gt, R])
    rhs = np.concatenate([yf, np.zeros(ng)])
    res = lsq_linear(A, rhs, bounds=(1.0, np.inf), method="bvls")
    return np.asarray(res.x, dtype=np.float64)[group]


def _half_diagonal_ties(
    bars: np.ndarray, faces: tuple, fids: np.ndarray, n_vertices: int
) -> np.ndarray | None:
    """(nf, 2, 2) column pairs ``[[i0, i2], [i1, i3]]`` of the half-diagonal bars of each N5B8
    quad (bars (nf, m, 2) per face, the centre node ``>= n_vertices``): the half-bars to
    corners 0 and 2, and to corners 1 and 3. None unless every face is such a quad."""
    F = np.array([faces[f] for f in fids], dtype=np.int64)
    if F.shape[1] != 4:
        return None
    hub = (bars >= n_vertices).any(axis=2)  # (nf, m)
    if not (hub.sum(axis=1) == 4).all():
        return None
    corner = np.where(bars[..., 0] >= n_vertices, bars[..., 1], bars[..., 0])  # (nf, m)
    # column of the half-bar to each corner position k
    at = (corner[:, None, :] == F[:, :, None]) & hub[:, None, :]  # (nf, 4, m)
    if not (at.sum(axis=2) == 1).all():
        return None
    col = np.argmax(at, axis=2)  # (nf, 4)
    return np.stack([col[:, [0, 2]], col[:, [1, 3]]], axis=1)


def _tie_matrix(tie: np.ndarray, m: int) -> np.ndarray:
    """(nf, m, m - 2): bar areas from the tied unknowns (each half-diagonal pair one)."""
    nf = len(tie)
    T = np.zeros((nf, m, m))
    T[:, np.arange(m), np.arange(m)] = 1.0
    rows = np.arange(nf)
    for p in range(2):
        T[rows, tie[:, p, 1], tie[:, p, 0]] = 1.0  # the second half follows the first
    drop = np.sort(tie[:, :, 1], axis=1)  # columns of the followers: removed
    keep = np.ones((nf, m), dtype=bool)
    keep[rows[:, None], drop] = False
    return T.transpose(0, 2, 1)[keep].reshape(nf, m - 2, m).transpose(0, 2, 1)


def bar_areas(
    cp: CreasePattern,
    tri: Triangulation,
    topo: Topology,
    material: Material,
    method: str = "fit",
) -> np.ndarray:
    """(n_bars,) cross-section areas by face-wise membrane energy matching (module doc).

    ``method``: ``"fit"`` (all six entries), ``"filipov"`` (shear-shear entry dropped,
    F17's closed form for rectangles) or ``"dilation"`` (``"fit"`` with the dilation energy
    imposed). A bar shared by two faces sums both contributions.
    """
    if method not in BAR_CALIBRATIONS:
        raise ConfigError(
            f"bar calibration {method!r} is unknown; expected one of {BAR_CALIBRATIONS}"
        )
    X = tri.X0
    pairs = topo.bar_face_pairs  # (bar, face) sorted by bar then face
    order = np.lexsort((pairs[:, 0], pairs[:, 1]))
    bf = pairs[order]
    faces = cp.faces
    per_face = np.bincount(bf[:, 1], minlength=cp.n_faces)
    start = np.concatenate([[0], np.cumsum(per_face)])
    C = material.membrane_mandel() * material.t / material.E
    iu = ([0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2])
    wy = np.array([1, 1, 1, np.sqrt(2), np.sqrt(2), np.sqrt(2)])
    y_unit = C[iu] * wy  # per unit area
    row_w = np.ones(6)
    if method == "filipov":
        row_w[2] = 0.0
    area = np.zeros(len(topo.bars))
    # group faces by (number of corners, number of bars): same shape of the problem
    ncorner = np.array([len(f) for f in faces], dtype=np.int64)
    groups = ncorner * 1000 + per_face
    for g in np.unique(groups):
        fids = np.flatnonzero(groups == g)
        m = int(per_face[fids[0]])
        idx = start[fids][:, None] + np.arange(m)[None, :]
        bar_ids = bf[idx, 0]  # (nf, m)
        e1, e2, A = face_frames(X, faces, fids)
        G = membrane_fit_matrices(X, topo.bars[bar_ids], e1, e2) * row_w[None, :, None]
        y = (A[:, None] * y_unit[None, :]) * row_w[None, :]
        if method == "dilation":
            # eps = I: energy row C11 + C22 + 2 C12 (row 3 holds sqrt2 C12)
            dil = np.array([1.0, 1.0, 0.0, np.sqrt(2.0), 0.0, 0.0]) * DILATION_WEIGHT
            G = np.concatenate([G, np.einsum("r,nrm->nm", dil, G)[:, None, :]], axis=1)
            y = np.concatenate([y, (y @ dil)[:, None]], axis=1)
        sol = np.einsum("nmr,nr->nm", np.linalg.pinv(G), y)
        a_min = MIN_AREA_FRACTION * material.t * A / topo_lengths(X, topo.bars[bar_ids])
        tie = _half_diagonal_ties(topo.bars[bar_ids], faces, fids, len(cp.vertices))
        bad = np.flatnonzero((sol < a_min[:, None]).any(axis=1))
        if len(bad):
            sol[bad] = _bounded_fits(G[bad], y[bad], a_min[bad])
        if tie is not None:
            # a diagonal's two half-bars get one area, so that the centre node is in
            # equilibrium under every uniform strain (triangulate.quad_centres); the fit
            # already gives it (to round-off) where the panel is point-symmetric
            pair = np.take_along_axis(sol, tie[:, :, 0], 1) - np.take_along_axis(
                sol, tie[:, :, 1], 1
            )
            uneq = np.flatnonzero(np.abs(pair).max(axis=1) > 1e-9 * np.abs(sol).max(axis=1))
            if len(uneq):
                T = _tie_matrix(tie[uneq], m)
                Gt = np.einsum("nrm,nmk->nrk", G[uneq], T)
                st = np.einsum("nkr,nr->nk", np.linalg.pinv(Gt), y[uneq])
                low = np.flatnonzero(
                    (np.einsum("nmk,nk->nm", T, st) < a_min[uneq, None]).any(axis=1)
                )
                if len(low):
                    st[low] = _bounded_fits(Gt[low], y[uneq][low], a_min[uneq][low])
                sol[uneq] = np.einsum("nmk,nk->nm", T, st)
        np.add.at(area, bar_ids.ravel(), np.maximum(sol, 0.0).ravel())
    return area
