"""Matplotlib charts of fold paths: actuator angles, energy split, actuator moments,
force-displacement, Poisson's ratio against fold.

Every function draws on ``ax`` (a new figure when None), saves to ``path`` when given, and
returns the axes. The Agg backend is used, so everything works headless.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "control_axis",
    "plot_actuator_angles",
    "plot_actuator_moments",
    "plot_energy",
    "plot_fold_angles",
    "plot_force_displacement",
    "plot_load_deflection",
    "plot_poisson",
    "summary_figure",
]

#: more actuators than this: no per-actuator legend
MAX_LEGEND = 4
COLORS = ("#1f5fa6", "#c0392b", "#2e8b57", "#8e44ad", "#d68910", "#566573")


def control_axis(fold_path: Any) -> tuple[np.ndarray, str]:
    """(n_states,) x values and label of the charts: what drives the path.

    The actuators' common fold-angle magnitude when actuators drive the path alike (else
    the first actuator's fold angle); the load factor under load, displacement or arc-length
    control; else the step.
    """
    steps = np.arange(fold_path.n_states, dtype=float)
    control = fold_path.meta.get("control")
    act = np.asarray(fold_path.actuator_edges)
    if len(act) and control in (None, "fold_angle"):
        A = np.asarray(fold_path.fold_angles_deg[:, act], float)
        if np.ptp(A[:, 0]) > 0:
            mag = np.abs(A)
            if np.allclose(mag, mag[:, :1], rtol=1e-6, atol=1e-6):
                return mag[:, 0], ("actuators'" if len(act) > 1 else "actuator") + (
                    " |fold angle| (deg)"
                )
            return A[:, 0], f"fold angle of actuator {act[0]} (deg)"
    lf = np.asarray(fold_path.load_factor, float)
    if control in ("load", "arc_length", "displacement") and np.ptp(lf) > 0:
        return lf, "load factor" if control != "displacement" else "displacement factor"
    return steps, "step"


def _actuator_label(fold_path: Any, k: int) -> str | None:
    """Legend label of the k-th actuator's line: one per actuator up to MAX_LEGEND, else one
    label for them all."""
    act = fold_path.actuator_edges
    if len(act) <= MAX_LEGEND:
        return f"crease {act[k]}"
    return f"{len(act)} actuators (creases {min(act)}-{max(act)})" if k == 0 else None


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _axes(ax, size=(6.0, 4.0)):
    if ax is not None:
        return ax
    fig, ax = _plt().subplots(figsize=size, layout="constrained")
    return ax


def _finish(ax, path: str | Path | None, title: str | None = None):
    ax.grid(True, color="#dddddd", linewidth=0.6)
    ax.spines[["top", "right"]].set_visible(False)
    if title:
        ax.set_title(title)
    if path is not None:
        ax.figure.savefig(path, dpi=150, facecolor="white")
        _plt().close(ax.figure)
    return ax


def plot_actuator_angles(fold_path: Any, ax=None, path: str | Path | None = None):
    """Measured fold angle (solid) and prescribed target (dashed) of every actuator vs step."""
    ax = _axes(ax)
    steps = np.arange(fold_path.n_states)
    for a, e in enumerate(fold_path.actuator_edges):
        c = COLORS[a % len(COLORS)]
        ax.plot(steps, fold_path.fold_angles_deg[:, e], color=c, lw=2,
                label=_actuator_label(fold_path, a))  # fmt: skip
        tgt = fold_path.actuator_targets_deg[:, a]
        if np.isfinite(tgt).any():
            ax.plot(steps, tgt, color=c, lw=1, ls="--")
    ax.set_xlabel("step")
    ax.set_ylabel("fold angle (deg, valley > 0)")
    if len(fold_path.actuator_edges):
        ax.legend(
            frameon=False,
            fontsize="small",
            title="solid: measured, dashed: target",
            title_fontsize="small",
        )
    return _finish(ax, path, "Actuator fold angles")


def plot_fold_angles(fold_path: Any, ax=None, path: str | Path | None = None):
    """Fold angle of every crease against the control (:func:`control_axis`); valleys blue,
    mountains red at the last state, actuators thick black."""
    ax = _axes(ax)
    steps, xlabel = control_axis(fold_path)
    A = np.asarray(fold_path.fold_angles_deg, float)
    moving = np.flatnonzero(np.abs(A).max(0) > 0)
    for e in moving:
        c = "#1f5fa6" if A[-1, e] > 0 else "#c0392b"
        ax.plot(steps, A[:, e], color=c, lw=0.7, alpha=0.5)
    for k, e in enumerate(fold_path.actuator_edges):
        n_act = len(fold_path.actuator_edges)
        label = (
            f"actuator {e}" if n_act <= MAX_LEGEND else (f"{n_act} actuators" if k == 0 else None)
        )
        ax.plot(steps, A[:, e], color="black", lw=2.0, label=label)
    ax.axhline(0, color="black", lw=0.6)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("fold angle (deg; valleys blue, mountains red)")
    if len(fold_path.actuator_edges):
        ax.legend(frameon=False, fontsize="small")
    return _finish(ax, path, f"Fold angles of {len(moving)} creases")


def plot_energy(fold_path: Any, ax=None, path: str | Path | None = None):
    """Stacked energy split (bars, panel bending, folds) against the control
    (:func:`control_axis`)."""
    ax = _axes(ax)
    steps, xlabel = control_axis(fold_path)
    parts = [
        ("folds", fold_path.energy_fold, "#1f5fa6"),
        ("panel bending", fold_path.energy_bend, "#2e8b57"),
        ("bars (stretching)", fold_path.energy_bars, "#c0392b"),
    ]
    ys = [np.nan_to_num(np.asarray(v, float)) for _, v, _ in parts]
    ax.stackplot(steps, *ys, labels=[p[0] for p in parts], colors=[p[2] for p in parts], alpha=0.85)
    ax.plot(steps, np.sum(ys, axis=0), color="black", lw=1.2, label="total")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("stored energy")
    ax.legend(frameon=False, fontsize="small", loc="upper left")
    if np.ptp(steps) > 0:
        ax.set_xlim(steps.min(), steps.max())
    return _finish(ax, path, "Energy split")


def plot_actuator_moments(fold_path: Any, ax=None, path: str | Path | None = None):
    """Actuator moment (Lagrange multiplier) against the actuator's fold angle."""
    ax = _axes(ax)
    for a, e in enumerate(fold_path.actuator_edges):
        ax.plot(
            fold_path.fold_angles_deg[:, e],
            fold_path.actuator_moments[:, a],
            marker="o",
            ms=3,
            lw=1.6,
            color=COLORS[a % len(COLORS)],
            label=_actuator_label(fold_path, a),
        )
    ax.axhline(0, color="black", lw=0.8)
    ax.set_xlabel("actuator fold angle (deg)")
    ax.set_ylabel("actuator moment (force x length)")
    if len(fold_path.actuator_edges):
        ax.legend(frameon=False, fontsize="small")
    return _finish(ax, path, "Actuator moments")


