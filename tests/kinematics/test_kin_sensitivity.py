"""Exact sensitivities of the rigid fold (implicit-function theorem on its KKT system) against
central finite differences of re-solved rigid folds (an independent check: no derivative
code is shared)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.families.miura import miura
from barhinge.families.yoshimura import yoshimura
from barhinge.kinematics.path import RigidOptions

OPTS = RigidOptions(check_actuators=False)
# step (degrees): truncation error O(H^2) ~ 1e-9; the finite differences also divide the
# energy minimiser's stopping tolerance (1e-9 rad) by 2H = 3.5e-5 rad: noise up to ~3e-5
# where the minimiser stops early (the least-squares case); the exact values are noise-free
H = 1e-3
FD_TOL = 1e-4


def _central(cp, edges, targets):
    drho, dX = [], []
    for j in range(len(edges)):
        tp = np.array(targets, float)
        tm = tp.copy()
        tp[j] += H
        tm[j] -= H
        pp = bh.rigid_fold(cp, edges, tp, steps=3, options=OPTS)
        pm = bh.rigid_fold(cp, edges, tm, steps=3, options=OPTS)
        drho.append((pp.fold_angles_deg[-1] - pm.fold_angles_deg[-1]) / (2 * H))
        dX.append((pp.X[-1] - pm.X[-1]) / (2 * np.radians(H)))
    return np.stack(drho, 1), np.stack(dX, -1)


def _signs(cp, edges):
    return np.where(cp.assignment[edges] == "M", -1.0, 1.0)


@pytest.mark.parametrize("count", [2, None], ids=["under-actuated", "every-dof"])
def test_sensitivity_matches_central_differences_yoshimura(count):
    """Yoshimura 2 x 2: two actuators (free motions resolved by the fold-spring energy, the
    multiplier Hessian matters) and every DOF actuated (the constraints alone)."""
    cp = yoshimura(nx=2, ny=2)
    A = np.asarray(bh.dof(cp).mechanism.actuators)[:count]
    t = _signs(cp, A) * np.linspace(25.0, 35.0, len(A))
    path = bh.rigid_fold(cp, A, t, steps=3, options=OPTS)
    s = bh.rigid_sensitivity(cp, path)
    fd_rho, fd_X = _central(cp, A, t)
    assert np.abs(fd_rho).max() > 0.1  # the folds do respond
    np.testing.assert_allclose(s.drho_dt, fd_rho, atol=FD_TOL)
    np.testing.assert_allclose(s.dX_dt, fd_X, atol=FD_TOL * np.abs(fd_X).max())


def test_sensitivity_matches_central_differences_least_squares():
    """Miura 2 x 2 (one DOF) with three actuators whose targets disagree: met in least
    squares, every crease free and the actuators springs to their targets."""
    cp = miura(nx=2, ny=2)
    E = cp.crease_edges[:3]
    t = _signs(cp, E) * np.array([30.0, 33.0, 27.0])
    path = bh.rigid_fold(cp, E, t, steps=3, options=OPTS)
    assert path.meta["least_squares"]
    s = bh.rigid_sensitivity(cp, path)
    fd_rho, _ = _central(cp, E, t)
    np.testing.assert_allclose(s.drho_dt, fd_rho, atol=FD_TOL)
    # least squares of a one-DOF motion: the responses to the three targets sum to the
    # response of the common motion (a uniform change of the targets moves the sheet along it)
    assert np.abs(s.drho_dt).max() < 1.0 + 1e-9


def test_sensitivity_matches_central_differences_compliant():
    """Miura 2 x 2 with three compliant actuators (springs 5x the stiffest fold) whose
    targets disagree: the derivatives of the least fold-plus-actuator-spring energy."""
    cp = miura(nx=2, ny=2)
    E = cp.crease_edges[:3]
    t = _signs(cp, E) * np.array([30.0, 33.0, 27.0])
    V = np.asarray(cp.vertices, float)
    lengths = np.linalg.norm(V[cp.edges[:, 1]] - V[cp.edges[:, 0]], axis=1)
    k = 5.0 * float(lengths[cp.crease_edges].max())  # the default fold stiffness: length

    def fold(targets):
        acts = bh.Actuators(edges=E, targets_deg=targets, stiffness=k)
        return bh.rigid_fold(cp, acts, steps=3, options=OPTS)

    path = fold(t)
    assert path.meta["compliant_actuators"] and path.meta["actuator_misfit_deg"][-1] > 1.0
    s = bh.rigid_sensitivity(cp, path)
    fd = []
    for j in range(len(E)):
        tp, tm = t.copy(), t.copy()
        tp[j] += H
        tm[j] -= H
        fd.append((fold(tp).fold_angles_deg[-1] - fold(tm).fold_angles_deg[-1]) / (2 * H))
    fd_rho = np.stack(fd, 1)
    assert np.abs(fd_rho).max() > 0.05
    np.testing.assert_allclose(s.drho_dt, fd_rho, atol=FD_TOL)


def test_sensitivity_needs_a_converged_rigid_path():
    cp = miura(nx=2, ny=2)
    path = bh.rigid_fold(cp, cp.crease_edges[:1], [30.0], steps=2, options=OPTS)
    with pytest.raises(ConfigError, match="converged rigid_fold"):
        bh.rigid_sensitivity(cp, dataclasses.replace(path, converged=False))
