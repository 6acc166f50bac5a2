"""The crease pattern: vertices, creases with assignments and fold angles, faces.

Conventions
-----------
* ``vertices`` are (n, 2) for a flat pattern or (n, 3) for any state (flat or folded).
* ``assignment`` uses the FOLD letters: ``M`` mountain, ``V`` valley, ``F`` flat (facet line),
  ``B`` boundary, ``U`` unassigned, ``C`` cut.
* ``fold_angles`` are **degrees**, FOLD sign convention: 0 flat, valley > 0, mountain < 0,
  ``|rho| <= 180``. They are the *target* fold angles (what the crease is meant to reach); the
  fold angles of the current geometry are :meth:`CreasePattern.state_fold_angles`.
* ``faces`` are vertex loops, counter-clockwise seen from +z in the flat state (the normal of
  a face points to the side a valley fold closes towards).
"""

from __future__ import annotations

import dataclasses
from functools import cached_property
from typing import Any

import numpy as np

from barhinge._typing import ASSIGNMENTS
from barhinge.errors import PatternError
from barhinge.pattern.planar import planar_faces
from barhinge.pattern.validate import check, merged_arrays

__all__ = ["CreasePattern"]


def _as_array(x: Any, dtype: Any, name: str) -> np.ndarray:
    """np.array (a copy) that turns ragged or non-numeric input into a PatternError."""
    try:
        return np.array(x, dtype=dtype)
    except (TypeError, ValueError, OverflowError):
        raise PatternError(f"{name} must be a rectangular array of numbers") from None


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@dataclasses.dataclass(frozen=True, eq=False)
class CreasePattern:
    """A crease pattern (flat or folded state).

    Parameters
    ----------
    vertices : (n, 2) or (n, 3) float
        Vertex coordinates (length unit of the user's choice).
    edges : (m, 2) int
        Vertex indices of each edge.
    assignment : (m,) str
        One of ``M V F B U C`` per edge.
    fold_angles : (m,) float, optional
        Target fold angle per edge in degrees (valley > 0, mountain < 0). Defaults to 0.
    faces : sequence of int sequences, optional
        Counter-clockwise vertex loops. Derived from the planar graph when omitted; stored as
        a tuple of int tuples.
    developable : bool
        Require sector angles to sum to 360 deg at flat interior vertices (set False for
        non-developable families such as the egg-box).
    meta : dict
        Extra data (FOLD file metadata and unknown keys, kept for round trips).
    validate : bool
        Run :func:`barhinge.pattern.validate.check` on construction.
    merge_tol : float, optional
        Repair on construction: merge vertices closer than this length, drop zero-length and
        duplicate edges (see :func:`barhinge.pattern.validate.merged_arrays`).
    """

    vertices: np.ndarray
    edges: np.ndarray
    assignment: np.ndarray
    fold_angles: Any = None  # (m,) float or None in, (m,) float array stored
    faces: Any = None  # Sequence[Sequence[int]] | None in, tuple[tuple[int, ...], ...] stored
    developable: bool = True
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)
    validate: dataclasses.InitVar[bool] = True
    merge_tol: dataclasses.InitVar[float | None] = None

    def __post_init__(self, validate: bool, merge_tol: float | None = None) -> None:
        V = _checked_vertices(self.vertices)
        E = _checked_edges(self.edges, len(V))
        A = _checked_assignment(self.assignment, len(E))
        F = _checked_fold_angles(self.fold_angles, len(E))
        faces = self.faces
        if merge_tol is not None:
            V, E, A, F, faces = merged_arrays(V, E, A, F, faces, merge_tol)
        faces_found = faces is None  # after the merge: faces of the merged graph
        faces_t = _checked_faces(planar_faces(V, E) if faces_found else faces, len(V))
        object.__setattr__(self, "vertices", _readonly(V))
        object.__setattr__(self, "edges", _readonly(E))
        object.__setattr__(self, "assignment", _readonly(A))
        object.__setattr__(self, "fold_angles", _readonly(F))
        object.__setattr__(self, "faces", faces_t)
        object.__setattr__(self, "meta", dict(self.meta))
        object.__setattr__(self, "_faces_found", faces_found)
        if validate:
            check(self)

    # ------------------------------------------------------------------ sizes
    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def faces_found(self) -> bool:
        """True when the faces were found from the planar graph (none were given); a repair
        with ``merge_tol`` then finds them again from the merged graph."""
        return bool(getattr(self, "_faces_found", False))

    @cached_property
    def vertices3d(self) -> np.ndarray:
        """(n, 3) float: vertex coordinates with z = 0 added to a 2-D pattern."""
        V = self.vertices
        if V.shape[1] == 3:
            return V
        return _readonly(np.column_stack([V, np.zeros(len(V))]))

    @cached_property
    def is_flat(self) -> bool:
        """True if all vertices lie in the plane z = 0 (to 1e-9 of the pattern size)."""
        V = self.vertices
        if V.shape[1] == 2:
            return True
        return bool(np.all(np.abs(V[:, 2]) <= 1e-9 * max(self.size, 1e-300)))

    @cached_property
    def size(self) -> float:
        """Diagonal of the bounding box (length unit)."""
        if self.n_vertices == 0:
            return 0.0
        V = self.vertices
        return float(np.linalg.norm(V.max(0) - V.min(0)))

    # --------------------------------------------------------------- topology
    @cached_property
    def edge_index(self) -> dict[tuple[int, int], int]:
        """Map from a sorted vertex pair to the edge id."""
        return {(int(min(a, b)), int(max(a, b))): e for e, (a, b) in enumerate(self.edges)}

    def edge_between(self, a: int, b: int) -> int:
        """Edge id joining vertices a and b; PatternError if there is none."""
        try:
            return self.edge_index[(min(a, b), max(a, b))]
        except KeyError:
            raise PatternError(f"no edge joins vertices {a} and {b}") from None

    @cached_property
    def face_loops(self) -> tuple[np.ndarray, np.ndarray]:
        """The face loops as flat arrays: (vertex ids of every face, concatenated; offsets
        ``(n_faces + 1,)``: face ``f`` is ``ids[offsets[f]:offsets[f + 1]]``)."""
        lens = np.fromiter((len(f) for f in self.faces), dtype=np.int64, count=self.n_faces)
        ids = np.fromiter((v for f in self.faces for v in f), dtype=np.int64, count=int(lens.sum()))
        return _readonly(ids), _readonly(np.concatenate([[0], np.cumsum(lens)]))

    def _loop_neighbours(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(face of every loop position, index of the next position in its loop, index of
        the previous one), over the flat arrays of :attr:`face_loops`."""
        ids, off = self.face_loops
        lens = np.diff(off)
        fid = np.repeat(np.arange(self.n_faces), lens)
        pos = np.arange(len(ids)) - off[fid]
        return fid, off[fid] + (pos + 1) % lens[fid], off[fid] + (pos - 1) % lens[fid]

    @cached_property
    def edge_faces(self) -> np.ndarray:
        """(m, 2) int: face on the left of the directed edge ``edges[e,0] -> edges[e,1]``
        (column 0) and on the right (column 1); -1 where there is none."""
        # vectorised over all face sides (same result and errors as a loop over the faces;
        # for a repeated vertex pair the last edge id wins, as in ``edge_index``)
        EF = -np.ones((self.n_edges, 2), dtype=np.int64)
        faces = self.faces
        if not faces:
            return _readonly(EF)
        a = self.face_loops[0]
        fid, nxt, _ = self._loop_neighbours()
        b = a[nxt]
        n = max(self.n_vertices, 1)
        E = self.edges
        key_e = np.minimum(E[:, 0], E[:, 1]) * n + np.maximum(E[:, 0], E[:, 1])
        order = np.lexsort((np.arange(len(E)), key_e))
        ks = key_e[order]
        last = np.r_[ks[1:] != ks[:-1], True] if len(ks) else np.zeros(0, bool)
        ks, eid = ks[last], order[last]
        key_h = np.minimum(a, b) * n + np.maximum(a, b)
        at = np.minimum(np.searchsorted(ks, key_h), max(len(ks) - 1, 0))
        found = ks[at] == key_h if len(ks) else np.zeros(len(a), bool)
        if not found.all():
            k = int(np.flatnonzero(~found)[0])
            raise PatternError(f"face {fid[k]} uses side ({a[k]}, {b[k]}), which is not an edge")
        e = eid[at]
        col = np.where(E[e, 0] == a, 0, 1)
        slot = e * 2 + col
        srt = np.argsort(slot, kind="stable")
        dup = np.flatnonzero(slot[srt][1:] == slot[srt][:-1])
        if len(dup):
            first, second = srt[dup[0]], srt[dup[0] + 1]
            raise PatternError(
                f"edge {e[second]} ({a[second]}, {b[second]}) is traversed in the same direction "
                f"by faces {fid[first]} and {fid[second]}: non-manifold or inconsistent orientation"
            )
        EF[e, col] = fid
        return _readonly(EF)

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """(k,) int: edges with fewer than two faces.

        An edge assigned B that two faces share is not a boundary: the sheet is continuous
        across it, so it is treated as an unassigned crease (see :attr:`crease_edges`;
        validation reports it as ``"interior-boundary-edge"``)."""
        EF = self.edge_faces
        return _readonly(np.flatnonzero((EF < 0).any(1)))

    @cached_property
    def crease_edges(self) -> np.ndarray:
        """(k,) int: interior edges that can fold (two faces, assignment M, V, F or U, and B
        between two faces, treated as U)."""
        EF = self.edge_faces
        ok = (EF >= 0).all(1) & np.isin(self.assignment, ("M", "V", "F", "U", "B"))
        return _readonly(np.flatnonzero(ok))

    @cached_property
    def is_planar(self) -> bool:
        """True if all vertices lie in one plane, in any orientation (to 1e-9 of the pattern
        size; judged from the best-fit plane: the smallest principal direction)."""
        V = self.vertices
        if V.shape[1] == 2 or self.n_vertices <= 3:
            return True
        C = V - V.mean(0)
        normal = np.linalg.svd(C, full_matrices=False)[2][-1]
        return bool(np.all(np.abs(C @ normal) <= 1e-9 * max(self.size, 1e-300)))

    @cached_property
    def boundary_vertices(self) -> np.ndarray:
        """(k,) int: vertices on a boundary edge (outer boundary or a hole)."""
        return _readonly(np.unique(self.edges[self.boundary_edges].ravel()))

    @cached_property
    def interior_vertices(self) -> np.ndarray:
        """(k,) int: vertices with edges that are not on the boundary."""
        used = np.zeros(self.n_vertices, bool)
        used[self.edges.ravel()] = True
        used[self.boundary_vertices] = False
        return _readonly(np.flatnonzero(used))

    @cached_property
    def vertex_degree(self) -> np.ndarray:
        """(n,) int: number of edges at each vertex."""
        return _readonly(np.bincount(self.edges.ravel(), minlength=self.n_vertices))

    @cached_property
    def face_adjacency(self) -> np.ndarray:
        """(k, 3) int rows ``(face_left, face_right, edge)`` for every edge shared by two
        faces."""
        EF = self.edge_faces
        both = np.flatnonzero((EF >= 0).all(1))
        return _readonly(np.column_stack([EF[both, 0], EF[both, 1], both]))

    @cached_property
    def vertex_corners(self) -> tuple[tuple[tuple[int, int], ...], ...]:
        """Per vertex, the (face, position-in-loop) corners around it in counter-clockwise
        order (a chain that may be open at boundary vertices)."""
        n = self.n_vertices
        at: list[dict[int, tuple[int, int]]] = [dict() for _ in range(n)]  # next-vertex -> corner
        for fi, f in enumerate(self.faces):
            k = len(f)
            for p in range(k):
                v, nxt = f[p], f[(p + 1) % k]
                at[v][nxt] = (fi, p)
        out: list[tuple[tuple[int, int], ...]] = []
        for v in range(n):
            corners = at[v]
            if not corners:
                out.append(())
                continue
            prev_of = {}
            for nxt, (fi, p) in corners.items():
                f = self.faces[fi]
                prev_of[nxt] = f[(p - 1) % len(f)]
            # start at a corner whose "next" edge is not the "prev" edge of any corner (open
            # chain at the boundary); any corner for a closed fan.
            prevs = set(prev_of.values())
            starts = [nx for nx in corners if nx not in prevs]
            start = starts[0] if starts else next(iter(corners))
            chain, nx, seen = [], start, set()
            while nx in corners and nx not in seen:
                seen.add(nx)
                chain.append(corners[nx])
                nx = prev_of[nx]
            if len(chain) != len(corners):  # more than one fan: non-manifold vertex
                chain = [corners[k] for k in corners]
            out.append(tuple(chain))
        return tuple(out)

    @cached_property
    def face_corner_angles(self) -> tuple[np.ndarray, ...]:
        """Per face, the interior angle (radians) at each corner of its loop, in the current
        geometry: measured counter-clockwise about the face normal, so a reflex corner of a
        non-convex face is more than pi."""
        if not self.n_faces:
            return ()
        X = self.vertices3d
        ids, off = self.face_loops
        fid, nxt, prv = self._loop_neighbours()
        P = X[ids]
        u, w = X[ids[nxt]] - P, X[ids[prv]] - P
        c = np.einsum("ij,ij->i", u, w)
        s = np.einsum("ij,ij->i", np.cross(u, w), self.face_normals[fid])
        angles = np.mod(np.arctan2(s, c), 2 * np.pi)
        return tuple(_readonly(a) for a in np.split(angles, off[1:-1]))

    @cached_property
    def sector_angles(self) -> tuple[np.ndarray, ...]:
        """Per vertex, the sector angles (radians) of the faces around it, counter-clockwise."""
        FA = self.face_corner_angles
        return tuple(
            _readonly(np.array([FA[fi][p] for fi, p in corners], dtype=float))
            for corners in self.vertex_corners
        )

    @cached_property
    def angle_defect(self) -> np.ndarray:
        """(n,) float radians: 2*pi minus the sum of sector angles at interior vertices
        (NaN at boundary or unused vertices)."""
        d = np.full(self.n_vertices, np.nan)
        for v in self.interior_vertices:
            d[v] = 2 * np.pi - float(self.sector_angles[v].sum())
        return _readonly(d)

    @cached_property
    def face_normals(self) -> np.ndarray:
        """(n_faces, 3) unit normals (Newell's method), +z for a counter-clockwise flat face."""
        if not self.n_faces:
            return _readonly(np.zeros((0, 3)))
        X = self.vertices3d
        ids, off = self.face_loops
        _, nxt, _ = self._loop_neighbours()
        N = np.add.reduceat(np.cross(X[ids], X[ids[nxt]]), off[:-1], axis=0)
        norm = np.linalg.norm(N, axis=1, keepdims=True)
        return _readonly(N / np.where(norm > 0, norm, 1.0))

    def state_fold_angles(self) -> np.ndarray:
        """(m,) float degrees: fold angle of every edge in the current geometry.

        Signed angle between the normals of the two faces of an edge, FOLD convention
        (valley > 0). Edges with fewer than two faces get 0.
        """
        EF = self.edge_faces
        both = (EF >= 0).all(1)
        rho = np.zeros(self.n_edges)
        if both.any():
            N = self.face_normals
            X = self.vertices3d
            e = np.flatnonzero(both)
            axis = X[self.edges[e, 1]] - X[self.edges[e, 0]]
            axis /= np.linalg.norm(axis, axis=1, keepdims=True)
            nl, nr = N[EF[e, 0]], N[EF[e, 1]]
            s = np.einsum("ij,ij->i", np.cross(nr, nl), axis)
            c = np.einsum("ij,ij->i", nl, nr)
            rho[e] = np.degrees(np.arctan2(s, c))
        return rho

    # ------------------------------------------------------------ new objects
    def replaced(self, **changes: Any) -> CreasePattern:
        """A copy with some fields replaced (e.g. ``vertices=X`` for another state).

        Faces that were found from the planar graph stay marked as found; with ``merge_tol``
        (and no new ``faces`` or ``vertices``) they are found again after the merge, so that
        merging never leaves the faces of the unmerged graph (which can miss a face).
        """
        kw = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        kw.update(changes)
        found = self.faces_found and "faces" not in changes
        if (
            found
            and changes.get("merge_tol") is not None
            and "vertices" not in changes
            and self.is_flat
        ):
            kw["faces"] = None
        new = CreasePattern(**kw)
        if found:
            object.__setattr__(new, "_faces_found", True)
        return new

    def __repr__(self) -> str:
        counts = {a: int((self.assignment == a).sum()) for a in ASSIGNMENTS}
        asg = " ".join(f"{a}={c}" for a, c in counts.items() if c)
        return (
            f"CreasePattern(n_vertices={self.n_vertices}, n_edges={self.n_edges}, "
            f"n_faces={self.n_faces}, {asg})"
        )


# ------------------------------------------------------------------ construction checks
def _checked_vertices(vertices: Any) -> np.ndarray:
    """(n, 2) or (n, 3) finite float coordinates."""
    V = _as_array(vertices, float, "vertices")
    if V.ndim != 2 or V.shape[1] not in (2, 3):
        raise PatternError(f"vertices must have shape (n, 2) or (n, 3), got {V.shape}")
    if not np.all(np.isfinite(V)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(V), axis=1))[0])
        raise PatternError(f"vertex {bad} has a non-finite coordinate: {V[bad].tolist()}")
    return V


