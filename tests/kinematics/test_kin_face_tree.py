"""The face tree that rebuilds coordinates from fold angles (FaceTree): a breadth-first
spanning tree of the faces, composed level by level for one state or a batch of states, and
by pointer doubling for deep trees; both compositions and both call forms agree."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
import barhinge.kinematics.constraints as constraints
from barhinge.kinematics.constraints import RigidConstraints


@pytest.fixture(scope="module")
def miura() -> RigidConstraints:
    return RigidConstraints.from_pattern(bh.families.miura(6, 6, fold=40))


def test_the_tree_is_breadth_first_over_foldable_creases(miura) -> None:
    ft = miura.face_tree
    pat = miura.pattern
    child = np.flatnonzero(ft.parent >= 0)
    assert np.count_nonzero(ft.parent < 0) == 1 and ft.depth[ft.parent < 0] == 0
    np.testing.assert_array_equal(ft.depth[child], ft.depth[ft.parent[child]] + 1)
    # the hinge to the parent is a crease both faces share, and it can fold
    E = np.asarray(pat.edges)
    ends = np.sort(np.column_stack([ft.a[child], ft.b[child]]), axis=1)
    for f, g, (i, j) in zip(child, ft.parent[child], ends, strict=True):
        e = np.flatnonzero((np.sort(E, axis=1) == (i, j)).all(axis=1))[0]
        assert set(pat.edge_faces[e]) == {f, g} and miura.var_of_edge[e] >= 0
    # breadth first: no face is deeper than its shortest path through the face graph
    assert ft.depth.max() == 12  # 12 x 12 panels, the root at the centre
    # every vertex takes the shallowest face holding it
    for v, f in enumerate(ft.vertex_face):
        holders = [k for k, face in enumerate(pat.faces) if v in face]
        assert v in pat.faces[f] and ft.depth[f] == min(ft.depth[holders])


def test_batches_and_doubling_agree_with_one_state_at_a_time(miura, monkeypatch) -> None:
    rng = np.random.default_rng(3)
    rhos = miura.rho0 + 0.1 * rng.standard_normal((4, miura.n_var))
    one = np.stack([miura.coordinates(r) for r in rhos])
    np.testing.assert_array_equal(miura.coordinates(rhos), one)
    monkeypatch.setattr(constraints, "DOUBLING_DEPTH", 0)
    np.testing.assert_allclose(miura.coordinates(rhos), one, rtol=0, atol=1e-12)
    np.testing.assert_allclose(miura.coordinates(rhos[1]), one[1], rtol=0, atol=1e-12)
    # at the reference angles every face stays where it is
    np.testing.assert_allclose(
        miura.coordinates(miura.rho0), miura.pattern.vertices3d, rtol=0, atol=1e-12
    )
