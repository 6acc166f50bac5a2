"""Fields of a state on its mesh, and the files that carry them (meshio): one ``.vtu`` per
state and an XDMF time series of a path.

Only this module imports meshio. Every file opens in ParaView / PyVista without glue:

* ``<name>_NNNN.vtu``: one state; points = node coordinates; two cell blocks:
  ``triangle`` (the panels of the triangulated sheet) and ``line`` (bars of a bar-and-hinge
  model, or the pattern's edges for a rigid path). Arrays are listed in :func:`state_data`.
* ``<name>.xdmf`` + ``<name>.h5`` (panels) and ``<name>_bars.xdmf`` + ``.h5`` (bars): the
  whole path on the state-0 mesh with point data ``displacement`` per step (ParaView's
  "Warp By Vector") and the same arrays.
"""

from __future__ import annotations

import contextlib
import os
import weakref
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.analysis.curvature import (
    angle_defect,
    boundary_nodes,
    corner_angles,
    mixed_voronoi_area,
    pattern_triangles,
)
from barhinge.analysis.forces import panel_membrane_resultants
from barhinge.errors import ConfigError
from barhinge.linalg.threads import worker_threads
from barhinge.results import FoldPath

__all__ = [
    "StateData",
    "read_state_vtu",
    "state_data",
    "state_mesh",
    "write_state_vtu",
    "write_state_vtus",
    "write_xdmf",
]


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


_TOPOLOGY: weakref.WeakKeyDictionary[Any, dict[str, np.ndarray]] = weakref.WeakKeyDictionary()


def _model_topology(model: Any) -> dict[str, np.ndarray]:
    """What :func:`state_data` needs of a model's mesh that no state changes (triangles, the
    bar of each fold hinge, the kind of each line), computed once per model (models are
    frozen)."""
    topo = _TOPOLOGY.get(model)
    if topo is not None:
        return topo
    n = model.n_nodes
    tri, wing_tri = _model_triangles(model.hinges)
    lines = np.asarray(model.bars, np.int64)
    fold = np.asarray(model.hinge_kind) == "fold"
    H = np.asarray(model.hinges, np.int64)
    key_line = _pair_index(lines, n)
    hf = np.flatnonzero(fold)
    order = np.argsort(key_line)
    key_h = _pair_index(H[hf, :2], n)
    at = np.minimum(np.searchsorted(key_line[order], key_h), len(order) - 1)
    ok = key_line[order[at]] == key_h
    on_edge = np.isin(key_line, _pair_index(model.pattern.edges, n))
    topo = {"tri": tri, "wing_tri": wing_tri, "tri_face": _triangle_faces(model, tri),
            "lines": lines, "fold": fold,
            "line_of_fold": order[at[ok]], "fold_hinge": hf[ok], "on_edge": on_edge,
            "boundary": boundary_nodes(tri, n)}  # fmt: skip
    _TOPOLOGY[model] = topo
    return topo


def _pattern_topology(cp: Any, n: int) -> dict[str, np.ndarray]:
    """What :func:`state_data` needs of a pattern's mesh (fan triangles, edges, creases,
    reference lengths, boundary nodes of ``n`` nodes), computed once per pattern (patterns
    are frozen)."""
    topo = _TOPOLOGY.get(cp)
    if topo is not None and len(topo["boundary"]) == n:
        return topo
    tri = pattern_triangles(cp)
    lines = np.asarray(cp.edges, np.int64)
    crease = np.zeros(len(lines), bool)
    crease[cp.crease_edges] = True
    V = cp.vertices3d
    topo = {"tri": tri, "lines": lines, "crease": crease,
            "L0": np.linalg.norm(V[lines[:, 1]] - V[lines[:, 0]], axis=1),
            "boundary": boundary_nodes(tri, n)}  # fmt: skip
    _TOPOLOGY[cp] = topo
    return topo


def _triangle_faces(model: Any, tri: np.ndarray) -> np.ndarray:
    """(n_tri,) the face of the model's pattern each triangle ``tri`` lies in (-1 where a
    triangle is not one of the model's triangulation)."""
    from barhinge.model.triangulate import triangulate

    t = triangulate(model.pattern, model.scheme)
    n = model.n_nodes
    key = lambda T: np.sort(np.asarray(T, np.int64), axis=1) @ np.array([n * n, n, 1])  # noqa: E731
    k_model, k_tri = key(t.triangles), key(tri)
    order = np.argsort(k_model)
    at = np.minimum(np.searchsorted(k_model[order], k_tri), len(order) - 1)
    found = k_model[order[at]] == k_tri
    return np.where(found, np.asarray(t.tri_face)[order[at]], -1)