def _checked_edges(edges: Any, n_vertices: int) -> np.ndarray:
    """(m, 2) int64 vertex pairs, every index in ``0..n_vertices - 1``."""
    E = _as_array(edges, None, "edges")
    if E.size == 0:
        E = np.zeros((0, 2), dtype=np.int64)
    if E.ndim != 2 or E.shape[1] != 2:
        raise PatternError(f"edges must have shape (m, 2), got {E.shape}")
    if not np.issubdtype(E.dtype, np.integer):
        Ef = _as_array(E, float, "edges")
        if not np.all(Ef == np.round(Ef)):
            raise PatternError("edges must hold integer vertex indices")
        E = Ef.astype(np.int64)
    E = E.astype(np.int64)
    if E.size and (E.min() < 0 or E.max() >= n_vertices):
        bad = int(np.flatnonzero((E < 0).any(1) | (E >= n_vertices).any(1))[0])
        raise PatternError(
            f"edge {bad} references vertex {E[bad].tolist()}, but there are {n_vertices} vertices"
        )
    return E


def _checked_assignment(assignment: Any, n_edges: int) -> np.ndarray:
    """(m,) one-letter assignments from ``ASSIGNMENTS`` (upper case; ``U`` when None)."""
    A = _as_array(assignment if assignment is not None else ["U"] * n_edges, None, "assignment")
    letters = [str(a).upper() for a in A.ravel()]
    for i, a in enumerate(letters):
        if a not in ASSIGNMENTS:
            raise PatternError(
                f"edge {i} has assignment {a!r}; expected one of {' '.join(ASSIGNMENTS)}"
            )
    A = np.array(letters, dtype="<U1") if letters else np.zeros(0, dtype="<U1")
    if len(A) != n_edges:
        raise PatternError(f"len(edges) = {n_edges}, but len(assignment) = {len(A)}")
    return A


