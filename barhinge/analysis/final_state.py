"""One flat record of a fold path's final state: the numbers ``barhinge fold`` prints and
writes under ``results`` in ``summary.json`` (:mod:`barhinge.output.summary`)."""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

from barhinge.analysis.curvature import gaussian_curvature
from barhinge.errors import BarhingeError

__all__ = ["energy_split", "final_state_results"]

log = logging.getLogger(__name__)


def final_state_results(
    fold_path: Any,
    model: Any | None = None,
    *,
    pattern: Any | None = None,
    fixed: np.ndarray | None = None,
    loads: np.ndarray | None = None,
    modes: int = 3,
) -> dict[str, Any]:
    """Final fold state, stiffness, Gaussian curvature, strains and time of a path.

    Parameters
    ----------
    fold_path : FoldPath
    model : BarHingeModel, optional
        Enables strains, angle defects of the model's triangles and stiffness.
    pattern : CreasePattern, optional
        Default ``model.pattern``; gives the facet centroids of the global form.
    fixed : (n_nodes, 3) bool, optional
        Supports for the stiffness (default: the 3-2-1 restraint of the model).
    loads : (n_nodes, 3) float, optional
        Load case for the effective stiffness (skipped if None or zero).
    modes : int
        Number of lowest eigenvalues of the constrained tangent to report (0: none).

    Returns
    -------
    dict of JSON-friendly scalars and short lists (angles in degrees).
    """
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    X = fold_path.X[-1]
    out: dict[str, Any] = {
        "kind": fold_path.kind,
        "converged": bool(fold_path.converged),
        "n_states": int(fold_path.n_states),
        "actuator_edges": [int(e) for e in fold_path.actuator_edges],
        "actuator_fold_deg": [
            float(fold_path.fold_angles_deg[-1, e]) for e in fold_path.actuator_edges
        ],
        "max_abs_fold_deg": float(np.abs(fold_path.fold_angles_deg[-1]).max(initial=0.0)),
        **energy_split(fold_path),
        "wall_time_s": float(fold_path.wall_time[-1]),
        "events": [str(e) for e in fold_path.meta.get("events", [])],
    }
    if cp is not None and cp.n_faces >= 6:
        try:
            c = gaussian_curvature(X, pattern=cp, model=model, local=False)
        except BarhingeError as exc:  # degenerate reference points
            log.info("no curvature: %s", exc)
        else:
            out["K_global"] = c.K_global
            out["H_global"] = c.H_global
            out["k1_global"] = c.global_fit.k1
            out["k2_global"] = c.global_fit.k2
            out["max_abs_angle_defect_deg"] = float(np.degrees(c.max_abs_defect))
    if model is not None:
        B = np.asarray(model.bars)
        L = np.linalg.norm(X[B[:, 1]] - X[B[:, 0]], axis=1)
        out["max_abs_bar_strain"] = float(np.abs(L / model.bar_L0 - 1).max(initial=0.0))
        out.update(_stiffness(model, X, fixed, loads, modes))
    return out


def energy_split(fold_path: Any, step: int = -1) -> dict[str, float | None]:
    """Stored energy of one state split into folds, panel bending and bars.

    Parameters
    ----------
    fold_path : FoldPath
    step : int
        State index (default: the last).

    Returns
    -------
    dict with ``energy_total``, ``energy_fold``, ``energy_bend`` (panel bending hinges),
    ``energy_bars`` and their fractions of the total ``energy_fraction_fold``,
    ``energy_fraction_bend``, ``energy_fraction_bars`` (summing to 1; None when the total is
    zero or unknown, as on a rigid path whose energies are NaN).
    """
    parts = {k: float(getattr(fold_path, f"energy_{k}")[step]) for k in ("bars", "bend", "fold")}
    total = parts["bars"] + parts["bend"] + parts["fold"]  # as FoldPath.energy
    out: dict[str, float | None] = {"energy_total": total}
    out.update({f"energy_{k}": v for k, v in parts.items()})
    known = math.isfinite(total) and total > 0.0
    out.update({f"energy_fraction_{k}": v / total if known else None for k, v in parts.items()})
    return out


def _stiffness(model: Any, X: np.ndarray, fixed, loads, modes: int) -> dict[str, Any]:
    from barhinge.analysis.stiffness import effective_stiffness, stiffness_modes, tangent_stiffness

    out: dict[str, Any] = {}
    if fixed is None:
        from barhinge.scene import restraint_321

        fixed = restraint_321(model)
    K = tangent_stiffness(model, X)
    try:
        if modes > 0:
            m = stiffness_modes(model, X, fixed=fixed, k=modes, K=K)
            out["lowest_eigenvalues"] = [float(v) for v in m.eigenvalues]
            out["n_soft_modes"] = m.n_soft
            out["n_free_dofs"] = m.n_free
        if loads is not None and np.any(loads):
            r = effective_stiffness(model, loads, fixed, X, K=K)
            out["effective_stiffness"] = r.stiffness
            out["deflection"] = r.deflection
    except (BarhingeError, RuntimeError, ValueError) as exc:  # eigsh / singular
        log.info("stiffness not evaluated: %s", exc)
    return out
