"""Shared helpers of the pattern generators: parameter checks, edges from faces, assembly.

Every generator builds vertices and counter-clockwise faces (seen from +z in the flat state),
derives the edge list from the faces (boundary edges get ``B``), sets the assignment per crease
and returns a validated :class:`~barhinge.pattern.crease.CreasePattern`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from barhinge._json import jsonable
from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = [
    "GridLayout",
    "build_pattern",
    "check_int",
    "check_range",
    "edges_from_faces",
    "grid_layout",
    "mv_assignment",
]


# ------------------------------------------------------------------------ checks
def check_range(
    name: str,
    value: float,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = True,
    hi_open: bool = True,
    family: str = "",
) -> float:
    """Return ``float(value)`` or raise PatternError naming ``name`` and the valid range."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise PatternError(f"{_who(family)}{name} must be a number, got {value!r}") from None
    ok = math.isfinite(v)
    if ok and lo is not None:
        ok = v > lo if lo_open else v >= lo
    if ok and hi is not None:
        ok = v < hi if hi_open else v <= hi
    if not ok:
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise PatternError(
            f"{_who(family)}{name} = {value!r} is outside the valid range "
            f"{left}{lo_s}, {hi_s}{right}"
        )
    return v


def check_int(
    name: str, value: Any, lo: int = 1, hi: int | None = None, *, family: str = ""
) -> int:
    """Return ``int(value)`` if it is an integer in [lo, hi], else raise PatternError."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise PatternError(f"{_who(family)}{name} must be an integer, got {value!r}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        rng = f"[{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise PatternError(f"{_who(family)}{name} = {v} is outside the valid range {rng}")
    return v


def _who(family: str) -> str:
    return f"{family}: " if family else ""


# ------------------------------------------------------------------ topology
def edges_from_faces(faces: Sequence[Sequence[int]] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unique edges of a set of face loops.

    Parameters
    ----------
    faces : (k, p) int array or sequence of int sequences
        Vertex loops.

    Returns
    -------
    edges : (m, 2) int
        Sorted vertex pairs (smaller index first), in lexicographic order.
    n_faces : (m,) int
        Number of faces using each edge (1 on the boundary, 2 inside).
    """
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        F = faces
        a = F.ravel()
        b = np.roll(F, -1, axis=1).ravel()
    else:
        a = np.concatenate([np.asarray(f) for f in faces])
        b = np.concatenate([np.roll(np.asarray(f), -1) for f in faces])
    pairs = np.column_stack([np.minimum(a, b), np.maximum(a, b)]).astype(np.int64)
    edges, counts = np.unique(pairs, axis=0, return_counts=True)
    if (counts > 2).any():
        bad = edges[np.flatnonzero(counts > 2)[0]]
        raise PatternError(f"edge {bad.tolist()} is shared by more than two faces")
    return edges, counts


def mv_assignment(reference_rho_deg: np.ndarray, boundary: np.ndarray) -> np.ndarray:
    """Assignment letters of a generated family from a reference folded state.

    Parameters
    ----------
    reference_rho_deg : (n_edges,) float
        Signed fold angles of any folded state of the family's branch, degrees (valley > 0).
    boundary : (n_edges,) bool
        Boundary edges.

    Returns
    -------
    (n_edges,) str
        ``"V"`` where the reference folds as a valley (rho > 0), ``"M"`` elsewhere, ``"B"``
        on the boundary.
    """
    A = np.where(np.asarray(reference_rho_deg) > 0, "V", "M").astype("<U1")
    A[np.asarray(boundary, dtype=bool)] = "B"
    return A


