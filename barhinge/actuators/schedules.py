"""Actuators: creases whose fold angles are prescribed along a path, and their schedules.

The same :class:`Actuators` object drives the rigid-kinematics path (``bh.rigid_fold``) and
the compliant bar-and-hinge solver (``bh.solve``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from barhinge import _check
from barhinge.errors import ConfigError

__all__ = ["Actuators"]


@dataclasses.dataclass(frozen=True, eq=False)
class Actuators:
    """A set of actuated creases and the fold angles they follow.

    Parameters
    ----------
    edges : (n_act,) int
        Pattern edge ids (indices into ``cp.edges``).
    targets_deg : (n_act,) float, optional
        Final fold angle of each actuator, degrees (valley > 0). Reached linearly over the
        steps from the starting angles.
    table_deg : (n_steps, n_act) float, optional
        Fold angle of each actuator at each step 1..n_steps, degrees: any schedule (e.g.
        creases folding in sequence). Exclusive with ``targets_deg``.
    stiffness : float or (n_act,) float, optional
        Compliant actuators: each actuator is a rotational spring of this stiffness (moment
        per radian, force x length / rad in the user's units; for ``bh.rigid_fold`` in the
        units of its ``fold_stiffness``) whose far end follows the schedule, so the crease
        settles where the spring's pull balances the structure: ``rho = target`` only when
        nothing resists. Default None: held actuators (``rho = target`` exactly, as
        constraints). Compliant actuators make targets that no fold can meet together a
        well-posed energy minimum, the same one for the rigid limit and for the bar-and-hinge
        model (which converges to it as its panels stiffen).
    """

    edges: Sequence[int] | np.ndarray
    targets_deg: Sequence[float] | np.ndarray | None = None
    table_deg: np.ndarray | None = None
    stiffness: float | Sequence[float] | np.ndarray | None = None

    def __post_init__(self) -> None:
        e = _check.int_array(self.edges, "actuators.edges", lo=0)
        if len(np.unique(e)) != len(e):
            raise ConfigError(f"actuators.edges repeat: {e.tolist()}")
        object.__setattr__(self, "edges", e)
        if (self.targets_deg is None) == (self.table_deg is None):
            raise ConfigError(
                "actuators: give exactly one of targets_deg (final angles) or table_deg"
            )
        if self.targets_deg is not None:
            t = _check.float_array(self.targets_deg, "actuators.targets_deg").ravel()
            if t.size == 1 and len(e) > 1:
                t = np.full(len(e), float(t[0]))
            if len(t) != len(e):
                raise ConfigError(
                    f"actuators.targets_deg has {len(t)} entries, but actuators.edges has {len(e)}"
                )
            if np.any(np.abs(t) >= 180.0):
                bad = int(np.flatnonzero(np.abs(t) >= 180.0)[0])
                raise ConfigError(
                    f"actuators.targets_deg = {t[bad]} for edge {e[bad]}; expected |angle| < 180"
                )
            object.__setattr__(self, "targets_deg", t)
        else:
            T = _check.float_array(self.table_deg, "actuators.table_deg")
            if T.ndim == 1 and len(e) == 1:
                T = T[:, None]
            if T.ndim != 2 or T.shape[1] != len(e) or len(T) < 1:
                raise ConfigError(
                    f"actuators.table_deg must have shape (n_steps, {len(e)}), got {T.shape}"
                )
            if np.any(np.abs(T) >= 180.0):
                i, j = np.argwhere(np.abs(T) >= 180.0)[0]
                raise ConfigError(
                    f"actuators.table_deg = {T[i, j]} at step {i + 1}, edge {e[j]}; "
                    "expected |angle| < 180"
                )
            object.__setattr__(self, "table_deg", T)
        if self.stiffness is not None:
            k = _check.float_array(self.stiffness, "actuators.stiffness").ravel()
            if k.size == 1:
                k = np.full(len(e), float(k[0]))
            if len(k) != len(e):
                raise ConfigError(
                    f"actuators.stiffness has {len(k)} entries, but actuators.edges has {len(e)}"
                )
            if np.any(~(k > 0.0)) or np.any(~np.isfinite(k)):
                bad = int(np.flatnonzero(~(k > 0.0) | ~np.isfinite(k))[0])
                raise ConfigError(
                    f"actuators.stiffness = {k[bad]} for edge {e[bad]}; expected a finite "
                    "value > 0 (omit it for held actuators)"
                )
            object.__setattr__(self, "stiffness", k)

    @property
    def compliant(self) -> bool:
        """Whether the actuators are springs (``stiffness`` given) rather than held."""
        return self.stiffness is not None

    @property
    def n(self) -> int:
        return len(self.edges)

    def schedule(self, steps: int, start_deg: np.ndarray | None = None) -> np.ndarray:
        """Prescribed actuator angles at states 0..steps, degrees, shape (steps + 1, n_act).

        Row 0 is ``start_deg`` (default 0: flat). With ``targets_deg`` the angles go linearly
        from the start to the targets; with ``table_deg`` its rows are used (its length must
        equal ``steps``).
        """
        steps = _check.integer(steps, "steps", 1)
        start = (
            np.zeros(self.n)
            if start_deg is None
            else _check.float_array(start_deg, "start_deg").ravel()
        )
        if len(start) != self.n:
            raise ConfigError(f"len(start_deg) = {len(start)}, but there are {self.n} actuators")
        if self.table_deg is not None:
            if len(self.table_deg) != steps:
                raise ConfigError(
                    f"table_deg has {len(self.table_deg)} rows, but {steps} steps were asked"
                )
            return np.vstack([start, self.table_deg])
        targets = np.asarray(self.targets_deg, dtype=float)
        s = np.linspace(0.0, 1.0, steps + 1)[:, None]
        return start[None, :] + s * (targets - start)[None, :]
