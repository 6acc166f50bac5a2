"""Local-DOF picture (matplotlib): vertices coloured by local or region DOF, actuators marked.

Drawn on the flat (x, y) layout of the pattern; creases grey, boundary black, suggested
actuators thick orange.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["draw_dof"]


#: label the actuators with their edge ids up to this many
MAX_LABELS = 40


def draw_dof(
    cp: Any,
    report: Any,
    path: str | Path | None = None,
    *,
    which: str = "region",
    ax: Any = None,
    title: str | None = None,
) -> Any:
    """Draw ``cp`` with its vertices coloured by local DOF from a ``DofReport``.

    Parameters
    ----------
    cp : CreasePattern
    report : DofReport
        From :func:`barhinge.kinematics.dof.dof`; its ``mechanism`` (the folded-state
        report for a flat pattern) is drawn.
    path : str or Path, optional
        Write a PNG there (and close the figure).
    which : "region" or "local"
        Colour by the one-ring region DOF or by the single-vertex DOF.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib Figure
    """
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    if which not in ("region", "local"):
        from barhinge.errors import ConfigError

        raise ConfigError(f"which = {which!r}; expected 'region' or 'local'")
    rep = report.mechanism
    V = np.asarray(cp.vertices)[:, :2]
    E = np.asarray(cp.edges)
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 6))
    else:
        fig = ax.figure
    bd = np.zeros(len(E), bool)
    bd[cp.boundary_edges] = True
    ax.add_collection(LineCollection(V[E[~bd]], colors="0.7", linewidths=0.6))
    ax.add_collection(LineCollection(V[E[bd]], colors="k", linewidths=1.0))
    acts = np.asarray(rep.actuators, dtype=np.int64)
    if len(acts):
        ax.add_collection(
            LineCollection(V[E[acts]], colors="tab:orange", linewidths=3.0, label="actuators")
        )
        if len(acts) <= MAX_LABELS:  # the edge ids the CLI prints, beside their creases
            mid = V[E[acts]].mean(axis=1)
            for e, (x, y) in zip(acts, mid, strict=True):
                ax.annotate(str(int(e)), (x, y), fontsize=7, color="tab:orange", zorder=4,
                            xytext=(2, 2), textcoords="offset points")  # fmt: skip
    val = np.asarray(rep.region if which == "region" else rep.local)
    ok = val >= 0
    if ok.any():
        vmax = max(int(val[ok].max()), 1)
        cmap = plt.get_cmap("viridis", vmax + 1)
        sc = ax.scatter(
            V[ok, 0],
            V[ok, 1],
            c=val[ok],
            cmap=cmap,
            vmin=-0.5,
            vmax=vmax + 0.5,
            s=max(4.0, 2000.0 / max(ok.sum(), 1)),
            zorder=3,
        )
        cb = fig.colorbar(sc, ax=ax, ticks=range(vmax + 1))
        cb.set_label(f"{which} DOF")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_axis_off()
    state = "folded state near flat" if report.flat and report.folded is not None else "state"
    ax.set_title(
        title
        or f"global DOF {rep.global_dof} (count {rep.counted_dof}, redundant {rep.redundant}), "
        f"{len(acts)} actuator{'' if len(acts) == 1 else 's'}; {state}",
        fontsize=9,
    )
    if path is not None:
        fig.savefig(path, dpi=150, bbox_inches="tight")
        plt.close(fig)
    return fig