def _checked_fold_angles(fold_angles: Any, n_edges: int) -> np.ndarray:
    """(m,) finite fold angles in degrees (zeros when None)."""
    if fold_angles is None:
        return np.zeros(n_edges)
    F = _as_array(fold_angles, float, "fold_angles").ravel()
    if len(F) != n_edges:
        raise PatternError(f"len(edges) = {n_edges}, but len(fold_angles) = {len(F)}")
    if not np.all(np.isfinite(F)):
        bad = int(np.flatnonzero(~np.isfinite(F))[0])
        raise PatternError(f"edge {bad} has a non-finite fold angle {F[bad]}")
    return F


def _checked_faces(faces: Any, n_vertices: int) -> tuple[tuple[int, ...], ...]:
    """Faces as a tuple of int tuples, each with >= 3 vertices in ``0..n_vertices - 1``."""
    try:
        faces_t = tuple(tuple(int(i) for i in f) for f in faces)
    except (TypeError, ValueError, OverflowError):
        raise PatternError("faces must be a sequence of vertex-index sequences") from None
    for fi, f in enumerate(faces_t):
        if len(f) < 3:
            raise PatternError(f"face {fi} has {len(f)} vertices; expected at least 3")
        if min(f) < 0 or max(f) >= n_vertices:
            raise PatternError(f"face {fi} references a vertex outside 0..{n_vertices - 1}")
    return faces_t
