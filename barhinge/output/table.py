"""The step table of a run (``states.csv``): one row per state, the same columns for every
kind of run (actuator, displacement, load or arc-length control, rigid kinematics).

A value that does not apply to a run (energies of a rigid path, reactions without supports)
is an empty cell. docs/outputs.md lists the columns and their units.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.analysis.curvature import fit_quadratic, reference_points
from barhinge.fields import StateData, state_data
from barhinge.results import FoldPath

__all__ = ["COLUMNS", "actuator_columns", "step_table", "write_iterate_table", "write_step_table"]

#: the columns of every run, in order; the actuator columns (:func:`actuator_columns`)
#: follow them
COLUMNS: tuple[str, ...] = (
    "state",
    "load_factor",
    "iterations",
    "wall_time_s",
    "energy_total",
    "energy_fold",
    "energy_bend",
    "energy_bars",
    "external_work",
    "reaction_x",
    "reaction_y",
    "reaction_z",
    "max_abs_fold_deg",
    "max_abs_bar_strain",
    "max_abs_angle_defect_deg",
    "K_global",
    "negative_eigenvalues",
    "negative_eigenvalues_held",
)


def actuator_columns(edges: Any) -> list[str]:
    """``actuator_<e>_target_deg``, ``actuator_<e>_fold_deg``, ``actuator_<e>_moment`` for
    each actuated edge ``e``, in actuator order."""
    return [f"actuator_{int(e)}_{q}" for e in edges for q in ("target_deg", "fold_deg", "moment")]


def step_table(
    fold_path: FoldPath,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    states: list[StateData] | None = None,
) -> list[dict[str, float]]:
    """One row per state with :data:`COLUMNS` and the actuator columns (NaN where a value
    does not apply).

    Parameters
    ----------
    fold_path : FoldPath
    model : BarHingeModel, optional
        Gives the bar strains and the angle defects of the model's triangles.
    pattern : CreasePattern, optional
        Default ``model.pattern``; without a model it gives the mesh of a rigid path, and
        (with 6 faces or more) the global form whose Gaussian curvature ``K_global`` is fitted.
    states : list of StateData, optional
        :func:`~barhinge.fields.path_state_data` of the path when already computed
        (the run writer shares it with the field files).
    """
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    act = fold_path.actuator_edges
    n = fold_path.n_states
    nan = np.full(n, np.nan)
    R = (
        np.asarray(fold_path.reactions).sum(axis=1)
        if fold_path.reactions is not None
        else np.full((n, 3), np.nan)
    )
    cols: dict[str, np.ndarray] = {
        "state": np.arange(n),
        "load_factor": np.asarray(fold_path.load_factor),
        "iterations": np.asarray(fold_path.iterations),
        "wall_time_s": np.asarray(fold_path.wall_time),
        "energy_total": fold_path.energy,
        "energy_fold": np.asarray(fold_path.energy_fold),
        "energy_bend": np.asarray(fold_path.energy_bend),
        "energy_bars": np.asarray(fold_path.energy_bars),
        "external_work": np.asarray(fold_path.external_work),
        "reaction_x": R[:, 0],
        "reaction_y": R[:, 1],
        "reaction_z": R[:, 2],
        "max_abs_fold_deg": np.abs(fold_path.fold_angles_deg).max(axis=1, initial=0.0),
        "max_abs_bar_strain": nan.copy(),
        "max_abs_angle_defect_deg": nan.copy(),
        "K_global": nan.copy(),
        # the stability counts of the states (docs/solver.md, "Stability events")
        "negative_eigenvalues": _counts(fold_path.meta.get("negative_eigenvalues"), n),
        "negative_eigenvalues_held": _counts(fold_path.meta.get("negative_eigenvalues_held"), n),
    }
    if model is not None or cp is not None:
        for s in range(n):
            d = (
                states[s]
                if states is not None
                else state_data(
                    fold_path.X[s],
                    model=model,
                    pattern=cp if model is None else None,
                    fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
                )
            )
            cols["max_abs_bar_strain"][s] = np.nanmax(np.abs(d.line_data["bar_strain"]))
            df = d.point_data["angle_defect"]
            fin = np.isfinite(df)
            cols["max_abs_angle_defect_deg"][s] = (
                np.degrees(np.abs(df[fin]).max()) if fin.any() else 0.0
            )
            if cp is not None and cp.n_faces >= 6:
                cols["K_global"][s] = fit_quadratic(reference_points(fold_path.X[s], cp)).K
    for a, e in enumerate(act):
        cols[f"actuator_{int(e)}_target_deg"] = np.asarray(fold_path.actuator_targets_deg)[:, a]
        cols[f"actuator_{int(e)}_fold_deg"] = fold_path.fold_angles_deg[:, e]
        cols[f"actuator_{int(e)}_moment"] = np.asarray(fold_path.actuator_moments)[:, a]
    ints = ("state", "iterations", "negative_eigenvalues", "negative_eigenvalues_held")
    return [
        {
            k: (int(v[s]) if k in ints and np.isfinite(v[s]) else float(v[s]))
            for k, v in cols.items()
        }
        for s in range(n)
    ]


def _counts(values: list[int | None] | None, n: int) -> np.ndarray:
    """(n,) per-state counts as floats, NaN where unknown (or not recorded)."""
    out = np.full(n, np.nan)
    for i, c in enumerate((values or [])[:n]):
        if c is not None:
            out[i] = c
    return out


def write_step_table(path: str | Path, rows: list[dict[str, float]]) -> Path:
    """Write :func:`step_table` rows as CSV (header = the keys of the first row; NaN is an
    empty cell; floats with all their digits)."""
    path = Path(path)
    keys = list(rows[0]) if rows else list(COLUMNS)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow(["" if isinstance(v, float) and not np.isfinite(v) else repr(v)
                        for v in (r[k] for k in keys)])  # fmt: skip
    return path


def write_iterate_table(path: str | Path, columns: dict[str, list[Any]]) -> Path:
    """Write the solver's iterate log (``FoldPath.meta["iterates"]``,
    :class:`barhinge.solver.trace.IterateLog`) as CSV, one row per iterate (a value not
    known is an empty cell; floats with all their digits)."""
    path = Path(path)
    keys = list(columns)
    n = len(columns[keys[0]]) if keys else 0
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for i in range(n):
            w.writerow([_cell(columns[k][i]) for k in keys])
    return path


def _cell(v: Any) -> str:
    """A CSV cell: empty for None and NaN, strings as they are, numbers with all digits."""
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return ""
    return v if isinstance(v, str) else repr(v)