def _triangle_membrane(model: Any, X: np.ndarray, tri_face: np.ndarray) -> np.ndarray:
    """(n_tri, 9) membrane stress resultant tensor ``N`` (global axes, row-major 3 x 3,
    force per length) of the panel each triangle lies in (its face ``tri_face``, from
    :func:`_triangle_faces`; NaN where -1)
    (:func:`barhinge.analysis.forces.panel_membrane_resultants`)."""
    _, Ng = panel_membrane_resultants(model, X)
    out = np.full((len(tri_face), 9), np.nan)
    found = tri_face >= 0
    out[found] = Ng[tri_face[found]].reshape(-1, 9)
    return out


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
    reactions: np.ndarray | None = None,
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
    reactions : (n_nodes, 3) float, optional
        Support reactions of the state (``FoldPath.reactions[s]``); written as point data
        ``reaction`` (force; zero at free nodes).

    Arrays
    ------
    Units are the user's: lengths of the pattern, forces consistent with its ``E``.
    point data: ``displacement`` (n, 3, length), ``angle_defect`` (rad, NaN at the
    boundary), ``defect_density`` (angle defect / mixed Voronoi area, 1/length^2),
    ``reaction`` (n, 3, force; when ``reactions`` is given).
    cell data (triangle and line blocks): ``fold_angle_deg`` (lines on creases; FOLD sign),
    ``bar_strain`` (engineering strain (L - L0)/L0 of bars), ``energy_density`` (bars and fold
    hinges: energy per unit length; panels: bending energy per unit area; the model's own
    laws of :mod:`barhinge.kernels.laws`), ``kind`` (0 panel, 1 bar inside a panel, 2 crease,
    3 other pattern edge: boundary or flat line); with a model also ``bar_force`` (lines: axial
    force, tension > 0, force) and ``moment`` (lines on creases: the fold hinge's moment
    ``dW/drho``, > 0 folding it further valley than its rest angle, force x length) and
    ``membrane_N`` (triangles: the membrane stress resultant tensor of their panel in global
    axes, 9 components row-major, tension > 0, force / length; NaN on lines).
    """
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ConfigError(f"X must have shape (n_nodes, 3), got {X.shape}")
    n = len(X)
    if model is None and pattern is None:
        raise ConfigError("state_data needs a model or a pattern to know the mesh")
    cp: Any = pattern  # a model or a pattern: checked above
    if model is not None:
        if model.n_nodes != n:
            raise ConfigError(f"len(X) = {n}, but the model has {model.n_nodes} nodes")
        topo = _model_topology(model)
        tri, wing_tri, lines = topo["tri"], topo["wing_tri"], topo["lines"]
        L = np.linalg.norm(X[lines[:, 1]] - X[lines[:, 0]], axis=1)
        L0 = np.asarray(model.bar_L0, float)
        eps = (L - L0) / L0
        el = model.element_states(X)  # one pass over the elements
        rho, e_h, hinge_moment = el.hinge_angle, el.hinge_energy, el.hinge_moment
        e_line = el.bar_energy / L0  # energy per length
        bar_force = el.bar_axial_force
        # fold hinges: angle and energy on the bar along their axis
        i, hf = topo["line_of_fold"], topo["fold_hinge"]
        fold_ang = np.full(len(lines), np.nan)
        is_crease = np.zeros(len(lines), bool)
        fold_ang[i] = np.degrees(rho[hf])
        moment_line = np.full(len(lines), np.nan)
        moment_line[i] = hinge_moment[hf]
        np.add.at(e_line, i, e_h[hf] / L0[i])
        is_crease[i] = True
        # bend hinges: energy split between their two triangles, per unit area
        P = X[tri]
        area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
        bend = np.flatnonzero(~topo["fold"])
        e_tri = np.bincount(
            wing_tri[bend].ravel(), weights=np.repeat(0.5 * e_h[bend], 2), minlength=len(tri)
        ) / np.where(area > 0, area, 1.0)
        strain_line = eps
        kind_line = np.where(is_crease, 2, np.where(topo["on_edge"], 3, 1))
        forces: tuple[np.ndarray, np.ndarray] | None = (bar_force, moment_line)
        membrane = _triangle_membrane(model, X, topo["tri_face"])
        Xr = model.X0 if X_ref is None else X_ref
    else:
        cp = pattern
        if n < cp.n_vertices:
            raise ConfigError(f"len(X) = {n}, but the pattern has {cp.n_vertices} vertices")
        topo = _pattern_topology(cp, n)
        tri, lines, crease = topo["tri"], topo["lines"], topo["crease"]
        if fold_angles_deg is None:
            fold_angles_deg = cp.replaced(
                vertices=X[: cp.n_vertices], validate=False
            ).state_fold_angles()
        fold_ang = np.asarray(fold_angles_deg, float).copy()
        fold_ang[~crease] = np.nan
        L0 = topo["L0"]
        L = np.linalg.norm(X[lines[:, 1]] - X[lines[:, 0]], axis=1)
        strain_line = (L - L0) / L0
        e_line = np.full(len(lines), np.nan)
        e_tri = np.full(len(tri), np.nan)
        kind_line = np.where(crease, 2, 3)
        forces = None
        membrane = None
        Xr = cp.vertices3d if X_ref is None else X_ref
    Xr = np.asarray(Xr, float)
    disp = X - Xr if Xr.shape == X.shape else np.zeros_like(X)
    ang = corner_angles(X, tri)
    defect = angle_defect(X, tri, angles=ang, boundary=topo["boundary"])
    with np.errstate(divide="ignore", invalid="ignore"):
        density = defect / mixed_voronoi_area(X, tri, angles=ang)
    nan_t = np.full(len(tri), np.nan)
    point_data = {"displacement": disp, "angle_defect": defect, "defect_density": density}
    if reactions is not None:
        point_data["reaction"] = np.asarray(reactions, float).reshape(n, 3)
    triangle_data = {
        "fold_angle_deg": nan_t,
        "bar_strain": nan_t,
        "energy_density": e_tri,
        "kind": np.zeros(len(tri)),
    }
    line_data = {
        "fold_angle_deg": fold_ang,
        "bar_strain": strain_line,
        "energy_density": e_line,
        "kind": kind_line.astype(float),
    }
    if forces is not None:  # a model: bar forces and crease moments on the lines
        triangle_data["bar_force"] = triangle_data["moment"] = nan_t
        line_data["bar_force"], line_data["moment"] = forces
    if membrane is not None:  # the panel's membrane stress resultant on its triangles
        triangle_data["membrane_N"] = membrane
        line_data["membrane_N"] = np.full((len(lines), 9), np.nan)
    return StateData(
        points=X,
        triangles=tri,
        lines=lines,
        point_data=point_data,
        triangle_data=triangle_data,
        line_data=line_data,
    )


def state_mesh(X: np.ndarray | None = None, *, data: StateData | None = None, **kwargs: Any):
    """A ``meshio.Mesh`` of one state: from ``data`` when given, else from the arguments of
    :func:`state_data`."""
    import meshio

    if data is None:
        if X is None:
            raise ConfigError("state_mesh needs X (with the state_data arguments) or data")
        data = state_data(X, **kwargs)
    d = data
    return meshio.Mesh(
        d.points,
        [("triangle", d.triangles), ("line", d.lines)],
        point_data=d.point_data,
        cell_data={k: [d.triangle_data[k], d.line_data[k]] for k in d.triangle_data},
    )


def write_state_vtu(path: str | Path, X: np.ndarray | None = None, **kwargs: Any) -> Path:
    """Write one state to a ``.vtu`` file (``data=`` a :class:`StateData`, or the arguments
    of :func:`state_data`)."""
    path = Path(path)
    state_mesh(X, **kwargs).write(path)
    return path


def write_state_vtus(paths: Sequence[str | Path], states: Sequence[StateData]) -> list[Path]:
    """Write ``states[i]`` to ``paths[i]`` (``.vtu``), several files at a time: meshio's
    zlib compression, most of a file's time, releases the GIL, so the files are written by
    :func:`barhinge.linalg.threads.worker_threads` threads.
    An error in any file is raised after the others are finished."""
    if len(paths) != len(states):
        raise ValueError(f"{len(paths)} paths for {len(states)} states")
    workers = min(len(paths), worker_threads())
    if workers <= 1:
        return [write_state_vtu(p, data=d) for p, d in zip(paths, states, strict=True)]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        jobs = [pool.submit(write_state_vtu, p, data=d) for p, d in zip(paths, states, strict=True)]
    return [job.result() for job in jobs]


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


def path_state_data(
    fold_path: FoldPath, *, model: Any | None = None, pattern: Any | None = None
) -> list[StateData]:
    """:func:`state_data` of every state of a path (displacements from state 0, the
    recorded reactions where the path has them)."""
    return [
        state_data(
            fold_path.X[s],
            model=model,
            pattern=pattern,
            X_ref=fold_path.X[0],
            fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
            reactions=None if fold_path.reactions is None else fold_path.reactions[s],
        )
        for s in range(fold_path.n_states)
    ]


def write_xdmf(
    path: str | Path,
    fold_path: FoldPath,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    states: list[StateData] | None = None,
) -> Path:
    """Write a fold path as XDMF time series: ``<stem>.xdmf`` (panels, triangles) and
    ``<stem>_bars.xdmf`` (bars or edges, lines), each with its ``.h5`` beside it.

    ``states``: the :func:`path_state_data` of the path when already computed (the run
    writer shares them with the VTU files). The mesh is state 0; each step holds point data
    ``displacement`` (from state 0), the support ``reaction`` where the path records
    reactions, and the arrays of :func:`state_data`. The time value of step s is s.

    meshio's time-series writer creates its ``.h5`` in the current directory, so it is run
    from inside the output folder (the working directory is restored afterwards).
    """
    import meshio

    given = Path(path)
    path = given.resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    if states is None:
        states = path_state_data(fold_path, model=model, pattern=pattern)
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
