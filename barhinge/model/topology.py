"""Bars and hinges of a triangulated pattern.

Every side of a triangle is a bar. Every side shared by two triangles is a hinge
``(i, j, k, l)``: axis ``i -> j`` with the triangle ``(i, j, k)`` on its left and ``(j, i, l)``
on its right (both counter-clockwise, see :mod:`barhinge.kernels.geometry`). A hinge on a
folding crease of the pattern (assignment M, V, F or U) is a *fold* hinge oriented along the
pattern edge ``edges[e, 0] -> edges[e, 1]``, so that its angle equals
``cp.state_fold_angles()[e]``; a hinge inside a face is a *bend* hinge.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from barhinge._typing import FOLDING_ASSIGNMENTS
from barhinge.errors import PatternError
from barhinge.model.triangulate import Triangulation
from barhinge.pattern.crease import CreasePattern

__all__ = ["Topology", "build_topology"]


@dataclasses.dataclass(frozen=True, eq=False)
class Topology:
    """Connectivity of a bar-and-hinge model.

    Attributes
    ----------
    bars : (n_bars, 2) int
    bar_edge : (n_bars,) int, pattern edge of each bar or -1 (bar inside a face)
    bar_face_pairs : (m, 2) int rows ``(bar, face)``: the faces whose triangulation uses a bar
        (a pattern edge between two faces appears twice)
    hinges : (n_hinges, 4) int
    hinge_kind : (n_hinges,) str ``"fold"`` or ``"bend"``
    hinge_edge : (n_hinges,) int, pattern edge of fold hinges, -1 for bend hinges
    hinge_face : (n_hinges,) int, pattern face of bend hinges, -1 for fold hinges
    """

    bars: np.ndarray
    bar_edge: np.ndarray
    bar_face_pairs: np.ndarray
    hinges: np.ndarray
    hinge_kind: np.ndarray
    hinge_edge: np.ndarray
    hinge_face: np.ndarray


def build_topology(cp: CreasePattern, tri: Triangulation) -> Topology:
    """Bars and fold/bend hinges of the triangulation ``tri`` of ``cp``."""
    T = tri.triangles
    n_nodes = len(tri.X0)
    # directed half-edges p -> q with the opposite node r, from the CCW triangles
    P = T.reshape(-1)
    Q = np.roll(T, -1, axis=1).reshape(-1)
    R = np.roll(T, -2, axis=1).reshape(-1)
    F = np.repeat(tri.tri_face, 3)
    lo, hi = np.minimum(P, Q), np.maximum(P, Q)
    key = lo * n_nodes + hi
    ukey, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
    if (counts > 2).any():
        b = int(np.flatnonzero(counts > 2)[0])
        raise PatternError(
            f"triangle side ({ukey[b] // n_nodes}, {ukey[b] % n_nodes}) is shared by "
            f"{counts[b]} triangles; expected at most 2 (non-manifold pattern)"
        )
    bars = np.column_stack([ukey // n_nodes, ukey % n_nodes]).astype(np.int64)

    # pattern edge of each bar
    E = cp.edges
    ekey = np.minimum(E[:, 0], E[:, 1]) * n_nodes + np.maximum(E[:, 0], E[:, 1])
    eorder = np.argsort(ekey)
    pos = np.searchsorted(ekey[eorder], ukey)
    pos = np.minimum(pos, len(ekey) - 1) if len(ekey) else pos
    bar_edge = -np.ones(len(bars), dtype=np.int64)
    if len(ekey):
        hit = ekey[eorder][pos] == ukey
        bar_edge[hit] = eorder[pos[hit]]

    bf = np.unique(np.column_stack([inv, F]), axis=0)

    # hinges: bars with two half-edges
    shared = np.flatnonzero(counts == 2)
    order = np.argsort(inv, kind="stable")
    first = np.searchsorted(inv[order], shared)
    h1, h2 = order[first], order[first + 1]  # the two half-edges of each shared side
    # a consistent pair has opposite directions
    bad = P[h1] != Q[h2]
    if bad.any():
        b = int(shared[np.flatnonzero(bad)[0]])
        raise PatternError(
            f"triangle side {bars[b].tolist()} is traversed in the same direction by two "
            "triangles; faces must be consistently oriented (counter-clockwise)"
        )
    e_of = bar_edge[shared]
    asg = cp.assignment
    is_crease = np.zeros(len(shared), bool)
    has_edge = e_of >= 0
    is_crease[has_edge] = np.isin(asg[e_of[has_edge]], FOLDING_ASSIGNMENTS)
    is_bend = ~has_edge
    keep = is_crease | is_bend
    # orient fold hinges along the pattern edge: half-edge h1 should run edges[e,0] -> edges[e,1]
    flip = np.zeros(len(shared), bool)
    flip[has_edge] = P[h1[has_edge]] != E[e_of[has_edge], 0]
    hl = np.where(flip, h2, h1)
    hr = np.where(flip, h1, h2)
    hinges = np.column_stack([P[hl], Q[hl], R[hl], R[hr]])[keep]
    kind = np.where(is_crease, "fold", "bend")[keep]
    hedge = np.where(is_crease, e_of, -1)[keep]
    hface = np.where(is_bend, F[hl], -1)[keep]
    return Topology(
        bars=bars,
        bar_edge=bar_edge,
        bar_face_pairs=bf.astype(np.int64),
        hinges=hinges.astype(np.int64),
        hinge_kind=kind.astype("<U4"),
        hinge_edge=hedge.astype(np.int64),
        hinge_face=hface.astype(np.int64),
    )
