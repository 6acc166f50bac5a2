"""Off-screen 3-D pictures of folded states: PNG renders coloured by a named array, GIF animations.

PyVista (VTK) is imported lazily, only when a picture is made. Off-screen rendering uses EGL
(``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``; Mesa's software renderer is enough). On a
machine without a GL stack VTK crashes the process instead of raising, so the first render
probes VTK in a subprocess (a success is remembered on disk, per machine set-up) and, if that
fails, falls back to a matplotlib 3-D render (``backend="auto"``) or raises
:class:`RenderError` (``backend="pyvista"``).

Colours follow the crease-pattern drawings: valley folds (rho > 0) blue, mountain folds red.
"""

from __future__ import annotations

import ctypes.util
import functools
import importlib.metadata
import json
import logging
import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.errors import BarhingeError, ConfigError
from barhinge.fields import StateData, state_data

__all__ = [
    "RenderError",
    "animate",
    "can_render_offscreen",
    "render_mode",
    "render_state",
]

log = logging.getLogger(__name__)

PAPER = "#efe9dc"
EDGE = "#3a3a3a"
_EGL = {"VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow"}
_PROBE = (
    "import pyvista as pv\n"
    "p = pv.Plotter(off_screen=True, window_size=(64, 64))\n"
    "p.add_mesh(pv.Sphere())\n"
    "img = p.screenshot(return_img=True)\n"
    "p.close()\n"
    "assert img.std() > 0\n"
)

#: array name -> (label with unit, colormap, symmetric colour range)
ARRAYS: dict[str, tuple[str, str, bool]] = {
    "fold_angle_deg": ("fold angle (deg, valley > 0)", "RdBu", True),
    "bar_strain": ("bar strain", "PuOr_r", True),
    "energy_density": ("stored energy per area (panels) / length (bars)", "magma_r", False),
    "angle_defect": ("angle defect (rad)", "PiYG", True),
    "defect_density": ("angle defect / area", "PiYG", True),
    "displacement": ("|displacement|", "viridis", False),
    "mode": ("mode amplitude (normalised)", "viridis", False),
}


class RenderError(BarhingeError, RuntimeError):
    """Off-screen rendering is not available on this machine."""


def _set_egl_env() -> None:
    for k, v in _EGL.items():
        os.environ.setdefault(k, v)


@functools.cache
def can_render_offscreen() -> bool:
    """True if VTK can render off-screen here.

    Probed in a subprocess (VTK may crash the process it runs in); a success is remembered
    on disk (``$XDG_CACHE_HOME/barhinge/offscreen.json``, keyed by the Python, the VTK
    version, the EGL library and the environment variables that choose the GL stack), so a
    machine is probed once, not on every run. Set ``BARHINGE_OFFSCREEN=1`` (or ``0``) to skip
    the probe.
    """
    forced = os.environ.get("BARHINGE_OFFSCREEN", "").strip()
    if forced in ("0", "1"):
        return forced == "1"
    key = _probe_key()
    cache = _probe_cache_file()
    try:
        if json.loads(cache.read_text()).get(key) is True:
            return True
    except (OSError, ValueError, AttributeError):
        pass
    env = {**os.environ, **_EGL}
    env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", _EGL["VTK_DEFAULT_OPENGL_WINDOW"])
    try:
        r = subprocess.run(
            [sys.executable, "-c", _PROBE], env=env, capture_output=True, timeout=120
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        log.warning("off-screen rendering probe failed: %s", exc)
        return False
    if r.returncode != 0:
        log.warning("off-screen rendering unavailable (probe exit %d)", r.returncode)
        return False
    _remember_probe(cache, key)
    return True


#: environment variables that choose the GL stack VTK renders with
_GL_ENV = (
    "DISPLAY",
    "WAYLAND_DISPLAY",
    "VTK_DEFAULT_OPENGL_WINDOW",
    "LIBGL_ALWAYS_SOFTWARE",
    "EGL_PLATFORM",
    "MESA_GL_VERSION_OVERRIDE",
    "PYVISTA_OFF_SCREEN",
)


def _probe_key() -> str:
    """What a cached probe result depends on: the Python, VTK, the EGL library file and the
    GL environment."""
    try:
        vtk = importlib.metadata.version("vtk")
    except importlib.metadata.PackageNotFoundError:
        vtk = "none"
    egl = ctypes.util.find_library("EGL") or "none"
    parts = [sys.executable, vtk, egl, *(f"{k}={os.environ.get(k, '')}" for k in _GL_ENV)]
    return "|".join(parts)


def _probe_cache_file() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(root) / "barhinge" / "offscreen.json"


def _remember_probe(cache: Path, key: str) -> None:
    """Record a successful probe (best effort: an unwritable cache costs one probe per run)."""
    try:
        try:
            known = json.loads(cache.read_text())
            known = known if isinstance(known, dict) else {}
        except (OSError, ValueError):
            known = {}
        known[key] = True
        cache.parent.mkdir(parents=True, exist_ok=True)
        tmp = cache.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps(known, indent=1))
        os.replace(tmp, cache)
    except OSError as exc:
        log.debug("could not cache the off-screen probe: %s", exc)


