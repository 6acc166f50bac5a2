"""FoldPath: the states of a fold path, rigid or compliant, and their records.

A path stores ``n_states`` states: state 0 is the initial configuration, states 1..N are the
requested steps. Angles are stored in degrees (FOLD convention, valley > 0).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FoldPath", "Interrupted"]


class Interrupted(KeyboardInterrupt):
    """Ctrl-C (KeyboardInterrupt) during a solve, carrying the converged part of the path.

    A subclass of KeyboardInterrupt, not of ``BarhingeError``: code that catches
    ``Exception`` or the package's errors still lets an interrupt through.

    Attributes
    ----------
    last_state : FoldPath or None
        The states converged before the interrupt (``converged=False``,
        ``meta["stopped"] = "interrupted"``); None when not even state 0 was reached.
    """

    def __init__(self, message: str = "interrupted", *, last_state: Any = None) -> None:
        super().__init__(message)
        self.last_state = last_state


#: ``f(fold_path) -> str``: the HTML of a path's rich display in Jupyter; set by
#: ``barhinge/__init__.py`` to the viewer of :mod:`barhinge.view` (a layer above this one)
HTML_DISPLAY: Callable[[Any], str] | None = None


@dataclasses.dataclass(frozen=True, eq=False)
class FoldPath:
    """States along a fold path and what was measured at each.

    Attributes
    ----------
    X : (n_states, n_nodes, 3) float
        Node coordinates. The first ``n_vertices`` nodes are the pattern's vertices.
    fold_angles_deg : (n_states, n_edges) float
        Fold angle of every pattern edge (0 for edges that cannot fold), degrees.
    actuator_edges : (n_act,) int
        Pattern edge ids of the actuators.
    actuator_targets_deg : (n_states, n_act) float
        Prescribed actuator fold angles, degrees.
    actuator_moments : (n_states, n_act) float
        Moments the actuators exert (Lagrange multipliers), force*length; NaN for rigid paths.
    energy_bars, energy_bend, energy_fold : (n_states,) float
        Stored energy in bars, bending hinges and fold hinges; NaN for rigid paths.
    reactions : (n_states, n_nodes, 3) float or None
        Support reactions (zero at free DOFs).
    load_factor : (n_states,) float
        Load factor of the applied loads (0 with no load).
    iterations : (n_states,) int
        Newton iterations of each step (0 for state 0).
    residual_norms : tuple of tuple of float
        Residual history of each step.
    wall_time : (n_states,) float
        Seconds spent to reach each state (cumulative from the start of the solve).
    external_work : (n_states,) float
        Work done on the structure by the loads, the support reactions (prescribed
        displacements) and the actuators from state 0 (trapezoidal rule over every
        increment); equals the stored energy change for an elastic structure. NaN if unknown.
    converged : bool
        False if the path stopped early; then ``message`` says why.
    kind : str
        ``"rigid"`` (rigid-origami kinematics) or ``"bar-hinge"``.
    meta : dict
        JSON-serialisable extras (scene name, scheme, options).
    """

    X: np.ndarray
    fold_angles_deg: np.ndarray
    actuator_edges: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, int))
    actuator_targets_deg: np.ndarray | None = None
    actuator_moments: np.ndarray | None = None
    energy_bars: np.ndarray | None = None
    energy_bend: np.ndarray | None = None
    energy_fold: np.ndarray | None = None
    reactions: np.ndarray | None = None
    load_factor: np.ndarray | None = None
    iterations: np.ndarray | None = None
    residual_norms: tuple[tuple[float, ...], ...] = ()
    wall_time: np.ndarray | None = None
    external_work: np.ndarray | None = None
    converged: bool = True
    message: str = ""
    kind: str = "bar-hinge"
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        X = np.asarray(self.X, dtype=float)
        if X.ndim != 3 or X.shape[2] != 3:
            raise ValueError(f"X must have shape (n_states, n_nodes, 3), got {X.shape}")
        n = X.shape[0]
        object.__setattr__(self, "X", X)
        object.__setattr__(self, "fold_angles_deg", np.asarray(self.fold_angles_deg, float))
        object.__setattr__(self, "actuator_edges", np.asarray(self.actuator_edges, np.int64))
        na = len(self.actuator_edges)
        nan = np.full(n, np.nan)
        defaults = {
            "actuator_targets_deg": np.full((n, na), np.nan),
            "actuator_moments": np.full((n, na), np.nan),
            "energy_bars": nan,
            "energy_bend": nan,
            "energy_fold": nan,
            "load_factor": np.zeros(n),
            "iterations": np.zeros(n, np.int64),
            "wall_time": nan,
            "external_work": nan,
        }
        for name, default in defaults.items():
            v = getattr(self, name)
            v = default.copy() if v is None else np.asarray(v, dtype=default.dtype)
            if v.shape[0] != n:
                raise ValueError(f"len(X) = {n}, but len({name}) = {v.shape[0]}")
            object.__setattr__(self, name, v)
        if self.fold_angles_deg.shape[0] != n:
            m = len(self.fold_angles_deg)
            raise ValueError(f"len(X) = {n}, but len(fold_angles_deg) = {m}")
        if self.reactions is not None:
            object.__setattr__(self, "reactions", np.asarray(self.reactions, float))
        object.__setattr__(
            self, "residual_norms", tuple(tuple(float(r) for r in h) for h in self.residual_norms)
        )

    @property
    def n_states(self) -> int:
        return self.X.shape[0]

    @property
    def energy(self) -> np.ndarray:
        """(n_states,) total stored energy (bars + bending + folds)."""
        return self.energy_bars + self.energy_bend + self.energy_fold

    def truncated(self, n_states: int) -> FoldPath:
        """The first ``n_states`` states of this path (e.g. the converged part)."""
        kw: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray) and f.name != "actuator_edges":
                v = v[:n_states]
            elif f.name == "residual_norms":
                v = v[:n_states]
            kw[f.name] = v
        return FoldPath(**kw)

    def _repr_html_(self) -> str | None:
        """Jupyter's rich display: the interactive viewer (:mod:`barhinge.view`) in an iframe."""
        return None if HTML_DISPLAY is None else HTML_DISPLAY(self)

    # ------------------------------------------------------------------- files
    def save(self, path: str | Path) -> Path:
        """Write the path to an ``.npz`` file (lossless; ``.npz`` is appended if missing).

        Atomic: the data go to a temporary file in the same folder, which then replaces
        ``path`` (``os.replace``), so a reader sees the old file or the new one, never a
        truncated one.
        """
        path = Path(path)
        final = path if path.suffix == ".npz" else path.with_suffix(path.suffix + ".npz")
        arrays: dict[str, Any] = {}
        scalars: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray):
                arrays[f.name] = v
            elif f.name == "residual_norms":
                scalars[f.name] = [list(h) for h in v]
            else:
                scalars[f.name] = v
        arrays["__json__"] = np.array(json.dumps(scalars))
        # a unique sibling, created with the umask's permissions (mkstemp would give 0600)
        tmp = final.with_name(f".{final.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez_compressed(fh, **arrays)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, final)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
        return final

    @classmethod
    def load(cls, path: str | Path) -> FoldPath:
        """Read a path written by :meth:`save`."""
        with np.load(Path(path), allow_pickle=False) as data:
            kw: dict[str, Any] = json.loads(str(data["__json__"]))
            for name in data.files:
                if name != "__json__":
                    kw[name] = data[name]
        return cls(**kw)
