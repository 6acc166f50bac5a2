"""Single bar-and-hinge panels against the continuum reference (:mod:`barhinge.model.continuum`):
the relative energy and force errors that docs/calibration.md tabulates.

It sits above :mod:`barhinge.model.model` (it builds panel models); the continuum reference
sits below (the ``"plate"`` bending calibration of the model uses it).
"""

from __future__ import annotations

import numpy as np

from barhinge.model.continuum import (
    homogeneous_energy,
    membrane_edge_load,
    panel_energy,
    plate_corner_energy,
    strain_modes,
)
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern

__all__ = ["panel_errors", "rectangle_edge_load_error", "subdivided_membrane_errors"]


def panel_errors(
    P: np.ndarray,
    material: Material,
    scheme: str = "N5B8",
    bar_calibration: str = "fit",
    bend_calibration: str = "plate",
    plate_refine: int = 4,
) -> dict[str, float]:
    """Relative energy errors ``U_bar / U_continuum - 1`` of a single flat panel ``P`` (k, 2):
    the three homogeneous membrane modes (corner displacements ``eps x``, other nodes free)
    and, for k >= 4, the corner-warping energy for ``w = (x - xc)(y - yc)`` at the corners
    (Morley reference)."""
    P = np.asarray(P, float)
    k = len(P)
    cp = CreasePattern(P, [[i, (i + 1) % k] for i in range(k)], ["B"] * k, faces=[list(range(k))])
    m = BarHingeModel.from_pattern(
        cp, scheme, material, bar_calibration=bar_calibration, bend_calibration=bend_calibration
    )
    out: dict[str, float] = {}
    for name, eps in strain_modes(material.nu).items():
        pre = np.full((m.n_nodes, 3), np.nan)
        pre[:, 2] = 0.0
        pre[:k, :2] = P @ eps.T
        out[name] = panel_energy(m, pre) / homogeneous_energy(P, material, eps) - 1.0
    if k >= 4:
        c = P.mean(axis=0)
        w = (P[:, 0] - c[0]) * (P[:, 1] - c[1])
        pre = np.full((m.n_nodes, 3), np.nan)
        pre[:, :2] = 0.0
        pre[:k, 2] = w
        out["warp"] = panel_energy(m, pre) / plate_corner_energy(P, material, w, plate_refine) - 1
    return out


def subdivided_membrane_errors(
    P: np.ndarray,
    material: Material,
    m: int,
    scheme: str = "N5B8",
    bar_calibration: str = "fit",
) -> dict[str, float]:
    """Relative energy errors ``U_bar / U_continuum - 1`` of the panel ``P`` (k, 2) cut into
    ``m x m`` cells (:func:`barhinge.pattern.subdivide.subdivided`) under the homogeneous
    membrane modes: the displacements ``eps x`` prescribed on the panel's boundary, every
    inner node free (the membrane patch test of the refined panel)."""
    from barhinge.pattern.subdivide import subdivided

    P = np.asarray(P, float)
    k = len(P)
    cp = CreasePattern(P, [[i, (i + 1) % k] for i in range(k)], ["B"] * k, faces=[list(range(k))])
    cpm, _ = subdivided(cp, m)
    model = BarHingeModel.from_pattern(cpm, scheme, material, bar_calibration=bar_calibration)
    X = np.asarray(model.X0)[:, :2]
    E = np.asarray(cpm.edges)
    on_boundary = np.zeros(model.n_nodes, bool)
    on_boundary[E[np.asarray(cpm.boundary_edges)].ravel()] = True
    out: dict[str, float] = {}
    for name, eps in strain_modes(material.nu).items():
        pre = np.full((model.n_nodes, 3), np.nan)
        pre[:, 2] = 0.0
        pre[on_boundary, :2] = X[on_boundary] @ eps.T
        out[name] = panel_energy(model, pre) / homogeneous_energy(P, material, eps) - 1.0
    return out


def rectangle_edge_load_error(
    W: float,
    H: float,
    material: Material,
    mode: str,
    scheme: str = "N5B8",
    bar_calibration: str = "fit",
    refine: int = 3,
) -> float:
    """Relative error ``F_bar / F_continuum - 1`` of the force of :func:`membrane_edge_load`
    (P2 membrane) for a W x H bar-and-hinge panel with the same supports (corners of the
    clamped edge fixed, corners of the moved edge displaced by (1, 0), other nodes free)."""
    P = np.array([[0, 0], [W, 0], [W, H], [0, H]], float)
    cp = CreasePattern(P, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    m = BarHingeModel.from_pattern(cp, scheme, material, bar_calibration=bar_calibration)
    fixed, moved = ([0, 3], [1, 2]) if mode == "stretch" else ([0, 1], [2, 3])
    pre = np.full((m.n_nodes, 3), np.nan)
    pre[:, 2] = 0.0
    pre[fixed, :2] = 0.0
    pre[moved, 0] = 1.0
    pre[moved, 1] = 0.0
    F_bar = 2.0 * panel_energy(m, pre)
    return F_bar / membrane_edge_load(W, H, material, mode, order=2, refine=refine) - 1.0
