"""Polynomial extrapolation of a path through its converged states
(:mod:`barhinge.linalg.extrapolation`), the predictor of the rigid corrector and of the
bar-and-hinge solver."""

from __future__ import annotations

import numpy as np
import pytest

from barhinge.linalg.extrapolation import EXTRAPOLATION_POINTS, extrapolate, lagrange


def _schenk_guest(rho_z: np.ndarray, gamma: float = np.radians(60.0)) -> np.ndarray:
    """Fold angles (rho_s, rho_z) of a Miura cell against its zig-zag fold angle (Schenk &
    Guest 2013: rho_z = 2 theta, rho_s = 2 arctan(cos gamma tan theta))."""
    return np.array([2.0 * np.arctan(np.cos(gamma) * np.tan(rho_z / 2.0)), rho_z])


@pytest.mark.parametrize("start_deg", [15.0, 60.0, 100.0])
def test_predictor_extrapolates_a_smooth_path_to_high_order(start_deg):
    """Eight states of the Schenk-Guest path 4 deg apart: the predictor's error is far below
    the cubic's (the predictor of earlier versions) and below 1e-6 rad; a polynomial path of
    degree 7 is reproduced to round-off."""
    h = np.radians(4.0)
    s = np.radians(start_deg) + h * np.arange(EXTRAPOLATION_POINTS)
    hist = [(si, _schenk_guest(si)) for si in s]
    s_new = s[-1] + h
    exact = _schenk_guest(s_new)
    err = np.abs(extrapolate(hist, s_new) - exact).max()
    cubic = np.abs(lagrange(hist[-4:], s_new) - exact).max()
    assert err < 1e-6
    assert err < 1e-2 * cubic
    coef = np.random.default_rng(3).standard_normal(EXTRAPOLATION_POINTS)
    poly = [(si, np.array([np.polyval(coef, si)])) for si in s]
    assert extrapolate(poly, s_new)[0] == pytest.approx(np.polyval(coef, s_new), abs=1e-9)


@pytest.mark.parametrize("states_after", [2, 3, 5])
def test_predictor_stops_its_degree_before_a_corner(states_after):
    """A control curve's corner makes the path's slope jump. With three or more states past
    the corner the predictor uses only those (exact on the new straight leg); with two it
    is no worse than the quadratic through the last three states."""
    h = 0.05

    def path(s: float) -> np.ndarray:  # slope 1, then -0.5 after s = 1
        return np.array([s if s <= 1.0 else 1.0 - 0.5 * (s - 1.0)])

    s = 1.0 + h * (np.arange(8) - 7 + states_after)
    hist = [(si, path(si)) for si in s]
    s_new = s[-1] + h
    err = abs(extrapolate(hist, s_new)[0] - path(s_new)[0])
    quadratic = abs(lagrange(hist[-3:], s_new)[0] - path(s_new)[0])
    if states_after >= 3:
        assert err < 1e-12
    else:
        assert err <= quadratic + 1e-12
