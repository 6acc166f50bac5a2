"""Writing a solved fold path to a result folder, atomically: the FoldPath (npz), a summary
(JSON and CSV), the hooks' files and the manifest (:func:`barhinge.io.result_folder`).

Other modules add files (pictures, VTU series) by appending a function to
:data:`OUTPUT_HOOKS`; :func:`write_outputs` calls each hook after its own files.
"""

from __future__ import annotations

import csv
import json
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.results import FoldPath

__all__ = ["OUTPUT_HOOKS", "stop_reason", "summary", "write_outputs"]

log = logging.getLogger(__name__)

#: extra writers: ``hook(path, scene, out_dir) -> list of written files``
OUTPUT_HOOKS: list[Callable[[FoldPath, Any, Path], list[Path]]] = []


def _results_hook(path: FoldPath, scene: Any, out_dir: Path) -> list[Path]:
    """Result files (XDMF/VTU, FOLD frames, CSV/JSON) and pictures: barhinge.plot."""
    from barhinge.plot import fold_outputs_hook

    return fold_outputs_hook(path, scene, out_dir)


OUTPUT_HOOKS.append(_results_hook)


def summary(path: FoldPath, scene: Any = None) -> dict[str, Any]:
    """A JSON-serialisable summary of a fold path (final state and totals)."""
    last = path.n_states - 1
    out: dict[str, Any] = {
        "scene": path.meta.get("scene", getattr(scene, "name", "")),
        "control": path.meta.get("control"),
        "converged": bool(path.converged),
        "reason": stop_reason(path),
        "message": path.message,
        "n_states": int(path.n_states),
        "n_nodes": int(path.X.shape[1]),
        "n_dof": path.meta.get("n_dof"),
        "linear_solver": path.meta.get("linear_solver"),
        "wall_time_s": float(path.wall_time[last]) if path.n_states else 0.0,
        "newton_iterations": int(np.sum(path.iterations)),
        "load_factor": float(path.load_factor[last]),
        "energy": {
            "bars": float(path.energy_bars[last]),
            "bend": float(path.energy_bend[last]),
            "fold": float(path.energy_fold[last]),
            "total": float(path.energy[last]),
            "external_work": float(path.external_work[last]),
        },
        "actuators": {
            "edges": path.actuator_edges.tolist(),
            "angle_deg": (
                path.fold_angles_deg[last][path.actuator_edges].tolist()
                if len(path.actuator_edges)
                else []
            ),
            "moment": path.actuator_moments[last].tolist(),
        },
        "timing": path.meta.get("timing", {}),
        # stability events (limit points, bifurcations, negative-stiffness branches) and
        # the work balance; see docs/solver.md
        "events": list(path.meta.get("events", [])),
        "work_balance": path.meta.get("work_balance"),
    }
    if path.reactions is not None:
        out["reaction_sum"] = path.reactions[last].sum(axis=0).tolist()
    return out


def stop_reason(path: FoldPath) -> str | None:
    """Why a path stopped early: None (it converged), ``"interrupted"`` (Ctrl-C) or
    ``"not converged"``."""
    if path.converged:
        return None
    return str(path.meta.get("stopped") or "not converged")


def write_outputs(
    path: FoldPath, scene: Any, out_dir: str | Path, *, overwrite: bool = False
) -> list[Path]:
    """Write a run into ``out_dir`` atomically and return its files (in ``out_dir``).

    ``fold_path.npz``, ``summary.json``, ``states.csv``, every :data:`OUTPUT_HOOKS` writer's
    files and the manifest ``barhinge-run.json`` (files, scene, version, ``converged`` and
    ``reason``: None, ``"not converged"`` or ``"interrupted"``) go to a temporary sibling
    folder that then replaces ``out_dir`` whole (:func:`barhinge.io.result_folder`): no
    stale files of an earlier run remain, and a kill leaves the previous run untouched.

    Raises
    ------
    ConfigError
        ``out_dir`` is a file, or a non-empty folder that is not a barhinge result folder
        (without ``overwrite``).
    """
    from barhinge.io import MANIFEST, result_folder

    with result_folder(out_dir, overwrite=overwrite, command="fold") as run:
        tmp_files = _write_run(path, scene, run.path)
        run.manifest.update(
            scene=path.meta.get("scene", getattr(scene, "name", "")),
            kind=path.kind,
            converged=bool(path.converged),
            reason=stop_reason(path),
            message=path.message,
            n_states=int(path.n_states),
            n_nodes=int(path.X.shape[1]),
        )
    out = Path(out_dir)
    moved = [out / (f.relative_to(run.path) if f.is_relative_to(run.path) else f.name)
             for f in map(Path, tmp_files)]  # fmt: skip
    return [*moved, out / MANIFEST]


def _write_run(path: FoldPath, scene: Any, out: Path) -> list[Path]:
    """The files of :func:`write_outputs`, written straight into ``out``."""
    files = [path.save(out / "fold_path.npz")]
    js = out / "summary.json"
    js.write_text(json.dumps(summary(path, scene), indent=2) + "\n")
    files.append(js)
    cs = out / "states.csv"
    with cs.open("w", newline="") as fh:
        w = csv.writer(fh)
        names = [f"actuator_{e}_moment" for e in path.actuator_edges]
        w.writerow(
            [
                "state",
                "load_factor",
                "iterations",
                "energy_bars",
                "energy_bend",
                "energy_fold",
                "external_work",
                "wall_time",
                *names,
            ]
        )
        for i in range(path.n_states):
            w.writerow(
                [
                    i,
                    path.load_factor[i],
                    path.iterations[i],
                    path.energy_bars[i],
                    path.energy_bend[i],
                    path.energy_fold[i],
                    path.external_work[i],
                    path.wall_time[i],
                    *path.actuator_moments[i].tolist(),
                ]
            )
    files.append(cs)
    for hook in OUTPUT_HOOKS:
        try:
            files.extend(hook(path, scene, out))
        except Exception as exc:  # an optional extra must not lose the solved path
            log.warning("output hook %s failed: %s", getattr(hook, "__name__", hook), exc)
    return files
