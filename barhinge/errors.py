"""Exceptions raised by barhinge.

Every error carries a one-line message naming the offending item and what was expected;
the CLI prints that line on stderr and exits with code 2 (bad input) or 3 (no convergence).
"""

from __future__ import annotations

from typing import Any


class BarhingeError(Exception):
    """Base class of all barhinge errors."""


class PatternError(BarhingeError, ValueError):
    """A crease pattern (file, generator parameters or geometry) is invalid."""


class ConfigError(BarhingeError, ValueError):
    """A scene, study or option is invalid (unknown key, wrong shape, out of range)."""


class ConvergenceError(BarhingeError, RuntimeError):
    """A nonlinear solve did not converge.

    Attributes
    ----------
    step : int
        Index of the requested step that failed (0-based).
    load_factor : float
        Load factor (or path parameter) reached at the failure.
    residuals : list of float
        Residual norms of the last attempted increment.
    last_state : Any
        The last converged state (coordinates or a partial ``FoldPath``); never lost.
    """

    def __init__(
        self,
        message: str,
        *,
        step: int = -1,
        load_factor: float = float("nan"),
        residuals: list[float] | None = None,
        last_state: Any = None,
    ) -> None:
        super().__init__(message)
        self.step = step
        self.load_factor = load_factor
        self.residuals = list(residuals or [])
        self.last_state = last_state


class BucklingError(BarhingeError, RuntimeError):
    """A linear buckling analysis has no answer (mechanism, nothing in compression, or the
    eigensolver failed)."""