def _backend(backend: str) -> str:
    if backend not in ("auto", "pyvista", "matplotlib"):
        raise ConfigError(f"backend = {backend!r}; expected 'auto', 'pyvista' or 'matplotlib'")
    if backend == "matplotlib":
        return backend
    if can_render_offscreen():
        _set_egl_env()
        return "pyvista"
    if backend == "pyvista":
        raise RenderError(
            "off-screen rendering is unavailable: VTK could not open an EGL window "
            "(install libegl1 and libgl1-mesa-dri) - use backend='matplotlib'"
        )
    return "matplotlib"


# ---------------------------------------------------------------------------- scalars
def _pick(d: StateData, scalars: str | np.ndarray | None) -> tuple[str, str, np.ndarray | None]:
    """Where the scalars live (``point``, ``triangle``, ``line`` or ``none``) and their values."""
    if scalars is None:
        return "none", "", None
    if isinstance(scalars, str):
        if scalars in d.point_data:
            v = np.asarray(d.point_data[scalars], float)
            return "point", scalars, (np.linalg.norm(v, axis=1) if v.ndim == 2 else v)
        if scalars in ("fold_angle_deg", "bar_strain"):
            return "line", scalars, np.asarray(d.line_data[scalars], float)
        if scalars in d.triangle_data:
            return "triangle", scalars, np.asarray(d.triangle_data[scalars], float)
        known = sorted({*d.point_data, *d.triangle_data})
        raise ConfigError(f"unknown array {scalars!r}; expected one of {', '.join(known)}")
    v = np.asarray(scalars, float)
    if v.ndim == 2 and v.shape == d.points.shape:
        return "point", "mode", np.linalg.norm(v, axis=1)
    for where, n in (
        ("point", len(d.points)),
        ("triangle", len(d.triangles)),
        ("line", len(d.lines)),
    ):
        if v.ndim == 1 and len(v) == n:
            return where, "values", v
    raise ConfigError(
        f"scalars of shape {v.shape} match neither the {len(d.points)} nodes, the "
        f"{len(d.triangles)} triangles nor the {len(d.lines)} lines"
    )


def nice_limits(lo: float, hi: float, max_ticks: int = 7) -> tuple[float, float, int]:
    """Limits widened to round numbers and the number of evenly spaced ticks between them,
    each tick a multiple of a step of 1, 2, 2.5 or 5 times a power of ten (at most
    ``max_ticks`` ticks)."""
    if not hi > lo:
        lo, hi = lo - 1.0, lo + 1.0
    raw = (hi - lo) / (max_ticks - 1)
    p = 10.0 ** np.floor(np.log10(raw))
    for k in (1.0, 2.0, 2.5, 5.0, 10.0, 20.0):
        step = k * p
        a, b = np.floor(lo / step + 1e-9) * step, np.ceil(hi / step - 1e-9) * step
        n = int(round((b - a) / step)) + 1
        if n <= max_ticks:
            return float(a), float(b), n
    return lo, hi, 2


