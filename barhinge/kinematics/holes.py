"""Loop closure around the holes of a crease pattern.

The vertex loop-closure conditions (:mod:`barhinge.kinematics.constraints`) generate every
closed loop of panels only when the sheet is a disk. Around a hole (an inner boundary loop)
the panels form a closed chain that no interior vertex encloses: going once around it, the
rigid motions across the creases must compose to the identity, 6 conditions per hole (3 for
the rotation, 3 for the translation). With them the generic count becomes
``E_in - 3 V_in - 6 h`` (Euler's formula for a disk with ``h`` holes, triangulated: equal to
the nodal count ``3 V - 6 - E``).

The chain around a hole: walk the hole's boundary edges; the panel on each hole edge, then
the fan of panels at the next hole vertex up to the panel on the next hole edge. Each step
from panel ``a`` to panel ``b`` across crease ``e`` (reference end points ``p -> q``) turns
``b`` about the line ``p q`` (reference coordinates) by ``s (rho_e - rho0_e)``, ``s = +1``
when ``b`` lies on the left of ``p -> q`` (the convention of
:class:`barhinge.kinematics.constraints.FaceTree`). The poses compose as
``P_i = P_{i-1} Rot_i``; the conditions are ``P_k = I``, written as
``r = (vee(skew R), t / L)`` with ``L`` the pattern size. With ``omega_i = R_{i-1} u_i`` and
``p_i' = R_{i-1} p_i + t_{i-1}`` (the crease's current axis and a point on it),
``dP_k / dtheta_i = xi_i' P_k``, so

    dr_R / dtheta_i = 1/2 (tr(R) I - R) omega_i,    dr_t / dtheta_i = omega_i x (t - p_i') / L.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import scipy.sparse as sp

from barhinge.kinematics.constraints import RigidConstraints, rodrigues

__all__ = ["HoleLoops", "hole_loops"]


@dataclasses.dataclass(frozen=True, eq=False)
class HoleLoops:
    """Closure conditions of the panel chains around the holes of a pattern.

    Attributes
    ----------
    n_var : int
        Number of crease variables (columns), as in the :class:`RigidConstraints`.
    var : list of (k_h,) int
        Crease variable crossed at each step of each hole's chain.
    sign : list of (k_h,) float
        +1 when the panel stepped into lies on the left of the crease's directed edge.
    point, axis : list of (k_h, 3) float
        A point on each crossed crease and its unit direction (reference state).
    rho0 : (n_var,) float
        Reference fold angles (radians).
    length : float
        Length scale of the translation rows (pattern size).
    unclosed : int
        Holes whose chain could not be built (a boundary vertex shared by two boundary
        loops, or a fan that does not join the two hole edges); they stay unconstrained.
    """

    n_var: int
    var: list[np.ndarray]
    sign: list[np.ndarray]
    point: list[np.ndarray]
    axis: list[np.ndarray]
    rho0: np.ndarray
    length: float
    unclosed: int = 0

    @property
    def n_holes(self) -> int:
        return len(self.var)

    @property
    def n_eq(self) -> int:
        return 6 * self.n_holes

    # ------------------------------------------------------------------ building
    @classmethod
    def from_constraints(cls, rc: RigidConstraints) -> HoleLoops:
        """The chains around every hole of ``rc.pattern`` (none for a disk)."""
        pat = rc.pattern
        empty = cls(rc.n_var, [], [], [], [], rc.rho0, max(pat.size, 1e-300))
        if rc.holes == 0:
            return empty
        loops = _boundary_loops(pat)
        X = pat.vertices3d
        EF = pat.edge_faces
        E = pat.edges
        idx = pat.edge_index
        corners = pat.vertex_corners
        faces = pat.faces
        # the outer loop of each component: the largest enclosed area
        comp = _face_components(pat)
        best: dict[int, tuple[float, int]] = {}
        for i, (vs, f0) in enumerate(loops):
            P = X[vs]
            area = 0.5 * float(np.linalg.norm(np.cross(P, np.roll(P, -1, axis=0)).sum(0)))
            c = int(comp[f0])
            if c not in best or area > best[c][0]:
                best[c] = (area, i)
        outer = {i for _, i in best.values()}
        out: tuple[list, list, list, list] = ([], [], [], [])
        unclosed = 0
        for i, (vs, _) in enumerate(loops):
            if i in outer:
                continue
            chain = _hole_chain(vs, corners, faces, idx, EF)
            if chain is None:
                unclosed += 1
                continue
            es, into = chain
            var = rc.var_of_edge[es]
            keep = var >= 0  # a crease that cannot fold is a rigid step
            es, into, var = es[keep], into[keep], var[keep]
            p, q = X[E[es, 0]], X[E[es, 1]]
            u = q - p
            u = u / np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
            out[0].append(var)
            out[1].append(np.where(EF[es, 0] == into, 1.0, -1.0))
            out[2].append(p)
            out[3].append(u)
        return dataclasses.replace(
            empty, var=out[0], sign=out[1], point=out[2], axis=out[3], unclosed=unclosed
        )

    # ------------------------------------------------------------------ evaluation
    def _poses(self, h: int, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Final pose (R, t) of hole ``h``'s chain and the (k, 3) current axes and points."""
        th = self.sign[h] * (rho - self.rho0)[self.var[h]]
        p, u = self.point[h], self.axis[h]
        Rs = rodrigues(u, th)
        ts = p - np.einsum("kij,kj->ki", Rs, p)
        k = len(th)
        om = np.empty((k, 3))
        pc = np.empty((k, 3))
        R, t = np.eye(3), np.zeros(3)
        for i in range(k):  # sequential composition along one hole's chain
            om[i] = R @ u[i]
            pc[i] = R @ p[i] + t
            R, t = R @ Rs[i], R @ ts[i] + t
        return R, t, np.stack([om, pc])

    def evaluate(self, rho: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
        """Residual (6 h,) and exact Jacobian (6 h, n_var) at fold angles ``rho``."""
        r = np.zeros(self.n_eq)
        rows, cols, vals = [], [], []
        L = self.length
        for h in range(self.n_holes):
            R, t, (om, pc) = self._poses(h, rho)
            r[6 * h : 6 * h + 3] = 0.5 * np.array(
                [R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]
            )
            r[6 * h + 3 : 6 * h + 6] = t / L
            G = 0.5 * (np.trace(R) * np.eye(3) - R)
            cR = om @ G.T
            cT = np.cross(om, t - pc) / L
            c = np.hstack([cR, cT]) * self.sign[h][:, None]  # (k, 6)
            rows.append(np.broadcast_to(6 * h + np.arange(6), c.shape).ravel())
            cols.append(np.repeat(self.var[h], 6))
            vals.append(c.ravel())
        if not rows:
            return r, sp.csr_matrix((0, self.n_var))
        J = sp.coo_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
            shape=(self.n_eq, self.n_var),
        ).tocsr()  # a crease crossed twice: its two entries are summed
        return r, J

    def closure_error(self, rho: np.ndarray) -> np.ndarray:
        """(h,) ``|R - I| + |t| / L`` of each hole's chain (0 when it closes)."""
        out = np.zeros(self.n_holes)
        for h in range(self.n_holes):
            R, t, _ = self._poses(h, rho)
            out[h] = np.linalg.norm(R - np.eye(3)) + np.linalg.norm(t) / self.length
        return out


