"""Continuum reference for the calibration of a single panel (scikit-fem).

* Plane-stress membrane (vector P1 or P2 Lagrange elements), thickness ``t``.
* Kirchhoff plate (Morley element), bending rigidity ``D = E t^3 / (12 (1 - nu^2))``.

Load cases, chosen so that the bar-and-hinge panel and the continuum see the same
kinematics:

* :func:`membrane_energy` -- displacements prescribed on the whole boundary, linear along each
  edge between the corner values (a bar-and-hinge panel's edges are bars, they stay
  straight); a homogeneous strain then gives the affine field (closed form), a non-affine
  corner motion gives a genuinely two-dimensional field;
* :func:`membrane_edge_load` -- a rectangle clamped along one edge, the opposite edge moved
  rigidly (stretch or shear), the two other edges free;
* :func:`plate_corner_energy` -- out-of-plane deflections prescribed at the corners only,
  edges free (the panel's twisting / warping mode). For a rectangle and ``w = kappa x y`` this
  is exact Kirchhoff theory: ``U = D (1 - nu) kappa^2 W H`` (Timoshenko & Woinowsky-Krieger
  1959, Sec. 11, pure twist with corner forces ``2 D (1 - nu) kappa``);
* :func:`panel_energy` -- the linear bar-and-hinge energy of a model with prescribed node
  displacements (the rest condensed out), for the same comparisons.

Meshes are small (a few hundred elements) so the tests stay fast. Whole-panel comparisons
(:func:`~barhinge.model.compare.panel_errors`) build models and live in
:mod:`barhinge.model.compare`, above the model.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.errors import ConfigError
from barhinge.model.material import Material
from barhinge.pattern.subdivide import corner_graded

__all__ = [
    "polygon_mesh",
    "graded_points",
    "morley_plate_matrix",
    "membrane_energy",
    "membrane_edge_load",
    "plate_corner_energy",
    "panel_energy",
    "homogeneous_energy",
    "strain_modes",
    "plate_corner_stiffness",
    "panel_corner_stiffness",
]


def polygon_mesh(P: np.ndarray, refine: int = 3, grading: float = 1.0):
    """skfem ``MeshTri`` of the simple polygon ``P`` (k, 2): a fan from the centroid if the
    polygon is star-shaped from it (every convex polygon), else an ear-clipping
    triangulation of the corners; refined ``refine`` times. The corners are mesh vertices
    ``0..k-1``. A polygon that is neither (self-intersecting, zero area) is a ConfigError.

    ``grading`` > 1 concentrates the nodes at the polygon's corners (:func:`graded_points`):
    along every edge the node at fraction ``s`` moves to ``s^p / (s^p + (1 - s)^p)``, so
    the elements next to a corner are ``h^p`` long instead of ``h`` (a radical mesh of
    exponent ``p``, the classical remedy for corner singularities; Babuska, Kellogg &
    Pitkaranta 1979, Numer. Math. 33, 447-471). The edge nodes depend on the edge alone, so
    neighbouring polygons meshed with the same ``refine`` and ``grading`` still share them."""
    from skfem import MeshTri

    if not grading >= 1.0:
        raise ConfigError(f"grading = {grading!r}; expected a number >= 1 (1: uniform)")
    P = np.asarray(P, dtype=float)
    k = len(P)
    c = P.mean(axis=0)
    area = _signed_area(P)
    if not abs(area) > 0.0:
        raise ConfigError(f"polygon with {k} corners has zero area")
    sign = 1.0 if area > 0 else -1.0
    nxt = np.roll(P, -1, axis=0)
    fan = sign * _cross(nxt - P, c - P)
    if np.all(fan > 1e-9 * abs(area)):
        pts = np.vstack([P, c])
        tri = np.array([[i, (i + 1) % k, k] for i in range(k)]).T
    else:
        pts = P
        tri = _ear_clip(P, sign).T
    mesh = MeshTri(pts.T, tri).refined(refine)
    if grading == 1.0:
        return mesh
    return MeshTri(graded_points(mesh.p.T, pts, tri.T, k, grading).T, mesh.t)


def graded_points(
    p: np.ndarray, corners: np.ndarray, coarse: np.ndarray, k: int, grading: float
) -> np.ndarray:
    """Points ``p`` (n, 2) of a refinement of the coarse triangles ``coarse`` (m, 3) of
    ``corners`` (the first ``k`` are the polygon's corners, a further one its fan centre)
    moved towards the corners. In each coarse triangle the barycentric coordinate ``l`` of
    every polygon corner becomes ``g(l) = l^p / (l^p + (1 - l)^p)`` and the fan centre's
    takes the rest (``g(l) + g(1 - l) = 1`` keeps points on the triangle's edges on them);
    a triangle of three corners renormalises its three. The coarse vertices, the first
    points of ``p``, stay exactly where they are."""
    out = p.copy()
    done = np.zeros(len(p), bool)
    scale = float(np.ptp(corners, axis=0).max())
    for tri in coarse:
        A = corners[tri]
        T = np.column_stack([A[0] - A[2], A[1] - A[2]])
        lam = np.linalg.solve(T, (p - A[2]).T).T
        L = np.column_stack([lam, 1.0 - lam.sum(axis=1)])
        inside = (L > -1e-9 * scale).all(axis=1) & ~done
        Lin = np.clip(L[inside], 0.0, 1.0)
        G = corner_graded(Lin, grading)
        is_corner = tri < k
        if is_corner.all():
            G /= G.sum(axis=1, keepdims=True)
        else:
            G[:, ~is_corner] = 0.0
            G[:, ~is_corner] = (1.0 - G.sum(axis=1))[:, None]
        out[inside] = G @ A
        done |= inside
    if not done.all():
        raise AssertionError("a refined point lies outside every coarse triangle")
    out[: len(corners)] = corners  # the coarse vertices come first in a refined skfem mesh
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z component of the cross product of 2-vectors (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _signed_area(P: np.ndarray) -> float:
    """Shoelace area of the polygon ``P`` (k, 2), positive counter-clockwise."""
    return 0.5 * float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))


def _ear_clip(P: np.ndarray, sign: float) -> np.ndarray:
    """(k - 2, 3) corner triangles of the simple polygon ``P`` (orientation ``sign``) by ear
    clipping: a convex corner whose triangle holds no other corner is cut off, repeatedly."""
    left = list(range(len(P)))
    tris: list[list[int]] = []
    tol = 1e-12 * abs(_signed_area(P))
    while len(left) > 3:
        for j in range(len(left)):
            a, b, c = left[j - 1], left[j], left[(j + 1) % len(left)]
            if sign * _cross(P[b] - P[a], P[c] - P[a]) <= tol:
                continue  # reflex or flat corner
            others = [v for v in left if v not in (a, b, c)]
            if any(_inside(P[v], P[a], P[b], P[c], sign) for v in others):
                continue
            tris.append([a, b, c])
            left.pop(j)
            break
        else:
            raise ConfigError(
                f"polygon with {len(P)} corners cannot be triangulated: it is not simple "
                "(self-intersecting or with zero-area parts)"
            )
    tris.append(left)
    T = np.array(tris, dtype=np.int64)
    covered = 0.5 * np.abs(_cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]])).sum()
    if not np.isclose(covered, abs(_signed_area(P)), rtol=1e-9):
        raise ConfigError(
            f"polygon with {len(P)} corners cannot be triangulated: it is not simple "
            "(self-intersecting)"
        )
    return T


def _inside(x: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray, sign: float) -> bool:
    """Whether the point ``x`` lies in the closed triangle ``a b c`` of orientation ``sign``."""
    return all(sign * _cross(q - p, x - p) >= 0.0 for p, q in ((a, b), (b, c), (c, a)))


def _edge_interp(P: np.ndarray, vals: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Values (n, m) at boundary points x (2, n), linear along each polygon edge between the
    corner values ``vals`` (k, m)."""
    k = len(P)
    best = np.full(x.shape[1], np.inf)
    out = np.zeros((x.shape[1], vals.shape[1]))
    for e in range(k):
        a, b = P[e], P[(e + 1) % k]
        d = b - a
        s = np.clip(((x.T - a) @ d) / (d @ d), 0.0, 1.0)
        dist = np.linalg.norm(x.T - (a + s[:, None] * d), axis=1)
        take = dist < best
        best[take] = dist[take]
        out[take] = (1 - s[take, None]) * vals[e] + s[take, None] * vals[(e + 1) % k]
    return out


def _membrane_stiffness(mesh, material: Material, order: int):
    from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector, asm
    from skfem.models.elasticity import linear_elasticity

    if order not in (1, 2):
        raise ConfigError(f"membrane order = {order}; expected 1 or 2")
    el = ElementVector(ElementTriP1() if order == 1 else ElementTriP2())
    basis = Basis(mesh, el)
    E, nu, t = material.E, material.nu, material.t
    mu = E / (2 * (1 + nu))
    lam_ps = E * nu / (1 - nu * nu)  # plane-stress Lame parameter
    K = t * asm(linear_elasticity(lam_ps, mu), basis)
    return basis, K


def _solve_prescribed(K: sp.spmatrix, D: np.ndarray, xD: np.ndarray) -> float:
    """Energy 1/2 u^T K u with u[D] = xD and the other dofs free (minimising)."""
    n = K.shape[0]
    free = np.setdiff1d(np.arange(n), D)
    K = sp.csr_matrix(K)
    u = np.zeros(n)
    u[D] = xD
    if len(free):
        rhs = -(K[free][:, D] @ xD)
        u[free] = spla.spsolve(sp.csc_matrix(K[free][:, free]), rhs)
    return 0.5 * float(u @ (K @ u))


def membrane_energy(
    P: np.ndarray,
    material: Material,
    corner_disp: np.ndarray,
    order: int = 2,
    refine: int = 3,
) -> float:
    """Plane-stress energy of the polygon ``P`` (k, 2) with the boundary displacement linear
    along each edge between the corner displacements ``corner_disp`` (k, 2)."""
    mesh = polygon_mesh(P, refine)
    basis, K = _membrane_stiffness(mesh, material, order)
    ix, iy = basis.split_indices()
    bnd = basis.get_dofs().all()
    bx = np.intersect1d(bnd, ix)
    by = np.intersect1d(bnd, iy)
    vals = np.asarray(corner_disp, dtype=float)
    ux = _edge_interp(np.asarray(P, float), vals, basis.doflocs[:, bx])[:, 0]
    uy = _edge_interp(np.asarray(P, float), vals, basis.doflocs[:, by])[:, 1]
    D = np.concatenate([bx, by])
    return _solve_prescribed(K, D, np.concatenate([ux, uy]))


def membrane_edge_load(
    W: float, H: float, material: Material, mode: str, order: int = 2, refine: int = 3
) -> float:
    """Force (per unit imposed displacement) of a W x H rectangle clamped along ``x = 0``
    (``mode="stretch"``, the edge ``x = W`` moved by (1, 0)) or along ``y = 0``
    (``mode="shear"``, the edge ``y = H`` moved by (1, 0)); the other two edges free.
    Equal to ``2 U`` for the unit displacement."""
    from skfem import MeshTri

    nx = max(2, int(round(4 * max(W / H, 1.0))))
    ny = max(2, int(round(4 * max(H / W, 1.0))))
    mesh = MeshTri.init_tensor(np.linspace(0, W, nx + 1), np.linspace(0, H, ny + 1)).refined(
        max(refine - 2, 0)
    )
    basis, K = _membrane_stiffness(mesh, material, order)
    ix, iy = basis.split_indices()
    x = basis.doflocs
    tol = 1e-12 * max(W, H)
    if mode == "stretch":
        fixed = np.abs(x[0]) < tol
        moved = np.abs(x[0] - W) < tol
    elif mode == "shear":
        fixed = np.abs(x[1]) < tol
        moved = np.abs(x[1] - H) < tol
    else:
        raise ConfigError(f"mode {mode!r} is unknown; expected 'stretch' or 'shear'")
    Dx = np.concatenate([ix[fixed[ix]], ix[moved[ix]]])
    Dy = np.concatenate([iy[fixed[iy]], iy[moved[iy]]])
    ux = np.concatenate([np.zeros(fixed[ix].sum()), np.ones(moved[ix].sum())])
    uy = np.zeros(len(Dy))
    return 2.0 * _solve_prescribed(K, np.concatenate([Dx, Dy]), np.concatenate([ux, uy]))


def morley_plate_matrix(mesh: Any, material: Material) -> tuple[Any, Any]:
    """Kirchhoff-plate stiffness on Morley's constant-moment triangle over a triangle mesh.

    Parameters
    ----------
    mesh : skfem.MeshTri
        For a polygon: :func:`polygon_mesh` (its first nodes are the polygon's corners).
    material : Material

    Returns
    -------
    K : scipy.sparse matrix
        Stiffness of the deflection dofs, bending rigidity ``D = E t^3 / (12 (1 - nu^2))`` of
        ``material`` (energy in the user's units).
    basis : skfem.Basis
        Its basis; for a :func:`polygon_mesh`, ``basis.nodal_dofs[0, :k]`` are the deflections
        of the k corners.
    """
    from skfem import Basis, BilinearForm, ElementTriMorley, asm
    from skfem.helpers import dd, ddot, trace

    basis = Basis(mesh, ElementTriMorley())
    Dp, nu = material.bending_rigidity, material.nu

    @BilinearForm
    def plate(u, v, w):
        return Dp * ((1.0 - nu) * ddot(dd(u), dd(v)) + nu * trace(dd(u)) * trace(dd(v)))

    return asm(plate, basis), basis


def plate_corner_energy(
    P: np.ndarray, material: Material, corner_w: np.ndarray, refine: int = 4
) -> float:
    """Kirchhoff-plate (Morley) energy of the polygon ``P`` (k, 2) with the deflection
    prescribed at the k corners only (all edges free)."""
    K, basis = morley_plate_matrix(polygon_mesh(P, refine), material)
    D = basis.nodal_dofs[0, : len(P)]
    return _solve_prescribed(K, D, np.asarray(corner_w, dtype=float))


#: largest estimated relative error of a panel's condensed plate stiffness (``_condensed``);
#: a panel whose condensation would exceed it is refused as a sliver (the error grows like
#: height^-3: a quadrilateral 1e-4 as high as wide is estimated at ~5e-8 and measured at up
#: to ~1e-7, the CPU's rounding setting the constant; 1e-5 high ~6e-6, refused)
CONDENSATION_ERROR_MAX = 1e-6


def _condensed(K: sp.spmatrix, keep: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """Dense Schur complement of K on the dofs ``keep`` (the ``drop`` dofs condensed out,
    every other dof fixed at zero)."""
    K = sp.csr_matrix(K)
    Kkk = K[keep][:, keep].toarray()
    if len(drop) == 0:
        return Kkk
    Kkd = K[keep][:, drop]
    # refused when the condensation would keep fewer than six digits: its relative error
    # is about eps / (smallest / largest LU pivot) of the matrix scaled to a unit diagonal
    # (free of the units of deflections and rotations, so of the panel's size); the
    # solve's own signals (a rank warning, NaN) are not enough, as some releases return
    # finite values of ~1e45 for a sliver 1e-12 high
    X = np.full((len(drop), len(keep)), np.nan)
    Kdd = sp.csc_matrix(K[drop][:, drop])
    diag = Kdd.diagonal()
    if np.all(diag > 0.0):
        s = 1.0 / np.sqrt(diag)
        scale = sp.diags(s)
        try:
            lu = spla.splu(sp.csc_matrix(scale @ Kdd @ scale))
        except RuntimeError:  # exactly singular
            lu = None
        if lu is not None:
            pivots = np.abs(lu.U.diagonal())
            if np.finfo(float).eps * pivots.max() < CONDENSATION_ERROR_MAX * pivots.min():
                X = s[:, None] * lu.solve(s[:, None] * Kkd.T.toarray())
    if not np.all(np.isfinite(X)):
        raise ConfigError(
            "the continuum plate of a panel is singular with its corners held: a sliver "
            "panel (corners nearly on a line) or a material without stiffness"
        )
    return Kkk - Kkd @ np.asarray(X).reshape(len(drop), len(keep))


def plate_corner_stiffness(P: np.ndarray, material: Material, refine: int = 4) -> np.ndarray:
    """(k, k) Kirchhoff-plate (Morley) stiffness of the polygon ``P`` condensed to the
    deflections of its k corners (edges free)."""
    K, basis = morley_plate_matrix(polygon_mesh(P, refine), material)
    keep = basis.nodal_dofs[0, : len(P)]
    drop = np.setdiff1d(np.arange(K.shape[0]), keep)
    return _condensed(K, keep, drop)


def panel_corner_stiffness(model, corners: np.ndarray) -> np.ndarray:
    """(k, k) out-of-plane stiffness of a flat bar-and-hinge panel condensed to the z
    displacement of the nodes ``corners`` (other z dofs condensed out, in-plane dofs fixed;
    they decouple at the flat state)."""
    K = model.tangent(model.X0)
    keep = 3 * np.asarray(corners) + 2
    drop = np.setdiff1d(3 * np.arange(model.n_nodes) + 2, keep)
    return _condensed(K, keep, drop)


#: homogeneous in-plane strain modes (eps_xx, eps_yy, eps_xy) of the comparison
def strain_modes(nu: float) -> dict[str, np.ndarray]:
    """Uniform dilation, uniaxial stress along x and y and pure shear, as 2x2 strain
    tensors."""
    return {
        "dilation": np.eye(2),
        "uniaxial_x": np.array([[1.0, 0.0], [0.0, -nu]]),
        "uniaxial_y": np.array([[-nu, 0.0], [0.0, 1.0]]),
        "shear": np.array([[0.0, 1.0], [1.0, 0.0]]),
    }


def homogeneous_energy(P: np.ndarray, material: Material, eps: np.ndarray) -> float:
    """Closed-form plane-stress energy ``t A eps:C:eps / 2`` of the polygon ``P`` under the
    homogeneous strain ``eps`` (2, 2) (what :func:`membrane_energy` gives for affine corner
    displacements, exactly)."""
    P = np.asarray(P, float)
    A = 0.5 * abs(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))
    e = np.array([eps[0, 0], eps[1, 1], np.sqrt(2.0) * eps[0, 1]])
    return 0.5 * material.t * A * float(e @ material.membrane_mandel() @ e)


def panel_energy(model, prescribed: np.ndarray) -> float:
    """Linear bar-and-hinge energy ``1/2 u^T K(X0) u`` with the node displacements
    ``prescribed`` (n_nodes, 3) where finite and the NaN entries free (condensed out)."""
    pre = np.asarray(prescribed, dtype=float).ravel()
    K = model.tangent(model.X0)
    D = np.flatnonzero(np.isfinite(pre))
    return _solve_prescribed(K, D, pre[D])
