"""Crease-pattern drawings with matplotlib (flat pattern and a simple 3-D folded view).

Colours: mountain red, valley blue, boundary black, flat / unassigned light grey, cut green.
Only this module (and the other ``barhinge.plot`` modules) import matplotlib, lazily.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from barhinge.pattern.crease import CreasePattern

__all__ = ["COLOURS", "draw_folded", "draw_pattern"]

#: line colour per assignment
COLOURS: dict[str, str] = {
    "M": "#d62728",
    "V": "#1f57c3",
    "B": "#000000",
    "F": "#c8c8c8",
    "U": "#c8c8c8",
    "C": "#2ca02c",
}
_WIDTH = {"M": 1.0, "V": 1.0, "B": 1.3, "F": 0.6, "U": 0.6, "C": 1.0}
_ORDER = ("F", "U", "C", "B", "V", "M")


def _figure(ax: Any, projection: str | None = None) -> tuple[Any, Any]:
    import matplotlib

    if ax is not None:
        return ax.figure, ax
    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "ps", "cairo"):
        try:
            matplotlib.use("Agg", force=False)
        except Exception:  # noqa: BLE001 - keep the user's backend if it cannot switch
            pass
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(111, projection=projection) if projection else fig.add_subplot(111)
    return fig, ax


def _save(fig: Any, path: str | Path | None, dpi: int) -> None:
    if path is None:
        return
    import matplotlib.pyplot as plt

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    plt.close(fig)


def draw_pattern(
    cp: CreasePattern,
    ax: Any = None,
    path: str | Path | None = None,
    *,
    title: str | None = None,
    dpi: int = 110,
) -> Any:
    """Draw the crease pattern in plan (x, y of the vertices), coloured by assignment.

    Parameters
    ----------
    cp : CreasePattern
        Pattern to draw (a folded state is drawn in plan projection).
    ax : matplotlib Axes, optional
        Axes to draw into; a new figure is made when omitted.
    path : str or Path, optional
        Save the figure there (PNG, SVG, PDF by extension) and close it.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib Axes
    """
    from matplotlib.collections import LineCollection

    fig, ax = _figure(ax)
    P = np.asarray(cp.vertices)[:, :2]
    for a in _ORDER:
        sel = np.flatnonzero(cp.assignment == a)
        if len(sel) == 0:
            continue
        segs = P[cp.edges[sel]]
        ax.add_collection(
            LineCollection(segs, colors=COLOURS[a], linewidths=_WIDTH[a], label=a, zorder=2)
        )
    if len(P):
        lo, hi = P.min(0), P.max(0)
        pad = 0.03 * max(float((hi - lo).max()), 1e-12)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if title:
        ax.set_title(title, fontsize=9)
    _save(fig, path, dpi)
    return ax


def draw_folded(
    cp: CreasePattern,
    X: np.ndarray | None = None,
    ax: Any = None,
    path: str | Path | None = None,
    *,
    title: str | None = None,
    elev: float = 30.0,
    azim: float = -60.0,
    dpi: int = 110,
) -> Any:
    """Draw a folded state in 3-D (mplot3d): shaded faces and creases coloured by assignment.

    Parameters
    ----------
    cp : CreasePattern
        Pattern (its faces and assignment are used).
    X : (n, 3) float, optional
        Vertex coordinates to draw; default ``cp.vertices3d``.
    """
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    fig, ax = _figure(ax, projection="3d")
    X = cp.vertices3d if X is None else np.asarray(X, float)
    polys = [X[list(f)] for f in cp.faces]
    N = []
    for P in polys:
        n = np.cross(P, np.roll(P, -1, axis=0)).sum(0)
        N.append(n / max(np.linalg.norm(n), 1e-300))
    light = np.array([0.3, -0.4, 0.87])
    shade = 0.55 + 0.4 * np.abs(np.asarray(N) @ light) if N else np.zeros(0)
    colours = [(0.93 * s, 0.9 * s, 0.8 * s) for s in shade]
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="none", alpha=1.0))
    for a in ("B", "V", "M"):
        sel = np.flatnonzero(cp.assignment == a)
        if len(sel):
            ax.add_collection3d(
                Line3DCollection(X[cp.edges[sel]], colors=COLOURS[a], linewidths=_WIDTH[a] * 0.8)
            )
    lo, hi = X.min(0), X.max(0)
    c, r = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-12)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    if title:
        ax.set_title(title, fontsize=9)
    _save(fig, path, dpi)
    return ax
