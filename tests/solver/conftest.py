"""Scenes shared by the solver's tests."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene


def flat_miura_scene(steps: int = 6) -> Scene:
    """A 3 x 3 Miura sheet folded from flat to 60 deg by its middle crease line in a few long
    steps: the first increments are cut back (max_iter 8: with the softer plate-calibrated
    panels 6 iterations no longer converge at any step size), and damped, chord and
    accelerated corrections all occur."""
    cp0 = bh.families.miura(3, 3, alpha=60.0, fold=0.0)
    cp1 = bh.families.miura(3, 3, alpha=60.0, fold=60.0)
    edges = miura_line_creases(cp0)
    model = BarHingeModel.from_pattern(cp0, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    return Scene(model, actuators=acts, steps=steps, options={"max_iter": 8})


@pytest.fixture
def flat_miura() -> Callable[..., Scene]:
    """:func:`flat_miura_scene`, as a fixture (call it with the number of steps)."""
    return flat_miura_scene
