"""Result files: VTU per state and an XDMF time series (meshio), FOLD frames, CSV/JSON summaries.

Only this module imports meshio. Every file opens in ParaView / PyVista without glue:

* ``<name>_NNNN.vtu``: one state; points = node coordinates; two cell blocks:
  ``triangle`` (the panels of the triangulated sheet) and ``line`` (bars of a bar-and-hinge
  model, or the pattern's edges for a rigid path). Arrays are listed in :func:`state_mesh`.
* ``<name>.xdmf`` + ``<name>.h5``: the whole path on the state-0 mesh with point data
  ``displacement`` per step (use ParaView's "Warp By Vector") and the same data arrays.
* ``<name>.fold``: the pattern with ``file_frames`` (one per state), if the FOLD writer exists.
* ``<name>_steps.csv`` and ``<name>_summary.json``: per-step numbers and the final state.
"""

from __future__ import annotations

import contextlib
import csv
import ctypes
import datetime
import errno
import glob
import json
import logging
import os
import secrets
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.analysis.curvature import (
    angle_defect,
    fit_quadratic,
    mixed_voronoi_area,
    pattern_triangles,
    reference_points,
)
from barhinge.errors import ConfigError
from barhinge.results import FoldPath

__all__ = [
    "MANIFEST",
    "RunFolder",
    "StateData",
    "add_to_manifest",
    "atomic_file",
    "check_output_folder",
    "read_manifest",
    "read_state_vtu",
    "result_folder",
    "state_data",
    "state_mesh",
    "step_table",
    "write_results",
    "write_state_vtu",
    "write_steps_csv",
    "write_summary_json",
    "write_xdmf",
]

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- geometry
class StateData:
    """Triangles, lines and data arrays of one state (plain numpy; no meshio).

    Attributes
    ----------
    points : (n_nodes, 3) float
    triangles : (n_tri, 3) int
    lines : (n_lines, 2) int
    point_data : dict of (n_nodes, ...) arrays
    triangle_data, line_data : dict of (n_tri,) / (n_lines,) arrays (same keys in both; NaN
        where an array does not apply to that kind of cell)
    """

    def __init__(self, points, triangles, lines, point_data, triangle_data, line_data) -> None:
        self.points = points
        self.triangles = triangles
        self.lines = lines
        self.point_data = point_data
        self.triangle_data = triangle_data
        self.line_data = line_data


