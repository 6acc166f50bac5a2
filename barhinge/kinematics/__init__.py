"""Rigid-origami kinematics: loop-closure constraints, degrees of freedom, actuator selection
and rigid folding paths (see docs/kinematics.md).

``bh.dof`` and ``bh.rigid_fold`` are re-exported lazily by :mod:`barhinge`.
"""

from __future__ import annotations

from barhinge.kinematics.constraints import NodalConstraints, RigidConstraints, triangulated_pattern
from barhinge.kinematics.dof import DofReport, dof, folded_sample, select_actuators
from barhinge.kinematics.path import RigidOptions, rigid_fold
from barhinge.kinematics.sensitivity import RigidSensitivity, rigid_sensitivity

__all__ = [
    "DofReport",
    "NodalConstraints",
    "RigidConstraints",
    "RigidOptions",
    "RigidSensitivity",
    "dof",
    "folded_sample",
    "rigid_fold",
    "rigid_sensitivity",
    "select_actuators",
    "triangulated_pattern",
]