def build_pattern(
    vertices: np.ndarray,
    faces: Sequence[Sequence[int]] | np.ndarray,
    *,
    edges: np.ndarray | None = None,
    assignment: np.ndarray | None = None,
    fold_angles: np.ndarray | None = None,
    family: str,
    parameters: dict[str, Any],
    developable: bool = True,
    extra_meta: dict[str, Any] | None = None,
) -> CreasePattern:
    """Assemble a CreasePattern with the family name and parameters in ``meta``.

    When ``edges`` is None the edges come from :func:`edges_from_faces`. When ``assignment``
    is None it must be given per edge later (callers pass it). Boundary edges (one face) are
    forced to ``B`` with fold angle 0.
    """
    if edges is None:
        edges, counts = edges_from_faces(faces)
    else:
        counts = None
    if assignment is None:
        raise PatternError(f"{family}: internal error, no assignment given")
    A = np.asarray(assignment).astype("<U1").copy()
    F = np.zeros(len(edges)) if fold_angles is None else np.asarray(fold_angles, float).copy()
    if counts is not None:
        A[counts == 1] = "B"
        F[counts == 1] = 0.0
    face_list = faces.tolist() if isinstance(faces, np.ndarray) else [list(f) for f in faces]
    meta: dict[str, Any] = {
        "frame_title": f"{family} " + " ".join(f"{k}={_fmt(v)}" for k, v in parameters.items()),
        "barhinge:family": family,
        "barhinge:parameters": {k: jsonable(v) for k, v in parameters.items()},
    }
    if extra_meta:
        meta.update(extra_meta)
    return CreasePattern(
        vertices=np.asarray(vertices, float),
        edges=np.asarray(edges, np.int64),
        assignment=A,
        fold_angles=F,
        faces=face_list,
        developable=developable,
        meta=meta,
    )


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_fmt(x) for x in v) + "]"
    return str(v)


# -------------------------------------------------------------- grid layouts
@dataclasses.dataclass(frozen=True)
class GridLayout:
    """Index map of a structured quad grid of (ni x nj) vertices.

    Vertex ``(i, j)`` (``i`` = column along x, ``j`` = row along y) has id ``j * ni + i``.
    Edge ids follow the generator's order: first the ``(ni - 1) * nj`` "row" edges
    ``(i, j) - (i + 1, j)`` with id ``j * (ni - 1) + i``, then the ``ni * (nj - 1)`` "column"
    edges ``(i, j) - (i, j + 1)`` with id ``n_row_edges + j * ni + i``.
    """

    ni: int
    nj: int

    def vertex(self, i: int | np.ndarray, j: int | np.ndarray) -> int | np.ndarray:
        """Vertex id of grid point (i, j) (negative indices count from the end)."""
        i = np.asarray(i) % self.ni
        j = np.asarray(j) % self.nj
        out = j * self.ni + i
        return int(out) if out.ndim == 0 else out

    @property
    def n_row_edges(self) -> int:
        return (self.ni - 1) * self.nj

    def row_edge(self, i: int | np.ndarray, j: int | np.ndarray) -> int | np.ndarray:
        """Edge id of (i, j) - (i + 1, j)."""
        out = np.asarray(j) * (self.ni - 1) + np.asarray(i)
        return int(out) if out.ndim == 0 else out

    def column_edge(self, i: int | np.ndarray, j: int | np.ndarray) -> int | np.ndarray:
        """Edge id of (i, j) - (i, j + 1)."""
        out = self.n_row_edges + np.asarray(j) * self.ni + np.asarray(i)
        return int(out) if out.ndim == 0 else out

    @property
    def row_edges(self) -> np.ndarray:
        """(n,) int: all row edges (along x)."""
        return np.arange(self.n_row_edges)

    @property
    def column_edges(self) -> np.ndarray:
        """(n,) int: all column edges (along y)."""
        return np.arange(self.n_row_edges, self.n_row_edges + self.ni * (self.nj - 1))

    # boundary groups (vertices in increasing i or j)
    @property
    def left(self) -> np.ndarray:
        """Vertices with i = 0 (ordered by j)."""
        return np.arange(self.nj) * self.ni

    @property
    def right(self) -> np.ndarray:
        """Vertices with i = ni - 1 (ordered by j)."""
        return np.arange(self.nj) * self.ni + self.ni - 1

    @property
    def bottom(self) -> np.ndarray:
        """Vertices with j = 0 (ordered by i)."""
        return np.arange(self.ni)

    @property
    def top(self) -> np.ndarray:
        """Vertices with j = nj - 1 (ordered by i)."""
        return (self.nj - 1) * self.ni + np.arange(self.ni)

    @property
    def left_edges(self) -> np.ndarray:
        return self.column_edge(0, np.arange(self.nj - 1))

    @property
    def right_edges(self) -> np.ndarray:
        return self.column_edge(self.ni - 1, np.arange(self.nj - 1))

    @property
    def bottom_edges(self) -> np.ndarray:
        return self.row_edge(np.arange(self.ni - 1), 0)

    @property
    def top_edges(self) -> np.ndarray:
        return self.row_edge(np.arange(self.ni - 1), self.nj - 1)

    def edges(self) -> np.ndarray:
        """(m, 2) int: row edges then column edges, in id order."""
        I, J = np.meshgrid(np.arange(self.ni - 1), np.arange(self.nj), indexing="xy")
        row = np.column_stack(
            [self.vertex(I.ravel(), J.ravel()), self.vertex(I.ravel() + 1, J.ravel())]
        )
        I, J = np.meshgrid(np.arange(self.ni), np.arange(self.nj - 1), indexing="xy")
        col = np.column_stack(
            [self.vertex(I.ravel(), J.ravel()), self.vertex(I.ravel(), J.ravel() + 1)]
        )
        return np.vstack([row, col]).astype(np.int64)

    def quads(self) -> np.ndarray:
        """(k, 4) int: faces (i,j),(i+1,j),(i+1,j+1),(i,j+1), face id ``j * (ni - 1) + i``
        (counter-clockwise when x grows with i and y with j)."""
        I, J = np.meshgrid(np.arange(self.ni - 1), np.arange(self.nj - 1), indexing="xy")
        i, j = I.ravel(), J.ravel()
        return np.column_stack(
            [
                self.vertex(i, j),
                self.vertex(i + 1, j),
                self.vertex(i + 1, j + 1),
                self.vertex(i, j + 1),
            ]
        ).astype(np.int64)

    def boundary_mask(self) -> np.ndarray:
        """(m,) bool over :meth:`edges`: True on the outer boundary."""
        m = np.zeros(self.n_row_edges + self.ni * (self.nj - 1), bool)
        for g in (self.left_edges, self.right_edges, self.bottom_edges, self.top_edges):
            m[g] = True
        return m


