"""Control surfaces (barhinge.actuators.curves.ControlSurface, surface_actuators)."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.actuators.curves import (
    ControlSurface,
    Parabola,
    curve_actuators,
    section_crossings,
    surface_actuators,
)
from barhinge.errors import ConfigError


def test_surface_sections_are_its_principal_parabolas() -> None:
    s = ControlSurface(0.2, -0.1)
    assert s.gaussian_curvature == pytest.approx(-0.02)
    assert s.sections() == (Parabola(0.2), Parabola(-0.1))
    assert s.scaled(0.5) == ControlSurface(0.1, -0.05)
    with pytest.raises(ConfigError):
        ControlSurface(float("nan"), 0.0)


def test_surface_actuators_drive_both_sections_with_their_curves() -> None:
    cp = bh.families.miura(nx=3, ny=3)
    surf = ControlSurface(0.15, -0.1)
    acts = surface_actuators(cp, surf)
    ex = section_crossings(cp)[0]
    ey = section_crossings(cp, direction=(0.0, 1.0))[0]
    ey = ey[~np.isin(ey, ex)]
    np.testing.assert_array_equal(acts.edges, np.concatenate([ex, ey]))
    want_x = curve_actuators(cp, ex, Parabola(0.15)).targets_deg
    want_y = curve_actuators(cp, ey, Parabola(-0.1), direction=(0.0, 1.0)).targets_deg
    np.testing.assert_allclose(acts.targets_deg, np.concatenate([want_x, want_y]), atol=1e-12)
    # the x section bends towards +z (valley rotations), the y section away (mountain)
    assert np.all(want_x > 0) and np.all(want_y < 0)


def test_shallow_parabola_rotation_is_curvature_times_spacing() -> None:
    """Small curvature: the turning angle at an actuator is kappa times the mean of the two
    gaps (chord geometry; the circle gives 2 arcsin(kappa d / 2) = kappa d + O(kappa^3))."""
    cp = bh.families.miura(nx=3, ny=3)
    k = 1e-4
    acts = surface_actuators(cp, ControlSurface(k, 0.0))
    ex, x, ends = section_crossings(cp)
    chain = np.concatenate([[ends[0]], x, [ends[1]]])
    want = np.degrees(k * 0.5 * (chain[2:] - chain[:-2]))
    np.testing.assert_allclose(acts.targets_deg[: len(ex)], want, rtol=1e-3)
