"""Gaussian curvature of a folded sheet: its global form and its per-vertex angle defect.

Two different curvatures are measured:

* **Global form** (what an architect sees): a coarse surface through reference points (by
  default one per facet: the facet centroids, which lie on the mid-surface of a corrugated
  sheet such as the Miura-ori), fitted by local quadratic height functions over a tangent
  plane around each point, and by one global quadratic. Gives principal curvatures ``k1 >= k2``,
  Gaussian curvature ``K = k1 k2`` and mean curvature ``H = (k1 + k2) / 2``.
* **Angle defect** (intrinsic, per vertex of the triangulated sheet): ``2 pi`` minus the sum of
  the corner angles around an interior vertex (Descartes; discrete Gauss-Bonnet). It is zero
  for any rigid (isometric) folding, so it measures panel straining. Divided by the mixed
  Voronoi area of Meyer, Desbrun, Schroeder & Barr (2003, "Discrete differential-geometry
  operators for triangulated 2-manifolds", Sec. 3.3 and Fig. 4) it gives a curvature density.

Sign convention
---------------
The normal of every fitted surface is oriented with a non-negative z component (``+z`` up).
A principal curvature is positive where the surface bends towards that normal: a bowl
``z = (x^2 + y^2) / (2R)`` has ``k1 = k2 = H = 1/R > 0`` and a dome ``H < 0``; ``K > 0`` for
both (synclastic), ``K < 0`` for a saddle (anticlastic), ``K = 0`` for a cylinder or a plane.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from barhinge.errors import ConfigError

__all__ = [
    "Curvature",
    "QuadraticFit",
    "angle_defect",
    "boundary_nodes",
    "corner_angles",
    "fit_quadratic",
    "gaussian_curvature",
    "local_curvatures",
    "mixed_voronoi_area",
    "pattern_triangles",
    "reference_points",
    "triangles_of_hinges",
]


# --------------------------------------------------------------------- quadratic fits
@dataclasses.dataclass(frozen=True)
class QuadraticFit:
    """Curvature of a quadratic height function fitted around a point.

    Attributes
    ----------
    center : (3,) float
        Point of the fitted surface where the curvature is evaluated.
    normal : (3,) float
        Unit normal there (``normal[2] >= 0``).
    k1, k2 : float
        Principal curvatures, ``k1 >= k2``, 1/length (sign convention: module docstring).
    K, H : float
        Gaussian curvature ``k1 k2`` (1/length^2) and mean curvature ``(k1 + k2)/2``.
    directions : (2, 3) float
        Principal directions (unit, tangent to the surface) of ``k1`` and ``k2``.
    rms : float
        Root-mean-square residual of the fit (length).
    """

    center: np.ndarray
    normal: np.ndarray
    k1: float
    k2: float
    K: float
    H: float
    directions: np.ndarray
    rms: float


def _frame(P: np.ndarray, up: np.ndarray | None = None) -> np.ndarray:
    """(3, 3) orthonormal rows (e1, e2, n): best-fit plane of the points P (m, 3) by PCA,
    n oriented along ``up`` (default +z)."""
    Q = P - P.mean(0)
    _, _, Vt = np.linalg.svd(Q, full_matrices=False)
    n = Vt[-1] if len(Vt) == 3 else np.cross(Vt[0], Vt[1])
    up = np.array([0.0, 0.0, 1.0]) if up is None else up
    if n @ up < 0:
        n = -n
    e1 = Vt[0] - (Vt[0] @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return np.vstack([e1, e2, n])


def fit_quadratic(
    P: np.ndarray, center: np.ndarray | None = None, *, up: np.ndarray | None = None
) -> QuadraticFit:
    """Fit ``w = f + d u + e v + a u^2 + b u v + c v^2`` over a plane and evaluate the
    curvature of that height function at ``center``.

    Parameters
    ----------
    P : (m, 3) float, m >= 6
        Points of the surface (not all on a line).
    center : (3,) float, optional
        Point whose projection is the evaluation point; the centroid of P by default.
    up : (3,) float, optional
        Direction the normal is oriented towards (+z by default).

    Notes
    -----
    Monge patch ``w(u, v)`` (do Carmo 1976, Sec. 3-3, Ex. 5): with ``g = 1 + w_u^2 + w_v^2``,
    ``K = (w_uu w_vv - w_uv^2) / g^2`` and the shape operator is ``I^-1 II`` with
    ``I = [[1 + w_u^2, w_u w_v], [w_u w_v, 1 + w_v^2]]``, ``II = [[w_uu, w_uv], [w_uv, w_vv]] /
    sqrt(g)``; its eigenvalues are the principal curvatures.
    """
    P = np.asarray(P, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3 or len(P) < 6:
        raise ConfigError(f"a quadratic fit needs at least 6 points of shape (m, 3), got {P.shape}")
    c0 = P.mean(0) if center is None else np.asarray(center, dtype=float)
    R = _frame(P, up)
    L = (P - c0) @ R.T  # local (u, v, w)
    scale = max(float(np.sqrt((L[:, :2] ** 2).sum(1).max())), 1e-300)
    u, v, w = L[:, 0] / scale, L[:, 1] / scale, L[:, 2]
    A = np.column_stack([np.ones_like(u), u, v, u * u, u * v, v * v])
    coef, *_ = np.linalg.lstsq(A, w, rcond=None)
    rms = float(np.sqrt(np.mean((A @ coef - w) ** 2)))
    f, d, e, a, b, c = coef
    wu, wv = d / scale, e / scale
    wuu, wuv, wvv = 2 * a / scale**2, b / scale**2, 2 * c / scale**2
    g = 1.0 + wu * wu + wv * wv
    first = np.array([[1 + wu * wu, wu * wv], [wu * wv, 1 + wv * wv]])
    second = np.array([[wuu, wuv], [wuv, wvv]]) / np.sqrt(g)
    # principal curvatures: generalised symmetric eigenproblem II x = k I x
    Lc = np.linalg.cholesky(first)
    Li = np.linalg.inv(Lc)
    kv, yv = np.linalg.eigh(Li @ second @ Li.T)
    xv = Li.T @ yv  # coefficient vectors in the (u, v) parameter basis
    order = np.argsort(kv)[::-1]
    kv, xv = kv[order], xv[:, order]
    # tangent vectors of the patch: X_u = e1 + w_u n, X_v = e2 + w_v n
    Xu, Xv = R[0] + wu * R[2], R[1] + wv * R[2]
    dirs = np.outer(xv[0], Xu) + np.outer(xv[1], Xv)
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    normal = np.cross(Xu, Xv)
    normal /= np.linalg.norm(normal)
    point = c0 + f * R[2]
    k1, k2 = float(kv[0]), float(kv[1])
    return QuadraticFit(
        center=point,
        normal=normal,
        k1=k1,
        k2=k2,
        K=k1 * k2,
        H=0.5 * (k1 + k2),
        directions=dirs,
        rms=rms,
    )


def local_curvatures(
    points: np.ndarray, *, radius: float | None = None, min_neighbours: int = 9
) -> dict[str, np.ndarray]:
    """Principal curvatures at every point from a quadratic fit over its neighbourhood.

    Parameters
    ----------
    points : (m, 3) float
        Samples of a surface (m >= 6).
    radius : float, optional
        Neighbourhood radius; default 2.5 times the median nearest-neighbour distance.
    min_neighbours : int
        Points with fewer neighbours inside ``radius`` use their ``min_neighbours`` nearest.

    Returns
    -------
    dict with ``k1, k2, K, H`` (m,) float and ``normals`` (m, 3), ``radius`` float.
    """
    P = np.asarray(points, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3:
        raise ConfigError(f"points must have shape (m, 3), got {P.shape}")
    m = len(P)
    if m < 6:
        raise ConfigError(f"curvature needs at least 6 reference points, got {m}")
    from scipy.spatial import cKDTree  # lazy: scipy.spatial costs ~0.25 s to import

    tree = cKDTree(P)
    if radius is None:
        dist, _ = tree.query(P, k=2)
        radius = 2.5 * float(np.median(dist[:, 1]))
    kmin = min(max(min_neighbours, 6), m)
    _, knn = tree.query(P, k=kmin)
    out = {k: np.full(m, np.nan) for k in ("k1", "k2", "K", "H")}
    normals = np.full((m, 3), np.nan)
    for i, nb in enumerate(tree.query_ball_point(P, r=radius)):
        idx = nb if len(nb) >= kmin else knn[i]
        fit = fit_quadratic(P[idx], P[i])
        out["k1"][i], out["k2"][i], out["K"][i], out["H"][i] = fit.k1, fit.k2, fit.K, fit.H
        normals[i] = fit.normal
    return {**out, "normals": normals, "radius": np.float64(radius)}


# -------------------------------------------------------------------- angle defect
def corner_angles(X: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(n_tri, 3) float radians: interior angle of each triangle at each of its corners."""
    P = X[triangles]  # (t, 3 corners, 3 xyz)
    a = P[:, _NEXT] - P
    b = P[:, _PREV] - P
    dot = np.einsum("tcx,tcx->tc", a, b)
    # |a x b| is twice the triangle's area at every corner
    twice_area = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    return np.arctan2(np.broadcast_to(twice_area[:, None], dot.shape), dot)


