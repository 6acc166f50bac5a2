"""Face quantities computed on flat arrays over all faces (normals, corner angles, centroids,
fan triangles, boundary nodes) against independent per-face constructions."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.curvature import boundary_nodes, pattern_triangles, reference_points
from barhinge.pattern.crease import CreasePattern


def _mixed_faces() -> CreasePattern:
    """An L-shaped hexagon (one reflex corner), a square and a triangle, flat."""
    V = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2], [3, 0], [3, 1], [3, 2]], float)
    E = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [1, 6], [6, 7], [7, 2], [7, 8], [8, 2]]
    return CreasePattern(V, E, ["B"] * 7 + ["M"] + ["B"] * 3)


def test_face_loops_round_trip_and_flat_angles() -> None:
    cp = _mixed_faces()
    ids, off = cp.face_loops
    assert [tuple(ids[off[f] : off[f + 1]]) for f in range(cp.n_faces)] == list(cp.faces)
    np.testing.assert_allclose(cp.face_normals, [[0, 0, 1]] * cp.n_faces, atol=1e-15)
    expected = {6: [90, 90, 90, 270, 90, 90], 4: [90] * 4}
    for f, ang in zip(cp.faces, cp.face_corner_angles, strict=True):
        deg = np.degrees(ang)
        assert deg.sum() == pytest.approx((len(f) - 2) * 180.0, abs=1e-9)
        if len(f) in expected:  # corner order follows the loop: compare as multisets
            np.testing.assert_allclose(np.sort(deg), np.sort(expected[len(f)]), atol=1e-12)


@pytest.mark.parametrize("fold", [20.0, 55.0])
def test_folded_face_normals_and_centroids(fold: float) -> None:
    """Folded Miura panels: unit normals perpendicular to every side of their face and on the
    side of (P1 - P0) x (P2 - P0); centroids equal to the vertex means face by face."""
    cp = bh.families.miura(3, 2, fold=fold)
    X = cp.vertices3d
    N = cp.face_normals
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-14)
    for f, n in zip(cp.faces, N, strict=True):
        P = X[list(f)]
        sides = np.roll(P, -1, axis=0) - P
        assert np.abs(sides @ n).max() < 1e-12
        assert np.cross(P[1] - P[0], P[2] - P[0]) @ n > 0
    means = np.array([X[list(f)].mean(axis=0) for f in cp.faces])
    np.testing.assert_allclose(reference_points(X, cp), means, rtol=0, atol=1e-14)


def test_fan_triangles_tile_the_faces_and_find_the_boundary() -> None:
    """The fan triangles of every face cover its area (shoelace formula) with corners from
    that face; the nodes on edges of exactly one triangle are the pattern's boundary."""
    for cp in (_mixed_faces(), bh.families.miura(3, 3), bh.families.waterbomb(2, 2)):
        T = pattern_triangles(cp)
        assert len(T) == sum(len(f) - 2 for f in cp.faces)
        P = cp.vertices[:, :2]
        u, w = P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]
        tri_area = 0.5 * np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
        face_area = [
            0.5 * abs(np.dot(P[list(f), 0], np.roll(P[list(f), 1], -1))
                      - np.dot(P[list(f), 1], np.roll(P[list(f), 0], -1)))
            for f in cp.faces
        ]  # fmt: skip
        assert tri_area.sum() == pytest.approx(sum(face_area), rel=1e-12)
        boundary = np.ones(cp.n_vertices, bool)
        boundary[list(cp.interior_vertices)] = False
        np.testing.assert_array_equal(boundary_nodes(T, cp.n_vertices), boundary)
