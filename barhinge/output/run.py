"""One writer for the files of a fold path: the result folder of ``barhinge fold``
(:func:`write_run`, atomic, with its manifest) and the same files into any folder
(:func:`write_results`).

A run writes ``fold_path.npz`` (the path), ``summary.json`` (one summary), ``states.csv``
(one step table), ``iterations.csv`` (the solver's iterate log), the fields
(``fold_path.xdmf``/``.h5``, ``fold_path_bars.xdmf``/``.h5``, ``fold_path_NNNN.vtu``), FOLD
frames (``fold_path.fold``), the interactive viewer (``viewer.html``), the pictures and the
manifest ``barhinge-run.json``; docs/outputs.md lists every file with its columns and units.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
from pathlib import Path
from typing import Any

import numpy as np

from barhinge._json import jsonable
from barhinge.errors import ConfigError
from barhinge.fields import StateData, path_state_data, write_state_vtus, write_xdmf
from barhinge.output.folder import MANIFEST, result_folder
from barhinge.output.summary import run_summary, stop_reason, summary_rows
from barhinge.output.table import step_table, write_iterate_table, write_step_table
from barhinge.results import FoldPath

__all__ = ["PICTURES", "RunOutput", "picture_level", "write_results", "write_run"]

log = logging.getLogger(__name__)

#: the files of one run that are not optional extras
SUMMARY, STEPS = "summary.json", "states.csv"
#: the solver's iterate log (bar-and-hinge solves; :mod:`barhinge.solver.trace`)
ITERATIONS = "iterations.csv"
#: the interactive viewer of a run (:mod:`barhinge.view`)
VIEWER = "viewer.html"
#: what ``pictures`` may ask for: no pictures, the PNGs and charts, or those and the GIF
PICTURES = ("none", "png", "all")


def picture_level(pictures: str | bool | None) -> str:
    """``"none"``, ``"png"`` or ``"all"`` from an option value: None reads the environment
    (``BARHINGE_PICTURES=0|none|png|all``; default ``"none"``: the interactive viewer is
    the picture of a run, and the static pictures cost more than the solve of a small scene),
    True means ``"png"`` and False ``"none"``."""
    if pictures is None:
        raw = os.environ.get("BARHINGE_PICTURES", "").strip().lower()
        pictures = {"0": "none", "1": "png", "": "none"}.get(raw, raw)
        if pictures == "none":
            log.info("BARHINGE_PICTURES: no pictures")
    if isinstance(pictures, bool):
        return "png" if pictures else "none"
    if pictures not in PICTURES:
        raise ConfigError(f"pictures = {pictures!r}; expected one of {', '.join(PICTURES)}")
    return pictures


@dataclasses.dataclass(frozen=True)
class RunOutput:
    """What a run wrote, and what the CLI prints of it.

    Attributes
    ----------
    out : Path
        The result folder.
    files : list of Path
        Every file of the run (in ``out``), the manifest last.
    summary : dict
        The content of ``summary.json``.
    rows : list of (str, str)
        (quantity, value) rows of the ``barhinge fold`` table.
    """

    out: Path
    files: list[Path]
    summary: dict[str, Any]
    rows: list[tuple[str, str]]


def _mesh_source(fold_path: FoldPath, model: Any | None, pattern: Any | None):
    """(model, pattern) for the fields: a rigid path lives on the pattern's vertices."""
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    if fold_path.kind == "rigid" or model is None:
        if cp is None:
            raise ConfigError("writing a path without a model needs its crease pattern")
        return None, cp
    return model, cp


def _write(
    fold_path: FoldPath,
    model: Any | None,
    out: Path,
    *,
    pattern: Any | None,
    name: str,
    scene: Any | None,
    vtu: str,
    fields: bool,
    pictures: str,
    npz: bool,
    fixed: Any | None,
    loads: Any | None,
    results: dict | None,
) -> tuple[dict[str, Path], dict[str, Any], list[StateData] | None]:
    """The files of one path, written straight into ``out``; (files by kind, summary, the
    fields of every state when written)."""
    if vtu not in ("all", "last", "none"):
        raise ConfigError(f"vtu = {vtu!r}; expected 'all', 'last' or 'none'")
    model, cp = _mesh_source(fold_path, model, pattern)
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}
    if npz:
        written["npz"] = fold_path.save(out / f"{name}.npz")
    if results is None:
        from barhinge.analysis.final_state import final_state_results

        try:
            results = final_state_results(fold_path, model, pattern=cp, fixed=fixed, loads=loads)
        except Exception as exc:  # noqa: BLE001 - analysis is an extra; keep the run
            log.warning("final-state analysis not written: %s", exc)
            results = {}
    if scene is not None and fold_path.kind == "bar-hinge" and model is not None:
        results = {**results, "forces": _forces(fold_path, scene)}
        if np.any(np.asarray(scene.loads)):
            results["buckling"] = _buckling(model, scene, out if fields else None)
    summary = jsonable({**run_summary(fold_path, scene), "results": results}, nan=False)
    written["json"] = out / SUMMARY
    written["json"].write_text(json.dumps(summary, indent=2) + "\n")
    # the fields of every state, once for the step table and the field files
    states: list[StateData] | None = None
    if fields:
        try:
            states = path_state_data(fold_path, model=model, pattern=cp)
        except Exception as exc:  # noqa: BLE001 - the fields are an extra; keep the run
            log.warning("fields not written: %s", exc)
    rows = step_table(fold_path, model=model, pattern=cp, states=states)
    written["csv"] = write_step_table(out / STEPS, rows)
    iterates = fold_path.meta.get("iterates")
    if iterates:
        written["iterations"] = write_iterate_table(out / ITERATIONS, iterates)
    try:
        marks = {"fixed": fixed, "loads": loads}
        written.update(_extras(fold_path, model, cp, out, name, vtu, states, pictures, marks))
    except Exception as exc:  # noqa: BLE001 - an optional extra must not lose the solved path
        log.warning("fields and pictures not all written: %s", exc)
    return written, summary, states


