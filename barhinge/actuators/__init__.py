"""Actuators: the creases a fold drives, their schedules, and the control curves and surfaces
that set their fold angles.

- :mod:`barhinge.actuators.schedules`: :class:`Actuators` (which creases, which targets, how
  the targets move along the path).
- :mod:`barhinge.actuators.curves`: control curves (circle, parabola, spline) and control
  surfaces that place the actuator points of a section on a curve and return the actuator
  fold angles (imported on first use: it loads scipy's interpolation).
"""

from __future__ import annotations

import importlib
from typing import Any

from barhinge.actuators.schedules import Actuators

__all__ = [
    "Actuators",
    "ControlCurve",
    "CircularArc",
    "Parabola",
    "SplineCurve",
    "ControlSurface",
    "curve_actuators",
    "surface_actuators",
    "spaced_lines",
    "section_lines",
    "section_crossings",
    "curve_schedule",
    "synchronised",
]

_CURVES = set(__all__) - {"Actuators"}


def __getattr__(name: str) -> Any:
    if name in _CURVES:
        return getattr(importlib.import_module("barhinge.actuators.curves"), name)
    raise AttributeError(f"module 'barhinge.actuators' has no attribute {name!r}")