def _model_triangles(hinges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the hinges (orientation of first use) and (n_hinges, 2) triangle index of
    each hinge's two wings."""
    H = np.asarray(hinges, np.int64)
    T = np.concatenate([H[:, [0, 1, 2]], H[:, [1, 0, 3]]])
    _, first, inv = np.unique(np.sort(T, axis=1), axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # unique rows in order of first use
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    tri = T[first[order]]
    wing_tri = rank[inv.ravel()].reshape(2, len(H)).T
    return tri, wing_tri


def _element_energies(model: Any, X: np.ndarray, rho: np.ndarray):
    """(n_bars,), (n_hinges,) stored energy of every bar and hinge with the model's own laws
    (per-hinge penetration limits included); ``rho`` is unused, kept for the call sites."""
    del rho
    return model.element_energies(X)


def _pair_index(pairs: np.ndarray, n: int) -> np.ndarray:
    """Integer key of unordered node pairs."""
    p = np.sort(np.asarray(pairs, np.int64), axis=1)
    return p[:, 0] * n + p[:, 1]


def state_data(
    X: np.ndarray,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    X_ref: np.ndarray | None = None,
    fold_angles_deg: np.ndarray | None = None,
) -> StateData:
    """Mesh and data arrays of one state.

    Parameters
    ----------
    X : (n_nodes, 3) float
        Node coordinates of the state.
    model : BarHingeModel, optional
        Gives triangles (from its hinges), lines (its bars), strains and energies.
    pattern : CreasePattern, optional
        Used without a model: fan-triangulated faces and the pattern's edges as lines.
    X_ref : (n_nodes, 3) float, optional
        Reference coordinates for ``displacement`` (default: ``model.X0`` or X itself).
    fold_angles_deg : (n_edges,) float, optional
        Fold angles per pattern edge (without a model; default: measured from X).

    Arrays
    ------
    point data: ``displacement`` (n, 3), ``angle_defect`` (rad, NaN at the boundary),
    ``defect_density`` (angle defect / mixed Voronoi area, 1/length^2).
    cell data (triangle and line blocks): ``fold_angle_deg`` (lines on creases; FOLD sign),
    ``bar_strain`` (engineering strain (L - L0)/L0 of bars), ``energy_density`` (bars and fold
    hinges: energy per unit length; panels: bending energy per unit area; the model's own
    laws of :mod:`barhinge.kernels.laws`), ``kind`` (0 panel, 1 bar inside a panel, 2 crease,
    3 other pattern edge: boundary or flat line).
    """
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ConfigError(f"X must have shape (n_nodes, 3), got {X.shape}")
    n = len(X)
    if model is None and pattern is None:
        raise ConfigError("state_data needs a model or a pattern to know the mesh")
    if model is not None:
        if model.n_nodes != n:
            raise ConfigError(f"len(X) = {n}, but the model has {model.n_nodes} nodes")
        tri, wing_tri = _model_triangles(model.hinges)
        lines = np.asarray(model.bars, np.int64)
        L = np.linalg.norm(X[lines[:, 1]] - X[lines[:, 0]], axis=1)
        L0 = np.asarray(model.bar_L0, float)
        eps = (L - L0) / L0
        rho = np.asarray(model.hinge_angles(X), float)
        e_line, e_h = _element_energies(model, X, rho)
        e_line = e_line / L0  # energy per length
        kind = np.asarray(model.hinge_kind)
        fold = kind == "fold"
        H = np.asarray(model.hinges, np.int64)
        # fold hinges: angle and energy on the bar along their axis
        key_line = _pair_index(lines, n)
        fold_ang = np.full(len(lines), np.nan)
        is_crease = np.zeros(len(lines), bool)
        hf = np.flatnonzero(fold)
        order = np.argsort(key_line)
        key_h = _pair_index(H[hf, :2], n)
        at = np.minimum(np.searchsorted(key_line[order], key_h), len(order) - 1)
        ok = key_line[order[at]] == key_h
        i, hf = order[at[ok]], hf[ok]
        fold_ang[i] = np.degrees(rho[hf])
        np.add.at(e_line, i, e_h[hf] / L0[i])
        is_crease[i] = True
        # bend hinges: energy split between their two triangles, per unit area
        P = X[tri]
        area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
        bend = np.flatnonzero(~fold)
        e_tri = np.bincount(
            wing_tri[bend].ravel(), weights=np.repeat(0.5 * e_h[bend], 2), minlength=len(tri)
        ) / np.where(area > 0, area, 1.0)
        strain_line = eps
        cp = model.pattern
        on_edge = np.isin(key_line, _pair_index(cp.edges, n))
        kind_line = np.where(is_crease, 2, np.where(on_edge, 3, 1))
        Xr = model.X0 if X_ref is None else X_ref
    else:
        cp = pattern
        if n < cp.n_vertices:
            raise ConfigError(f"len(X) = {n}, but the pattern has {cp.n_vertices} vertices")
        tri = pattern_triangles(cp)
        lines = np.asarray(cp.edges, np.int64)
        if fold_angles_deg is None:
            fold_angles_deg = cp.replaced(
                vertices=X[: cp.n_vertices], validate=False
            ).state_fold_angles()
        fold_ang = np.asarray(fold_angles_deg, float).copy()
        crease = np.zeros(len(lines), bool)
        crease[cp.crease_edges] = True
        fold_ang[~crease] = np.nan
        L0 = np.linalg.norm(cp.vertices3d[lines[:, 1]] - cp.vertices3d[lines[:, 0]], axis=1)
        L = np.linalg.norm(X[lines[:, 1]] - X[lines[:, 0]], axis=1)
        strain_line = (L - L0) / L0
        e_line = np.full(len(lines), np.nan)
        e_tri = np.full(len(tri), np.nan)
        kind_line = np.where(crease, 2, 3)
        Xr = cp.vertices3d if X_ref is None else X_ref
    Xr = np.asarray(Xr, float)
    disp = X - Xr if Xr.shape == X.shape else np.zeros_like(X)
    defect = angle_defect(X, tri)
    with np.errstate(divide="ignore", invalid="ignore"):
        density = defect / mixed_voronoi_area(X, tri)
    nan_t = np.full(len(tri), np.nan)
    return StateData(
        points=X,
        triangles=tri,
        lines=lines,
        point_data={"displacement": disp, "angle_defect": defect, "defect_density": density},
        triangle_data={
            "fold_angle_deg": nan_t,
            "bar_strain": nan_t,
            "energy_density": e_tri,
            "kind": np.zeros(len(tri)),
        },
        line_data={
            "fold_angle_deg": fold_ang,
            "bar_strain": strain_line,
            "energy_density": e_line,
            "kind": kind_line.astype(float),
        },
    )


def state_mesh(X: np.ndarray, **kwargs: Any):
    """A ``meshio.Mesh`` of one state (arguments of :func:`state_data`)."""
    import meshio

    d = state_data(X, **kwargs)
    return meshio.Mesh(
        d.points,
        [("triangle", d.triangles), ("line", d.lines)],
        point_data=d.point_data,
        cell_data={k: [d.triangle_data[k], d.line_data[k]] for k in d.triangle_data},
    )


def write_state_vtu(path: str | Path, X: np.ndarray, **kwargs: Any) -> Path:
    """Write one state to a ``.vtu`` file (arguments of :func:`state_data`)."""
    path = Path(path)
    state_mesh(X, **kwargs).write(path)
    return path


def read_state_vtu(path: str | Path) -> StateData:
    """Read a ``.vtu`` file written by :func:`write_state_vtu` back into a :class:`StateData`."""
    import meshio

    try:
        m = meshio.read(Path(path))
        blocks = [c.type for c in m.cells]
        t, li = blocks.index("triangle"), blocks.index("line")
        return StateData(
            points=np.asarray(m.points, float),
            triangles=np.asarray(m.cells[t].data, np.int64),
            lines=np.asarray(m.cells[li].data, np.int64),
            point_data={k: np.asarray(v, float) for k, v in m.point_data.items()},
            triangle_data={k: np.asarray(v[t], float) for k, v in m.cell_data.items()},
            line_data={k: np.asarray(v[li], float) for k, v in m.cell_data.items()},
        )
    except (OSError, ValueError, KeyError, IndexError) as exc:
        raise ConfigError(f"{path} is not a state written by barhinge ({exc})") from None


@contextlib.contextmanager
def _cwd(folder: Path) -> Iterator[None]:
    old = Path.cwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(old)


def write_xdmf(
    path: str | Path, fold_path: FoldPath, *, model: Any | None = None, pattern: Any | None = None
) -> Path:
    """Write a fold path as XDMF time series: ``<stem>.xdmf`` (panels, triangles) and
    ``<stem>_bars.xdmf`` (bars or edges, lines), each with its ``.h5`` beside it.

    The mesh is state 0; each step holds point data ``displacement`` (from state 0) and the
    arrays of :func:`state_data`. The time value of step s is s.

    meshio's time-series writer creates its ``.h5`` in the current directory, so it is run
    from inside the output folder (the working directory is restored afterwards).
    """
    import meshio

    given = Path(path)
    path = given.resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    states = [
        state_data(
            fold_path.X[s],
            model=model,
            pattern=pattern,
            X_ref=fold_path.X[0],
            fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
        )
        for s in range(fold_path.n_states)
    ]
    lines_path = path.with_name(path.stem + "_bars.xdmf")
    d0 = states[0]
    # meshio's XDMF writer cannot mix triangles and lines in one grid: two files
    blocks = [
        (path, "triangle", d0.triangles, "triangle_data"),
        (lines_path, "line", d0.lines, "line_data"),
    ]
    with _cwd(path.parent):
        for file, cell_type, conn, attr in blocks:
            with meshio.xdmf.TimeSeriesWriter(file.name) as writer:
                writer.write_points_cells(d0.points, [(cell_type, conn)])
                for s, d in enumerate(states):
                    cd = getattr(d, attr)
                    writer.write_data(
                        float(s),
                        point_data=d.point_data,
                        cell_data={k: [v] for k, v in cd.items()},
                    )
    return given


# --------------------------------------------------------------------------- tables
def step_table(
    fold_path: FoldPath, *, model: Any | None = None, pattern: Any | None = None
) -> list[dict[str, float]]:
    """One row per state: load factor, actuator targets / angles / moments (deg, force*length),
    energies, reaction resultant, iterations, max |bar strain|, max |angle defect| (deg) and the
    Gaussian curvature of a global quadratic fit through the facet centroids."""
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    rows = []
    act = fold_path.actuator_edges
    for s in range(fold_path.n_states):
        row: dict[str, float] = {"step": s, "load_factor": float(fold_path.load_factor[s])}
        for a, e in enumerate(act):
            row[f"target_deg_{e}"] = float(fold_path.actuator_targets_deg[s, a])
            row[f"fold_deg_{e}"] = float(fold_path.fold_angles_deg[s, e])
            row[f"moment_{e}"] = float(fold_path.actuator_moments[s, a])
        row["energy_bars"] = float(fold_path.energy_bars[s])
        row["energy_bend"] = float(fold_path.energy_bend[s])
        row["energy_fold"] = float(fold_path.energy_fold[s])
        row["energy_total"] = float(fold_path.energy[s])
        if fold_path.reactions is not None:
            Rsum = np.asarray(fold_path.reactions[s]).sum(0)
            row.update({"reaction_x": Rsum[0], "reaction_y": Rsum[1], "reaction_z": Rsum[2]})
        row["iterations"] = int(fold_path.iterations[s])
        row["wall_time"] = float(fold_path.wall_time[s])
        if model is not None or cp is not None:
            d = state_data(
                fold_path.X[s],
                model=model,
                pattern=cp if model is None else None,
                fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
            )
            row["max_abs_bar_strain"] = float(np.nanmax(np.abs(d.line_data["bar_strain"])))
            df = d.point_data["angle_defect"]
            row["max_abs_angle_defect_deg"] = (
                float(np.degrees(np.nanmax(np.abs(df)))) if np.isfinite(df).any() else 0.0
            )
        if cp is not None and cp.n_faces >= 6:
            row["K_global"] = fit_quadratic(reference_points(fold_path.X[s], cp)).K
        rows.append(
            {k: (int(v) if k in ("step", "iterations") else float(v)) for k, v in row.items()}
        )
    return rows


def write_steps_csv(path: str | Path, rows: list[dict[str, float]]) -> Path:
    """Write :func:`step_table` rows to a CSV file (header = union of the keys)."""
    path = Path(path)
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if k not in r else repr(r[k])) for k in keys})
    return path


