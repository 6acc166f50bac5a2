"""Faces of planar straight-line graphs (half-edge traversal) against independent facts:
Delaunay triangles, Euler's formula and the area of the convex hull."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, Delaunay

from barhinge.errors import PatternError
from barhinge.pattern.planar import pattern_plane, planar_faces, signed_areas


def _sets(faces) -> list[tuple[int, ...]]:
    """Faces as sorted vertex tuples, in sorted order (orientation-free comparison)."""
    return sorted(tuple(sorted(f)) for f in faces)


def test_square_with_centre() -> None:
    V = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], float)
    E = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 4], [1, 4], [2, 4], [3, 4]]
    faces = planar_faces(V, E)
    assert _sets(faces) == _sets([(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)])
    assert np.all(signed_areas(V, faces) > 0)  # counter-clockwise
    np.testing.assert_allclose(signed_areas(V, faces), 0.25, rtol=0, atol=1e-15)


def test_two_components_and_dangling_edge() -> None:
    # two separate triangles plus a dangling edge: 2 faces, the dangling edge bounds none
    V = np.array([[0, 0], [1, 0], [0, 1], [5, 0], [6, 0], [5, 1], [7, 7]], float)
    E = [[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3], [5, 6]]
    faces = planar_faces(V, E)
    assert _sets(faces) == [(0, 1, 2), (3, 4, 5)]


def test_plane_other_than_xy() -> None:
    # the same square in the plane y = 0 (like Origami Simulator's exports): normal +y
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], float)
    E = [[0, 1], [1, 2], [2, 3], [3, 0]]
    (f,) = planar_faces(V, E)
    c, B = pattern_plane(V, 1e-12)
    assert B[2] @ [0, 1, 0] == pytest.approx(1.0)
    P = V[f]
    n = np.cross(P[1] - P[0], P[2] - P[1])
    assert n @ B[2] > 0  # counter-clockwise about the plane normal


def test_part_inside_a_face_is_rejected() -> None:
    # a small triangle floating inside a square: the square face would need a hole
    V = np.array([[0, 0], [4, 0], [4, 4], [0, 4], [1, 1], [2, 1], [1, 2]], float)
    E = [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 4]]
    with pytest.raises(PatternError, match="vertex 4 lies inside face"):
        planar_faces(V, E)
    # side by side (not nested) is fine
    V[4:] += 10
    assert len(planar_faces(V, E)) == 2


def test_not_planar_without_faces() -> None:
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    with pytest.raises(PatternError, match="one plane"):
        planar_faces(V, [[0, 1], [1, 2], [2, 0], [0, 3]])


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(4, 40),
    drop=st.floats(0.0, 0.6),
)
def test_random_planar_graphs(seed: int, n: int, drop: float) -> None:
    rng = np.random.default_rng(seed)
    P = rng.random((n, 2))
    tri = Delaunay(P)
    T = tri.simplices
    E = np.unique(np.sort(np.vstack([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), 1), axis=0)
    hull = np.unique(np.sort(tri.convex_hull, 1), axis=0)
    is_hull = (E[:, None, :] == hull[None]).all(2).any(1)
    keep = is_hull | (rng.random(len(E)) >= drop)
    E = E[keep]
    try:
        faces = planar_faces(P, E)
    except PatternError as exc:  # a part lies inside a face of another: must be true
        assert "lies inside face" in str(exc)
        g = coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
        deg = np.bincount(E.ravel(), minlength=n)
        C, lab = connected_components(g, directed=False)
        assert len(np.unique(lab[deg > 0])) > 1
        return
    # Euler's formula for a plane graph with C components: V - E + (F + 1) = 1 + C
    g = coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    C, _ = connected_components(g, directed=False)
    assert len(faces) == len(E) - n + C
    # bounded faces tile the convex hull (its edges are kept)
    area = signed_areas(P, faces)
    assert np.all(area > 0)
    assert area.sum() == pytest.approx(ConvexHull(P).volume, rel=1e-12, abs=1e-14)
    if drop == 0.0:  # no edge dropped: faces are the Delaunay triangles
        assert _sets(faces) == _sets(T.tolist())