#: the next and the previous corner of each corner of a triangle
_NEXT, _PREV = np.array([1, 2, 0]), np.array([2, 0, 1])


def mixed_voronoi_area(
    X: np.ndarray, triangles: np.ndarray, angles: np.ndarray | None = None
) -> np.ndarray:
    """(n_nodes,) float: mixed Voronoi area of every node (Meyer et al. 2003, Fig. 4).

    Non-obtuse triangle: Voronoi region ``(|PR|^2 cot Q + |PQ|^2 cot R) / 8`` for corner P;
    obtuse triangle: half its area to the obtuse corner, a quarter to each other corner. The
    areas of all nodes sum to the area of the mesh. ``angles``: the triangles'
    :func:`corner_angles` at ``X``, where the caller has them.
    """
    X = np.asarray(X, float)
    T = np.asarray(triangles, np.int64)
    ang = corner_angles(X, T) if angles is None else angles
    P = X[T]
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    # squared length of the side opposite each corner c: between corners c+1 and c+2
    opp = P[:, _NEXT] - P[:, _PREV]
    l2 = np.einsum("tcx,tcx->tc", opp, opp)
    cot = 1.0 / np.tan(np.clip(ang, 1e-12, np.pi - 1e-12))
    # corner c: sides to c+1 and c+2 are opposite c+2 and c+1 respectively
    lc = l2 * cot
    vor = (lc[:, _NEXT] + lc[:, _PREV]) / 8.0
    obtuse = ang > 0.5 * np.pi
    any_obtuse = obtuse.any(axis=1, keepdims=True)
    A = np.where(any_obtuse, np.where(obtuse, 0.5, 0.25) * area[:, None], vor)
    return np.bincount(T.ravel(), weights=A.ravel(), minlength=len(X))


