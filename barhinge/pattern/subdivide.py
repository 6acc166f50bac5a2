"""Panel subdivision: every face cut into ``m x m`` smaller faces by flat ``F`` lines.

Quadrilaterals are cut along their bilinear grid (``s, t = i/m, j/m``; a planar quadrilateral
gives planar sub-faces), triangles along their barycentric grid (``m^2`` triangles). Every
pattern edge is cut into ``m`` equal segments that keep its assignment and fold angle; the new
lines inside a face are ``F`` at fold angle 0. The pattern's vertices keep their ids
(``0 .. n_vertices - 1``); the state is unchanged (the same surface, more lines), so a
bar-and-hinge model of the subdivided pattern resolves the panels' own bending and
stretching ``m`` times finer.

With ``grading`` ``p > 1`` the grid lines of quadrilateral faces crowd towards their
corners, where the stresses of a folded plate concentrate (corners of supported edges, crease
ends): every grid coordinate ``x = i/m`` becomes ``g(x) = x^p / (x^p + (1 - x)^p)``
(:func:`corner_graded`). ``g(1 - x) = 1 - g(x)``, so an edge is cut at the same points from
either end and neighbouring faces share them; a parallelogram's cells stay parallelograms.
The shell reference of :mod:`barhinge.model.shell` grades its facet meshes the same way.
Triangles are not graded (a pattern with triangular faces and ``grading > 1`` is refused).
The coupled plate rule (:func:`barhinge.model.plate_hinges.coupled_bending`) reads the
neighbours of a graded triangle grid where they are and passes its patch test there, but
its triangles converge at first order even on a smooth plate, and a graded barycentric grid
(every barycentric coordinate graded as above and renormalised) converged more slowly than
the equal one on Navier's simply supported square plate: the cells it crowds along the
edges are slender.
"""

from __future__ import annotations

import numpy as np

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = ["corner_graded", "subdivided", "subdivided_size"]


def corner_graded(x: np.ndarray, grading: float) -> np.ndarray:
    """``x^p / (x^p + (1 - x)^p)`` with ``p = grading``: points of [0, 1] moved towards its
    ends (``p = 1``: unchanged); symmetric, ``g(1 - x) = 1 - g(x)``."""
    x = np.asarray(x, float)
    a, b = x**grading, (1.0 - x) ** grading
    return a / (a + b)


