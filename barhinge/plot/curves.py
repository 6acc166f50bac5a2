"""Figures of control curves: the curve, the inscribed actuator chain and its fold angles."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from barhinge.actuators.curves import (
    Chain,
    CircularArc,
    ControlCurve,
    Parabola,
    SplineCurve,
    chain_on_curve,
    height_angles_deg,
)

__all__ = ["control_curves_figure", "plot_control_curve"]


def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_control_curve(
    curve: ControlCurve,
    chain: Chain,
    *,
    ax: Any = None,
    title: str | None = None,
    path: str | Path | None = None,
    annotate: bool = True,
    legend: bool = True,
) -> Any:
    """Draw the control curve, the chain points (ends hollow, actuators filled) and Phi_i.

    Parameters
    ----------
    curve : ControlCurve
    chain : Chain
        From :func:`barhinge.actuators.curves.chain_on_curve`.
    ax : matplotlib Axes, optional
        Drawn into; a new figure otherwise.
    path : path, optional
        Save the figure there (PNG, 150 dpi).

    Returns
    -------
    matplotlib Axes
    """
    if ax is None:
        _, ax = _plt().subplots(figsize=(6.0, 3.6), layout="constrained")
    u0, u1 = float(chain.u.min()), float(chain.u.max())
    pad = 0.15 * (u1 - u0)
    C = curve.point(np.linspace(u0 - pad, u1 + pad, 400))
    P = chain.points
    ax.plot(C[:, 0], C[:, 1], color="0.6", lw=1.2, label="control curve C")
    ax.plot(P[:, 0], P[:, 1], color="tab:blue", lw=2.0, label="folded section")
    ax.plot(P[[0, -1], 0], P[[0, -1], 1], "o", mfc="white", mec="k", label="section ends")
    ax.plot(P[1:-1, 0], P[1:-1, 1], "o", color="tab:red", label="actuator points P")
    if annotate:
        for p, a in zip(P[1:-1], chain.angles_deg, strict=True):
            ax.annotate(
                f"{a:.1f}°",
                p,
                textcoords="offset points",
                xytext=(0, -14 if a > 0 else 8),
                ha="center",
                fontsize=7,
            )
    ax.set_aspect("equal")
    ax.set_xlabel("x (section)")
    ax.set_ylabel("z")
    if title:
        ax.set_title(title, fontsize=10, pad=12)
    ax.margins(y=0.25)
    if legend:
        ax.legend(fontsize=7, loc="upper center")
    if path is not None:
        ax.figure.savefig(path, dpi=150)
    return ax


def control_curves_figure(path: str | Path | None = None, d: float = 1.0, n: int = 7) -> Any:
    """The figure of docs/control-curves.md: three curves and the three mappings compared.

    A pleat section with ``n`` actuators at spacing ``d`` and ends one spacing beyond the first
    and last actuator: (a) circle kappa = 0.25, (b) parabola c = 0.3, (c) spline through five
    user points; (d) the fold angles of the parabola by the turning mapping, the height mapping
    (same largest angle) and the synchronised mode (their mean).

    Returns
    -------
    matplotlib Figure
    """
    plt = _plt()
    x = (np.arange(n + 2) - (n + 1) / 2) * d
    user = (np.array([-4.5, -2.0, 0.0, 2.5, 4.5]), np.array([0.0, 1.2, 0.4, -0.6, 0.3]))
    curves = [
        ("(a) circle, kappa = 0.25", CircularArc(0.25)),
        ("(b) parabola z = c x^2 / 2, c = 0.3", Parabola(0.3)),
        ("(c) spline through user points (x)", SplineCurve(*user)),
    ]
    fig, axes = plt.subplots(2, 2, figsize=(10.0, 6.4), layout="constrained")
    for ax, (title, curve) in zip(axes.flat[:3], curves, strict=True):
        plot_control_curve(
            curve, chain_on_curve(curve, x), ax=ax, title=title, legend=ax is axes[0, 0]
        )
    axes.flat[2].plot(*user, "x", color="k", ms=7)
    ax = axes.flat[3]
    turning = chain_on_curve(Parabola(0.3), x).angles_deg
    height = height_angles_deg(Parabola(0.3), x[1:-1], float(np.max(np.abs(turning))))
    sync = np.full(n, float(np.mean(turning)))
    idx = np.arange(n)
    for k, (lab, val) in enumerate(
        [("turning (points on C)", turning), ("height", height), ("synchronised", sync)]
    ):
        ax.bar(idx + (k - 1) * 0.27, val, width=0.27, label=lab)
    ax.set_xlabel("actuator i")
    ax.set_ylabel("fold angle (deg, valley > 0)")
    ax.set_title("(d) parabola c = 0.3: the three mappings", fontsize=10)
    ax.legend(fontsize=7)
    if path is not None:
        fig.savefig(path, dpi=130)
    return fig
