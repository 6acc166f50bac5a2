"""``barhinge fold --form-only``: the model a scene needs when only its folded form is
wanted, and the rigid fold of such a scene.

Rigid kinematics is exact and fastest for a form driven by actuators alone
(docs/speed-accuracy.md); loads or prescribed displacements need the compliant model.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from barhinge.errors import ConfigError
from barhinge.results import FoldPath
from barhinge.scene import Scene

__all__ = ["form_only_model", "rigid_form"]


def form_only_model(scene: Scene) -> tuple[Literal["rigid", "bar-hinge"], str]:
    """("rigid" | "bar-hinge", reason): the model ``scene`` needs for its folded form."""
    if scene.actuators is None or not scene.actuators.n:
        return "bar-hinge", "no actuators"
    if np.any(scene.loads) or np.isfinite(np.asarray(scene.prescribed, float)).any():
        return "bar-hinge", "the scene has loads or prescribed displacements"
    return "rigid", "actuators only"


def rigid_form(scene: Scene) -> FoldPath:
    """Fold ``scene`` by rigid kinematics, free motions resolved with the model's own fold
    springs (its rigid limit); a path on the vertices of ``scene.model.pattern``.

    Raises
    ------
    BarhingeError
        Rigid kinematics cannot follow the actuators (e.g. over-actuated with contradicting
        targets); the caller then uses the bar-and-hinge solver.
    """
    from barhinge.kinematics.path import RigidOptions, rigid_fold
    from barhinge.solver.branch import fold_weights

    if scene.actuators is None:
        raise ConfigError("rigid kinematics folds a scene by its actuators; this one has none")

    # no DOF recount per state (a diagnostic that costs a dense SVD per state)
    opts = RigidOptions(max_cutbacks=3, check_rank=False, over_actuated="error")
    weights, _ = fold_weights(scene.model)
    path = rigid_fold(
        scene.model.pattern,  # its state is the model's reference state X0
        scene.actuators,
        steps=scene.steps,
        options=opts,
        fold_stiffness=weights,
    )
    path.meta.setdefault("scene", scene.name)
    return path