def subdivided(cp: CreasePattern, m: int, grading: float = 1.0) -> tuple[CreasePattern, np.ndarray]:
    """The pattern ``cp`` with every face cut ``m`` times along each side (module docstring;
    ``grading`` >= 1 crowds the cuts of quadrilateral faces towards their corners, 1: equal
    cuts).

    Returns
    -------
    cp_m : CreasePattern
    parent_edge : (cp_m.n_vertices,) int
        Edge of ``cp`` each new vertex lies on; -1 for vertices inside faces and for the
        original vertices (ids ``0 .. cp.n_vertices - 1``).
    """
    if not isinstance(m, (int, np.integer)) or m < 1:
        raise PatternError(f"subdivision m = {m!r}; expected an integer >= 1")
    if not grading >= 1.0:
        raise PatternError(f"subdivision grading = {grading!r}; expected a number >= 1")
    if grading != 1.0 and any(len(f) != 4 for f in cp.faces):
        raise PatternError(
            f"subdivision grading = {grading!r} applies to quadrilateral faces only; this "
            "pattern has other faces (subdivide it with grading = 1)"
        )
    if m == 1:
        return cp, np.full(cp.n_vertices, -1, np.int64)
    V = np.asarray(cp.vertices3d, float)
    nv = len(V)
    E = np.asarray(cp.edges, np.int64)
    ekey = {(min(a, b), max(a, b)): e for e, (a, b) in enumerate(E)}
    pts: list[np.ndarray] = [V]
    pedge: list[np.ndarray] = [np.full(nv, -1, np.int64)]
    # edge points, oriented from the lower to the higher vertex id
    edge_pts = {}
    base = nv
    for e, (a, b) in enumerate(E):
        lo, hi = min(a, b), max(a, b)
        s = corner_graded(np.arange(1, m)[:, None] / m, grading)
        pts.append((1 - s) * V[lo] + s * V[hi])
        pedge.append(np.full(m - 1, e, np.int64))
        edge_pts[e] = np.concatenate([[lo], base + np.arange(m - 1), [hi]])
        base += m - 1

    def on_edge(a: int, b: int) -> np.ndarray:
        """Ids of the m + 1 points from vertex a to vertex b."""
        key = (min(a, b), max(a, b))
        if key not in ekey:
            raise PatternError(f"face side {a}-{b} is not an edge of the pattern")
        ids = edge_pts[ekey[key]]
        return ids if a < b else ids[::-1]

    faces: list[list[int]] = []
    new_lines: set[tuple[int, int]] = set()
    for fi, face in enumerate(cp.faces):
        F = list(face)
        if len(F) == 4:
            g = np.full((m + 1, m + 1), -1, np.int64)  # g[i, j]: s = i/m, t = j/m
            g[:, 0] = on_edge(F[0], F[1])
            g[m, :] = on_edge(F[1], F[2])
            g[:, m] = on_edge(F[3], F[2])
            g[0, :] = on_edge(F[0], F[3])
            s = corner_graded(np.arange(1, m) / m, grading)
            S, T = np.meshgrid(s, s, indexing="ij")
            P = V[F]
            X = (
                ((1 - S) * (1 - T))[..., None] * P[0]
                + (S * (1 - T))[..., None] * P[1]
                + (S * T)[..., None] * P[2]
                + ((1 - S) * T)[..., None] * P[3]
            ).reshape(-1, 3)
            g[1:m, 1:m] = (base + np.arange(len(X))).reshape(m - 1, m - 1)
            base += len(X)
            pts.append(X)
            pedge.append(np.full(len(X), -1, np.int64))
            for i in range(m):
                for j in range(m):
                    faces.append([g[i, j], g[i + 1, j], g[i + 1, j + 1], g[i, j + 1]])
            for i in range(1, m):
                for j in range(m):
                    new_lines.add(tuple(sorted((int(g[i, j]), int(g[i, j + 1])))))
                    new_lines.add(tuple(sorted((int(g[j, i]), int(g[j + 1, i])))))
        elif len(F) == 3:
            # barycentric grid: point (i, j) = P0 + i/m (P1 - P0) + j/m (P2 - P0), i + j <= m
            idx = {}
            e01, e02, e12 = on_edge(F[0], F[1]), on_edge(F[0], F[2]), on_edge(F[1], F[2])
            for i in range(m + 1):
                idx[(i, 0)] = e01[i]
                idx[(0, i)] = e02[i]
                idx[(m - i, i)] = e12[i]
            P = V[F]
            inner = [(i, j) for i in range(1, m) for j in range(1, m - i)]
            for i, j in inner:
                idx[(i, j)] = base
                pts.append((P[0] + i / m * (P[1] - P[0]) + j / m * (P[2] - P[0]))[None])
                pedge.append(np.array([-1], np.int64))
                base += 1
            for i in range(m):
                for j in range(m - i):
                    faces.append([idx[(i, j)], idx[(i + 1, j)], idx[(i, j + 1)]])
                    if i + j < m - 1:
                        faces.append([idx[(i + 1, j)], idx[(i + 1, j + 1)], idx[(i, j + 1)]])
            for i in range(m + 1):
                for j in range(m + 1 - i):
                    for di, dj in ((1, 0), (0, 1), (-1, 1)):
                        a, b = (i, j), (i + di, j + dj)
                        if b in idx and not _on_side(a, b, m):
                            new_lines.add(tuple(sorted((int(idx[a]), int(idx[b])))))
        else:
            raise PatternError(
                f"face {fi} has {len(F)} corners; subdivision cuts triangles and "
                "quadrilaterals (triangulate the others first)"
            )
    X = np.vstack(pts)
    rho = np.asarray(cp.fold_angles, float)
    edges, asg, fold = [], [], []
    for e in range(len(E)):
        ids = edge_pts[e]
        for k in range(m):
            edges.append((int(ids[k]), int(ids[k + 1])))
            asg.append(str(cp.assignment[e]))
            fold.append(float(rho[e]))
    for a, b in sorted(new_lines):
        edges.append((a, b))
        asg.append("F")
        fold.append(0.0)
    out = CreasePattern(
        vertices=X,
        edges=np.array(edges, np.int64),
        assignment=np.array(asg),
        fold_angles=np.array(fold),
        faces=faces,
        developable=cp.developable,
    )
    return out, np.concatenate(pedge)


def subdivided_size(cp: CreasePattern, m: int) -> tuple[int, int]:
    """(vertices, quadrilateral faces) of ``subdivided(cp, m)``, counted without building it.

    Each edge gains ``m - 1`` points, each quadrilateral ``(m - 1)^2`` inner points and
    ``m^2`` faces, each triangle ``(m - 1)(m - 2) / 2`` inner points and ``m^2`` faces. An N5B8
    model of the subdivided pattern has ``3 (vertices + quadrilaterals)`` DOFs (one centre
    node per quadrilateral), which is how a refinement plans its next level against a
    memory budget.
    """
    if not isinstance(m, (int, np.integer)) or m < 1:
        raise PatternError(f"subdivision m = {m!r}; expected an integer >= 1")
    sizes = np.array([len(f) for f in cp.faces])
    n_quad, n_tri = int((sizes == 4).sum()), int((sizes == 3).sum())
    if n_quad + n_tri != len(sizes) and m > 1:
        raise PatternError("subdivision cuts triangles and quadrilaterals only")
    m = int(m)
    n_v = cp.n_vertices + cp.n_edges * (m - 1) + n_quad * (m - 1) ** 2
    n_v += n_tri * (m - 1) * (m - 2) // 2
    return n_v, n_quad * m * m


def _on_side(a: tuple[int, int], b: tuple[int, int], m: int) -> bool:
    """Both barycentric grid points on the same side of the triangle."""
    return (a[1] == 0 and b[1] == 0) or (a[0] == 0 and b[0] == 0) or (sum(a) == m and sum(b) == m)