def _clean(o: Any) -> Any:
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_clean(v) for v in o]
    if isinstance(o, np.ndarray):
        return _clean(o.tolist())
    if isinstance(o, np.generic):
        o = o.item()
    if isinstance(o, float) and not np.isfinite(o):
        return None  # JSON has no NaN
    return o


def write_summary_json(
    path: str | Path, fold_path: FoldPath, rows: list[dict[str, float]], extra: dict | None = None
) -> Path:
    """Write the final state's numbers, the path's status and every step (NaN -> null)."""
    path = Path(path)
    data = {
        "kind": fold_path.kind,
        "converged": fold_path.converged,
        "message": fold_path.message,
        "n_states": fold_path.n_states,
        "actuator_edges": fold_path.actuator_edges,
        "final": rows[-1] if rows else {},
        "steps": rows,
        "meta": fold_path.meta,
        **(extra or {}),
    }
    path.write_text(json.dumps(_clean(data), indent=2) + "\n")
    return path


# ------------------------------------------------------------------------ everything
def write_results(
    fold_path: FoldPath,
    model: Any | None,
    out_dir: str | Path,
    *,
    pattern: Any | None = None,
    name: str = "result",
    vtu: str = "all",
    extra: dict | None = None,
    fixed: np.ndarray | None = None,
    loads: np.ndarray | None = None,
    npz: bool = True,
) -> dict[str, Path]:
    """Write every result file of a fold path into ``out_dir``.

    Parameters
    ----------
    fold_path : FoldPath
    model : BarHingeModel or None
        None for a rigid path (then ``pattern`` is required).
    out_dir : path
        Created if missing.
    pattern : CreasePattern, optional
        Default ``model.pattern``.
    name : str
        Stem of the files.
    vtu : {"all", "last", "none"}
        Which states get a ``.vtu`` file.
    extra : dict, optional
        The ``summary`` record of the JSON file; default
        :func:`barhinge.analysis.summary.summarize` of the path (with ``fixed`` and ``loads``
        for the stiffness).
    fixed, loads : (n_nodes, 3) arrays, optional
        Supports and load case of the scene (for the stiffness in the summary).
    npz : bool
        Also save the path itself (``<name>.npz``; skip it when the caller saved it).

    Returns
    -------
    dict from a file kind (``xdmf``, ``xdmf_bars``, ``vtu``, ``fold``, ``csv``, ``json``,
    ``npz``) to its path (``vtu``: the last one written).
    """
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    if model is None and cp is None:
        raise ConfigError("write_results needs a model or a pattern")
    if vtu not in ("all", "last", "none"):
        raise ConfigError(f"vtu = {vtu!r}; expected 'all', 'last' or 'none'")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}
    if npz:
        written["npz"] = fold_path.save(out / f"{name}.npz")
    written["xdmf"] = write_xdmf(out / f"{name}.xdmf", fold_path, model=model, pattern=cp)
    written["xdmf_bars"] = out / f"{name}_bars.xdmf"
    steps = {"all": range(fold_path.n_states), "last": [fold_path.n_states - 1], "none": []}[vtu]
    for s in steps:
        written["vtu"] = write_state_vtu(
            out / f"{name}_{s:04d}.vtu",
            fold_path.X[s],
            model=model,
            pattern=cp if model is None else None,
            X_ref=fold_path.X[0],
            fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
        )
    if cp is not None:
        try:
            from barhinge.pattern.fold import write_fold_path
        except ImportError:
            log.info("FOLD writer not available; no .fold file written")
        else:
            fold_file = out / f"{name}.fold"
            write_fold_path(cp, fold_path, fold_file)
            written["fold"] = fold_file
    rows = step_table(fold_path, model=model, pattern=cp)
    written["csv"] = write_steps_csv(out / f"{name}_steps.csv", rows)
    if extra is None:
        from barhinge.analysis.summary import summarize

        extra = summarize(fold_path, model, pattern=cp, fixed=fixed, loads=loads)
    written["json"] = write_summary_json(
        out / f"{name}_summary.json", fold_path, rows, {"summary": extra}
    )
    return written


