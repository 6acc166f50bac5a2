"""What the viewer shows, gathered from a fold path: the mesh, the creases, the states and
the numbers of the run, as plain numpy arrays (:class:`ViewData`).

Sources: a result folder of ``barhinge fold`` (``fold_path.npz``, ``fold_path.fold`` and the
``fold_path_NNNN.vtu`` states), a saved ``fold_path.npz``, a :class:`~barhinge.FoldPath`
(with its model, scene or pattern when known) or a FOLD file with ``file_frames``.

Only positions, fold angles and (with a model) crease moments and energies change from state
to state; strains, displacements and curvatures are recomputed by the viewer from the
positions.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.errors import ConfigError
from barhinge.fields import StateData, read_state_vtu, state_data
from barhinge.pattern.fold import read_fold, read_fold_path
from barhinge.plot.charts import control_axis
from barhinge.results import FoldPath

__all__ = ["ViewData", "load_view_data", "node_energy_density", "view_data"]


@dataclasses.dataclass(frozen=True, eq=False)
class ViewData:
    """Everything the viewer draws.

    Attributes
    ----------
    title : str
    X : (n_states, n_nodes, 3) float
        Node coordinates of every state.
    triangles : (n_tri, 3) int
        Panels of the sheet (node ids).
    bars : (n_bars, 2) int; bar_L0 : (n_bars,) float
        Bars (or pattern edges of a rigid path) and their reference lengths, for the strain.
    creases : (n_edges, 2) int; assignment : (n_edges,) str
        Pattern edges (node ids; the first ``n_vertices`` nodes are the pattern's vertices)
        and their M/V/B/F/U assignment.
    flat : (n_vertices, 2) float
        Crease pattern coordinates for the 2-D drawing.
    fold_deg : (n_states, n_edges) float
        Fold angles, degrees (FOLD convention: valley > 0, mountain < 0).
    moment : (n_states, n_edges) float or None
        Moment of every crease (force x length; NaN where unknown).
    energy_density : (n_states, n_nodes) float or None
        Stored energy lumped to the nodes per unit reference area (:func:`node_energy_density`).
    fixed : (n_nodes, 3) bool or None; loads : (n_nodes, 3) float or None
    actuators : (n_act,) int
        Pattern edge ids of the actuators.
    series : dict of str -> (n_states,) float
        Per-state numbers for the charts (load factor, energies, actuator angles, moments).
    summary : dict
        Summary numbers of the run (JSON-serialisable).
    x_label : str
        The series the charts use as x-axis: the control of the path
        (:func:`barhinge.plot.charts.control_axis`).
    """

    title: str
    X: np.ndarray
    triangles: np.ndarray
    bars: np.ndarray
    bar_L0: np.ndarray
    creases: np.ndarray
    assignment: np.ndarray
    flat: np.ndarray
    fold_deg: np.ndarray
    moment: np.ndarray | None = None
    energy_density: np.ndarray | None = None
    fixed: np.ndarray | None = None
    loads: np.ndarray | None = None
    actuators: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, int))
    series: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    summary: dict[str, Any] = dataclasses.field(default_factory=dict)
    x_label: str = "state"

    @property
    def n_states(self) -> int:
        return self.X.shape[0]


# ------------------------------------------------------------------------------ fields
def _tri_area(X: np.ndarray, tri: np.ndarray) -> np.ndarray:
    P = X[tri]
    return 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)


def node_energy_density(d: StateData, bar_L0: np.ndarray, node_area: np.ndarray) -> np.ndarray:
    """(n_nodes,) stored energy per unit area, lumped to the nodes.

    Each bar's energy (with the fold hinge along it: ``energy_density * L0`` of a line of
    :func:`barhinge.fields.state_data`) goes half to each end; each panel's bending energy
    (``energy_density * area``) a third to each corner; a node's sum is divided by its
    ``node_area`` (a third of the reference area of its triangles). So
    ``sum(density * node_area)`` is the total stored energy of the state.
    """
    n = len(d.points)
    e_line = np.nan_to_num(d.line_data["energy_density"]) * bar_L0
    e_tri = np.nan_to_num(d.triangle_data["energy_density"]) * _tri_area(d.points, d.triangles)
    E = np.bincount(d.lines.ravel(), weights=np.repeat(0.5 * e_line, 2), minlength=n)
    E += np.bincount(d.triangles.ravel(), weights=np.repeat(e_tri / 3.0, 3), minlength=n)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(node_area > 0, E / node_area, 0.0)


def _node_area(X: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(n_nodes,) a third of the area of the triangles around each node."""
    a = _tri_area(X, tri)
    return np.bincount(tri.ravel(), weights=np.repeat(a / 3.0, 3), minlength=len(X))


