"""Validation of crease patterns, and the repair of near-coincident vertices.

:func:`findings` lists every problem found (errors, warnings and notes); :func:`check` raises
:class:`~barhinge.errors.PatternError` with a one-line message for the first error and runs on
every :class:`~barhinge.pattern.crease.CreasePattern` construction, so every check here is
vectorised (sorting, a uniform grid for crossings, a k-d tree for coincident vertices).

Tolerances are relative to the pattern size ``s`` (diagonal of the bounding box): vertices
closer than ``REL_TOL * s`` coincide, edges shorter than that have zero length, a vertex that
close to the interior of an edge lies on it. Sector angles at an interior vertex must sum to
360 deg within ``ANGLE_TOL_DEG``.

Checks that need the crease-pattern layout (coincident vertices, crossings) run only when the
state is the flat crease pattern: all vertices in one plane and every face counter-clockwise
in it. Folded states (3-D, or flat-folded with some faces flipped) may legitimately have
coincident vertices and overlapping faces.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Literal, Protocol, TypeVar

import numpy as np

from barhinge.errors import PatternError
from barhinge.pattern.planar import pattern_plane

__all__ = [
    "ANGLE_TOL_DEG",
    "REL_TOL",
    "Finding",
    "PatternLike",
    "check",
    "findings",
    "holes",
    "merged",
    "merged_arrays",
    "pattern_plane",
]

#: vertices closer than REL_TOL * size coincide; edges shorter than that have zero length
REL_TOL = 1e-6
#: tolerance on the 360-degree sum of sector angles at an interior vertex
ANGLE_TOL_DEG = 1e-3
#: faces whose area is below AREA_TOL * perimeter**2 have zero area
AREA_TOL = 1e-10

Severity = Literal["error", "warning", "info"]


class PatternLike(Protocol):
    """What validation reads of a crease pattern.

    :class:`~barhinge.pattern.crease.CreasePattern` checks itself on construction with
    :func:`check`, so this module sits below it and names the attributes it needs here
    instead of importing the class.
    """

    @property
    def vertices(self) -> np.ndarray: ...
    @property
    def vertices3d(self) -> np.ndarray: ...
    @property
    def edges(self) -> np.ndarray: ...
    @property
    def assignment(self) -> np.ndarray: ...
    @property
    def fold_angles(self) -> np.ndarray: ...
    @property
    def faces(self) -> tuple[tuple[int, ...], ...]: ...
    @property
    def faces_found(self) -> bool: ...
    @property
    def edge_faces(self) -> np.ndarray: ...
    @property
    def developable(self) -> bool: ...
    @property
    def size(self) -> float: ...
    @property
    def n_vertices(self) -> int: ...
    @property
    def n_edges(self) -> int: ...
    @property
    def n_faces(self) -> int: ...
    def replaced(self, **changes: Any) -> Any: ...


_P = TypeVar("_P", bound=PatternLike)


@dataclasses.dataclass(frozen=True)
class Finding:
    """One validation result.

    Attributes
    ----------
    code : str
        Stable identifier, e.g. ``"duplicate-vertex"``, ``"crossing-edges"``.
    message : str
        One line naming the offending item and what was expected.
    index : int or tuple of int or None
        The offending vertex / edge / face id (a pair for pairwise problems).
    severity : "error" | "warning" | "info"
    """

    code: str
    message: str
    index: int | tuple[int, ...] | None
    severity: Severity = "error"

    def as_dict(self) -> dict:
        idx = self.index
        return {
            "code": self.code,
            "severity": self.severity,
            "index": list(idx) if isinstance(idx, tuple) else idx,
            "message": self.message,
        }


# ----------------------------------------------------------------------------- helpers
def _corners(faces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flatten face loops: (vertex, face id, index of the next corner) per corner."""
    lens = np.fromiter((len(f) for f in faces), np.int64, len(faces))
    if lens.sum() == 0:
        z = np.zeros(0, np.int64)
        return z, z, z
    flat = np.fromiter((v for f in faces for v in f), np.int64, int(lens.sum()))
    starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
    fid = np.repeat(np.arange(len(faces)), lens)
    idx = np.arange(len(flat))
    nxt = np.where(idx + 1 == starts[fid] + lens[fid], starts[fid], idx + 1)
    return flat, fid, nxt


