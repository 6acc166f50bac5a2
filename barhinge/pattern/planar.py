"""Faces of a planar straight-line graph (half-edge traversal).

Every undirected edge ``(a, b)`` gives two half-edges ``a -> b`` and ``b -> a``. Around each
vertex the outgoing half-edges are sorted by angle; the half-edge that follows ``u -> v`` on
the boundary of the face to its left is the outgoing half-edge of ``v`` just clockwise of
``v -> u``. The cycles of this "next" permutation are the face boundaries: bounded faces come
out counter-clockwise (positive signed area), the outer boundary of each connected component
clockwise (negative area), and those are dropped.
"""

from __future__ import annotations

import numpy as np

from barhinge.errors import PatternError

__all__ = ["planar_faces", "half_edge_cycles", "pattern_plane", "signed_areas"]


def _pruned(n: int, edges: np.ndarray) -> np.ndarray:
    """(m,) bool: edges that survive iterative removal of degree-1 vertices (dangling
    creases bound no face)."""
    keep = np.ones(len(edges), bool)
    while True:
        deg = np.bincount(edges[keep].ravel(), minlength=n)
        dangling = keep & ((deg[edges[:, 0]] <= 1) | (deg[edges[:, 1]] <= 1))
        if not dangling.any():
            return keep
        keep &= ~dangling


def half_edge_cycles(vertices: np.ndarray, edges: np.ndarray) -> list[np.ndarray]:
    """All face cycles (as vertex loops) of the planar graph, including outer boundaries.

    Parameters
    ----------
    vertices : (n, 2) float
    edges : (m, 2) int
        Edges without duplicates, self-loops or crossings.

    Returns
    -------
    list of (k,) int arrays
        One loop per cycle of the half-edge "next" permutation; bounded faces are
        counter-clockwise, outer boundaries clockwise.
    """
    V = np.asarray(vertices, float)[:, :2]
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    m = len(E)
    if m == 0:
        return []
    org = np.concatenate([E[:, 0], E[:, 1]])  # half-edge h < m: a->b ; h >= m: b->a
    dst = np.concatenate([E[:, 1], E[:, 0]])
    twin = np.concatenate([np.arange(m, 2 * m), np.arange(m)])
    d = V[dst] - V[org]
    ang = np.arctan2(d[:, 1], d[:, 0])
    order = np.lexsort((ang, org))  # grouped by origin, ccw by angle
    org_sorted = org[order]
    start = np.searchsorted(org_sorted, org_sorted, side="left")
    count = np.bincount(org, minlength=len(V))[org_sorted]
    # clockwise neighbour (previous in ccw order, cyclic within the vertex group)
    prev_sorted = order[start + (np.arange(2 * m) - start - 1) % count]
    cw = np.empty(2 * m, np.int64)
    cw[order] = prev_sorted
    nxt = cw[twin]
    seen = np.zeros(2 * m, bool)
    cycles = []
    nxt_l = nxt.tolist()
    org_l = org.tolist()
    for h0 in range(2 * m):
        if seen[h0]:
            continue
        loop = []
        h = h0
        while not seen[h]:
            seen[h] = True
            loop.append(org_l[h])
            h = nxt_l[h]
        cycles.append(np.array(loop, np.int64))
    return cycles


def signed_areas(vertices: np.ndarray, loops: list) -> np.ndarray:
    """(k,) float: signed area (shoelace) of each vertex loop in the xy plane, positive for
    counter-clockwise loops."""
    V = np.asarray(vertices, float)
    if not len(loops):
        return np.zeros(0)
    lens = np.array([len(f) for f in loops])
    flat = np.concatenate([np.asarray(f, np.int64) for f in loops])
    starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
    idx = np.arange(len(flat))
    fid = np.repeat(np.arange(len(loops)), lens)
    nxt = np.where(idx + 1 == starts[fid] + lens[fid], starts[fid], idx + 1)
    P, Q = V[flat], V[flat[nxt]]
    # shift by the loop's first vertex to limit round-off on large coordinates
    O = V[flat[starts[fid]]]
    cross = (P[:, 0] - O[:, 0]) * (Q[:, 1] - O[:, 1]) - (P[:, 1] - O[:, 1]) * (Q[:, 0] - O[:, 0])
    return 0.5 * np.bincount(fid, weights=cross, minlength=len(loops))