@functools.lru_cache(maxsize=16)
def hole_loops(rc: RigidConstraints) -> HoleLoops:
    """:meth:`HoleLoops.from_constraints`, cached per constraints object."""
    return HoleLoops.from_constraints(rc)


def _face_components(pat) -> np.ndarray:
    """(n_faces,) component label of each face (faces joined by shared edges)."""
    from scipy.sparse.csgraph import connected_components

    FA = pat.face_adjacency
    nf = pat.n_faces
    G = sp.coo_matrix((np.ones(len(FA)), (FA[:, 0], FA[:, 1])), shape=(nf, nf))
    return connected_components(G, directed=False)[1]


def _boundary_loops(pat) -> list[tuple[np.ndarray, int]]:
    """Closed boundary loops as (vertex sequence with the panels on the left, a face on the
    loop); loops through a vertex with two outgoing boundary edges are dropped."""
    EF = pat.edge_faces
    E = pat.edges
    one = (EF >= 0).sum(1) == 1
    bd = np.flatnonzero(one)
    left = EF[bd, 0] >= 0
    src = np.where(left, E[bd, 0], E[bd, 1])
    dst = np.where(left, E[bd, 1], E[bd, 0])
    face = np.where(left, EF[bd, 0], EF[bd, 1])
    nxt: dict[int, int] = {}
    bad: set[int] = set()
    for j, s in enumerate(src.tolist()):
        if s in nxt:
            bad.add(s)
        nxt[s] = j
    loops = []
    seen = np.zeros(len(bd), bool)
    for j0 in range(len(bd)):
        if seen[j0]:
            continue
        vs, j, ok = [], j0, True
        while not seen[j]:
            seen[j] = True
            vs.append(int(src[j]))
            d = int(dst[j])
            if d in bad or d not in nxt:
                ok = False
                break
            j = nxt[d]
        if ok and j == j0:
            loops.append((np.asarray(vs, dtype=np.int64), int(face[j0])))
    return loops


def _hole_chain(vs, corners, faces, idx, EF) -> tuple[np.ndarray, np.ndarray] | None:
    """Crossed edges and the face stepped into, once around the hole ``vs`` (panels on the
    left of ``vs[i] -> vs[i+1]``); None if a fan does not join two hole edges."""
    k = len(vs)
    edges, into = [], []
    for i in range(k):
        a, v, b = vs[i - 1], vs[i], vs[(i + 1) % k]
        e_in = idx[(min(a, v), max(a, v))]
        e_out = idx[(min(v, b), max(v, b))]
        g_in = EF[e_in, 0] if EF[e_in, 0] >= 0 else EF[e_in, 1]
        g_out = EF[e_out, 0] if EF[e_out, 0] >= 0 else EF[e_out, 1]
        fan = list(corners[v])
        fs = [fi for fi, _ in fan]
        if not fs or {fs[0], fs[-1]} != {g_in, g_out}:
            return None
        if fs[0] != g_in:
            fan = fan[::-1]
            fs = fs[::-1]
            forward = False
        else:
            forward = True
        for j in range(len(fan) - 1):
            # the edge shared by consecutive corners of the counter-clockwise fan at v is
            # (v, previous vertex of the earlier corner)
            fi, p = fan[j] if forward else fan[j + 1]
            f = faces[fi]
            w = f[p - 1]
            edges.append(idx[(min(v, w), max(v, w))])
            into.append(fs[j + 1])
    return np.asarray(edges, dtype=np.int64), np.asarray(into, dtype=np.int64)
