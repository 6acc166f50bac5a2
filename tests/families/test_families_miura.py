"""Miura-ori generator against the closed forms of Schenk & Guest (2013).

Reference: M. Schenk, S. D. Guest, "Geometry of Miura-folded metamaterials", PNAS 110(9):
3276-3281, 2013, Eq. 1 (H, S, L, V) and Eq. 2 (nu_SL). Every closed form is checked against
quantities measured independently on the generated vertex coordinates.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import PatternError
from barhinge.families import miura, miura_geometry, miura_layout, miura_layout_of
from barhinge.families.properties import kawasaki_error, maekawa_count, sector_sum_error

CASES = [(1.0, 1.0, 60.0, 30.0), (1.3, 0.7, 45.0, 70.0), (0.5, 2.0, 75.0, 10.0)]


def _edge_lengths(cp):
    X = cp.vertices3d
    return np.linalg.norm(X[cp.edges[:, 1]] - X[cp.edges[:, 0]], axis=1)


@pytest.mark.parametrize("fold", [None, 0.0, 25.0, 80.0])
def test_edge_lengths_exact(fold):
    a, b = 1.3, 0.8
    cp = miura(3, 2, a=a, b=b, alpha=55.0, fold=fold)
    lay = miura_layout(3, 2)
    L = _edge_lengths(cp)
    np.testing.assert_allclose(L[lay.straight_edges], a, rtol=0, atol=1e-13)
    np.testing.assert_allclose(L[lay.zigzag_edges], b, rtol=0, atol=1e-13)


@pytest.mark.parametrize("fold", [None, 40.0, 85.0])
def test_sector_angles_are_gamma_and_its_supplement(fold):
    gamma = 55.0
    cp = miura(2, 3, a=1.0, b=1.4, alpha=gamma, fold=fold)
    for v in cp.interior_vertices:
        sec = np.sort(np.degrees(cp.sector_angles[v]))
        np.testing.assert_allclose(sec, [gamma, gamma, 180 - gamma, 180 - gamma], atol=1e-10)


@pytest.mark.parametrize("a,b,gamma,theta", CASES)
def test_cell_dimensions_against_schenk_guest(a, b, gamma, theta):
    """S&G 2013 Eq. 1 vs the generated folded sheet (measured from coordinates)."""
    g, t = math.radians(gamma), math.radians(theta)
    geo = miura_geometry(a, b, gamma, theta)
    # the closed forms as printed in S&G 2013, Eq. 1
    D = math.sqrt(1 + math.cos(t) ** 2 * math.tan(g) ** 2)
    assert geo.H == pytest.approx(a * math.sin(t) * math.sin(g), rel=1e-14)
    assert geo.S == pytest.approx(b * math.cos(t) * math.tan(g) / D, rel=1e-14)
    assert geo.L == pytest.approx(a * math.sqrt(1 - math.sin(t) ** 2 * math.sin(g) ** 2), rel=1e-14)
    assert geo.V == pytest.approx(b / D, rel=1e-14)
    nx, ny = 3, 2
    cp = miura(nx, ny, a=a, b=b, alpha=gamma, fold=theta)
    lay = miura_layout(nx, ny)
    X = cp.vertices
    p00, p10, p01 = X[lay.vertex(0, 0)], X[lay.vertex(1, 0)], X[lay.vertex(0, 1)]
    assert abs(p10[2] - p00[2]) == pytest.approx(geo.H, abs=1e-13)
    assert abs(p10[0] - p00[0]) == pytest.approx(geo.L, abs=1e-13)
    assert abs(p01[1] - p00[1]) == pytest.approx(geo.S, abs=1e-13)
    assert abs(p01[0] - p00[0]) == pytest.approx(geo.V, abs=1e-13)
    # outer dimensions of the whole sheet (bounding box) vs 2 nx L + V, 2 ny S, H
    ext = X.max(0) - X.min(0)
    np.testing.assert_allclose(ext, geo.sheet_size(nx, ny), rtol=0, atol=1e-12)
    # facet angle: angle between each facet normal and +z equals theta (S&G definition)
    cosang = np.abs(cp.face_normals[:, 2])
    np.testing.assert_allclose(cosang, math.cos(t), atol=1e-12)


@pytest.mark.parametrize("a,b,gamma,theta", CASES)
def test_poisson_ratio_by_finite_differences(a, b, gamma, theta):
    """nu_SL = -(dL/L)/(dS/S) = -cos^2(theta) tan^2(gamma) (S&G 2013 Eq. 2), by central
    differences of L and S measured on generated sheets."""
    h = 1e-4

    def measured(t):
        cp = miura(1, 1, a=a, b=b, alpha=gamma, fold=t)
        ext = cp.vertices.max(0) - cp.vertices.min(0)
        geo = miura_geometry(a, b, gamma, t)
        return (ext[0] - geo.V) / 2, ext[1] / 2  # L, S

    Lp, Sp = measured(theta + h)
    Lm, Sm = measured(theta - h)
    L0, S0 = measured(theta)
    nu_fd = -((Lp - Lm) / L0) / ((Sp - Sm) / S0)
    g, t = math.radians(gamma), math.radians(theta)
    expected = -(math.cos(t) ** 2) * math.tan(g) ** 2
    assert miura_geometry(a, b, gamma, theta).nu_SL == pytest.approx(expected, rel=1e-14)
    assert nu_fd == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("gamma,theta", [(60.0, 30.0), (45.0, 70.0), (80.0, 5.0), (30.0, 89.0)])
def test_fold_angles_match_state_and_assignment(gamma, theta):
    """Closed-form fold angles (2 theta; 2 arctan(cos gamma tan theta)) against the fold angles
    measured from the facet normals, and their signs against the assignment (valley > 0)."""
    cp = miura(3, 3, a=1.0, b=1.2, alpha=gamma, fold=theta)
    rho = cp.state_fold_angles()
    np.testing.assert_allclose(rho, cp.fold_angles, atol=1e-9)
    geo = miura_geometry(1.0, 1.2, gamma, theta)
    lay = miura_layout(3, 3)
    zz, st = lay.interior_zigzag_edges, lay.interior_straight_edges
    np.testing.assert_allclose(np.abs(rho[zz]), 2 * theta, atol=1e-9)
    np.testing.assert_allclose(np.abs(rho[st]), geo.rho_straight, atol=1e-9)
    # degree-4 flat-foldable vertex relation tan(rho_s/2) = cos(gamma) tan(rho_z/2)
    assert math.tan(math.radians(geo.rho_straight) / 2) == pytest.approx(
        math.cos(math.radians(gamma)) * math.tan(math.radians(theta)), rel=1e-12
    )
    creases = cp.crease_edges
    A = cp.assignment[creases]
    assert set(A) <= {"M", "V"}
    assert np.all(np.sign(rho[creases]) == np.where(A == "V", 1, -1))
    # the flat pattern carries the same assignment and target angles of the same sign
    flat = miura(3, 3, a=1.0, b=1.2, alpha=gamma)
    assert np.array_equal(flat.assignment, cp.assignment)
    assert np.all(np.sign(flat.fold_angles[creases]) == np.sign(rho[creases]))


def test_flat_pattern_targets_are_the_documented_default_state():
    flat = miura(2, 2, alpha=50.0)
    folded = miura(2, 2, alpha=50.0, fold=60.0)
    np.testing.assert_allclose(flat.fold_angles, folded.state_fold_angles(), atol=1e-9)
    assert flat.vertices.shape[1] == 2


def test_flat_foldability_conditions():
    """Developability, Maekawa |M - V| = 2 and Kawasaki at every interior vertex."""
    cp = miura(4, 3, a=1.0, b=0.9, alpha=65.0)
    iv = cp.interior_vertices
    assert len(iv) == (2 * 4 - 1) * (2 * 3 - 1)
    np.testing.assert_allclose(sector_sum_error(cp)[iv], 0.0, atol=1e-12)
    assert np.all(np.abs(maekawa_count(cp)[iv]) == 2)
    np.testing.assert_allclose(kawasaki_error(cp)[iv], 0.0, atol=1e-12)
    assert np.all(cp.vertex_degree[iv] == 4)


def test_faces_counter_clockwise_and_planar():
    cp = miura(2, 2, alpha=70.0)
    assert np.all(cp.face_normals[:, 2] > 0.999999)
    folded = miura(2, 2, alpha=70.0, fold=50.0)
    X = folded.vertices
    for f in folded.faces:
        P = X[list(f)]
        n = np.cross(P[1] - P[0], P[3] - P[0])
        assert abs(np.dot(P[2] - P[0], n)) < 1e-12


def test_layout_groups(tmp_path):
    lay = miura_layout(2, 1)
    cp = miura(2, 1)
    # the layout can be recovered from the pattern, also after a FOLD round trip
    path = bh.write_fold(cp, tmp_path / "m.fold")
    assert miura_layout_of(bh.read_fold(path)) == lay
    X = cp.vertices
    assert np.all(X[lay.left, 0] <= X[:, 0].min() + 1.0)
    assert np.allclose(X[lay.bottom, 1], 0.0)
    assert np.allclose(X[lay.top, 1], X[:, 1].max())
    b = set(cp.boundary_edges.tolist())
    for g in (lay.left_edges, lay.right_edges, lay.bottom_edges, lay.top_edges):
        assert set(np.asarray(g).tolist()) <= b
    assert len(lay.interior_zigzag_edges) + len(lay.interior_straight_edges) == len(cp.crease_edges)


@pytest.mark.parametrize(
    "kwargs,name",
    [
        ({"alpha": 0.0}, "alpha"),
        ({"alpha": 90.0}, "alpha"),
        ({"alpha": -5.0}, "alpha"),
        ({"a": 0.0}, "a"),
        ({"b": -1.0}, "b"),
        ({"fold": -1.0}, "fold"),
        ({"fold": 90.5}, "fold"),
        ({"nx": 0}, "nx"),
        ({"ny": 1.5}, "ny"),
    ],
)
def test_out_of_range_parameters(kwargs, name):
    args = {"nx": 2, "ny": 2, **kwargs}
    with pytest.raises(PatternError, match=rf"\b{name}\b"):
        miura(**args)
