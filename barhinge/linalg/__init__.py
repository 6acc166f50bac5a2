"""Linear algebra at the bottom of the package: sparse factorisation backends
(:mod:`~barhinge.linalg.backends`: SuperLU, CHOLMOD, PARDISO) and the numerical rank and null
space of sparse matrices (:mod:`~barhinge.linalg.nullspace`).

Rigid kinematics and the nonlinear solver both build on it; it imports nothing of barhinge but
:mod:`barhinge.errors`.
"""

from __future__ import annotations

from barhinge.linalg.backends import (
    LinearBackend,
    SingularMatrixError,
    available_backends,
    get_backend,
)
from barhinge.linalg.nullspace import NullSpace, null_space

__all__ = [
    "LinearBackend",
    "NullSpace",
    "SingularMatrixError",
    "available_backends",
    "get_backend",
    "null_space",
]
