"""An independent shell reference of a folded sheet: flat facet shell elements (scikit-fem).

Every planar face (facet) of the pattern gets its own triangle mesh
(:func:`barhinge.model.continuum.polygon_mesh`: a fan from the centroid refined ``refine``
times, so every polygon edge is cut into ``2^refine`` segments, equal or, with ``grading``,
shorter towards the corners; neighbouring facets share their nodes). On each facet, in its
own plane frame ``(e1, e2, N)``:

* **membrane**: plane-stress constant-strain triangles (vector P1 Lagrange,
  ``skfem.ElementVector(ElementTriP1())``), thickness ``t``;
* **plate**: Kirchhoff plate, Morley's constant-moment triangle (``skfem.ElementTriMorley``:
  deflection at the vertices, normal slope at the edge midpoints), ``D = E t^3 / (12 (1 -
  nu^2))``.

Coupling (the facet shell of CST + Morley, no drilling rotation): every mesh vertex has three
global translations, seen by the facet as ``(u, v, w) = (e1, e2, N) . U``; every mesh edge
on a facet boundary that another facet shares carries, for each facet, the rotation ``omega``
about the global edge axis ``t`` (from the lower to the higher global node), related to the
Morley slope dof by ``dw/dn = omega (t x n) . N`` (``n`` the dof's in-plane unit normal).
Along flat joins (``F`` lines, boundaries ``B`` never shared) the two facets share one
``omega`` (a continuous plate); along creases (``M``, ``V``, ``U``) too (a monolithic fold)
unless ``crease_stiffness`` (moment per radian per unit length) is given: then each side keeps
its own ``omega`` and a rotational spring ``k l (omega_A - omega_B)^2 / 2`` per edge segment of
length ``l`` joins them (the same crease law as the bar-and-hinge fold hinges).

Convergence: displacements converge as ``O(h^2)`` (CST membrane and Morley plate alike). The
checks (tests/model/test_model_shell.py): the square plate under uniform load, simply
supported and clamped (Timoshenko & Woinowsky-Krieger 1959, Tables 8 and 35), and the
Scordelis-Lo roof (MacNeal & Harder 1985), faceted.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge.errors import ConfigError
from barhinge.model.continuum import morley_plate_matrix, polygon_mesh
from barhinge.model.material import Material

__all__ = ["ShellModel", "shell_model"]

_CREASES = ("M", "V", "U")


@dataclasses.dataclass(frozen=True, eq=False)
class ShellModel:
    """A facet shell of a folded sheet (module docstring). Build with :func:`shell_model`.

    Attributes
    ----------
    points : (n_nodes, 3) float
        Mesh nodes (the pattern's vertices are nodes ``0 .. n_vertices - 1``).
    triangles : (n_tri, 3) int
        All facet triangles (global node ids), for pictures.
    K : csr (n_dof, n_dof)
        Linear stiffness. DOFs: ``3 node + axis`` translations first, then rotations and
        slopes.
    n_nodes : int
    node_edge : (n_nodes,) int
        Pattern edge each node lies on (-1 for nodes inside a facet; a vertex gives one of
        its edges).
    edges : (n_edges, 2) int
        The pattern's edges (vertex ids = node ids).
    dof_edge : (n_dof,) int
        Pattern edge of each rotation / slope DOF on a facet boundary (-1 for the
        translations and the DOFs inside facets): fix them to clamp an edge.
    """

    points: np.ndarray
    triangles: np.ndarray
    K: sp.csr_matrix
    n_nodes: int
    node_edge: np.ndarray
    edges: np.ndarray
    dof_edge: np.ndarray
    _T: list = dataclasses.field(repr=False)  # per facet: local dofs = T @ global dofs
    _frames: np.ndarray = dataclasses.field(repr=False)  # (n_faces, 3, 3) rows e1, e2, N
    _areas: list = dataclasses.field(repr=False)  # per facet: (mem (2nv,), morley (n,)) unit loads

    @property
    def n_dof(self) -> int:
        return self.K.shape[0]

    def surface_load(self, q: Any, per: str = "area") -> np.ndarray:
        """(n_dof,) consistent load of a uniform surface force ``q`` (3,) per unit facet area
        (``per="area"``) or per unit area projected on the horizontal plane (``per="plan"``:
        the facet's force is ``q |N_z|`` per unit facet area; snow-like)."""
        q = np.asarray(q, float).reshape(3)
        if per not in ("area", "plan"):
            raise ConfigError(f"per = {per!r}; expected 'area' or 'plan'")
        f = np.zeros(self.n_dof)
        for fi, T in enumerate(self._T):
            R = self._frames[fi]
            s = abs(R[2, 2]) if per == "plan" else 1.0
            ql = R @ q * s
            mem, mor = self._areas[fi]
            nv2 = len(mem)
            loc = np.concatenate([mem * np.tile(ql[:2], nv2 // 2), mor * ql[2]])
            f += T.T @ loc
        return f

    def solve(
        self, f: np.ndarray, fixed_nodes: np.ndarray, fixed_dofs: np.ndarray | None = None
    ) -> np.ndarray:
        """(n_dof,) linear displacements under ``f`` with the translations of
        ``fixed_nodes`` held (pinned) and the DOFs ``fixed_dofs`` held too. The sparse
        factorisation is the package's linear backend (:func:`barhinge.linalg.get_backend`:
        PARDISO where it installs, else SuperLU)."""
        from barhinge.linalg.backends import SingularMatrixError, get_backend

        fixed = (3 * np.asarray(fixed_nodes, np.int64)[:, None] + np.arange(3)).ravel()
        if fixed_dofs is not None:
            fixed = np.union1d(fixed, np.asarray(fixed_dofs, np.int64))
        free = np.setdiff1d(np.arange(self.n_dof), fixed)
        Kff = sp.csr_matrix(self.K[free][:, free])
        try:
            uf = get_backend("auto").factorize(Kff).solve(np.asarray(f, float)[free])
        except SingularMatrixError as exc:
            raise ConfigError("shell model: the supports leave a mechanism") from exc
        if not np.all(np.isfinite(uf)):
            raise ConfigError("shell model: the supports leave a mechanism")
        u = np.zeros(self.n_dof)
        u[free] = uf
        return u

    def translations(self, u: np.ndarray) -> np.ndarray:
        """(n_nodes, 3) node translations of the DOF vector ``u``."""
        return np.asarray(u)[: 3 * self.n_nodes].reshape(-1, 3)

    def nodes_on_edges(self, edges: Any) -> np.ndarray:
        """Node ids on the pattern edges ``edges`` (end vertices included)."""
        e = np.asarray(edges, np.int64)
        ends = self.edges[e].ravel()
        return np.union1d(np.flatnonzero(np.isin(self.node_edge, e)), ends)


def _facet_local(P2: np.ndarray, material: Material, refine: int, grading: float = 1.0):
    """Mesh and local matrices of one facet in its plane coordinates ``P2`` (k, 2)."""
    from skfem import (
        Basis,
        ElementTriP1,
        ElementVector,
        LinearForm,
        asm,
    )
    from skfem.models.elasticity import linear_elasticity

    mesh = polygon_mesh(P2, refine, grading)
    E, nu, t = material.E, material.nu, material.t
    bm = Basis(mesh, ElementVector(ElementTriP1()))
    mu, lam = E / (2 * (1 + nu)), E * nu / (1 - nu * nu)
    Km = t * asm(linear_elasticity(lam, mu), bm)
    Kp, bp = morley_plate_matrix(mesh, material)

    @LinearForm
    def one(v, w):
        return v

    # unit load vectors: membrane per component (x dofs get the x load, y dofs the y load)
    lm = asm(LinearForm(lambda v, w: v[0] + v[1]), bm)
    lp = asm(one, bp)
    # in-plane unit normal of every Morley edge dof (its sign convention): project x and y
    nx = bp.project(lambda x: x[0])[bp.facet_dofs[0]]
    ny = bp.project(lambda x: x[1])[bp.facet_dofs[0]]
    return {
        "mesh": mesh,
        "Km": sp.csr_matrix(Km),
        "Kp": sp.csr_matrix(Kp),
        "mem_dofs": bm.nodal_dofs,  # (2, nv)
        "w_dofs": bp.nodal_dofs[0],  # (nv,)
        "slope_dofs": bp.facet_dofs[0],  # (n_edges,)
        "n": np.column_stack([nx, ny]),
        "lm": lm,
        "lp": lp,
    }


def shell_model(
    cp: Any,
    material: Material | None = None,
    refine: int = 2,
    crease_stiffness: float | None = None,
    planarity_tol: float = 1e-6,
    grading: float = 1.0,
) -> ShellModel:
    """Facet shell of the pattern ``cp`` at its state (module docstring).

    Parameters
    ----------
    cp : CreasePattern
        Folded state (``vertices3d``); every face must be planar.
    material : Material
    refine : int
        Each polygon edge is cut into ``2^refine`` elements.
    crease_stiffness : float, optional
        Rotational stiffness of the creases per unit length (moment per radian per length);
        ``None``: monolithic creases.
    planarity_tol : float
        Largest out-of-plane distance of a face's vertices, relative to its size.
    grading : float
        1: uniform facet meshes; ``p`` > 1: nodes concentrated at the facets' corners
        (:func:`barhinge.model.continuum.polygon_mesh`; elements next to a corner
        ``h^p`` long), for folded sheets whose stresses are singular at the pattern's
        vertices.
    """
    from scipy.spatial import cKDTree

    mat = Material() if material is None else material
    if not isinstance(refine, (int, np.integer)) or not 0 <= refine <= 7:
        raise ConfigError(f"refine = {refine!r}; expected an integer 0..7")
    if crease_stiffness is not None and not crease_stiffness >= 0:
        raise ConfigError(f"crease_stiffness = {crease_stiffness}; expected >= 0 or None")
    V = np.asarray(cp.vertices3d, float)
    nv = len(V)
    size = float(np.linalg.norm(np.ptp(V, axis=0))) or 1.0
    edges = np.asarray(cp.edges, np.int64)
    asg = np.asarray(cp.assignment)
    edge_key = {(min(a, b), max(a, b)): e for e, (a, b) in enumerate(edges)}

    # 1. per facet: frame, local mesh (cached by shape), node coordinates in 3-D
    cache: dict[bytes, dict] = {}
    facets = []
    for fi, face in enumerate(cp.faces):
        F = list(face)
        P = V[F]
        c = P.mean(axis=0)
        Nn = np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0)
        if not np.linalg.norm(Nn) > 0:
            raise ConfigError(f"face {fi} has no area")
        Nn /= np.linalg.norm(Nn)
        off = float(np.abs((P - c) @ Nn).max())
        if off > planarity_tol * size:
            raise ConfigError(
                f"face {fi} is not planar (a vertex lies {off:.3g} off its plane); the shell "
                "model needs planar facets"
            )
        e1 = P[1] - P[0]
        e1 -= (e1 @ Nn) * Nn
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(Nn, e1)
        R = np.stack([e1, e2, Nn])
        P2 = (P - P[0]) @ R[:2].T
        key = np.round(P2 / size, 10).tobytes()
        if key not in cache:
            cache[key] = _facet_local(P2, mat, refine, grading)
        loc = cache[key]
        X3 = P[0] + loc["mesh"].p.T @ R[:2]  # (n_loc, 3)
        X3[: len(F)] = P  # corners exactly
        facets.append((F, R, loc, X3))

    # 2. global nodes: the pattern's vertices first, then the others, merged by position
    allX = np.vstack([V] + [X3[len(F) :] for F, _, _, X3 in facets])
    tree = cKDTree(allX)
    pairs = tree.query_pairs(1e-9 * size, output_type="ndarray")
    parent = np.arange(len(allX))
    if len(pairs):
        g = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), (len(allX),) * 2)
        from scipy.sparse.csgraph import connected_components

        _, lab = connected_components(g, directed=False)
        first = np.full(lab.max() + 1, len(allX))
        np.minimum.at(first, lab, np.arange(len(allX)))
        parent = first[lab]
    uniq, gid = np.unique(parent, return_inverse=True)
    points = allX[uniq]
    n_nodes = len(points)
    node_of = []  # per facet: global node of each local mesh vertex
    off = nv
    for F, _, loc, _ in facets:
        k = len(F)
        m = loc["mesh"].p.shape[1]
        ids = np.empty(m, np.int64)
        ids[:k] = gid[F]
        ids[k:] = gid[off : off + m - k]
        off += m - k
        node_of.append(ids)

    # pattern edge of each node: nodes on the segment between an edge's end vertices
    node_edge = np.full(n_nodes, -1, np.int64)
    for e, (a, b) in enumerate(edges):
        d = V[b] - V[a]
        L2 = float(d @ d)
        s = (points - V[a]) @ d / L2
        dist = np.linalg.norm(points - V[a] - s[:, None] * d, axis=1)
        on = (s > -1e-9) & (s < 1 + 1e-9) & (dist < 1e-9 * size) & (node_edge < 0)
        node_edge[on] = e

    # 3. edge-rotation dofs of shared facet-boundary segments
    seg_sides: dict[tuple[int, int], list] = {}
    for fi, (_, _, loc, _) in enumerate(facets):
        mf = loc["mesh"].facets  # (2, n_edges) local vertex ids
        ga, gb = node_of[fi][mf[0]], node_of[fi][mf[1]]
        for j in range(mf.shape[1]):
            k2 = (int(min(ga[j], gb[j])), int(max(ga[j], gb[j])))
            seg_sides.setdefault(k2, []).append((fi, j))
    ndof = 3 * n_nodes
    slope_col: list[np.ndarray] = [np.full(len(loc["slope_dofs"]), -1) for _, _, loc, _ in facets]
    slope_coef: list[np.ndarray] = [np.ones(len(loc["slope_dofs"])) for _, _, loc, _ in facets]
    springs = []  # (dof A, dof B, k l)
    dof_edge = [np.full(ndof, -1, np.int64)]
    for (a, b), sides in seg_sides.items():
        ed = _segment_edge(a, b, nv, node_edge, edges, edge_key)
        if len(sides) == 1:
            fi, j = sides[0]
            slope_col[fi][j] = ndof  # own slope dof, coefficient 1
            ndof += 1
            dof_edge.append(np.array([ed]))
            continue
        if len(sides) > 2:
            raise ConfigError(f"more than two facets meet along the segment of nodes {a}, {b}")
        t = points[b] - points[a]
        ell = float(np.linalg.norm(t))
        t /= ell
        crease = ed >= 0 and asg[ed] in _CREASES and crease_stiffness is not None
        cols = []
        for fi, j in sides:
            _, R, loc, _ = facets[fi]
            n3 = loc["n"][j] @ R[:2]
            slope_coef[fi][j] = float(np.cross(t, n3) @ R[2])
            if crease or not cols:
                cols.append(ndof)
                ndof += 1
                dof_edge.append(np.array([ed]))
            slope_col[fi][j] = cols[-1]
        if crease:
            springs.append((cols[0], cols[1], float(crease_stiffness) * ell))

    # 4. assemble K = sum T^T K_f T
    rows_all, cols_all, vals_all = [], [], []
    Ts, frames, tris = [], [], []
    for fi, (_, R, loc, _) in enumerate(facets):
        g = node_of[fi]
        nloc = len(g)
        nm = loc["Km"].shape[0]
        npl = loc["Kp"].shape[0]
        r, c, v = [], [], []
        for comp in range(2):  # membrane u, v = e_comp . U
            for ax in range(3):
                r.append(loc["mem_dofs"][comp])
                c.append(3 * g + ax)
                v.append(np.full(nloc, R[comp, ax]))
        for ax in range(3):  # plate w = N . U
            r.append(nm + loc["w_dofs"])
            c.append(3 * g + ax)
            v.append(np.full(nloc, R[2, ax]))
        r.append(nm + loc["slope_dofs"])
        c.append(slope_col[fi])
        v.append(slope_coef[fi])
        T = sp.csr_matrix(
            (np.concatenate(v), (np.concatenate(r), np.concatenate(c))), shape=(nm + npl, ndof)
        )
        Kf = sp.block_diag([loc["Km"], loc["Kp"]], format="csr")
        Kg = (T.T @ Kf @ T).tocoo()
        rows_all.append(Kg.row)
        cols_all.append(Kg.col)
        vals_all.append(Kg.data)
        Ts.append(T)
        frames.append(R)
        tris.append(g[loc["mesh"].t.T])
    for a, b, kl in springs:
        rows_all.append(np.array([a, a, b, b]))
        cols_all.append(np.array([a, b, a, b]))
        vals_all.append(kl * np.array([1.0, -1.0, -1.0, 1.0]))
    K = sp.csr_matrix(
        (np.concatenate(vals_all), (np.concatenate(rows_all), np.concatenate(cols_all))),
        shape=(ndof, ndof),
    )
    # unit loads per facet: membrane (x, y interleaved) and plate
    areas = [(_per_dof(loc), loc["lp"]) for _, _, loc, _ in facets]
    return ShellModel(
        points=points,
        triangles=np.vstack(tris),
        K=K,
        n_nodes=n_nodes,
        node_edge=node_edge,
        edges=edges,
        dof_edge=np.concatenate(dof_edge),
        _T=Ts,
        _frames=np.array(frames),
        _areas=areas,
    )


def _segment_edge(a: int, b: int, nv: int, node_edge, edges, edge_key) -> int:
    """Pattern edge the mesh segment ``a - b`` lies on, -1 if none (inside a facet)."""
    if a < nv and b < nv:
        return int(edge_key.get((a, b), -1))
    if a >= nv and b >= nv:
        return int(node_edge[a]) if node_edge[a] == node_edge[b] else -1
    v, x = (a, b) if a < nv else (b, a)
    e = int(node_edge[x])
    return e if e >= 0 and v in edges[e] else -1


def _per_dof(loc: dict) -> np.ndarray:
    """Membrane load vector of a unit (1, 1) in-plane force, ordered so that multiplying by
    ``tile([qx, qy])`` gives the consistent load (skfem's vector P1 dofs interleave x, y)."""
    lm = np.asarray(loc["lm"], float)
    md = loc["mem_dofs"]
    if not (np.array_equal(md[0], np.arange(0, lm.size, 2)) and np.array_equal(md[1], md[0] + 1)):
        raise ConfigError("unexpected dof order of skfem's vector P1 element")
    return lm