def _clim(name: str, v: np.ndarray | None, clim: Sequence[float] | None) -> tuple[float, float]:
    """Colour limits: ``clim`` as given, else the data's range widened to round numbers
    (:func:`nice_limits`; symmetric about 0 for signed arrays such as fold angles)."""
    if clim is not None:
        return float(clim[0]), float(clim[1])
    finite = v[np.isfinite(v)] if v is not None else np.zeros(0)
    if finite.size == 0:
        return (-1.0, 1.0)
    sym = ARRAYS.get(name, ("", "", False))[2]
    if sym:
        m = float(np.abs(finite).max()) or 1.0
        lo, hi, _ = nice_limits(-m, m)
        return (-max(-lo, hi), max(-lo, hi))
    lo, hi = float(finite.min()), float(finite.max())
    return nice_limits(lo, hi)[:2] if hi > lo else (lo - 1.0, lo + 1.0)


# ---------------------------------------------------------------------------- pyvista
def _polydata(d: StateData) -> dict[str, Any]:
    """PyVista meshes of a state sharing its points: ``panels`` (triangles), ``lines`` (all
    bars / edges), ``crease`` (kind 2) and ``outline`` (kind 3; None when empty)."""
    import pyvista as pv

    def lines_of(L: np.ndarray):
        if len(L) == 0:
            return None
        return pv.PolyData(d.points.copy(), lines=np.column_stack([np.full(len(L), 2), L]).ravel())

    kind = d.line_data["kind"]
    tri = np.column_stack([np.full(len(d.triangles), 3), d.triangles]).ravel()
    return {
        "panels": pv.PolyData(d.points.copy(), faces=tri),
        "lines": lines_of(d.lines),
        "crease": lines_of(d.lines[kind == 2]),
        "outline": lines_of(d.lines[kind == 3]),
    }


def _assign(meshes: dict[str, Any], d: StateData, where: str, name: str, values) -> None:
    """Put the state's coordinates and the coloured array on the meshes (in place)."""
    for m in meshes.values():
        if m is not None:
            m.points = d.points
    if where == "point":
        meshes["panels"].point_data[name] = values
    elif where == "triangle":
        meshes["panels"].cell_data[name] = values
    elif where == "line":
        if name == "fold_angle_deg":
            if meshes["crease"] is not None:
                meshes["crease"].cell_data[name] = values[d.line_data["kind"] == 2]
        else:
            meshes["lines"].cell_data[name] = values


def _plotter(window_size: tuple[int, int]):
    import pyvista as pv

    p = pv.Plotter(off_screen=True, window_size=list(window_size))
    p.set_background("white")
    return p


