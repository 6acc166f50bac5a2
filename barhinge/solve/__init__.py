"""Nonlinear incremental solver: Newton with fold-angle (actuator), displacement, load and
arc-length control; sparse factorisation backends.

``bh.solve`` is both this sub-package and the function :func:`barhinge.solve.newton.solve`:
once the sub-package is imported Python binds ``barhinge.solve`` to it, so the module is made
callable and forwards to the function (``bh.solve(scene)`` works either way).
"""

from __future__ import annotations

import sys
import types
from typing import Any

from barhinge.solve.newton import solve
from barhinge.solve.options import SolverOptions

__all__ = ["SolverOptions", "solve"]


class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return solve(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
