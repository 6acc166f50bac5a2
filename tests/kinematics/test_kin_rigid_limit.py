"""Rigid path vs the compliant bar-and-hinge solver in the rigid limit: same fold angles
along the same Actuators schedule as the panels are made stiff relative to the folds."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh


def test_compliant_solution_approaches_rigid_path():
    try:
        from barhinge.model.material import Material
        from barhinge.model.model import BarHingeModel
    except ImportError:  # pragma: no cover - the model helper's work is absent
        pytest.skip("bar-and-hinge model not available")
    # start folded (no branch choice at the flat bifurcation point) and fold further
    cp = bh.families.miura(2, 2, fold=20.0)
    e = int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])
    act = bh.Actuators(edges=[e], targets_deg=[3.0 * cp.fold_angles[e]])
    rigid = bh.rigid_fold(cp, act, steps=8)
    creases = cp.crease_edges
    errors = []
    for ratio in (1e3, 1e4, 1e5):  # 1/r regime (plate-calibrated panel bending)
        model = BarHingeModel.from_pattern(
            cp,
            scheme="N5B8",
            material=Material(E=1e9, nu=0.3, t=1e-3),
            crease_length_scale=0.1,
            stiffness_ratio=ratio,
        )
        path = bh.solve(bh.Scene(model, actuators=act, steps=8))
        np.testing.assert_allclose(path.actuator_targets_deg, rigid.actuator_targets_deg)
        diff = path.fold_angles_deg[:, creases] - rigid.fold_angles_deg[:, creases]
        errors.append(float(np.abs(diff).max()))
    # stiffer panels -> closer to the rigid kinematics (at least 3x per decade here)
    assert errors[1] < errors[0] / 3 and errors[2] < errors[1] / 3
    assert errors[2] < 1.0  # degrees