def _add_state(p, meshes, where: str, name: str, cmap, clim, line_width: float, label=None):
    """Add the meshes of :func:`_polydata` (arrays set by :func:`_assign`) to plotter p;
    returns (coloured actor, scalar bar arguments) for :func:`_scalar_bar`, or None when
    nothing is coloured."""
    panels, lines = meshes["panels"], meshes["lines"]
    default_label, default_cmap, _ = ARRAYS.get(name, (name, "viridis", False))
    label = label or default_label
    cmap = cmap or default_cmap
    fs = max(10, int(round(p.window_size[1] / 45)))
    lo, hi = clim
    n_labels = nice_limits(lo, hi, 7 if p.window_size[0] >= 800 else 5)[2]
    sbar = {
        "n_labels": n_labels,  # on the round numbers of nice_limits when clim is theirs
        "title": label,
        "vertical": False,
        "position_x": 0.25,
        "position_y": 0.05,
        "width": 0.5,
        "height": 0.08,
        "color": "black",
        "fmt": "%.3g",
        "title_font_size": fs,
        "label_font_size": max(9, fs - 3),
    }
    crease, outline = meshes["crease"], meshes["outline"]
    tube = max(line_width, 1.0)
    if where in ("point", "triangle"):
        actor = p.add_mesh(
            panels,
            scalars=name,
            cmap=cmap,
            clim=clim,
            nan_color=PAPER,
            show_scalar_bar=False,
            ambient=0.3,
            diffuse=0.75,
        )
        for part in (crease, outline):
            if part is not None:
                p.add_mesh(part, color=EDGE, line_width=0.8 * tube)
        return actor, sbar
    p.add_mesh(panels, color=PAPER, ambient=0.35, diffuse=0.7, specular=0.1)
    if where == "line" and name == "fold_angle_deg":
        actor = None
        if crease is not None:
            actor = p.add_mesh(
                crease,
                scalars=name,
                cmap=cmap,
                clim=clim,
                line_width=2.5 * tube,
                render_lines_as_tubes=True,
                show_scalar_bar=False,
            )
        if outline is not None:
            p.add_mesh(outline, color="#6e6e6e", line_width=0.8 * tube)
        return (actor, sbar) if actor is not None else None
    if where == "line":
        actor = p.add_mesh(
            lines,
            scalars=name,
            cmap=cmap,
            clim=clim,
            line_width=2.0 * tube,
            render_lines_as_tubes=True,
            show_scalar_bar=False,
            nan_color="#8c8c8c",
        )
        return actor, sbar
    for part in (crease, outline):
        if part is not None:
            p.add_mesh(part, color=EDGE, line_width=tube)
    return None


def _scalar_bar(p, bar) -> None:
    if bar is not None:
        actor, sbar = bar
        sb = p.add_scalar_bar(mapper=actor.mapper, **sbar)
        if sb is not None:
            sb.SetTextPositionToPrecedeScalarBar()  # tick labels under the bar, title above


def _fit(
    p, margin: float = 0.05, bottom: float = 0.16, top: float = 0.0, shrink_only: bool = False
) -> None:
    """Zoom and pan so the picture fills the window between a band at the top (title) and
    one at the bottom (colour bar), fractions of the height; one test render without them."""
    p.render()
    img = np.asarray(p.screenshot(return_img=True), float)
    h, w = img.shape[:2]
    ink = np.argwhere(img.min(axis=2) < 245)
    if len(ink) == 0:
        return
    (r0, c0), (r1, c1) = ink.min(0), ink.max(0)
    ch, cw = r1 - r0 + 1, c1 - c0 + 1
    free = h * (1 - bottom - top)
    avail_h, avail_w = free * (1 - 2 * margin), w * (1 - 2 * margin)
    scale = min(avail_h / ch, avail_w / cw)
    free_rows = (h * top, h * (1 - bottom))
    if shrink_only and scale >= 1 and r0 >= free_rows[0] and r1 <= free_rows[1]:
        return
    cam = p.camera
    pos, foc = np.asarray(cam.position), np.asarray(cam.focal_point)
    fwd = foc - pos
    dist = float(np.linalg.norm(fwd))
    up = np.asarray(cam.up, float)
    up = up - (up @ fwd) / dist**2 * fwd
    up /= np.linalg.norm(up)
    right = np.cross(fwd / dist, up)
    world_per_px = 2 * dist * np.tan(np.radians(cam.view_angle) / 2) / h
    dx = ((c0 + c1) / 2 - w / 2) * world_per_px  # move the centre of the content ...
    dy = (h / 2 - (r0 + r1) / 2) * world_per_px
    # ... to the centre of the free area (above the centre by (bottom - top) h / 2)
    ty = (bottom - top) * h / 2 * world_per_px / scale
    shift = dx * right + dy * up - ty * up
    cam.position = tuple(pos + shift)
    cam.focal_point = tuple(foc + shift)
    cam.zoom(scale)


def _camera(p, bounds, view: Sequence[float]) -> None:
    x0, x1, y0, y1, z0, z1 = bounds
    c = np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    diag = float(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0])) or 1.0
    v = np.asarray(view, float)
    v /= np.linalg.norm(v)
    p.camera_position = [tuple(c + 2.2 * diag * v), tuple(c), (0.0, 0.0, 1.0)]
    p.camera.view_angle = 30.0
    p.reset_camera(bounds=bounds)