def pattern_plane(X: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Plane holding every vertex, or None.

    Returns ``(origin (3,), basis (3, 3))`` with rows ``u, w, n`` (``n`` the unit normal,
    ``u x w = n``); ``n = +z`` when the pattern lies in a plane z = const.
    """
    X = np.asarray(X, float)
    if X.shape[1] == 2 or len(X) == 0:
        return np.zeros(3), np.eye(3)
    c = X.mean(0)
    if np.all(np.abs(X[:, 2] - c[2]) <= tol):
        return c, np.eye(3)
    if len(X) < 3:
        return None
    _, _, vt = np.linalg.svd(X - c, full_matrices=False)
    n = vt[2]
    if np.max(np.abs((X - c) @ n)) > tol:
        return None
    # canonical sign: n_z > 0, else n_y > 0, else n_x > 0
    for k in (2, 1, 0):
        if abs(n[k]) > 1e-12:
            n = n if n[k] > 0 else -n
            break
    u = vt[0]
    w = np.cross(n, u)
    return c, np.array([u, w, n])


def planar_faces(vertices: np.ndarray, edges: np.ndarray) -> list[list[int]]:
    """Counter-clockwise bounded faces of a planar straight-line graph.

    Parameters
    ----------
    vertices : (n, 2) float
        Vertex coordinates. Three columns are allowed when all vertices lie in one plane;
        faces are then counter-clockwise about its normal ``n`` (``+z`` for a plane z = const;
        otherwise the sign with ``n_z > 0``, else ``n_y > 0``, else ``n_x > 0``).
    edges : (m, 2) int
        Vertex indices per edge. Edges must not cross except at shared vertices (validation
        reports crossings); dangling edges (ending at a degree-1 vertex) bound no face and are
        ignored, duplicate edges are used once.

    Returns
    -------
    list of list of int
        Vertex loops of the bounded faces, counter-clockwise (positive signed area). The
        outer boundary of every connected component (a clockwise cycle) is dropped. A
        component lying inside a face of another one is not merged into it: the enclosing
        face is returned as its outer loop (the inner component then covers part of it).
    """
    V = np.asarray(vertices, float)
    if V.ndim != 2 or V.shape[1] not in (2, 3):
        raise PatternError(f"vertices must have shape (n, 2) or (n, 3), got {V.shape}")
    E = np.asarray(edges)
    if E.size == 0 or len(V) == 0:
        return []
    if V.shape[1] == 3:
        size = float(np.linalg.norm(np.ptp(V, axis=0)))
        plane = pattern_plane(V, 1e-6 * size)
        if plane is None:
            raise PatternError(
                "faces are missing and the vertices do not lie in one plane; expected "
                "faces_vertices for a folded (3-D) state"
            )
        V = (V - plane[0]) @ plane[1][:2].T
    E = E.astype(np.int64).reshape(-1, 2)
    if E.min() < 0 or E.max() >= len(V):
        raise PatternError(f"edges reference vertices outside 0..{len(V) - 1}")
    E = E[E[:, 0] != E[:, 1]]
    E = np.unique(np.sort(E, axis=1), axis=0)
    E = E[_pruned(len(V), E)]
    cycles = half_edge_cycles(V, E)
    if not cycles:
        return []
    area = signed_areas(V, cycles)
    scale = float(np.ptp(V[:, :2], axis=0).max()) if len(V) else 0.0
    tiny = 1e-14 * scale * scale
    faces = [c for c, a in zip(cycles, area, strict=True) if a > tiny]
    outer = [c for c, a in zip(cycles, area, strict=True) if a <= tiny]
    if len(outer) > 1 and faces:
        _check_nesting(V, E, faces, outer)
    return [c.tolist() for c in faces]


def _check_nesting(V: np.ndarray, E: np.ndarray, faces: list, outer: list) -> None:
    """Raise PatternError if a connected part lies inside a face of another part: that face
    would have a hole, which a single vertex loop cannot describe."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(V)
    g = coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    _, comp = connected_components(g, directed=False)
    lens = np.array([len(f) for f in faces])
    flat = np.concatenate(faces)
    fid = np.repeat(np.arange(len(faces)), lens)
    starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
    idx = np.arange(len(flat))
    nxt = np.where(idx + 1 == starts[fid] + lens[fid], starts[fid], idx + 1)
    a, b = V[flat], V[flat[nxt]]
    fcomp = comp[flat[starts]]
    for c in outer:
        v = int(c[np.argmin(V[c, 0])])
        px, py = V[v, 0], V[v, 1]
        straddle = (a[:, 1] > py) != (b[:, 1] > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = a[:, 0] + (py - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        hits = np.bincount(fid[straddle & (px < xc)], minlength=len(faces))
        inside = np.flatnonzero((hits % 2 == 1) & (fcomp != comp[v]))
        if len(inside):
            raise PatternError(
                f"the part of the pattern containing vertex {v} lies inside face "
                f"{faces[inside[0]].tolist()[:6]}... of another part; expected connected "
                "creases (a face with a hole cannot be described; connect the parts)"
            )
