"""Fold-angle (actuator) control on small patterns with independent checks."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene


def _single_fold(k: float = 0.3, rest_deg: float = 0.0) -> BarHingeModel:
    """A unit square folded along one diagonal (two triangles, one valley crease)."""
    V = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]])
    cp = bh.CreasePattern(V, E, ["B", "B", "B", "B", "V"])
    return BarHingeModel.from_pattern(cp, "N4B5", Material(E=1e5, nu=0.3, t=0.01), fold_stiffness=k)


def test_single_fold_actuator_moment_equals_spring_moment():
    """The actuator holds the fold spring alone: moment = k L (rho - rho_rest), the linear
    fold law, at every step (k per unit length, L the crease length sqrt 2)."""
    model = _single_fold(k=0.3)
    scene = Scene(
        model,
        actuators=bh.Actuators(edges=[4], targets_deg=[120.0]),
        steps=6,
        options={"tol_force": 1e-13, "tol_disp": 1e-13},  # converge to round-off
    )
    path = bh.solve(scene)
    rho = np.radians(path.fold_angles_deg[:, 4])
    np.testing.assert_allclose(rho, np.radians(np.linspace(0, 120, 7)), rtol=0, atol=1e-9)
    expected = 0.3 * np.sqrt(2.0) * (rho - 0.0)
    np.testing.assert_allclose(path.actuator_moments[:, 0], expected, rtol=1e-9, atol=1e-12)
    # the stored fold energy k L rho^2 / 2 equals the actuator's work (trapezoid on a linear
    # moment-angle law is exact)
    np.testing.assert_allclose(path.energy_fold, 0.5 * 0.3 * np.sqrt(2) * rho**2, rtol=1e-9)
    np.testing.assert_allclose(path.external_work, path.energy, rtol=1e-8, atol=1e-14)


def test_mountain_target_gives_negative_moment_and_table_schedule():
    model = _single_fold(k=0.5)
    table = np.array([[-20.0], [-40.0], [-10.0]])  # any per-step schedule
    scene = Scene(
        model,
        actuators=bh.Actuators(edges=[4], table_deg=table),
        steps=3,
        options={"tol_force": 1e-12},  # moments checked to 1e-9 below
    )
    path = bh.solve(scene)
    np.testing.assert_allclose(path.fold_angles_deg[1:, 4], table[:, 0], atol=1e-8)
    np.testing.assert_allclose(path.actuator_targets_deg[1:, 0], table[:, 0], atol=1e-12)
    expected = 0.5 * np.sqrt(2.0) * np.radians(table[:, 0])
    np.testing.assert_allclose(path.actuator_moments[1:, 0], expected, rtol=1e-9)


def test_zero_fold_stiffness_mechanism_is_driven_by_the_constraint_alone():
    """With k = 0 the fold is a free mechanism: K is singular and only the actuator row
    removes it. The augmented form K + p G^T G must still give the exact answer (zero
    moment, target reached) — no regularisation left in the result."""
    model = _single_fold(k=0.0)
    scene = Scene(model, actuators=bh.Actuators(edges=[4], targets_deg=[90.0]), steps=3)
    path = bh.solve(scene)
    np.testing.assert_allclose(path.fold_angles_deg[-1, 4], 90.0, atol=1e-8)
    assert np.abs(path.actuator_moments).max() < 1e-9
    assert path.energy[-1] < 1e-14


def test_equilibrium_at_every_step_with_supports_loads_and_actuators():
    """Reactions + applied loads balance (forces and moments about the origin), since
    internal forces and actuator forces G^T mu are self-equilibrated; the imbalance is the
    free-DOF residual, i.e. the solver tolerance."""
    model = _single_fold(k=0.2)
    n = model.n_nodes
    S = np.zeros((n, 3), bool)
    S[0] = True
    S[1] = True
    S[3, 2] = True  # corner 3 held vertically: the two triangles are held, the crease folds
    P = np.zeros((n, 3))
    P[2, 2] = -0.01
    scene = Scene(
        model,
        supports=S,
        loads=P,
        actuators=bh.Actuators(edges=[4], targets_deg=[30.0]),
        steps=4,
        # balance checked to 1e-8 of the load below: the force floor (default 1e-12 of the
        # bars' stiffness x size, ~1e-9 here) must lie under it
        options={"tol_force": 1e-12, "tol_disp": 1e-12, "force_floor": 1e-14},
    )
    path = bh.solve(scene)
    for i in range(path.n_states):
        F = path.load_factor[i] * P + path.reactions[i]
        scale = max(np.abs(path.reactions[i]).max(), np.abs(P).max())
        np.testing.assert_allclose(F.sum(0), 0.0, atol=1e-8 * scale)
        np.testing.assert_allclose(np.cross(path.X[i], F).sum(0), 0.0, atol=1e-8 * scale)
        assert np.all(path.reactions[i][~S] == 0.0)


def test_convergence_error_carries_partial_path():
    model = _single_fold(k=0.3)
    # an impossible schedule step: 170 deg in one step with one Newton iteration allowed
    # (the tangent predictor off the flat start: the rigid-fold prediction of a single
    # fold would be exact and converge at once)
    scene = Scene(
        model,
        actuators=bh.Actuators(edges=[4], targets_deg=[170.0]),
        steps=2,
        options={"max_iter": 1, "max_cutbacks": 0, "flat_start": "tangent"},
    )
    with pytest.raises(bh.ConvergenceError) as info:
        bh.solve(scene)
    err = info.value
    assert err.step == 1 and err.last_state.n_states == 1
    assert err.residuals and not err.last_state.converged