def _bounds(Xs: np.ndarray) -> tuple[float, ...]:
    lo = Xs.reshape(-1, 3).min(0)
    hi = Xs.reshape(-1, 3).max(0)
    return (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])


# ------------------------------------------------------------------------- matplotlib
def _render_mpl(d, where, name, values, cmap, clim, path, window_size, view, title, label=None,
                fixed=None, loads=None):  # fmt: skip
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    default_label, default_cmap, _ = ARRAYS.get(name, (name, "viridis", False))
    label = label or default_label
    cm_ = plt.get_cmap(cmap or default_cmap)
    norm = colors.Normalize(*clim)
    dpi = 100
    fig = plt.figure(figsize=(window_size[0] / dpi, window_size[1] / dpi), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    P = d.points
    face_col: Any = PAPER
    if where == "triangle":
        face_col = [cm_(norm(v)) if np.isfinite(v) else PAPER for v in values]
    elif where == "point":
        with np.errstate(invalid="ignore"):
            tv = values[d.triangles].mean(axis=1)
        face_col = [cm_(norm(v)) if np.isfinite(v) else PAPER for v in tv]
    ax.add_collection3d(
        Poly3DCollection(
            P[d.triangles], facecolors=face_col, edgecolors=face_col, linewidths=0.3, shade=True
        )
    )
    seg = P[d.lines]
    if where == "line":
        lc = [cm_(norm(v)) if np.isfinite(v) else "#8c8c8c" for v in values]
        lw = np.where(np.isfinite(values), 2.5, 0.8)
    else:
        lc, lw = EDGE, 0.8
    ax.add_collection3d(Line3DCollection(seg, colors=lc, linewidths=lw))
    sup, at, vec = _supports_and_loads(P, fixed, loads)
    if len(sup):
        ax.scatter(*sup.T, color="black", s=18, depthshade=False)
    if len(at):
        ax.quiver(*at.T, *vec.T, color="#8e44ad", linewidth=1.5)
    b = np.array(_bounds(P[None])).reshape(3, 2)
    ax.set_box_aspect(np.maximum(b[:, 1] - b[:, 0], 1e-3 * np.ptp(b)))
    for setlim, (lo, hi) in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), b, strict=True):
        setlim(lo, hi if hi > lo else lo + 1e-9)
    v = np.asarray(view, float)
    ax.view_init(
        elev=np.degrees(np.arctan2(v[2], np.hypot(v[0], v[1]))),
        azim=np.degrees(np.arctan2(v[1], v[0])),
    )
    ax.set_axis_off()
    if where != "none":
        fig.colorbar(
            cm.ScalarMappable(norm=norm, cmap=cm_),
            ax=ax,
            orientation="horizontal",
            shrink=0.5,
            pad=0.02,
            label=label,
        )
    if title:
        ax.set_title(title)
    fig.text(0.99, 0.01, extent_text(P), ha="right", va="bottom", fontsize=8, color="#555555")
    fig.savefig(path, dpi=dpi, facecolor="white", bbox_inches="tight")
    plt.close(fig)
    return path


def extent_text(X: np.ndarray) -> str:
    """The scale of a picture in words: the extent of the state along x, y and z (in the
    pattern's length unit), e.g. ``"extent x 12 × y 8.5 × z 3.1"``."""
    dx, dy, dz = np.ptp(np.asarray(X, float).reshape(-1, 3), axis=0)
    return f"extent x {dx:.3g} × y {dy:.3g} × z {dz:.3g}"


