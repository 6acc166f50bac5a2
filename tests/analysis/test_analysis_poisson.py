"""Poisson's ratios. Reference: Schenk & Guest (2013) "Geometry of Miura-folded
metamaterials", PNAS 110(9):3276, Eq. 2: nu_SL = -(dL/L)/(dS/S) = -cos^2(theta) tan^2(gamma)."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.poisson import (
    bending_poisson,
    end_to_end_poisson,
    grid_ends,
    grid_pairs,
    periodic_poisson,
)
from barhinge.errors import ConfigError

patterns = pytest.importorskip("barhinge.families")


def _miura_path(n: int, alpha: float = 60.0):
    theta = np.linspace(10.0, 80.0, n + 1)
    X = np.array([patterns.miura(3, 2, alpha=alpha, fold=t).vertices3d for t in theta])
    return theta, X, patterns.miura(3, 2, alpha=alpha, fold=10.0)


def _closed_form(theta_deg, alpha_deg):
    t, g = np.radians(theta_deg), np.radians(alpha_deg)
    return -(np.cos(t) ** 2) * np.tan(g) ** 2  # Schenk & Guest 2013, Eq. 2


@pytest.mark.parametrize("alpha", [45.0, 60.0, 70.0])
def test_miura_periodic_in_plane_ratio_matches_schenk_guest(alpha):
    err = []
    ns = [20, 40, 80]
    for n in ns:
        theta, X, cp = _miura_path(n, alpha)
        px, py = grid_pairs(cp)  # x: 2L apart, y: 2S apart
        res = periodic_poisson(X, py, px, parameter=np.radians(theta))  # drive S, measure L
        assert res.definition == "periodic"
        err.append(np.abs(res.nu - _closed_form(theta, alpha)).max())
    slope = np.polyfit(np.log(1.0 / np.array(ns)), np.log(err), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.3)  # second-order differences along the path
    assert err[-1] < 0.02 * np.tan(np.radians(alpha)) ** 2
    # the patterns helper's closed form agrees with ours
    g = patterns.miura_geometry(1.0, 1.0, alpha, 37.0)
    assert g.nu_SL == pytest.approx(_closed_form(37.0, alpha), rel=1e-12)


def _schenk_guest_dims(theta_rad, alpha_deg, a=1.0, b=1.0):
    """Cell dimensions S, L, V of Schenk & Guest (2013), Eq. 1 (complex-safe)."""
    g = np.radians(alpha_deg)
    D = np.sqrt(1.0 + np.cos(theta_rad) ** 2 * np.tan(g) ** 2)
    S = b * np.cos(theta_rad) * np.tan(g) / D
    L = a * np.sqrt(1.0 - np.sin(theta_rad) ** 2 * np.sin(g) ** 2)
    return S, L, b / D


def _finite_sheet_nu(theta_deg, alpha_deg, n):
    """Closed form of a Miura sheet of n cells along x: overall dimensions 2 n L + V (the
    zig-zag offset V of alternate rows adds once) and 2 n S, Schenk & Guest (2013) Eq. 1;
    nu = -(d ln(2 n L + V)) / (d ln S), derivatives by complex step (exact to round-off)."""
    h = 1e-30
    S, L, V = _schenk_guest_dims(np.radians(theta_deg) + 1j * h, alpha_deg)
    return -(np.imag(np.log(2 * n * L + V)) / h) / (np.imag(np.log(S)) / h)


@pytest.mark.parametrize("n", [1, 3, 5])
def test_miura_end_to_end_and_periodic_against_schenk_guest(n):
    """An n x n-cell Miura sheet (gamma = 60 deg) around the facet angle where the periodic
    ratio is -1 (cos^2 theta tan^2 gamma = 1). Periodic: -cos^2 theta tan^2 gamma (S&G Eq. 2).
    End-to-end (extents between the end edges): the finite-sheet closed form above, -1/3 for
    one cell. Tolerance: second-order central differences with d theta = 0.01 deg, error
    ~ (d theta)^2 ~ 3e-8 relative; 1e-6."""
    alpha = 60.0
    th0 = np.degrees(np.arccos(1.0 / np.tan(np.radians(alpha))))  # periodic nu = -1
    theta = th0 + np.array([-0.01, 0.0, 0.01])
    X = np.array([patterns.miura(n, n, alpha=alpha, fold=t).vertices3d for t in theta])
    cp = patterns.miura(n, n, alpha=alpha, fold=th0)
    px, py = grid_pairs(cp)
    (left, right), (bottom, top) = grid_ends(cp)
    per = periodic_poisson(X, py, px)  # drive S (y), measure L (x)
    e2e = end_to_end_poisson(X, (bottom, top), (left, right))
    assert e2e.definition == "end-to-end"
    assert per.nu[1] == pytest.approx(_closed_form(th0, alpha), abs=1e-6)
    assert per.nu[1] == pytest.approx(-1.0, abs=1e-6)
    assert e2e.nu[1] == pytest.approx(_finite_sheet_nu(th0, alpha, n), abs=1e-6)
    if n == 1:
        assert e2e.nu[1] == pytest.approx(-1.0 / 3.0, abs=1e-6)
    # the finite-sheet value tends to the periodic one as the sheet grows
    assert abs(e2e.nu[1] + 1.0) < abs(_finite_sheet_nu(th0, alpha, max(n - 2, 1)) + 1.0) or n == 1
    # the extent is the sheet's size: 2 n L + V by 2 n S
    S, L, V = _schenk_guest_dims(np.radians(th0), alpha)
    assert e2e.length_2[1] == pytest.approx(2 * n * L + V, rel=1e-12)
    assert e2e.length_1[1] == pytest.approx(2 * n * S, rel=1e-12)
    # the centroid measure cancels the zig-zag offset: the periodic ratio again
    cen = end_to_end_poisson(X, (bottom, top), (left, right), measure="centroid")
    assert cen.nu[1] == pytest.approx(per.nu[1], abs=1e-9)


def test_miura_periodic_and_centroid_measures_agree_along_a_path():
    theta, X, cp = _miura_path(12)
    px, py = grid_pairs(cp)
    (left, right), (bottom, top) = grid_ends(cp)
    per = periodic_poisson(X, py, px)
    cen = end_to_end_poisson(X, (bottom, top), (left, right), measure="centroid")
    np.testing.assert_allclose(cen.nu, per.nu, rtol=0, atol=1e-9)
    # S and L both shrink as the sheet folds: the strains have the same sign (auxetic)
    assert np.all(per.strain_1[1:] < 0) and np.all(per.strain_2[1:] < 0)
    with pytest.raises(ConfigError, match="measure"):
        end_to_end_poisson(X, (bottom, top), (left, right), measure="bbox")


def test_bending_ratio_of_analytic_surfaces():
    x, y = np.meshgrid(np.linspace(-1, 1, 9), np.linspace(-0.7, 0.7, 7))
    x, y = x.ravel(), y.ravel()
    for kx, ky in [(0.2, -0.1), (0.3, 0.3), (-0.05, 0.02)]:
        X = np.column_stack([x, y, 0.5 * kx * x**2 + 0.5 * ky * y**2 + 0.1])
        r = bending_poisson(X)
        assert r.kappa_x == pytest.approx(kx, rel=1e-10)
        assert r.kappa_y == pytest.approx(ky, rel=1e-10)
        assert r.nu == pytest.approx(-ky / kx, rel=1e-10)
        assert np.sign(r.K) == np.sign(kx * ky)


def test_bad_inputs():
    with pytest.raises(ConfigError, match="at least 3 states"):
        periodic_poisson(np.zeros((2, 4, 3)), [[0, 1]], [[0, 2]])
    with pytest.raises(ConfigError, match="references node"):
        periodic_poisson(np.zeros((3, 4, 3)), [[0, 9]], [[0, 2]])
    with pytest.raises(ConfigError, match="grid"):
        grid_pairs(bh.CreasePattern(np.eye(3)[:, :2], [[0, 1], [1, 2], [2, 0]], ["B"] * 3))


@pytest.mark.parametrize("theta", [30.0, 45.0, 60.0])
def test_miura_bent_by_end_moments_is_a_saddle_with_schenk_guest_ratio(theta):
    """Linear response of a 6 x 6-cell Miura sheet (N4B5, bars and panel bending 1000x the
    default: the rigid-panel limit with panels bending along a diagonal) to end moments about
    x on the y-ends (a couple of y-forces between the top and bottom vertex layers). Schenk &
    Guest (2013): a saddle with -kappa_L/kappa_S = +cos^2(theta) tan^2(gamma) (L along x,
    S along y). Tolerance 3 %: a finite sheet, fitted on its inner rows (measured 0.6-0.8 %)."""
    pytest.importorskip("barhinge.model.model")
    from barhinge.analysis.stiffness import linear_response
    from barhinge.scene import restraint_321

    alpha = 60.0
    cp = patterns.miura(6, 6, alpha=alpha, fold=theta)
    model = bh.BarHingeModel.from_pattern(
        cp, scheme="N4B5", material=bh.Material(E=1e6, nu=1 / 3, t=0.01), stiffness_ratio=1e3
    )
    nv = cp.n_vertices
    ni, nj = cp.meta["barhinge:grid"]
    J = np.arange(nv) // ni
    top = np.isclose(cp.vertices[:, 2], cp.vertices[:, 2].max())
    F = np.zeros((model.n_nodes, 3))
    for end, sign in ((J == 0, -1.0), (J == nj - 1, 1.0)):
        F[:nv][end & top, 1] += sign / (end & top).sum()
        F[:nv][end & ~top, 1] -= sign / (end & ~top).sum()
    U, R = linear_response(model, F, restraint_321(model))
    np.testing.assert_allclose(R.sum(0), 0, atol=1e-9)  # self-equilibrated load
    X = model.X0 + 1e-3 / np.abs(U).max() * U
    inner = (J > 1) & (J < nj - 2)
    res = bending_poisson(X, np.flatnonzero(top & inner))
    assert res.K < 0  # anticlastic
    assert res.nu_yx == pytest.approx(-_closed_form(theta, alpha), rel=0.03)