# --------------------------------------------------------------- atomic result folders
#: name of the manifest that marks a folder as one barhinge run
MANIFEST = "barhinge-run.json"
#: version of the manifest's layout
MANIFEST_FORMAT = 1
_TMP_TAG = "barhinge-tmp"  # .<name>.barhinge-tmp-<pid>-<hex>: a run being written
_OLD_TAG = "barhinge-old"  # .<name>.barhinge-old-<pid>-<hex>: a replaced run being removed


def _sibling(out: Path, tag: str) -> Path:
    return out.with_name(f".{out.name}.{tag}-{os.getpid()}-{secrets.token_hex(4)}")


def _pid_alive(pid: int) -> bool:
    if os.name != "posix":  # os.kill(pid, 0) would terminate the process on Windows
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: alive, someone else's
        return True
    return True


def _remove_leftovers(out: Path) -> None:
    """Remove temporary siblings of ``out`` left by runs that were killed (their process is
    gone); those of live processes are left alone."""
    for tag in (_TMP_TAG, _OLD_TAG):
        for p in out.parent.glob(f".{glob.escape(out.name)}.{tag}-*"):
            pid = p.name.rsplit("-", 2)[-2]
            if pid.isdigit() and not _pid_alive(int(pid)):
                log.info("removing %s, left by a killed run", p)
                shutil.rmtree(p, ignore_errors=True)


