"""Nonlinear incremental solver: Newton with fold-angle (actuator), displacement, load and
arc-length control (the factorisation backends are in :mod:`barhinge.linalg`).

The function is :func:`barhinge.solve` (defined in :mod:`barhinge.solver.newton`).
Nothing is imported eagerly, so importing a module of the solver (or this package for
:class:`~barhinge.solver_options.SolverOptions`, kept here for convenience; it lives below the
scene) does not load the Newton driver before it is needed.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["SolverOptions", "solve"]

# name -> module that defines it (imported on first use)
_LAZY = {"solve": "barhinge.solver.newton", "SolverOptions": "barhinge.solver_options"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'barhinge.solver' has no attribute {name!r}")