def _forces(fold_path: FoldPath, scene: Any) -> dict[str, Any]:
    """Reactions, member forces, moments and the largest displacement at the last state
    (:mod:`barhinge.analysis.forces`); an empty record (and a warning) if they fail."""
    from barhinge.analysis.forces import path_state_results, results_summary

    try:
        return results_summary(path_state_results(fold_path, scene, step=-1))
    except Exception as exc:  # noqa: BLE001 - an extra of the summary; keep the run
        log.warning("forces and reactions not written: %s", exc)
        return {}


def _buckling(model: Any, scene: Any, folder: Path | None) -> dict[str, Any]:
    """Linear buckling factors of the reference state under the scene's loads
    (:func:`barhinge.analysis.buckling.linear_buckling`), and (``folder``) one VTU per mode;
    a record ``{"error": ...}`` when there is no buckling factor (a mechanism, nothing in
    compression, an eigensolver failure)."""
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.errors import BucklingError

    try:
        b = linear_buckling(model, scene.loads, scene.fixed, n_modes=3)
    except BucklingError as exc:
        return {"error": str(exc)}
    rec: dict[str, Any] = {"factors": [float(f) for f in b.factors], "state": 0}
    if folder is not None:
        from barhinge.output.modes import write_mode_vtus

        try:
            files = write_mode_vtus(folder, model, b.X, b.modes, b.factors)
            rec["mode_files"] = [p.name for p in files]
        except Exception as exc:  # noqa: BLE001 - an extra; keep the run
            log.warning("buckling modes not written: %s", exc)
    return rec


def _extras(fold_path, model, cp, out: Path, name: str, vtu: str,
            states: list[StateData] | None, pictures: str, marks: dict[str, Any]):  # fmt: skip
    """FOLD frames, then (``states``: the fields of every state) XDMF and VTU files, then
    pictures (``"png"``: the final state and the charts; ``"all"``: and the energy-density
    picture and the GIF)."""
    from barhinge.pattern.fold import write_fold_path

    written: dict[str, Path] = {"fold": write_fold_path(cp, fold_path, out / f"{name}.fold")}
    if states is not None:
        written["xdmf"] = write_xdmf(out / f"{name}.xdmf", fold_path, states=states)
        written["xdmf_bars"] = out / f"{name}_bars.xdmf"
        n = fold_path.n_states
        chosen = {"all": range(n), "last": [n - 1], "none": []}[vtu]
        paths = write_state_vtus(
            [out / f"{name}_{s:04d}.vtu" for s in chosen], [states[s] for s in chosen]
        )
        if paths:
            written["vtu"] = paths[-1]
    if pictures != "none":
        from barhinge.output.pictures import write_pictures

        try:
            every = pictures == "all"  # "png": the final state and the charts only
            written.update(write_pictures(fold_path, model, out, pattern=cp, name=name,
                                          gif=every,
                                          extra_arrays=("energy_density",) if every else (),
                                          **marks))  # fmt: skip
        except Exception as exc:  # noqa: BLE001 - pictures are optional; never lose results
            log.warning("pictures not written: %s", exc)
    return written