def _listed_files(folder: Path) -> dict[str, int]:
    """Relative POSIX path -> size of every file under ``folder`` (the manifest excluded)."""
    return {
        p.relative_to(folder).as_posix(): p.stat().st_size
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != MANIFEST
    }


def read_manifest(folder: str | Path, *, check: bool = True) -> dict[str, Any]:
    """The manifest of a result folder (``barhinge-run.json``), checked against the files.

    Parameters
    ----------
    folder : path
        A folder written by ``barhinge fold`` (or :func:`result_folder`).
    check : bool
        Also check that every listed file exists with its listed size and that the folder
        holds no other file.

    Raises
    ------
    ConfigError
        No manifest, an unreadable one, or (``check``) files that do not match it.
    """
    folder = Path(folder)
    f = folder / MANIFEST
    if not f.is_file():
        raise ConfigError(f"{folder} is not a barhinge result folder (no {MANIFEST})")
    try:
        man = json.loads(f.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ConfigError(f"{f}: unreadable manifest ({exc})") from None
    if not isinstance(man, dict) or not isinstance(man.get("files"), dict):
        raise ConfigError(f"{f}: not a barhinge manifest (expected an object with 'files')")
    if check:
        have = _listed_files(folder)
        want = man["files"]
        missing = sorted(set(want) - set(have))
        if missing:
            raise ConfigError(f"{folder}: {len(missing)} file(s) of the run missing: {missing[0]}")
        extra = sorted(set(have) - set(want))
        if extra:
            raise ConfigError(f"{folder}: {len(extra)} file(s) not of the run: {extra[0]}")
        wrong = sorted(k for k in want if have[k] != want[k])
        if wrong:
            raise ConfigError(
                f"{folder}/{wrong[0]}: {have[wrong[0]]} bytes, the manifest says {want[wrong[0]]}"
            )
    return man


def _probe_writable(out: Path) -> None:
    """ConfigError unless a folder can be made beside ``out`` (where the run is written
    before it is swapped in): its parent is created if needed and probed with a real
    folder, since permission bits do not tell (root, read-only or virtual file systems)."""
    parent = out.absolute().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        probe = tempfile.mkdtemp(prefix=".barhinge-probe-", dir=parent)
        os.rmdir(probe)
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise ConfigError(f"--out {out}: cannot write in {parent} ({why})") from None


def check_output_folder(out: str | Path, *, overwrite: bool = False) -> Path:
    """Check, before any work, that ``out`` may receive a run; returns it.

    ``out`` may be absent, an empty folder or a barhinge result folder (a manifest and no
    file outside it); anything else needs ``overwrite=True``. Refused even then: a path that
    is a file, the working directory or one of its parents, the home folder and the root.

    Raises
    ------
    ConfigError
        With one line naming the folder and what to do.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file, not a folder")
    for parent in out.absolute().parents:
        if parent.exists() and not parent.is_dir():
            raise ConfigError(f"--out {out}: {parent} is a file, not a folder")
    _probe_writable(out)
    if not out.is_dir():
        return out
    real = out.resolve()
    if real == Path.cwd().resolve() or real in Path.cwd().resolve().parents:
        raise ConfigError(f"--out {out} is the working folder or one of its parents; choose "
                          "a folder for the results")  # fmt: skip
    with contextlib.suppress(RuntimeError, KeyError):  # no home folder known
        if real == Path.home().resolve():
            raise ConfigError(f"--out {out} is the home folder; choose a folder for the results")
    if real == Path(real.anchor):
        raise ConfigError(f"--out {out} is the root folder; choose a folder for the results")
    if overwrite or not any(out.iterdir()):
        return out
    if not (out / MANIFEST).is_file():
        raise ConfigError(
            f"--out {out} is not empty and not a barhinge result folder (no {MANIFEST}); "
            "choose another folder or pass --overwrite to replace it"
        )
    try:
        listed = set(read_manifest(out, check=False)["files"])
    except ConfigError as exc:
        raise ConfigError(f"{exc}; pass --overwrite to replace the folder") from None
    extra = sorted(set(_listed_files(out)) - listed)
    if extra:
        raise ConfigError(
            f"--out {out} holds {len(extra)} file(s) that are not part of its barhinge run "
            f"({extra[0]}); pass --overwrite to replace the folder, those files included"
        )
    return out


def _exchange(a: Path, b: Path) -> bool:
    """Swap two existing paths in one step (Linux ``renameat2(RENAME_EXCHANGE)``); False
    where the system or file system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _fsync_tree(folder: Path) -> None:
    """Flush every file (and the folder) to disk, so a rename never exposes empty files
    after a power cut."""
    if os.name != "posix":
        return
    for p in [*sorted(folder.rglob("*")), folder]:
        fd = os.open(p, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


class RunFolder:
    """A result folder being written (see :func:`result_folder`).

    Attributes
    ----------
    path : Path
        The temporary folder to write into (a hidden sibling of ``out``).
    out : Path
        Where the run lands.
    manifest : dict
        Written to ``barhinge-run.json`` at the end; fill in ``scene``, ``converged``,
        ``reason``, ``message``, ``n_states`` (``files`` is listed from the folder).
    """

    def __init__(self, path: Path, out: Path, manifest: dict[str, Any]) -> None:
        self.path = path
        self.out = out
        self.manifest = manifest


@contextlib.contextmanager
def result_folder(
    out: str | Path, *, overwrite: bool = False, command: str = "fold"
) -> Iterator[RunFolder]:
    """Write a run into ``out`` atomically.

    Yields a :class:`RunFolder` whose ``path`` is a new hidden sibling of ``out`` (same
    parent, so the final rename stays on one file system). On a normal exit the manifest
    ``barhinge-run.json`` (the files and their sizes, the barhinge version, the command and
    what the caller put in ``manifest``) is written last and the folder swapped in: the old
    ``out`` is exchanged with it in one step (Linux), or moved aside first, then removed.
    On an exception (KeyboardInterrupt included) the temporary folder is removed and
    ``out`` is untouched. A reader thus sees no folder, the complete previous run or the
    complete new run; a killed run leaves only a hidden sibling, removed by the next run.

    Raises
    ------
    ConfigError
        ``out`` may not receive a run (see :func:`check_output_folder`).
    """
    from barhinge._version import __version__

    out = check_output_folder(out, overwrite=overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    _remove_leftovers(out)
    tmp = _sibling(out, _TMP_TAG)
    tmp.mkdir()
    run = RunFolder(
        tmp,
        out,
        {
            "barhinge_run": MANIFEST_FORMAT,
            "barhinge_version": __version__,
            "command": command,
            "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        },
    )
    try:
        yield run
        man = {**run.manifest, "files": _listed_files(tmp)}
        (tmp / MANIFEST).write_text(json.dumps(_clean(man), indent=2) + "\n")
        _fsync_tree(tmp)
        if not out.exists():
            os.rename(tmp, out)
        elif _exchange(tmp, out):
            shutil.rmtree(tmp, ignore_errors=True)  # tmp now holds the old run
        else:
            old = _sibling(out, _OLD_TAG)
            os.rename(out, old)
            os.rename(tmp, out)
            shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def atomic_file(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix) to write to; on a normal exit it
    replaces ``path`` in one step (``os.replace``), on an exception it is removed."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}-{secrets.token_hex(4)}.tmp{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def add_to_manifest(folder: str | Path, files: list[Path]) -> None:
    """List ``files`` (inside ``folder``) in its manifest, if it has one (``barhinge
    render`` adds its pictures to the run this way); the manifest is replaced atomically."""
    folder = Path(folder)
    f = folder / MANIFEST
    if not f.is_file():
        return
    man = read_manifest(folder, check=False)
    root = folder.resolve()
    for p in files:
        rel = Path(p).resolve().relative_to(root).as_posix()
        man["files"][rel] = Path(p).stat().st_size
    with atomic_file(f) as tmp:
        tmp.write_text(json.dumps(_clean(man), indent=2) + "\n")
