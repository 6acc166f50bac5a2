"""Nonlinear incremental solver: Newton with fold-angle (actuator), displacement, load and
arc-length control (the factorisation backends are in :mod:`barhinge.linalg`).

``bh.solve`` is both this sub-package and the function :func:`barhinge.solve.newton.solve`:
once the sub-package is imported Python binds ``barhinge.solve`` to it, so the module is made
callable and forwards to the function (``bh.solve(scene)`` works either way).

Nothing is imported eagerly, so importing a module of the solver (or ``barhinge.solve`` for
:class:`~barhinge.solver_options.SolverOptions`, kept here for convenience; it lives below the
scene) does not load the Newton driver before it is needed.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any

__all__ = ["SolverOptions", "solve"]

# name -> module that defines it (imported on first use)
_LAZY = {"solve": "barhinge.solve.newton", "SolverOptions": "barhinge.solver_options"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'barhinge.solve' has no attribute {name!r}")


class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from barhinge.solve.newton import solve

        return solve(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