def plot_force_displacement(
    displacement: Sequence[float],
    force: Sequence[float],
    ax=None,
    path: str | Path | None = None,
    *,
    label: str | None = None,
    xlabel: str = "displacement",
    ylabel: str = "force",
    reference: tuple[Sequence[float], Sequence[float], str] | None = None,
):
    """Force against displacement; ``reference = (x, y, label)`` adds a dashed curve."""
    ax = _axes(ax)
    ax.plot(displacement, force, marker="o", ms=3, lw=1.8, color=COLORS[0], label=label)
    if reference is not None:
        ax.plot(reference[0], reference[1], ls="--", color="black", lw=1.2, label=reference[2])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if label or reference:
        ax.legend(frameon=False, fontsize="small")
    return _finish(ax, path, "Force-displacement")


def plot_poisson(
    fold_deg: Sequence[float],
    nu: Sequence[float],
    ax=None,
    path: str | Path | None = None,
    *,
    label: str = "measured",
    reference: tuple[Sequence[float], Sequence[float], str] | None = None,
    xlabel: str = "facet angle theta (deg)",
):
    """Poisson's ratio against a fold parameter; ``reference = (x, nu, label)`` dashed."""
    ax = _axes(ax)
    if reference is not None:
        ax.plot(reference[0], reference[1], ls="--", color="black", lw=1.2, label=reference[2])
    ax.plot(fold_deg, nu, marker="o", ms=4, lw=0, color=COLORS[1], label=label)
    ax.axhline(0, color="black", lw=0.6)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("Poisson's ratio")
    ax.legend(frameon=False, fontsize="small")
    return _finish(ax, path, "Poisson's ratio")


def max_displacement(fold_path: Any) -> tuple[np.ndarray, int]:
    """(n_states,) largest nodal displacement from state 0 (length) in every state, and the
    node where the last state's is largest."""
    X = np.asarray(fold_path.X, float)
    u = np.linalg.norm(X - X[0], axis=2)
    return u.max(axis=1), int(np.argmax(u[-1]))


def plot_load_deflection(fold_path: Any, ax=None, path: str | Path | None = None):
    """Load factor against the largest nodal displacement (from state 0) of each state: the
    load-deflection curve of a load- or arc-length-controlled path (limit points show as
    turning points)."""
    ax = _axes(ax)
    u, node = max_displacement(fold_path)
    lam = np.asarray(fold_path.load_factor, float)
    ax.plot(u, lam, "-o", ms=3, color=COLORS[0], label=f"max |u| (node {node} at the end)")
    ax.set_xlabel("largest displacement |u| (length)")
    ax.set_ylabel("load factor")
    ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax.legend(frameon=False, fontsize="small")
    return _finish(ax, path, "Load-deflection")


def summary_figure(fold_path: Any, path: str | Path | None = None):
    """Actuator angles (when actuators drive the path) and fold angles of all creases, the
    load-deflection curve under load or arc-length control, then the energy split and
    actuator moments where the path has them (not for rigid paths). Returns the figure."""
    plt = _plt()
    panels = [plot_fold_angles]
    if len(np.asarray(fold_path.actuator_edges)):
        panels.insert(0, plot_actuator_angles)
    if fold_path.meta.get("control") in ("load", "arc_length"):
        panels.insert(0, plot_load_deflection)
    energy = np.column_stack([fold_path.energy_bars, fold_path.energy_bend, fold_path.energy_fold])
    if np.isfinite(energy).any():
        panels.append(plot_energy)
    moments = np.asarray(fold_path.actuator_moments, float)
    if moments.size and np.isfinite(moments).any():
        panels.append(plot_actuator_moments)
    shape = (2, 2) if len(panels) == 4 else (1, len(panels))
    size = (11.0, 8.0) if len(panels) == 4 else (5.0 * len(panels), 4.2)
    fig, axs = plt.subplots(*shape, figsize=size, layout="constrained")
    for draw, ax in zip(panels, np.ravel(axs), strict=True):
        draw(fold_path, ax)
    if path is not None:
        fig.savefig(path, dpi=130, facecolor="white")
        plt.close(fig)
    return fig
