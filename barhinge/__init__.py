"""barhinge: bar-and-hinge structural analysis of origami tessellations.

The public API (see docs/ and DESIGN.md §4) is re-exported here lazily, so ``import barhinge``
stays cheap and never imports rendering libraries.
"""

from __future__ import annotations

import importlib
from typing import Any

from barhinge import _deprecated
from barhinge import results as _results
from barhinge._version import __version__ as __version__
from barhinge.actuators import Actuators
from barhinge.errors import BarhingeError, ConfigError, ConvergenceError, PatternError
from barhinge.pattern.crease import CreasePattern
from barhinge.results import FoldPath

# name -> module that defines it (imported on first use)
_LAZY = {
    "read": "barhinge.pattern.io",
    "read_fold": "barhinge.pattern.fold",
    "write_fold": "barhinge.pattern.fold",
    "read_svg": "barhinge.pattern.svg",
    "families": "barhinge.families",
    "kinematics": "barhinge.kinematics",
    "analysis": "barhinge.analysis",
    "sweep": "barhinge.sweep",
    "dof": "barhinge.kinematics.dof",
    "rigid_fold": "barhinge.kinematics.path",
    "rigid_sensitivity": "barhinge.kinematics.sensitivity",
    "BarHingeModel": "barhinge.model.model",
    "Material": "barhinge.model.material",
    "Scene": "barhinge.scene",
    "load_scene": "barhinge.scene",
    "Imperfection": "barhinge.scene",
    "seed_imperfection": "barhinge.analysis.imperfection",
    "solve": "barhinge.solver.newton",
    "tangent_stiffness": "barhinge.analysis.stiffness",
    "gaussian_curvature": "barhinge.analysis.curvature",
    "periodic_cell": "barhinge.analysis.periodic",
}

__all__ = [
    "Actuators",
    "BarhingeError",
    "ConfigError",
    "ConvergenceError",
    "CreasePattern",
    "FoldPath",
    "PatternError",
    *_LAZY,
]


def _html_display(path: FoldPath) -> str:
    """The viewer of a fold path inside an iframe (Jupyter's rich display of FoldPath)."""
    from barhinge.view import iframe_html

    return iframe_html(path)


_results.HTML_DISPLAY = _html_display


_deprecated.install()

#: attribute names of 0.1 that were renamed (old -> new)
_RENAMED = {"patterns": "families"}


def __getattr__(name: str) -> Any:
    if name in _RENAMED:
        _deprecated.warn_renamed(f"barhinge.{name}", f"barhinge.{_RENAMED[name]}")
        return __getattr__(_RENAMED[name])
    if name in _LAZY:
        module = importlib.import_module(_LAZY[name])
        value = module if module.__name__ == f"barhinge.{name}" else getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'barhinge' has no attribute {name!r}")