def _supports_and_loads(
    X: np.ndarray, fixed: np.ndarray | None, loads: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(supported points (m, 3), loaded points (k, 3), their load vectors scaled so the
    largest is 8 % of the state's size (k, 3))."""
    size = float(np.linalg.norm(np.ptp(X, axis=0))) or 1.0
    sup = np.zeros((0, 3))
    if fixed is not None:
        sup = X[np.asarray(fixed, bool).reshape(-1, 3)[: len(X)].any(axis=1)]
    at, vec = np.zeros((0, 3)), np.zeros((0, 3))
    if loads is not None:
        F = np.asarray(loads, float).reshape(-1, 3)[: len(X)]
        mag = np.linalg.norm(F, axis=1)
        on = mag > 0
        if on.any():
            at, vec = X[on], F[on] * (0.08 * size / mag.max())
    return sup, at, vec


def _add_supports_and_loads(
    p, X: np.ndarray, fixed: np.ndarray | None, loads: np.ndarray | None
) -> None:
    """Black dots at the supported nodes, purple arrows along the loads."""
    sup, at, vec = _supports_and_loads(X, fixed, loads)
    if len(sup):
        p.add_points(sup, color="black", point_size=12, render_points_as_spheres=True)
    if len(at):
        p.add_arrows(at, vec, mag=1.0, color="#8e44ad")


# ------------------------------------------------------------------------------ API
def render_state(
    X: np.ndarray,
    path: str | Path,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    scalars: str | np.ndarray | None = "fold_angle_deg",
    fold_angles_deg: np.ndarray | None = None,
    cmap: str | None = None,
    clim: Sequence[float] | None = None,
    window_size: tuple[int, int] = (1200, 900),
    view: Sequence[float] = (0.9, -1.2, 1.8),
    title: str | None = None,
    label: str | None = None,
    backend: str = "auto",
    fixed: np.ndarray | None = None,
    loads: np.ndarray | None = None,
) -> Path:
    """Render one state to a PNG, coloured by a named array.

    Parameters
    ----------
    X : (n_nodes, 3) float
        Node coordinates.
    path : path
        Output PNG.
    model, pattern : optional
        Mesh and data source (see :func:`barhinge.fields.state_data`); one is required.
    scalars : str or array or None
        A name of :data:`ARRAYS` (``fold_angle_deg`` colours the creases, ``angle_defect`` /
        ``defect_density`` / ``displacement`` the nodes, ``energy_density`` the panels), or
        values per node (n,), per node vector (n, 3) (a mode shape: its magnitude), per
        triangle or per line; None for plain paper.
    cmap, clim : optional
        Matplotlib colormap name and colour range (symmetric about 0 for signed arrays).
    view : (3,) float
        Direction from the centre of the state to the camera.
    title, label : str, optional
        Title of the picture; title of the colour bar (default: the array's name and unit).
    backend : {"auto", "pyvista", "matplotlib"}
    fixed : (n_nodes, 3) bool, optional
        Supports: nodes with a fixed DOF are drawn as black dots.
    loads : (n_nodes, 3) float, optional
        Loads: purple arrows at the loaded nodes, the largest 8 % of the state's size long.

    Every picture states its scale: the extent of the state along x, y and z, in the
    pattern's length unit (lower right).
    """
    path = Path(path)
    d = state_data(
        np.asarray(X, float),
        model=model,
        pattern=pattern if model is None else None,
        fold_angles_deg=fold_angles_deg,
    )
    where, name, values = _pick(d, scalars)
    lim = _clim(name, values, clim)
    if _backend(backend) == "matplotlib":
        return _render_mpl(d, where, name, values, cmap, lim, path, window_size, view, title,
                           label, fixed=fixed, loads=loads)  # fmt: skip
    p = _plotter(window_size)
    try:
        meshes = _polydata(d)
        _assign(meshes, d, where, name, values)
        bar = _add_state(p, meshes, where, name, cmap, lim, line_width=2.0, label=label)
        _add_supports_and_loads(p, d.points, fixed, loads)
        _camera(p, _bounds(d.points[None]), view)
        _fit(p, bottom=0.16 if bar is not None else 0.0, top=0.08 if title else 0.0)
        _scalar_bar(p, bar)
        if title:
            p.add_text(title, position="upper_left", font_size=14, color="black")
        p.add_text(extent_text(d.points), position="lower_right", font_size=9, color="#555555")
        p.screenshot(str(path))
    finally:
        p.close()
    return path


def render_mode(
    X: np.ndarray,
    mode: np.ndarray,
    path: str | Path,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    scale: float | None = None,
    title: str | None = None,
    **kwargs: Any,
) -> Path:
    """Render a mode shape: the state ``X + scale * mode`` coloured by ``|mode|``.

    ``mode`` is (n_nodes, 3) or (3 n_nodes,); ``scale`` defaults to 10 % of the state's size
    divided by the largest nodal amplitude.
    """
    X = np.asarray(X, float)
    U = np.asarray(mode, float).reshape(X.shape)
    amp = float(np.linalg.norm(U, axis=1).max()) or 1.0
    if scale is None:
        scale = 0.1 * float(np.linalg.norm(np.ptp(X, axis=0))) / amp
    return render_state(
        X + scale * U,
        path,
        model=model,
        pattern=pattern,
        scalars=U / amp,
        clim=(0.0, 1.0),
        title=title,
        **kwargs,
    )


def animate(
    fold_path: Any,
    path: str | Path,
    *,
    model: Any | None = None,
    pattern: Any | None = None,
    scalars: str | None = "fold_angle_deg",
    fps: int = 12,
    max_frames: int = 60,
    window_size: tuple[int, int] = (640, 480),
    view: Sequence[float] = (0.9, -1.2, 1.8),
    clim: Sequence[float] | None = None,
    boomerang: bool = True,
    backend: str = "auto",
) -> Path:
    """GIF animation of a fold path with a fixed camera and colour range.

    Parameters
    ----------
    fold_path : FoldPath
    path : path
        Output ``.gif``.
    max_frames : int
        States are subsampled evenly to at most this many frames.
    boomerang : bool
        Play forwards then backwards (a seamless loop).
    """
    from PIL import Image

    path = Path(path)
    n = fold_path.n_states
    idx = np.unique(np.linspace(0, n - 1, min(n, max_frames)).round().astype(int))
    datas = [
        state_data(
            fold_path.X[s],
            model=model,
            pattern=pattern if model is None else None,
            fold_angles_deg=fold_path.fold_angles_deg[s] if model is None else None,
        )
        for s in idx
    ]
    picked = [_pick(d, scalars) for d in datas]
    allv = [v[np.isfinite(v)] for _, _, v in picked if v is not None]
    name = picked[0][1]
    lim = _clim(name, np.concatenate(allv) if allv else None, clim)
    bounds = _bounds(fold_path.X[idx])
    frames = []
    if _backend(backend) == "matplotlib":
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            for k, (d, (where, nm, v)) in enumerate(zip(datas, picked, strict=True)):
                f = _render_mpl(
                    d, where, nm, v, None, lim, Path(tmp) / f"{k}.png", window_size, view, None
                )
                frames.append(Image.open(f).convert("RGB"))
    else:
        # one plotter and one set of actors, updated in place: VTK compiles its shaders
        # (slow with a software renderer) only for the first frame
        p = _plotter(window_size)
        try:
            meshes = _polydata(datas[0])
            for k, (d, (where, nm, v)) in enumerate(zip(datas, picked, strict=True)):
                _assign(meshes, d, where, nm, v)
                if k == 0:
                    bar = _add_state(p, meshes, where, nm, None, lim, line_width=1.5)
                    _camera(p, bounds, view)
                    # fit the first and the last state, then show the colour bar
                    bottom = 0.16 if bar is not None else 0.0
                    _fit(p, bottom=bottom)
                    _assign(meshes, datas[-1], *picked[-1])
                    _fit(p, bottom=bottom, shrink_only=True)
                    _assign(meshes, d, where, nm, v)
                    _scalar_bar(p, bar)
                p.render()
                frames.append(Image.fromarray(p.screenshot(return_img=True)))
        finally:
            p.close()
    if boomerang and len(frames) > 2:
        frames = frames + frames[-2:0:-1]
    pal = [f.convert("P", palette=Image.Palette.ADAPTIVE, colors=255) for f in frames]
    pal[0].save(
        path, save_all=True, append_images=pal[1:], duration=int(1000 / fps), loop=0, optimize=False
    )
    return path
