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

patterns = pytest.importorskip("barhinge.patterns")


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


def test_miura_end_to_end_equals_periodic_for_a_uniform_sheet():
    """A uniformly folded Miura sheet has no boundary effects: boundary-group centroids are
    whole periods apart, so both definitions agree to round-off."""
    theta, X, cp = _miura_path(12)
    px, py = grid_pairs(cp)
    (left, right), (bottom, top) = grid_ends(cp)
    per = periodic_poisson(X, py, px)
    e2e = end_to_end_poisson(X, (bottom, top), (left, right))
    assert e2e.definition == "end-to-end"
    np.testing.assert_allclose(e2e.nu, per.nu, rtol=0, atol=1e-9)
    # S and L both shrink as the sheet folds: the strains have the same sign (auxetic)
    assert np.all(per.strain_1[1:] < 0) and np.all(per.strain_2[1:] < 0)


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