def grid_layout(cp: CreasePattern) -> GridLayout:
    """The :class:`GridLayout` of a pattern made by a grid-based generator (Miura family,
    Yoshimura-free grids, pleats); PatternError if ``cp`` does not carry one."""
    g = cp.meta.get("barhinge:grid")
    if not g or len(g) != 2:
        raise PatternError("pattern has no 'barhinge:grid' entry in meta; not a grid pattern")
    lay = GridLayout(int(g[0]), int(g[1]))
    if lay.ni * lay.nj != cp.n_vertices:
        raise PatternError(
            f"meta 'barhinge:grid' = {g} implies {lay.ni * lay.nj} vertices, "
            f"but the pattern has {cp.n_vertices}"
        )
    return lay


# ------------------------------------------------------------ folded geometry
def fold_angles_of(X: np.ndarray, faces: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Signed fold angles (degrees, FOLD convention, valley > 0) of ``edges`` in the geometry
    ``X`` (n, 3) for uniform-arity faces ``(k, p)`` (vectorised; 0 on boundary edges).

    Same definition as :meth:`CreasePattern.state_fold_angles` (left face = the face whose
    loop runs along the edge's direction ``edges[e,0] -> edges[e,1]``), written independently
    with array operations so large generated patterns stay fast.
    """
    X = np.asarray(X, float)
    if X.shape[1] == 2:
        return np.zeros(len(edges))
    F = np.asarray(faces)
    P = X[F]  # (k, p, 3)
    N = np.cross(P, np.roll(P, -1, axis=1)).sum(1)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    n_v = len(X)
    a = F.ravel()
    b = np.roll(F, -1, axis=1).ravel()
    fid = np.repeat(np.arange(len(F)), F.shape[1])
    key_half = a.astype(np.int64) * n_v + b
    E = np.asarray(edges, np.int64)
    key_fwd = E[:, 0] * n_v + E[:, 1]
    key_bwd = E[:, 1] * n_v + E[:, 0]
    order = np.argsort(key_half)
    ks = key_half[order]

    def lookup(keys: np.ndarray) -> np.ndarray:
        pos = np.searchsorted(ks, keys)
        pos = np.minimum(pos, len(ks) - 1)
        found = ks[pos] == keys
        return np.where(found, fid[order][pos], -1)

    left, right = lookup(key_fwd), lookup(key_bwd)
    both = (left >= 0) & (right >= 0)
    rho = np.zeros(len(E))
    e = np.flatnonzero(both)
    axis = X[E[e, 1]] - X[E[e, 0]]
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    nl, nr = N[left[e]], N[right[e]]
    s = np.einsum("ij,ij->i", np.cross(nr, nl), axis)
    c = np.einsum("ij,ij->i", nl, nr)
    rho[e] = np.degrees(np.arctan2(s, c))
    return rho


def zip_strip(
    lower: np.ndarray, lower_u: np.ndarray, upper: np.ndarray, upper_u: np.ndarray
) -> list[tuple[int, int, int]]:
    """Triangulate the strip between two rows of vertices sorted by ``u`` (left to right).

    Walks both rows and at each step adds the triangle whose new diagonal is the shorter (in
    ``u``), which joins every vertex to the nearest ones of the other row. Triangles are
    counter-clockwise when ``upper`` lies above ``lower`` (larger y) and ``u`` grows with x.
    """
    tris: list[tuple[int, int, int]] = []
    i = k = 0
    nl, nu = len(lower), len(upper)
    while i < nl - 1 or k < nu - 1:
        adv_upper = i == nl - 1 or (
            k < nu - 1
            and abs(upper_u[k + 1] - lower_u[i]) < abs(lower_u[i + 1] - upper_u[k]) - 1e-12
        )
        if adv_upper:
            tris.append((int(lower[i]), int(upper[k + 1]), int(upper[k])))
            k += 1
        else:
            tris.append((int(lower[i]), int(lower[i + 1]), int(upper[k])))
            i += 1
    return tris


def unfold(
    X: np.ndarray, faces: Sequence[Sequence[int]] | np.ndarray, tol: float = 1e-9
) -> np.ndarray:
    """Develop a folded state with planar faces into the plane (isometric unfolding).

    Breadth-first over the faces: the first face is laid out with its first side along +x,
    every next face is placed on an already placed side, keeping its shape. Raises
    PatternError if a vertex is reached twice at different places (the surface is not
    developable) or a face is not planar.

    Parameters
    ----------
    X : (n, 3) float
        Folded coordinates.
    faces : sequence of counter-clockwise vertex loops (seen from the faces' normal side)

    Returns
    -------
    (n, 2) float
        Flat coordinates; faces stay counter-clockwise from +z.
    """
    X = np.asarray(X, float)
    face_list = [list(map(int, f)) for f in faces]
    n = len(X)
    flat = np.full((n, 2), np.nan)
    placed = np.zeros(n, bool)
    scale = max(float(np.ptp(X, axis=0).max()), 1e-300)
    side_faces: dict[tuple[int, int], list[int]] = {}
    for fi, f in enumerate(face_list):
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            side_faces.setdefault((min(a, b), max(a, b)), []).append(fi)

    def local(f: list[int], p: int) -> np.ndarray:
        """2-D coordinates of face f in its own frame: origin f[p], x along f[p] -> f[p+1]."""
        P = X[f]
        o, q = P[p], P[(p + 1) % len(f)]
        ex = (q - o) / np.linalg.norm(q - o)
        nrm = np.cross(P, np.roll(P, -1, axis=0)).sum(0)
        nrm /= np.linalg.norm(nrm)
        ey = np.cross(nrm, ex)
        D = P - o
        off = np.abs(D @ nrm).max()
        if off > tol * scale * 1e3:
            raise PatternError(f"face {f} is not planar (off by {off:.3g}); cannot unfold")
        return np.column_stack([D @ ex, D @ ey])

    done = np.zeros(len(face_list), bool)
    queue = [0]
    f0 = face_list[0]
    flat[f0] = local(f0, 0)
    placed[f0] = True
    done[0] = True
    while queue:
        fi = queue.pop(0)
        f = face_list[fi]
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            for gj in side_faces[(min(a, b), max(a, b))]:
                if done[gj]:
                    continue
                g = face_list[gj]
                p = g.index(b) if g[(g.index(b) + 1) % len(g)] == a else g.index(a)
                loc = local(g, p)
                o, q = flat[g[p]], flat[g[(p + 1) % len(g)]]
                ex = (q - o) / np.linalg.norm(q - o)
                ey = np.array([-ex[1], ex[0]])
                pts = o + np.outer(loc[:, 0], ex) + np.outer(loc[:, 1], ey)
                for v, pt in zip(g, pts, strict=True):
                    if placed[v]:
                        if np.linalg.norm(flat[v] - pt) > tol * scale * 1e3:
                            raise PatternError(
                                f"vertex {v} unfolds to two places: the surface is not developable"
                            )
                    else:
                        flat[v] = pt
                        placed[v] = True
                done[gj] = True
                queue.append(gj)
    if not done.all():
        raise PatternError("faces are not connected; cannot unfold")
    return flat


class SegmentBuilder:
    """Collects crease segments between points (merging coincident points) and turns them into
    a flat CreasePattern with faces from the planar graph.

    Points are merged when they agree to ``1e-9`` of ``scale``. Segments must not cross
    (generators place a vertex at every crossing).
    """

    def __init__(self, scale: float) -> None:
        self.scale = float(scale)
        self._index: dict[tuple[int, int], int] = {}
        self.points: list[tuple[float, float]] = []
        self.segments: list[tuple[int, int, str, float]] = []

    def point(self, p: Sequence[float]) -> int:
        """Vertex id of point p (created if new)."""
        q = 1e-9 * self.scale
        key = (round(float(p[0]) / q), round(float(p[1]) / q))
        idx = self._index.get(key)
        if idx is None:
            idx = len(self.points)
            self._index[key] = idx
            self.points.append((float(p[0]), float(p[1])))
        return idx

    def add(
        self, p: Sequence[float], q: Sequence[float], assignment: str, angle: float = 0.0
    ) -> None:
        """Add the crease p-q with an assignment and target fold angle (degrees)."""
        a, b = self.point(p), self.point(q)
        if a != b:
            self.segments.append((a, b, assignment, float(angle)))

    def build(
        self,
        *,
        family: str,
        parameters: dict[str, Any],
        extra_meta: dict[str, Any] | None = None,
    ) -> CreasePattern:
        """The CreasePattern (boundary edges forced to ``B``; duplicate segments keep the
        first assignment)."""
        from barhinge.pattern.planar import planar_faces

        V = np.array(self.points, float)
        seen: dict[tuple[int, int], int] = {}
        E, A, F = [], [], []
        for a, b, asg, ang in self.segments:
            key = (min(a, b), max(a, b))
            if key in seen:
                continue
            seen[key] = len(E)
            E.append(key)
            A.append(asg)
            F.append(ang)
        edges = np.array(E, dtype=np.int64)
        faces = planar_faces(V, edges)
        fe, counts = edges_from_faces([list(f) for f in faces])
        # edges used by one face are boundary edges
        face_count = {tuple(e): c for e, c in zip(fe.tolist(), counts.tolist(), strict=True)}
        Aa = np.array(A, dtype="<U1")
        Fa = np.array(F, float)
        for k, e in enumerate(E):
            if face_count.get(e, 0) < 2:
                Aa[k] = "B"
                Fa[k] = 0.0
        return build_pattern(
            V,
            faces,
            edges=edges,
            assignment=Aa,
            fold_angles=Fa,
            family=family,
            parameters=parameters,
            extra_meta=extra_meta,
        )
