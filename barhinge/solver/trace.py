"""The iterate log of a solve: one row per iterate of every increment, failed ones included
(``FoldPath.meta["iterates"]``; ``barhinge fold`` writes it as ``iterations.csv``).

Where the step table (``states.csv``) gives each step's Newton iterations, this log shows
how each increment got there: the size of every correction, whether it factorised the
tangent, was accelerated or was a chord step, and when. On a near-mechanism (a large sheet
leaving the flat state) it shows corrections along the soft modes that alternate with
short ones taking out the bars' stretch, the pattern that sets a fold's factorisations
(docs/solver-performance.md).
"""

from __future__ import annotations

import math
import time
from typing import Any

__all__ = ["ITERATE_COLUMNS", "ITERATE_KINDS", "IterateLog"]

#: the columns of the log, in order (docs/outputs.md, ``iterations.csv``)
ITERATE_COLUMNS: tuple[str, ...] = (
    "step",
    "increment",
    "iterate",
    "value",
    "length",
    "residual",
    "correction",
    "kind",
    "factorizations",
    "wall_time_s",
)

#: what made an iterate: the increment's predictor; a Newton correction (one factorisation
#: of the tangent, "accelerated" with its geodesic acceleration); a chord correction (a
#: back-substitution with the increment's factorisation); a damped (Levenberg-Marquardt)
#: correction (option ``damping``)
ITERATE_KINDS: tuple[str, ...] = ("predictor", "newton", "accelerated", "chord", "damped")


class IterateLog:
    """Rows of :data:`ITERATE_COLUMNS`, appended as the solve goes (a few numbers per
    iterate: a 50-step fold of a 200 x 200 Miura sheet makes a few hundred)."""

    def __init__(self) -> None:
        self.rows: list[tuple[Any, ...]] = []
        #: the clock's origin (the solver sets it to the start of its states' clock), s
        self.t0 = time.perf_counter()
        self._n_increment = 0

    def begin_increment(self) -> None:
        """An increment starts (numbered from 1 over the whole solve)."""
        self._n_increment += 1

    def add(
        self,
        step: int,
        iterate: int,
        value: float,
        length: float,
        residual: float,
        correction: float,
        kind: str,
        factorizations: int,
    ) -> None:
        """One iterate: ``correction`` is the norm of the displacement change on the free
        DOFs that made it (from the last converged state for the predictor), length;
        ``factorizations`` the solve's factorisations so far."""
        if kind not in ITERATE_KINDS:
            raise ValueError(f"iterate kind {kind!r}; expected one of {ITERATE_KINDS}")
        wall = time.perf_counter() - self.t0
        self.rows.append(
            (
                int(step),
                self._n_increment,
                int(iterate),
                float(value),
                float(length),
                float(residual),
                float(correction),
                kind,
                int(factorizations),
                wall,
            )
        )

    def columns(self) -> dict[str, list[Any]]:
        """The log column by column (JSON-ready: a correction not known is None)."""
        cols: dict[str, list[Any]] = {c: [] for c in ITERATE_COLUMNS}
        for row in self.rows:
            for c, v in zip(ITERATE_COLUMNS, row, strict=True):
                cols[c].append(None if isinstance(v, float) and not math.isfinite(v) else v)
        return cols