def write_results(
    fold_path: FoldPath,
    model: Any | None,
    out_dir: str | Path,
    *,
    pattern: Any | None = None,
    name: str = "result",
    vtu: str = "all",
    results: dict | None = None,
    fixed: Any | None = None,
    loads: Any | None = None,
    npz: bool = True,
    pictures: str | bool = False,
) -> dict[str, Path]:
    """Write the files of a fold path into ``out_dir`` as it is (created if missing; not
    atomic: :func:`write_run` writes a whole result folder).

    Parameters
    ----------
    fold_path : FoldPath
    model : BarHingeModel or None
        None for a rigid path (then ``pattern`` is required).
    out_dir : path
    pattern : CreasePattern, optional
        Default ``model.pattern``.
    name : str
        Stem of the path's files (``<name>.npz``, ``<name>.xdmf``, ``<name>_NNNN.vtu``,
        ``<name>.fold``); the summary and the step table are ``summary.json`` and
        ``states.csv``.
    vtu : {"all", "last", "none"}
        Which states get a ``.vtu`` file.
    results : dict, optional
        The ``results`` record of ``summary.json``; default
        :func:`barhinge.analysis.final_state.final_state_results` of the path (with ``fixed`` and
        ``loads`` for the stiffness).
    fixed, loads : (n_nodes, 3) arrays, optional
        Supports and load case of the scene (for the stiffness in the summary).
    npz : bool
        Also save the path itself (``<name>.npz``).
    pictures : {"none", "png", "all"} or bool
        Also draw the pictures (:func:`barhinge.output.pictures.write_pictures`): the state
        pictures and charts (``"png"`` or True), and the GIF too (``"all"``).

    Returns
    -------
    dict from a file kind (``npz``, ``json``, ``csv``, ``fold``, ``xdmf``, ``xdmf_bars``,
    ``vtu``: the last one written, and the picture kinds) to its path.
    """
    files, _, _ = _write(fold_path, model, Path(out_dir), pattern=pattern, name=name, scene=None,
                      vtu=vtu, fields=True, pictures=picture_level(pictures), npz=npz,
                      fixed=fixed,
                      loads=loads, results=results)  # fmt: skip
    return files


def write_run(
    fold_path: FoldPath,
    scene: Any,
    out_dir: str | Path,
    *,
    overwrite: bool = False,
    command: str = "fold",
    fields: bool = True,
    pictures: str | bool | None = None,
    viewer: bool = True,
) -> RunOutput:
    """Write a run into the result folder ``out_dir`` atomically.

    Every file goes to a temporary sibling folder that then replaces ``out_dir`` whole
    (:func:`barhinge.output.folder.result_folder`): no stale files of an earlier run remain,
    and a kill leaves the previous run untouched. The manifest ``barhinge-run.json`` (files,
    scene, version, ``converged`` and ``reason``: None, ``"not converged"`` or
    ``"interrupted"``) is written last.

    Parameters
    ----------
    fold_path : FoldPath
        A bar-and-hinge path (``bh.solve``) or a rigid one (``bh.rigid_fold``, on the
        vertices of ``scene.model.pattern``).
    scene : Scene
        Gives the model, the supports and loads (for the stiffness in the summary).
    overwrite : bool
        Replace ``out_dir`` even when it is a non-empty folder that is not a result folder.
    command : str
        Recorded in the manifest.
    fields : bool
        Write the XDMF and VTU files (``fold --form-only`` does not).
    pictures : {"none", "png", "all"}, optional
        ``"png"``: the final state and the charts; ``"all"``: and the energy-density picture
        and the GIF of the path;
        ``"none"``: no pictures. Default from ``BARHINGE_PICTURES`` (``0`` or ``none``,
        ``png``, ``all``), else ``"none"`` (the viewer shows the run). (``fields=False``
        draws none.)
    viewer : bool
        Write the interactive viewer ``viewer.html`` (:func:`barhinge.view.write_viewer`).

    Raises
    ------
    ConfigError
        ``out_dir`` is a file, or a non-empty folder that is not a barhinge result folder
        (without ``overwrite``).
    """
    level = picture_level(pictures)
    model = scene.model
    with result_folder(out_dir, overwrite=overwrite, command=command) as run:
        _, summary, states = _write(fold_path, model, run.path, pattern=model.pattern,
                                  name="fold_path", scene=scene, vtu="all", fields=fields,
                                  pictures=level if fields else "none", npz=True,
                                  fixed=getattr(scene, "fixed", None),
                                  loads=getattr(scene, "loads", None), results=None)  # fmt: skip
        if viewer:
            _write_viewer(run.path, model.pattern, states)
        run.manifest.update(
            scene=summary["scene"],
            kind=fold_path.kind,
            converged=bool(fold_path.converged),
            reason=stop_reason(fold_path),
            message=fold_path.message,
            n_states=int(fold_path.n_states),
            n_nodes=int(fold_path.X.shape[1]),
        )
        names = sorted(p.relative_to(run.path) for p in run.path.rglob("*") if p.is_file())
    out = Path(out_dir)
    files = [*(out / n for n in names), out / MANIFEST]
    return RunOutput(out, files, summary, summary_rows(summary, fold_path))


def _write_viewer(folder: Path, pattern: Any, states: list[StateData] | None) -> Path | None:
    """``viewer.html`` of the result folder being written (``pattern``: the crease pattern
    of its ``fold_path.fold``; ``states``: the fields of its VTU files, not read back); a
    warning (not a failure) if it cannot be made: the solved path is never lost for a
    picture."""
    from barhinge.view import write_viewer

    try:
        return write_viewer(folder, folder / VIEWER, pattern=pattern, states=states)
    except Exception as exc:  # noqa: BLE001 - the viewer is an extra; keep the run
        log.warning("viewer not written: %s", exc)
        return None