def _oriented(X0: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Triangles turned so that their state-0 normals agree with the sheet's mean normal (for
    smooth shading: a node's normal is the sum of its triangles')."""
    P = X0[tri]
    nrm = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    u, _, vt = np.linalg.svd(X0 - X0.mean(axis=0), full_matrices=False)
    flip = nrm @ vt[2] < 0
    out = tri.copy()
    out[flip] = out[flip][:, [0, 2, 1]]
    return out


def _supports_from_reactions(path: FoldPath) -> np.ndarray | None:
    """(n_nodes, 3) bool: DOFs with a nonzero reaction in some state (supports carry one)."""
    if path.reactions is None:
        return None
    R = np.abs(np.asarray(path.reactions))
    return (R > 1e-12 * max(float(R.max(initial=0.0)), 1e-300)).any(axis=0)


def _series(path: FoldPath) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {"state": np.arange(path.n_states, dtype=float)}
    x, label = control_axis(path)
    out[label] = x
    if np.ptp(path.load_factor) > 0:
        out["load factor"] = path.load_factor
    for name in ("energy_bars", "energy_bend", "energy_fold"):
        v = getattr(path, name)
        if np.isfinite(v).any():
            out[name.replace("_", " ")] = v
    if np.isfinite(path.energy).any():
        out["energy total"] = path.energy
    for a, e in enumerate(path.actuator_edges):
        out[f"actuator {e} angle (deg)"] = path.fold_angles_deg[:, e]
        if np.isfinite(path.actuator_moments[:, a]).any():
            out[f"actuator {e} moment"] = path.actuator_moments[:, a]
    if np.isfinite(path.wall_time).any():
        out["wall time (s)"] = path.wall_time
    return out


def _summary(path: FoldPath, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    last = path.n_states - 1
    s: dict[str, Any] = {
        "scene": path.meta.get("scene", ""),
        "kind": path.kind,
        "states": path.n_states,
        "nodes": int(path.X.shape[1]),
        "converged": bool(path.converged),
    }
    if path.message:
        s["message"] = path.message
    if path.meta.get("control"):
        s["control"] = path.meta["control"]
    if np.isfinite(path.energy[last]):
        s["energy total"] = float(path.energy[last])
    if np.isfinite(path.wall_time[last]):
        s["wall time (s)"] = float(path.wall_time[last])
    s["Newton iterations"] = int(np.sum(path.iterations))
    s["max |fold angle| (deg)"] = float(np.nanmax(np.abs(path.fold_angles_deg[last]), initial=0))
    labels = {
        "max_abs_bar_strain": "max |bar strain|",
        "max_abs_angle_defect_deg": "max |angle defect| (deg)",
        "K_global": "Gaussian curvature K (global fit)",
        "energy_fraction_fold": "energy share: folds",
        "energy_fraction_bend": "energy share: panel bending",
        "energy_fraction_bars": "energy share: bars",
        "n_soft_modes": "soft modes",
    }
    for k, label in labels.items():
        v = (extra or {}).get(k)
        if isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v):
            s[label] = v
    return s


# ------------------------------------------------------------------------------ builders
def view_data(
    path: FoldPath,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    fixed: np.ndarray | None = None,
    loads: np.ndarray | None = None,
    states: list[StateData] | None = None,
    summary: dict[str, Any] | None = None,
    title: str | None = None,
) -> ViewData:
    """Gather a :class:`ViewData` from a fold path and its model or pattern.

    Parameters
    ----------
    path : FoldPath
    model : BarHingeModel, optional
        Gives the panels, bars, crease moments and energies.
    pattern : CreasePattern, optional
        Without a model: panels are the pattern's faces, bars its edges.
    fixed, loads : (n_nodes, 3) arrays, optional
        Supports and reference loads (default: supports where the path has reactions).
    states : list of StateData, optional
        The states as written to a result folder (energies without a model).
    summary : dict, optional
        Extra summary numbers (``results`` of ``summary.json``).
    """
    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    n = path.X.shape[1]
    if cp is None:
        return _without_pattern(path, title)
    if n < cp.n_vertices:
        raise ConfigError(f"the path has {n} nodes, but the pattern has {cp.n_vertices} vertices")
    if path.fold_angles_deg.shape[1] != cp.n_edges:
        raise ConfigError(
            f"the path has fold angles of {path.fold_angles_deg.shape[1]} edges, but the "
            f"pattern has {cp.n_edges} edges"
        )
    X = path.X
    moment = None
    energy = None
    if model is not None:
        if model.n_nodes != n:
            raise ConfigError(f"the path has {n} nodes, but the model has {model.n_nodes}")
        d0 = state_data(X[0], model=model, X_ref=X[0])
        L0 = np.asarray(model.bar_L0, float)
        area = _node_area(X[0], d0.triangles)
        energy = np.empty((path.n_states, n))
        moment = np.full(path.fold_angles_deg.shape, np.nan)
        fold = np.flatnonzero((np.asarray(model.hinge_kind) == "fold") & (model.hinge_edge >= 0))
        for s in range(path.n_states):
            d = d0 if s == 0 else state_data(X[s], model=model, X_ref=X[0])
            energy[s] = node_energy_density(d, L0, area)
            ev = model.evaluate(X[s], tangent=False)
            moment[s, model.hinge_edge[fold]] = ev.hinge_moment[fold]
        tri, bars = d0.triangles, d0.lines
    elif states is not None and len(states) == path.n_states:
        d0 = states[0]
        tri, bars = d0.triangles, d0.lines
        L = np.linalg.norm(X[0][bars[:, 1]] - X[0][bars[:, 0]], axis=1)
        L0 = L / (1.0 + np.nan_to_num(d0.line_data["bar_strain"]))
        area = _node_area(X[0], tri)
        if np.isfinite(np.concatenate([d0.line_data["energy_density"],
                                       d0.triangle_data["energy_density"]])).any():  # fmt: skip
            energy = np.stack([node_energy_density(d, L0, area) for d in states])
    else:
        d0 = state_data(X[0, : cp.n_vertices], pattern=cp, fold_angles_deg=path.fold_angles_deg[0])
        tri, bars = d0.triangles, d0.lines
        V = cp.vertices3d
        L0 = np.linalg.norm(V[bars[:, 1]] - V[bars[:, 0]], axis=1)
        X = X[:, : cp.n_vertices]
    if len(path.actuator_edges):  # an actuator's moment: what drives it (the multiplier)
        if moment is None:
            moment = np.full(path.fold_angles_deg.shape, np.nan)
        moment[:, path.actuator_edges] = path.actuator_moments
    if fixed is None:
        fixed = _supports_from_reactions(path)
    if fixed is not None:
        fixed = np.asarray(fixed, bool)[: X.shape[1]]
    if loads is not None:
        loads = np.asarray(loads, float)[: X.shape[1]]
        if not np.any(loads):
            loads = None
    V = np.asarray(cp.vertices, float)
    tri = _oriented(X[0], np.asarray(tri, np.int64))
    return ViewData(
        title=title or str(path.meta.get("scene") or "fold path"),
        X=X,
        triangles=tri,
        bars=np.asarray(bars, np.int64),
        bar_L0=np.asarray(L0, float),
        creases=np.asarray(cp.edges, np.int64),
        assignment=np.asarray(cp.assignment).astype(str),
        flat=V[:, :2],
        fold_deg=path.fold_angles_deg,
        moment=moment,
        energy_density=energy,
        fixed=fixed,
        loads=loads,
        actuators=np.asarray(path.actuator_edges, np.int64),
        series=_series(path),
        summary=_summary(path, summary),
        x_label=control_axis(path)[1],
    )


def _without_pattern(path: FoldPath, title: str | None) -> ViewData:
    """A path with no pattern or model: panels from a Delaunay triangulation of state 0 in
    its best-fit plane (triangles much longer than the typical edge dropped), no creases."""
    from scipy.spatial import Delaunay

    X0 = path.X[0]
    _, _, vt = np.linalg.svd(X0 - X0.mean(axis=0), full_matrices=False)
    uv = (X0 - X0.mean(axis=0)) @ vt[:2].T
    tri = Delaunay(uv).simplices.astype(np.int64)
    P = uv[tri]
    longest = np.max(np.linalg.norm(P - np.roll(P, 1, axis=1), axis=2), axis=1)
    tri = _oriented(X0, tri[longest <= 2.5 * np.median(longest)])
    bars = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]),
                             axis=1), axis=0)  # fmt: skip
    L0 = np.linalg.norm(X0[bars[:, 1]] - X0[bars[:, 0]], axis=1)
    return ViewData(
        title=title or str(path.meta.get("scene") or "fold path"),
        X=path.X,
        triangles=tri,
        bars=bars,
        bar_L0=L0,
        creases=np.zeros((0, 2), np.int64),
        assignment=np.zeros(0, str),
        flat=uv,
        fold_deg=np.zeros((path.n_states, 0)),
        fixed=_supports_from_reactions(path),
        series=_series(path),
        summary=_summary(path),
        x_label=control_axis(path)[1],
    )


def _from_folder(
    folder: Path, pattern: Any | None = None, states: list[StateData] | None = None
) -> ViewData:
    """The view of a result folder; ``pattern`` and ``states``: the crease pattern its
    ``fold_path.fold`` holds and the fields of its VTU files, when the caller has them (the
    run writer: reading them back is skipped)."""
    npz = folder / "fold_path.npz"
    if not npz.is_file():
        raise ConfigError(f"{folder} has no fold_path.npz: not a result folder of barhinge fold")
    path = _load_path(npz)
    fold = folder / "fold_path.fold"
    if not fold.is_file():
        raise ConfigError(f"{folder} has no fold_path.fold (the crease pattern of the path)")
    cp = pattern if pattern is not None else read_fold(fold, validate=False)
    if states is None or len(states) != path.n_states:
        vtus = [folder / f"fold_path_{s:04d}.vtu" for s in range(path.n_states)]
        states = [read_state_vtu(f) for f in vtus] if all(f.is_file() for f in vtus) else None
    summary: dict[str, Any] = {}
    js = folder / "summary.json"
    if js.is_file():
        summary = json.loads(js.read_text()).get("results") or {}
    return view_data(path, pattern=cp, states=states, summary=summary)


def _load_path(npz: Path) -> FoldPath:
    try:
        return FoldPath.load(npz)
    except Exception as exc:  # noqa: BLE001 - any unreadable file becomes one clear error
        raise ConfigError(
            f"{npz} is not a fold path saved by barhinge ({type(exc).__name__})"
        ) from None


def _from_fold_file(file: Path) -> ViewData:
    cp, X, ang = read_fold_path(file)
    if len(X) == 0:
        raise ConfigError(f"{file} has no file_frames: nothing to play")
    ang = np.where(np.isfinite(ang), ang, 0.0)
    kind = json.loads(file.read_text()).get("barhinge:path_kind", "rigid")
    path = FoldPath(X=X, fold_angles_deg=ang, kind=str(kind), meta={"scene": file.stem})
    return view_data(path, pattern=cp, title=cp.meta.get("frame_title") or file.stem)


def load_view_data(source: Any, **kwargs: Any) -> ViewData:
    """A :class:`ViewData` from a result folder, a ``.npz``, a ``.fold`` file with frames, a
    :class:`FoldPath` (with ``model=``, ``pattern=`` or ``scene=``) or a ViewData.

    Raises
    ------
    ConfigError
        The path does not exist or is not one of these.
    """
    if isinstance(source, ViewData):
        return source
    if isinstance(source, FoldPath):
        scene = kwargs.pop("scene", None)
        if scene is not None:
            kwargs.setdefault("model", scene.model)
            kwargs.setdefault("fixed", getattr(scene, "fixed", None))
            kwargs.setdefault("loads", getattr(scene, "loads", None))
        return view_data(source, **kwargs)
    p = Path(source)
    if p.is_dir():
        return _from_folder(p, kwargs.get("pattern"), kwargs.get("states"))
    if not p.exists():
        raise ConfigError(f"{p} does not exist")
    if p.suffix == ".npz":
        if (p.parent / "fold_path.fold").is_file() and p.name == "fold_path.npz":
            return _from_folder(p.parent)
        fold = p.with_suffix(".fold")
        if not fold.is_file():
            raise ConfigError(f"no crease pattern for {p.name}: expected {fold.name} beside it")
        return view_data(_load_path(p), pattern=read_fold(fold, validate=False))
    if p.suffix == ".fold":
        return _from_fold_file(p)
    raise ConfigError(f"{p}: expected a result folder, a .npz fold path or a .fold file")