def _edge_lookup(E: np.ndarray, n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Edge id of each vertex pair (a[i], b[i]) (first edge if duplicated), -1 if none."""
    if len(E) == 0:
        return -np.ones(len(a), np.int64)
    key = np.minimum(E[:, 0], E[:, 1]) * n + np.maximum(E[:, 0], E[:, 1])
    order = np.argsort(key, kind="stable")
    ks = key[order]
    q = np.minimum(a, b) * n + np.maximum(a, b)
    pos = np.clip(np.searchsorted(ks, q), 0, len(ks) - 1)
    return np.where(ks[pos] == q, order[pos], -1)


def _project(X: np.ndarray, plane) -> np.ndarray:
    c, B = plane
    X3 = X if X.shape[1] == 3 else np.column_stack([X, np.zeros(len(X))])
    return (X3 - c) @ B[:2].T


def _pairs_in_groups(
    keys: np.ndarray, items: np.ndarray, with_keys: bool = False
) -> tuple[np.ndarray, ...]:
    """All pairs (i < j position-wise) of items sharing a key (vectorised); with
    ``with_keys`` also the shared key of each pair."""
    order = np.argsort(keys, kind="stable")
    k, it = keys[order], items[order]
    if len(k) == 0:
        z = np.zeros(0, np.int64)
        return (z, z, z) if with_keys else (z, z)
    brk = np.flatnonzero(np.diff(k)) + 1
    starts = np.concatenate([[0], brk])
    ends = np.concatenate([brk, [len(k)]])
    gid = np.repeat(np.arange(len(starts)), ends - starts)
    cnt = ends[gid] - np.arange(len(k)) - 1  # partners after each position
    total = int(cnt.sum())
    first = np.repeat(np.arange(len(k)), cnt)
    off = np.repeat(np.cumsum(cnt) - cnt, cnt)
    second = first + 1 + (np.arange(total) - off)
    if with_keys:
        return it[first], it[second], k[first]
    return it[first], it[second]


def box_pairs(lo: np.ndarray, hi: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) of axis-aligned boxes ``[lo, hi]`` (each (k, 2)) that share a cell of a
    uniform grid of spacing ``cell`` (a superset of the overlapping pairs; vectorised).
    The spacing is doubled until the number of (box, cell) entries stays modest."""
    k = len(lo)
    z = np.zeros(0, np.int64)
    if k < 2:
        return z, z
    origin = lo.min(0)
    extent = float((hi.max(0) - origin).max()) or 1.0
    cell = max(float(cell), extent / 4096.0)
    while True:
        i0 = np.floor((lo - origin) / cell).astype(np.int64)
        i1 = np.floor((hi - origin) / cell).astype(np.int64)
        nx, ny = i1[:, 0] - i0[:, 0] + 1, i1[:, 1] - i0[:, 1] + 1
        ncell = nx * ny
        if ncell.sum() <= 40 * k + 100_000 or cell >= extent:
            break
        cell *= 2.0
    total = int(ncell.sum())
    e = np.repeat(np.arange(k), ncell)
    r = np.arange(total) - np.repeat(np.cumsum(ncell) - ncell, ncell)
    cx = i0[e, 0] + r % nx[e]
    cy = i0[e, 1] + r // nx[e]
    stride = int(i1[:, 1].max()) + 2
    p, q, key = _pairs_in_groups(cx * stride + cy, e, with_keys=True)
    # report each pair once: in the cell holding the lower corner of the boxes' overlap
    ref = (key // stride == np.maximum(i0[p, 0], i0[q, 0])) & (
        key % stride == np.maximum(i0[p, 1], i0[q, 1])
    )
    p, q = p[ref], q[ref]
    return np.minimum(p, q), np.maximum(p, q)


def _candidate_edge_pairs(P: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of edges whose bounding boxes share a cell of a uniform grid."""
    if len(E) < 2:
        z = np.zeros(0, np.int64)
        return z, z
    A, B = P[E[:, 0]], P[E[:, 1]]
    L = np.linalg.norm(B - A, axis=1)
    return box_pairs(np.minimum(A, B), np.maximum(A, B), float(np.median(L)))


def _crossings(P: np.ndarray, E: np.ndarray, tol: float) -> list[Finding]:
    """Crossing edges, vertices on the interior of an edge, collinear overlaps."""
    out: list[Finding] = []
    e, f = _candidate_edge_pairs(P, E)
    if len(e) == 0:
        return out
    a, b, c, d = E[e, 0], E[e, 1], E[f, 0], E[f, 1]
    same = (a == c) & (b == d) | (a == d) & (b == c)
    e, f, a, b, c, d = (x[~same] for x in (e, f, a, b, c, d))
    pa, pb, pc, pd = P[a], P[b], P[c], P[d]

    def dist(p0, p1, q):  # signed distance of q from the line p0 -> p1
        t = p1 - p0
        n = np.linalg.norm(t, axis=1)
        n = np.where(n > 0, n, 1.0)
        return ((t[:, 0] * (q[:, 1] - p0[:, 1]) - t[:, 1] * (q[:, 0] - p0[:, 0])) / n), n

    def inside(p0, p1, q, n):  # q strictly inside the segment (by more than tol)
        s = np.einsum("ij,ij->i", q - p0, p1 - p0) / n
        return (s > tol) & (s < n - tol)

    dc, nab = dist(pa, pb, pc)
    dd, _ = dist(pa, pb, pd)
    da, ncd = dist(pc, pd, pa)
    db, _ = dist(pc, pd, pb)
    shared = (a == c) | (a == d) | (b == c) | (b == d)
    proper = (~shared) & (dc * dd < 0) & (da * db < 0)
    proper &= (np.abs(dc) > tol) & (np.abs(dd) > tol) & (np.abs(da) > tol) & (np.abs(db) > tol)
    for i in np.flatnonzero(proper):
        out.append(
            Finding(
                "crossing-edges",
                f"edges {e[i]} and {f[i]} cross without a vertex at the crossing; "
                "expected edges to meet only at shared vertices",
                (int(e[i]), int(f[i])),
            )
        )
    # a vertex of one edge lying on the interior of the other (T-junction, overlap)
    onedge = []
    for q, vq, dq, base, p0, p1, n in (
        (pc, c, dc, e, pa, pb, nab),
        (pd, d, dd, e, pa, pb, nab),
        (pa, a, da, f, pc, pd, ncd),
        (pb, b, db, f, pc, pd, ncd),
    ):
        hit = (np.abs(dq) <= tol) & inside(p0, p1, q, n)
        onedge.append((vq[hit], base[hit]))
    vs = np.concatenate([o[0] for o in onedge])
    es = np.concatenate([o[1] for o in onedge])
    if len(vs):
        vk = np.unique(vs * len(E) + es)
        for k in vk:
            v, ed = int(k // len(E)), int(k % len(E))
            out.append(
                Finding(
                    "vertex-on-edge",
                    f"vertex {v} lies on the interior of edge {ed} {E[ed].tolist()}; expected "
                    "the edge to be split there (crossing or overlapping edges)",
                    (v, ed),
                )
            )
    return out


def holes(cp: PatternLike) -> list[list[int]]:
    """Boundary loops that are holes: per face-connected component, every boundary loop but
    the outer one (the one with the largest bounding box). Each loop is a list of edge ids."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    EF = cp.edge_faces
    nf = cp.n_faces
    bnd = np.flatnonzero((EF >= 0).sum(1) == 1)
    if nf == 0 or len(bnd) == 0:
        return []
    both = np.flatnonzero((EF >= 0).all(1))
    g = coo_matrix((np.ones(len(both)), (EF[both, 0], EF[both, 1])), shape=(nf, nf))
    _, comp = connected_components(g, directed=False)
    n = cp.n_vertices
    Eb = cp.edges[bnd]
    gb = coo_matrix((np.ones(len(bnd)), (Eb[:, 0], Eb[:, 1])), shape=(n, n))
    _, vlab = connected_components(gb, directed=False)
    loop = vlab[Eb[:, 0]]
    face_of = EF[bnd].max(1)
    X = cp.vertices3d
    out: list[list[int]] = []
    for c in np.unique(comp[face_of]):
        sel = comp[face_of] == c
        loops = np.unique(loop[sel])
        if len(loops) < 2:
            continue
        diag = []
        for lp in loops:
            vv = np.unique(Eb[sel & (loop == lp)].ravel())
            diag.append(float(np.linalg.norm(np.ptp(X[vv], axis=0))))
        outer = loops[int(np.argmax(diag))]
        for lp in loops:
            if lp != outer:
                out.append(sorted(int(i) for i in bnd[sel & (loop == lp)]))
    return out


# ----------------------------------------------------------------------------- findings
@dataclasses.dataclass
class _Ctx:
    """Arrays shared by the checks of one pattern."""

    cp: PatternLike
    tol: float
    cv: np.ndarray  # (K,) vertex of each face corner
    cf: np.ndarray  # (K,) face of each corner
    cn: np.ndarray  # (K,) index of the next corner in the same face
    faces_ok: bool = True
    nfaces_e: np.ndarray | None = None  # (m,) number of faces at each edge
    face_normal: np.ndarray | None = None  # (n_faces, 3) unit normals

    @property
    def E(self) -> np.ndarray:
        return self.cp.edges


def _edge_findings(c: _Ctx) -> list[Finding]:
    out: list[Finding] = []
    E, n, m, tol = c.E, c.cp.n_vertices, c.cp.n_edges, c.tol
    X = c.cp.vertices3d
    A = c.cp.assignment
    F = c.cp.fold_angles
    L = np.linalg.norm(X[E[:, 1]] - X[E[:, 0]], axis=1) if m else np.zeros(0)
    for e in np.flatnonzero(L <= tol):
        out.append(
            Finding(
                "zero-length-edge",
                f"edge {e} {E[e].tolist()} has length {L[e]:.3g}; expected more than "
                f"{tol:.3g} (merge its vertices with merge_tol)",
                int(e),
            )
        )
    key = np.minimum(E[:, 0], E[:, 1]) * n + np.maximum(E[:, 0], E[:, 1])
    first, second = _pairs_in_groups(key, np.arange(m))
    for e1, e2 in zip(first.tolist(), second.tolist(), strict=True):
        if A[e1] != A[e2] or F[e1] != F[e2]:
            out.append(
                Finding(
                    "duplicate-edge-conflict",
                    f"edges {e1} and {e2} join the same vertices {E[e1].tolist()} with "
                    f"different assignments/fold angles ({A[e1]} {F[e1]:g} vs {A[e2]} "
                    f"{F[e2]:g}); expected one edge",
                    (e1, e2),
                )
            )
        else:
            out.append(
                Finding(
                    "duplicate-edge",
                    f"edges {e1} and {e2} duplicate each other {E[e1].tolist()} "
                    "(repair with barhinge.pattern.validate.merged)",
                    (e1, e2),
                    "warning",
                )
            )

    return out


def _angle_findings(c: _Ctx) -> list[Finding]:
    out: list[Finding] = []
    A, F = c.cp.assignment, c.cp.fold_angles
    for e in np.flatnonzero((A == "M") & (F > 0)):
        out.append(
            Finding(
                "assignment-sign",
                f"edge {e} is a mountain (M) with fold angle {F[e]:g} deg; expected <= 0 "
                "(FOLD convention: valley > 0, mountain < 0)",
                int(e),
            )
        )
    for e in np.flatnonzero((A == "V") & (F < 0)):
        out.append(
            Finding(
                "assignment-sign",
                f"edge {e} is a valley (V) with fold angle {F[e]:g} deg; expected >= 0 "
                "(FOLD convention: valley > 0, mountain < 0)",
                int(e),
            )
        )
    for e in np.flatnonzero(np.abs(F) > 180):
        out.append(
            Finding(
                "fold-angle-range",
                f"edge {e} has fold angle {F[e]:g} deg; expected within [-180, 180]",
                int(e),
            )
        )

    return out


def _face_findings(c: _Ctx) -> list[Finding]:
    """Faces bounded by edges, simple, manifold, consistently oriented; sets c.faces_ok and
    c.nfaces_e."""
    out: list[Finding] = []
    cp, E, cv, cf, cn = c.cp, c.E, c.cv, c.cf, c.cn
    n, m, A = cp.n_vertices, cp.n_edges, cp.assignment
    faces_ok = True
    if len(cv):
        side_e = _edge_lookup(E, n, cv, cv[cn])
        for k in np.flatnonzero(side_e < 0)[:20]:
            faces_ok = False
            out.append(
                Finding(
                    "face-side-not-edge",
                    f"face {cf[k]} has side ({cv[k]}, {cv[cn[k]]}), which is not an edge; "
                    "expected every face to be bounded by edges",
                    int(cf[k]),
                )
            )
        fk = cf * n + cv
        u, cnt = np.unique(fk, return_counts=True)
        for k in u[cnt > 1][:20]:
            faces_ok = False
            out.append(
                Finding(
                    "face-repeated-vertex",
                    f"face {k // n} visits vertex {k % n} more than once; expected a simple loop",
                    int(k // n),
                )
            )
        ok = side_e >= 0
        se, sa = side_e[ok], cv[ok]
        left = E[se, 0] == sa  # face lies on the left of the edge's direction
        nl = np.bincount(se[left], minlength=m)
        nr = np.bincount(se[~left], minlength=m)
        for e in np.flatnonzero(nl + nr > 2):
            faces_ok = False
            out.append(
                Finding(
                    "non-manifold-edge",
                    f"edge {e} {E[e].tolist()} borders {nl[e] + nr[e]} faces; expected at most 2",
                    int(e),
                )
            )
        for e in np.flatnonzero((A == "B") & (nl == 1) & (nr == 1))[:20]:
            out.append(
                Finding(
                    "interior-boundary-edge",
                    f"edge {e} {E[e].tolist()} is assigned B but borders two faces; treated as "
                    "an unassigned crease (U), the sheet being continuous across it (assign C "
                    "for a cut)",
                    int(e),
                    "warning",
                )
            )
        for e in np.flatnonzero(((nl > 1) | (nr > 1)) & (nl + nr <= 2)):
            faces_ok = False
            out.append(
                Finding(
                    "face-orientation",
                    f"edge {e} {E[e].tolist()} is traversed in the same direction by both of "
                    "its faces; expected consistently oriented (counter-clockwise) faces",
                    int(e),
                )
            )
        nfaces_e = nl + nr
    else:
        nfaces_e = np.zeros(m, np.int64)
    if cp.n_faces:
        for e in np.flatnonzero(nfaces_e == 0)[:20]:
            out.append(
                Finding(
                    "edge-without-face",
                    f"edge {e} {E[e].tolist()} ({A[e]}) borders no face (dangling crease?)",
                    int(e),
                    "warning",
                )
            )
        for e in np.flatnonzero((nfaces_e == 1) & np.isin(A, ("M", "V")))[:20]:
            out.append(
                Finding(
                    "crease-on-boundary",
                    f"edge {e} {E[e].tolist()} is a crease ({A[e]}) with a face on one side "
                    "only; expected B on the boundary",
                    int(e),
                    "warning",
                )
            )
    if cp.n_faces == 0:
        if not m:
            why = "no edges either; expected a crease pattern with faces"
        elif cp.faces_found:
            why = "its edges enclose no area; expected faces bounded by its edges"
        else:
            why = (
                "the face list is empty (faces_vertices = []); expected faces bounded by its "
                "edges (omit faces_vertices to have them found from the edges)"
            )
        out.append(Finding("no-faces", f"the pattern has {m} edges but no faces: {why}", None))
    deg = np.bincount(E.ravel(), minlength=n) if m else np.zeros(n, np.int64)
    iso = np.flatnonzero(deg == 0)
    if len(iso):
        out.append(
            Finding(
                "isolated-vertex",
                f"{len(iso)} vertices (first: {iso[0]}) belong to no edge",
                int(iso[0]),
                "warning",
            )
        )

    c.faces_ok, c.nfaces_e = faces_ok, nfaces_e
    return out


def _geometry_findings(c: _Ctx) -> list[Finding]:
    """Zero-area and non-planar faces (vectorised Newell normals); sets c.face_normal."""
    out: list[Finding] = []
    cp, cv, cf, cn = c.cp, c.cv, c.cf, c.cn
    X = cp.vertices3d
    faces_ok = c.faces_ok
    face_normal = np.zeros((cp.n_faces, 3))
    if len(cv):
        c0 = X[np.asarray([f[0] for f in cp.faces])]
        P, Q = X[cv] - c0[cf], X[cv[cn]] - c0[cf]
        nf = cp.n_faces
        N = np.stack([np.bincount(cf, weights=w, minlength=nf) for w in np.cross(P, Q).T], 1)
        N *= 0.5
        area = np.linalg.norm(N, axis=1)
        per = np.bincount(cf, weights=np.linalg.norm(Q - P, axis=1), minlength=nf)
        for fi in np.flatnonzero(area <= AREA_TOL * per**2)[:20]:
            faces_ok = False
            out.append(
                Finding(
                    "zero-area-face",
                    f"face {fi} {list(cp.faces[fi])} has area {area[fi]:.3g}; expected a "
                    "face with positive area",
                    int(fi),
                )
            )
        nrm = N / np.where(area > 0, area, 1.0)[:, None]
        face_normal = nrm
        lens = np.bincount(cf, minlength=nf)
        cen = np.stack([np.bincount(cf, weights=w, minlength=nf) for w in P.T], 1) / lens[:, None]
        dev = np.abs(np.einsum("ij,ij->i", P - cen[cf], nrm[cf]))
        maxdev = np.zeros(nf)
        np.maximum.at(maxdev, cf, dev)
        for fi in np.flatnonzero((maxdev > REL_TOL * per) & (lens > 3))[:20]:
            out.append(
                Finding(
                    "non-planar-face",
                    f"face {fi} deviates from its plane by {maxdev[fi]:.3g}; expected a "
                    "planar face (triangulate it, or use validate=False for a bent state)",
                    int(fi),
                )
            )

    c.faces_ok, c.face_normal = faces_ok, face_normal
    return out


def _layout_findings(c: _Ctx) -> list[Finding]:
    """Flat crease-pattern states only: orientation, coincident vertices, crossings."""
    out: list[Finding] = []
    cp, E, tol, faces_ok, face_normal = c.cp, c.E, c.tol, c.faces_ok, c.face_normal
    V, n = cp.vertices, cp.n_vertices
    plane = pattern_plane(V, tol) if n else None
    layout = False
    if plane is not None and cp.n_faces and faces_ok:
        s = face_normal @ plane[1][2]
        if plane[1][2][2] != 1.0 and np.all(s < 0):  # plane normal sign is a convention
            plane = (plane[0], plane[1] * np.array([[1.0], [-1.0], [-1.0]]))
            s = -s
        if np.all(s < 0):
            out.append(
                Finding(
                    "face-orientation",
                    "every face is clockwise seen from +z; expected counter-clockwise faces",
                    0,
                )
            )
        elif np.any(s < 0) and np.any(s > 0):
            out.append(
                Finding(
                    "flat-folded",
                    "flat state with flipped faces (flat-folded): coincident vertices and "
                    "crossings are not checked",
                    None,
                    "info",
                )
            )
        else:
            layout = True
    elif plane is not None and cp.n_faces == 0:
        layout = True
    if layout and n:
        from scipy.spatial import cKDTree

        P2 = _project(V, plane)
        pairs = cKDTree(P2).query_pairs(r=tol, output_type="ndarray")
        for i, j in pairs[:20]:
            out.append(
                Finding(
                    "duplicate-vertex",
                    f"vertices {i} and {j} coincide (distance "
                    f"{np.linalg.norm(P2[i] - P2[j]):.3g} <= {tol:.3g}); expected distinct "
                    "vertices (repair with merge_tol / barhinge.pattern.validate.merged)",
                    (int(min(i, j)), int(max(i, j))),
                )
            )
        ok = E[:, 0] != E[:, 1]
        idx = np.flatnonzero(ok)
        for fnd in _crossings(P2, E[ok], tol)[:50]:
            ind = fnd.index
            if fnd.code == "crossing-edges":
                e1, e2 = int(idx[ind[0]]), int(idx[ind[1]])
                msg = fnd.message.replace(f"edges {ind[0]} and {ind[1]}", f"edges {e1} and {e2}")
                out.append(dataclasses.replace(fnd, index=(e1, e2), message=msg))
            else:
                v, e = ind[0], int(idx[ind[1]])
                msg = fnd.message.replace(f"edge {ind[1]} ", f"edge {e} ")
                out.append(dataclasses.replace(fnd, index=(v, e), message=msg))

    return out


def _sector_findings(c: _Ctx, developable: bool) -> list[Finding]:
    """Sector angles at interior vertices must sum to 360 deg (developability)."""
    out: list[Finding] = []
    cp, E, cv, cf, cn = c.cp, c.E, c.cv, c.cf, c.cn
    n, X, nfaces_e, face_normal = cp.n_vertices, cp.vertices3d, c.nfaces_e, c.face_normal
    if len(cv) and c.faces_ok:
        interior = np.zeros(n, bool)
        interior[E.ravel()] = True
        bad_e = nfaces_e != 2
        interior[E[bad_e].ravel()] = False
        P = X[cv[cn]] - X[cv]
        Q = X[cv[_prev(cn)]] - X[cv]
        # interior angle from the next side to the previous side, counter-clockwise about the
        # face normal: reflex corners of non-convex faces count more than 180 deg
        sgn = np.einsum("ij,ij->i", np.cross(P, Q), face_normal[cf])
        ang = np.mod(np.arctan2(sgn, np.einsum("ij,ij->i", P, Q)), 2 * np.pi)
        total = np.bincount(cv, weights=ang, minlength=n)
        dev = np.degrees(total - 2 * np.pi)
        badv = np.flatnonzero(interior & (np.abs(dev) > ANGLE_TOL_DEG))
        sev: Severity = "error" if developable else "info"
        for v in badv[:20] if developable else badv[:5]:
            out.append(
                Finding(
                    "not-developable",
                    f"sector angles at interior vertex {v} sum to {np.degrees(total[v]):.6g} "
                    "deg; expected 360 (pass developable=False for a non-developable pattern)",
                    int(v),
                    sev,
                )
            )
        if len(badv) > 5 and not developable:
            out.append(
                Finding(
                    "not-developable",
                    f"{len(badv)} interior vertices are not developable (allowed: "
                    "developable=False)",
                    None,
                    "info",
                )
            )

    return out


def findings(cp: PatternLike, *, developable: bool | None = None) -> list[Finding]:
    """Every problem found in ``cp`` (errors first, then warnings and notes).

    Parameters
    ----------
    cp : CreasePattern
    developable : bool, optional
        Overrides ``cp.developable``: require the sector angles at every interior vertex to sum
        to 360 deg (an error when violated; a note when ``False``).

    Returns
    -------
    list of Finding
    """
    if developable is None:
        developable = cp.developable
    if not np.isfinite(cp.size):
        return [
            Finding(
                "coordinates-overflow",
                "vertex coordinates are too large (the bounding box diagonal overflows); "
                "expected finite lengths",
                None,
            )
        ]
    c = _Ctx(cp, REL_TOL * cp.size, *_corners(cp.faces))
    out = _edge_findings(c) + _angle_findings(c) + _face_findings(c)
    out += _geometry_findings(c) + _layout_findings(c) + _sector_findings(c, developable)
    faces_ok = c.faces_ok
    # ---- holes
    if faces_ok and cp.n_faces:
        try:
            for loop in holes(cp):
                out.append(
                    Finding(
                        "hole",
                        f"hole bounded by {len(loop)} edges (first: edge {loop[0]})",
                        int(loop[0]),
                        "info",
                    )
                )
        except PatternError:  # pragma: no cover - faces were checked above
            pass

    rank = {"error": 0, "warning": 1, "info": 2}
    out.sort(key=lambda f: rank[f.severity])
    return out


def _prev(nxt: np.ndarray) -> np.ndarray:
    prv = np.empty_like(nxt)
    prv[nxt] = np.arange(len(nxt))
    return prv


def check(cp: PatternLike, *, developable: bool | None = None) -> None:
    """Raise :class:`PatternError` with a one-line message for the first error in ``cp``."""
    for f in findings(cp, developable=developable):
        if f.severity == "error":
            raise PatternError(f.message)


# ----------------------------------------------------------------------------- repair
def merged_arrays(V, E, A, F, faces, tol: float | None):
    """Merge vertices closer than ``tol``; drop zero-length and duplicate edges.

    Parameters
    ----------
    V : (n, d) float ; E : (m, 2) int ; A : (m,) str ; F : (m,) float degrees
    faces : sequence of loops or None
    tol : float or None
        Absolute merge distance (length unit); None uses ``REL_TOL * size``.

    Returns
    -------
    (V, E, A, F, faces) with vertices renumbered in order of first occurrence. Each merged
    vertex keeps the coordinates of its lowest-numbered member. Duplicate edges must agree
    in assignment and fold angle (PatternError otherwise).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    V = np.asarray(V, float)
    E = np.asarray(E, np.int64).reshape(-1, 2)
    n = len(V)
    if tol is None:
        with np.errstate(over="ignore"):
            size = float(np.linalg.norm(np.ptp(V, axis=0))) if n else 0.0
        tol = REL_TOL * size
    if tol < 0 or not np.isfinite(tol):
        raise PatternError(f"merge_tol must be a finite length >= 0, got {tol}")
    if n:
        pairs = cKDTree(V).query_pairs(r=tol, output_type="ndarray")
        g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, lab = connected_components(g, directed=False)
    else:
        lab = np.zeros(0, np.int64)
    # representative = lowest index of each cluster; renumber in order of representatives
    rep = np.full(lab.max() + 1 if n else 0, n, np.int64)
    np.minimum.at(rep, lab, np.arange(n))
    order = np.argsort(rep)
    newid = np.empty_like(order)
    newid[order] = np.arange(len(order))
    vmap = newid[lab]
    V2 = V[rep[order]]
    E2 = vmap[E]
    keep = E2[:, 0] != E2[:, 1]
    A = np.asarray(A)
    F = np.asarray(F, float)
    key = np.minimum(E2[:, 0], E2[:, 1]) * max(len(V2), 1) + np.maximum(E2[:, 0], E2[:, 1])
    p, q = _pairs_in_groups(np.where(keep, key, -1 - np.arange(len(E2))), np.arange(len(E2)))
    for e1, e2 in zip(p.tolist(), q.tolist(), strict=True):
        if A[e1] != A[e2] or F[e1] != F[e2]:
            raise PatternError(
                f"edges {e1} and {e2} become the same edge after merging but have different "
                f"assignments/fold angles ({A[e1]} {F[e1]:g} vs {A[e2]} {F[e2]:g})"
            )
        keep[max(e1, e2)] = False
    faces2 = None
    if faces is not None:
        faces2 = []
        for f in faces:
            loop = [int(vmap[v]) for v in f]
            loop = [v for i, v in enumerate(loop) if v != loop[i - 1]] if len(loop) > 1 else loop
            if len(loop) >= 3:
                faces2.append(loop)
    return V2, E2[keep], A[keep], F[keep], faces2


def merged(cp: _P, tol: float | None = None, *, derive_faces: bool | None = None) -> _P:
    """A repaired copy of ``cp``.

    Vertices closer than ``tol`` (default ``REL_TOL * size``) are merged and zero-length and
    duplicate edges removed, then the faces are settled: found again from the planar graph
    of the merged pattern when ``derive_faces`` is True, or when it is None (default) and
    ``cp``'s faces were found rather than given (:attr:`CreasePattern.faces_found`); the
    given faces renumbered otherwise (loops that collapse below three vertices are
    dropped). Finding faces needs a flat pattern, and turns a hole into a face.
    """
    tol = tol if tol is not None else REL_TOL * cp.size
    if derive_faces is None:
        derive_faces = cp.faces_found
    return cp.replaced(merge_tol=tol, faces=None if derive_faces else cp.faces)