def boundary_nodes(triangles: np.ndarray, n_nodes: int) -> np.ndarray:
    """(n_nodes,) bool: nodes on an edge used by exactly one triangle."""
    T = np.asarray(triangles, np.int64)
    a = T.ravel()
    b = np.roll(T, -1, axis=1).ravel()
    key = np.minimum(a, b) * max(n_nodes, 1) + np.maximum(a, b)
    uniq, count = np.unique(key, return_counts=True)
    once = uniq[count == 1]
    flag = np.zeros(n_nodes, bool)
    flag[once // max(n_nodes, 1)] = True
    flag[once % max(n_nodes, 1)] = True
    return flag


def angle_defect(
    X: np.ndarray,
    triangles: np.ndarray,
    angles: np.ndarray | None = None,
    boundary: np.ndarray | None = None,
) -> np.ndarray:
    """(n_nodes,) float radians: ``2 pi - sum of corner angles`` at interior nodes.

    NaN at boundary nodes and at nodes used by no triangle. For a closed triangulated surface
    of genus 0 the defects sum to ``4 pi`` (Descartes' theorem, discrete Gauss-Bonnet).
    ``angles`` (the triangles' :func:`corner_angles` at ``X``) and ``boundary`` (their
    :func:`boundary_nodes`, which no state changes) are computed when not given.
    """
    X = np.asarray(X, float)
    T = np.asarray(triangles, np.int64)
    n = len(X)
    ang = corner_angles(X, T) if angles is None else angles
    total = np.bincount(T.ravel(), weights=ang.ravel(), minlength=n)
    d = 2 * np.pi - total
    used = np.bincount(T.ravel(), minlength=n) > 0
    d[~used | (boundary_nodes(T, n) if boundary is None else boundary)] = np.nan
    return d


def triangles_of_hinges(hinges: np.ndarray) -> np.ndarray:
    """(n_tri, 3) int: the triangles (i, j, k) and (j, i, l) of a bar-and-hinge model's
    hinges ``(i, j, k, l)``, each once (every triangle of a connected triangulated sheet
    with more than one triangle shares an edge with a hinge)."""
    H = np.asarray(hinges, np.int64)
    T = np.concatenate([H[:, [0, 1, 2]], H[:, [1, 0, 3]]])
    _, first = np.unique(np.sort(T, axis=1), axis=0, return_index=True)
    return T[np.sort(first)]


def pattern_triangles(cp: Any) -> np.ndarray:
    """(n_tri, 3) int: fan triangulation ``(f0, fi, fi+1)`` of a crease pattern's faces."""
    ids, off = cp.face_loops
    ntri = np.diff(off) - 2  # a face of k vertices gives k - 2 triangles
    face = np.repeat(np.arange(len(ntri)), ntri)
    i = np.arange(int(ntri.sum())) - np.repeat(np.cumsum(ntri) - ntri, ntri) + 1
    first = off[:-1][face]
    return np.column_stack([ids[first], ids[first + i], ids[first + i + 1]]).astype(np.int64)


# ------------------------------------------------------------------------- entry point
@dataclasses.dataclass(frozen=True)
class Curvature:
    """Curvature of one state of a folded sheet (sign convention: module docstring).

    Attributes
    ----------
    points : (m, 3) float
        Reference points of the global form (facet centroids by default).
    k1, k2, K, H : (m,) float
        Principal (``k1 >= k2``), Gaussian and mean curvature at each reference point from a
        local quadratic fit over its neighbourhood (a region of radius ``radius``).
    normals : (m, 3) float
        Unit normals of the local fits (z >= 0).
    radius : float
        Neighbourhood radius of the local fits.
    global_fit : QuadraticFit
        One quadratic through all reference points, evaluated at their centroid.
    angle_defect : (n_nodes,) float or None
        Per node, radians (NaN at boundary nodes); None without a triangulation.
    vertex_area : (n_nodes,) float or None
        Mixed Voronoi area per node (Meyer et al. 2003).
    """

    points: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    K: np.ndarray
    H: np.ndarray
    normals: np.ndarray
    radius: float
    global_fit: QuadraticFit
    angle_defect: np.ndarray | None = None
    vertex_area: np.ndarray | None = None

    @property
    def K_global(self) -> float:
        """Gaussian curvature of the global quadratic fit (1/length^2)."""
        return self.global_fit.K

    @property
    def H_global(self) -> float:
        """Mean curvature of the global quadratic fit (1/length)."""
        return self.global_fit.H

    @property
    def defect_density(self) -> np.ndarray | None:
        """(n_nodes,) float: angle defect / mixed Voronoi area (1/length^2), NaN at the
        boundary."""
        if self.angle_defect is None or self.vertex_area is None:
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.angle_defect / self.vertex_area

    @property
    def max_abs_defect(self) -> float:
        """Largest |angle defect| over interior nodes (radians; 0 without a triangulation)."""
        if self.angle_defect is None or not np.isfinite(self.angle_defect).any():
            return 0.0
        return float(np.nanmax(np.abs(self.angle_defect)))


def reference_points(X: np.ndarray, cp: Any | None) -> np.ndarray:
    """(m, 3) float: facet centroids (vertex means of each face of ``cp``, taken from the
    first ``cp.n_vertices`` rows of X), or all of X without a pattern."""
    if cp is None:
        return np.asarray(X, float)
    V = np.asarray(X, float)[: cp.n_vertices]
    ids, off = cp.face_loops
    if not len(ids):
        return np.zeros((0, 3))
    return np.add.reduceat(V[ids], off[:-1], axis=0) / np.diff(off)[:, None]


def gaussian_curvature(
    path_or_X: Any,
    step: int = -1,
    *,
    points: np.ndarray | None = None,
    pattern: Any | None = None,
    model: Any | None = None,
    triangles: np.ndarray | None = None,
    radius: float | None = None,
    local: bool = True,
) -> Curvature:
    """Curvature of the global form and angle defects of one state.

    Parameters
    ----------
    path_or_X : FoldPath or (n_nodes, 3) float
        A fold path (state ``step`` is used) or node coordinates.
    step : int
        State index of a path (default: the last).
    points : (m,) int or (m, 3) float, optional
        Reference points of the global form: node indices (a chosen vertex layer) or
        coordinates. Default: facet centroids of ``pattern`` (or ``model.pattern``), else all
        nodes.
    pattern : CreasePattern, optional
        Gives the facets (reference points, and a fan triangulation for the angle defect).
    model : BarHingeModel, optional
        Gives the pattern and the triangulation of the model (triangles of its hinges).
    triangles : (t, 3) int, optional
        Triangulation of the nodes for the angle defect (overrides the above).
    radius : float, optional
        Neighbourhood radius of the local fits (default 2.5 x median spacing).
    local : bool
        Also fit the local quadratics (``k1``, ``k2``, ``K``, ``H``, ``normals``); False
        leaves them empty (``radius`` NaN) when only the global form is wanted.
    """
    from barhinge.results import FoldPath

    if isinstance(path_or_X, FoldPath):
        n = path_or_X.n_states
        if not -n <= step < n:
            raise ConfigError(f"step {step} is outside the path's {n} states")
        X = path_or_X.X[step]
    else:
        X = np.asarray(path_or_X, dtype=float)
        if X.ndim == 3:
            X = X[step]
        if X.ndim != 2 or X.shape[1] != 3:
            raise ConfigError(f"X must have shape (n_nodes, 3), got {X.shape}")
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    if triangles is None:
        if model is not None:
            triangles = triangles_of_hinges(model.hinges)
        elif cp is not None:
            triangles = pattern_triangles(cp)
    if points is None:
        P = reference_points(X, cp)
    else:
        pts = np.asarray(points)
        P = X[pts.astype(np.int64)] if pts.ndim == 1 else pts.astype(float)
    if local:
        fits = local_curvatures(P, radius=radius)
    else:
        empty = np.zeros(0)
        fits = {"k1": empty, "k2": empty, "K": empty, "H": empty,
                "normals": np.zeros((0, 3)), "radius": np.nan}  # fmt: skip
    glob = fit_quadratic(P)
    defect = area = None
    if triangles is not None:
        T = np.asarray(triangles, np.int64)
        if T.size and T.max() >= len(X):
            raise ConfigError(f"triangles reference node {T.max()}, but X has {len(X)} nodes")
        ang = corner_angles(X, T)
        defect = angle_defect(X, T, angles=ang)
        area = mixed_voronoi_area(X, T, angles=ang)
    return Curvature(
        points=P,
        k1=fits["k1"],
        k2=fits["k2"],
        K=fits["K"],
        H=fits["H"],
        normals=fits["normals"],
        radius=float(fits["radius"]),
        global_fit=glob,
        angle_defect=defect,
        vertex_area=area,
    )
