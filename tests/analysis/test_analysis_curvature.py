"""Curvature of the global form (local / global quadratic fits) and per-vertex angle defects.

References: do Carmo (1976) Differential Geometry of Curves and Surfaces, Sec. 3-3 (Monge
patch curvature); Meyer, Desbrun, Schroeder & Barr (2003) "Discrete differential-geometry
operators for triangulated 2-manifolds", Sec. 3.3 (angle defect, mixed Voronoi area);
Descartes' theorem: the angle defects of a closed genus-0 polyhedron sum to 4 pi.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

import barhinge as bh
from barhinge.analysis.curvature import (
    angle_defect,
    fit_quadratic,
    local_curvatures,
    mixed_voronoi_area,
)
from barhinge.errors import ConfigError

HS = [0.1, 0.05, 0.025, 0.0125]


def _grid(h: float, f, half: float = 0.2, c=(0.0, 0.0)) -> np.ndarray:
    n = int(round(half / h))
    t = np.arange(-n, n + 1) * h
    x, y = np.meshgrid(t + c[0], t + c[1])
    x, y = x.ravel(), y.ravel()
    return np.column_stack([x, y, f(x, y)])


def _at(P: np.ndarray, c) -> int:
    return int(np.argmin(((P[:, :2] - np.asarray(c)) ** 2).sum(1)))


def _bowl(R: float):
    return lambda x, y: R - np.sqrt(R * R - x * x - y * y)


@pytest.mark.parametrize("c", [(0.0, 0.0), (0.3, 0.2)])
def test_sphere_K_converges_at_second_order(c):
    """Sphere of radius R: K = 1/R^2, k1 = k2 = H = 1/R (bowl, normal up, so H > 0)."""
    R = 1.0
    err = []
    for h in HS:
        P = _grid(h, _bowl(R), c=c)
        i = _at(P, c)
        lc = local_curvatures(P)
        err.append(abs(lc["K"][i] - 1 / R**2))
        assert lc["H"][i] == pytest.approx(1 / R, rel=0.05)
        assert lc["k1"][i] >= lc["k2"][i] > 0
    slope = np.polyfit(np.log(HS), np.log(err), 1)[0]
    # symmetric neighbourhoods cancel the cubic terms: error O(h^2)
    assert slope == pytest.approx(2.0, abs=0.2)
    assert err[-1] < 1e-3


def test_dome_has_negative_mean_and_positive_gaussian_curvature():
    P = _grid(0.05, lambda x, y: -_bowl(2.0)(x, y))
    i = _at(P, (0, 0))
    lc = local_curvatures(P)
    assert lc["K"][i] == pytest.approx(0.25, rel=0.02)
    assert lc["H"][i] == pytest.approx(-0.5, rel=0.02)


def test_hyperbolic_paraboloid_is_exact_for_quadratic_fits():
    """z = x y: at the origin K = -1, H = 0, principal directions along x = +-y."""
    P = _grid(0.05, lambda x, y: x * y, half=0.3)
    lc = local_curvatures(P)
    i = _at(P, (0, 0))
    assert lc["K"][i] == pytest.approx(-1.0, abs=1e-10)
    assert lc["H"][i] == pytest.approx(0.0, abs=1e-10)
    g = fit_quadratic(P)
    assert g.K == pytest.approx(-1.0, abs=1e-10)
    assert abs(g.directions[0] @ np.array([1, 1, 0]) / np.sqrt(2)) == pytest.approx(1, abs=1e-9)


def test_cylinder_K_tends_to_zero_and_H_to_half_inverse_radius():
    """Cylinder of radius R (dome-like, axis y): K = 0, H = -1/(2R)."""
    R = 1.0
    err = []
    for h in HS:
        P = _grid(h, lambda x, y: np.sqrt(R * R - x * x) - R)
        lc = local_curvatures(P)
        i = _at(P, (0, 0))
        err.append(abs(lc["K"][i]))
        assert lc["H"][i] == pytest.approx(-0.5 / R, rel=0.02)
    slope = np.polyfit(np.log(HS), np.log(err), 1)[0]
    assert slope > 1.8
    assert err[-1] < 1e-5


def test_global_fit_of_a_large_sphere_cap():
    R = 5.0
    g = fit_quadratic(_grid(0.05, _bowl(R), half=0.5))
    assert g.K == pytest.approx(1 / R**2, rel=0.01)
    assert g.normal[2] > 0.999


@settings(max_examples=20, deadline=None)
@given(n=st.integers(8, 120), seed=st.integers(0, 10_000))
def test_angle_defects_of_a_closed_polyhedron_sum_to_4pi(n, seed):
    """Descartes' theorem for random convex polyhedra (convex hulls of points on a sphere)."""
    rng = np.random.default_rng(seed)
    Q = rng.normal(size=(n, 3)) * np.array([1.0, 0.7, 1.3])
    hull = ConvexHull(Q)
    used = np.unique(hull.simplices)
    d = angle_defect(Q, hull.simplices)
    assert np.isfinite(d[used]).all()
    assert d[used].sum() == pytest.approx(4 * np.pi, abs=1e-10)
    assert mixed_voronoi_area(Q, hull.simplices).sum() == pytest.approx(hull.area, rel=1e-12)


def test_mixed_voronoi_area_of_simple_triangles():
    # equilateral: the Voronoi region of each corner is a third of the area
    X = np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    A = mixed_voronoi_area(X, np.array([[0, 1, 2]]))
    np.testing.assert_allclose(A, np.sqrt(3) / 12, rtol=1e-12)
    # obtuse at corner 2: half the area there, a quarter at the others (Meyer et al. Fig. 4)
    X = np.array([[0, 0, 0], [2, 0, 0], [1, 0.2, 0]])
    A = mixed_voronoi_area(X, np.array([[0, 1, 2]]))
    np.testing.assert_allclose(A, [0.05, 0.05, 0.1], rtol=1e-12)


def test_flat_sheet_has_zero_defect_and_nan_on_boundary():
    P = _grid(0.1, lambda x, y: 0 * x, half=0.3)
    n = 7
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1]
    T = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d.ravel()])])
    res = bh.gaussian_curvature(P, triangles=T)
    interior = np.isfinite(res.angle_defect)
    assert interior.sum() == (n - 2) ** 2
    assert np.abs(res.angle_defect[interior]).max() < 1e-14
    assert res.K_global == pytest.approx(0, abs=1e-12)


def test_bad_input_is_a_config_error():
    with pytest.raises(ConfigError, match="shape"):
        bh.gaussian_curvature(np.zeros((5, 2)))
    with pytest.raises(ConfigError, match="at least 6"):
        bh.gaussian_curvature(np.zeros((4, 3)))


def test_rigidly_folded_miura_has_zero_angle_defect():
    """Rigid folding is an isometry of every panel: the defects stay zero (to round-off)."""
    patterns = pytest.importorskip("barhinge.families")
    for theta in (20.0, 45.0, 70.0):
        cp = patterns.miura(4, 4, a=1.0, b=1.0, alpha=60.0, fold=theta)
        res = bh.gaussian_curvature(cp.vertices3d, pattern=cp)
        d = res.angle_defect[np.isfinite(res.angle_defect)]
        assert len(d) > 0
        assert np.abs(d).max() < 1e-12
        # the uniformly folded Miura's global form is flat
        assert abs(res.K_global) < 1e-10
