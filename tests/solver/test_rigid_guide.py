"""The rigid guide of a flat start: its first step is resolved in sub-steps that lie on the
rigid fold (a chord between two rigid states does not), and where the actuators leave free
motions it keeps the requested steps."""

from __future__ import annotations

import numpy as np

import barhinge as bh
from barhinge.solver.branch import GUIDE_FIRST_STEP, rigid_guide

MAT = bh.Material(E=1e6, nu=0.3, t=0.01)


def _bar_strain(model, X: np.ndarray) -> float:
    b = np.asarray(model.bars)
    L = np.linalg.norm(X[b[:, 1]] - X[b[:, 0]], axis=1)
    return float(np.abs(L / model.bar_L0 - 1.0).max())


def _guide(model, acts, steps):
    free = np.zeros((model.n_nodes, 3), bool)
    return rigid_guide(model, acts, steps, free, np.asarray(model.X0))


def test_first_step_of_a_determined_fold_is_on_the_rigid_fold():
    """Miura driven by one zig-zag crease to 60 deg in 5 steps: the guide's states inside
    the first step keep every bar length (rigid panels, to the closure tolerance), while the
    chord between the flat state and step 1 shortens bars by ~theta^2 / 8 (theta = 12 deg:
    ~5e-3 of the fold's curvature acting on the sheet); the sub-step states are those of the
    rigid fold itself (bh.rigid_fold at the same actuator angle)."""
    cp = bh.families.miura(3, 3)
    z = int(bh.families.miura_layout(3, 3).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, "N5B8", MAT, stiffness_ratio=1e5)
    target = 60.0 * np.sign(cp.fold_angles[z])
    steps = 5
    g = _guide(model, bh.Actuators(edges=[z], targets_deg=[target]), steps)
    k = GUIDE_FIRST_STEP
    assert len(g.t) == steps + k
    np.testing.assert_allclose(g.t[: k + 1], np.arange(k + 1) / (k * steps))
    mid = 0.5 / steps
    chord = 0.5 * (g.X[0] + g.X[k])
    assert _bar_strain(model, g.at(mid)) < 1e-12
    assert _bar_strain(model, chord) > 1e-4
    # the sub-step state at half the first step is the rigid fold at half its angle
    half = bh.rigid_fold(cp, [z], targets_deg=[target / (2 * steps)], steps=1)
    n_v = cp.n_vertices
    np.testing.assert_allclose(g.at(mid)[:n_v], np.asarray(half.X[-1]), atol=1e-9)


def test_underactuated_guide_keeps_the_requested_steps():
    """Ron Resch driven by fewer actuators than its DOF: the free motions are resolved per
    step by the fold springs, so the guide is the rigid fold of the requested steps only."""
    cp = bh.families.resch(3, 3)
    a = [int(e) for e in bh.dof(cp).mechanism.actuators][:1]
    model = bh.BarHingeModel.from_pattern(cp, "N5B8", MAT, stiffness_ratio=1e4)
    g = _guide(model, bh.Actuators(edges=a, targets_deg=0.5 * cp.fold_angles[a]), 5)
    assert g.record["free_dof"]
    np.testing.assert_allclose(g.t, np.arange(6) / 5)
