"""Panel subdivision keeps the surface, the creases and the vertex ids."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import PatternError
from barhinge.pattern.subdivide import corner_graded, subdivided, subdivided_size


def _area(cp) -> float:
    X = np.asarray(cp.vertices3d)
    return sum(
        0.5 * np.linalg.norm(np.cross(X[list(f)], np.roll(X[list(f)], -1, 0)).sum(0))
        for f in cp.faces
    )


@pytest.mark.parametrize(
    "cp",
    [bh.families.miura(2, 2, fold=50.0), bh.families.yoshimura(3, 2, fold=20.0)],
    ids=["quads", "triangles"],
)
@pytest.mark.parametrize("m", [2, 3])
@pytest.mark.parametrize("grading", [1.0, 2.5])
def test_subdivision_keeps_surface_creases_and_ids(cp, m, grading):
    if grading != 1.0 and any(len(f) != 4 for f in cp.faces):
        with pytest.raises(PatternError, match="quadrilateral faces only"):
            subdivided(cp, m, grading)
        return
    out, parent = subdivided(cp, m, grading)
    assert out.n_faces == m * m * cp.n_faces
    assert _area(out) == pytest.approx(_area(cp), rel=1e-12)
    np.testing.assert_array_equal(np.asarray(out.vertices3d)[: cp.n_vertices], cp.vertices3d)
    # the folded state is unchanged: every line's state angle is its fold angle (F lines 0)
    np.testing.assert_allclose(out.state_fold_angles(), out.fold_angles, rtol=0, atol=1e-9)
    crease = lambda c: np.isin(np.asarray(c.assignment), ["M", "V"])  # noqa: E731
    assert crease(out).sum() == m * crease(cp).sum()
    # new vertices on an edge lie on it
    X, V, E = np.asarray(out.vertices3d), np.asarray(cp.vertices3d), np.asarray(cp.edges)
    on = np.flatnonzero(parent >= 0)
    a, b = V[E[parent[on], 0]], V[E[parent[on], 1]]
    d = np.linalg.norm(np.cross(X[on] - a, b - a), axis=1) / np.linalg.norm(b - a, axis=1)
    assert d.max() < 1e-12


def test_pentagons_are_refused():
    from barhinge.pattern.crease import CreasePattern

    t = 2 * np.pi * np.arange(5) / 5
    cp = CreasePattern(
        np.column_stack([np.cos(t), np.sin(t)]),
        [[i, (i + 1) % 5] for i in range(5)],
        ["B"] * 5,
        faces=[list(range(5))],
    )
    with pytest.raises(PatternError, match="5 corners"):
        subdivided(cp, 2)


@pytest.mark.parametrize(
    "cp",
    [bh.families.miura(2, 2, fold=50.0), bh.families.yoshimura(3, 2, fold=20.0)],
    ids=["quads", "triangles"],
)
@pytest.mark.parametrize("m", [1, 2, 3, 5])
def test_subdivided_size_counts_what_subdivided_builds(cp, m):
    out, _ = subdivided(cp, m)
    n_quad = sum(len(f) == 4 for f in out.faces)
    assert subdivided_size(cp, m) == (out.n_vertices, n_quad)
    # and the N5B8 model of it has 3 (vertices + quadrilaterals) DOFs
    model = bh.BarHingeModel.from_pattern(out, "N5B8")
    assert 3 * model.n_nodes == 3 * sum(subdivided_size(cp, m))


def test_subdivision_keeps_a_non_developable_pattern_non_developable():
    """A formed (slightly non-developable) state can be refined: the flag is kept."""
    from barhinge.pattern.crease import CreasePattern

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]])
    edges = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 4], [1, 4], [2, 4], [3, 4]]
    faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    flat = CreasePattern(sq, edges, ["B"] * 4 + ["V"] * 4, faces=faces)
    X = np.column_stack([sq, np.zeros(5)])
    X[4, 2] = 0.2  # a pyramid: the sector angles at the apex sum to less than 360 degrees
    pyramid = flat.replaced(vertices=X, developable=False)
    out, _ = subdivided(pyramid, 2)
    assert out.developable is False
    assert _area(out) == pytest.approx(_area(pyramid), rel=1e-12)


@pytest.mark.parametrize(
    "cp",
    [bh.families.miura(2, 2, fold=50.0), bh.families.miura_arc(3, 2, fold=40.0)],
    ids=["parallelograms", "trapezoids"],
)
def test_graded_subdivision_cuts_every_edge_at_the_graded_points(cp):
    m, p = 4, 2.0
    out, parent = subdivided(cp, m, grading=p)
    X, V, E = np.asarray(out.vertices3d), np.asarray(cp.vertices3d), np.asarray(cp.edges)
    expect = np.sort(corner_graded(np.arange(1, m) / m, p))
    for e in range(cp.n_edges):
        a, b = V[E[e, 0]], V[E[e, 1]]
        on = X[parent == e]
        s = np.sort((on - a) @ (b - a) / ((b - a) @ (b - a)))
        np.testing.assert_allclose(s, expect, atol=1e-12)  # the same from either end
    # the sub-faces at a panel's corner are smaller than those at its middle
    area = np.array(
        [0.5 * np.linalg.norm(np.cross(X[list(f)], np.roll(X[list(f)], -1, 0)).sum(0))
         for f in out.faces]
    )  # fmt: skip
    corner = [k for k, f in enumerate(out.faces) if any(v < cp.n_vertices for v in f)]
    middle = [k for k, f in enumerate(out.faces) if all(parent[v] < 0 and v >= cp.n_vertices
                                                        for v in f)]  # fmt: skip
    assert area[corner].max() < area[middle].min()


def test_corner_grading_is_symmetric_and_fixes_the_ends():
    x = np.linspace(0.0, 1.0, 11)
    for p in (1.0, 2.0, 3.5):
        g = corner_graded(x, p)
        np.testing.assert_allclose(g + corner_graded(1.0 - x, p), 1.0, atol=1e-15)
        assert g[0] == 0.0 and g[-1] == 1.0 and np.all(np.diff(g) > 0)
    np.testing.assert_allclose(corner_graded(x, 1.0), x, atol=1e-15)
    with pytest.raises(PatternError, match="grading"):
        subdivided(bh.families.miura(1, 1, fold=30.0), 2, grading=0.5)
