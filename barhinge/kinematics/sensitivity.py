"""Exact sensitivities of the energy-minimising rigid fold to its actuator angles.

A converged state of :func:`~barhinge.kinematics.path.rigid_fold` satisfies the KKT
conditions of the fold-spring energy on the loop-closure manifold (``F`` free creases, ``A``
actuators held at their targets ``t``)::

    W_F (rho_F - rho0_F) + J_F^T lam = 0,      r(rho) = 0,      rho_A = t.

Differentiating them (implicit-function theorem) gives the change of every fold angle per
change of the actuator targets from one linear solve with the exact Lagrangian Hessian
``H = W + sum lam_i d2 r_i`` (:meth:`RigidConstraints.multiplier_hessian`)::

    [H_FF  J_F^T] [drho_F]     [H_FA]
    [J_F   0    ] [dlam  ] = - [J_A ] dt.

Where incompatible targets were met in least squares (``path.meta["least_squares"]``) or the
actuators are compliant (``path.meta["compliant_actuators"]``) every crease is free and the
actuators are springs of stiffness ``w_s`` to their targets: the right side is
``[w_s E_A; 0] dt``. Redundant loop equations make ``lam`` non-unique; ``drho`` is
unique where the reduced Hessian is non-singular (a strict minimum).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from barhinge.errors import ConfigError
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.pattern.crease import CreasePattern
from barhinge.results import FoldPath

__all__ = ["RigidSensitivity", "rigid_sensitivity"]


@dataclasses.dataclass(frozen=True)
class RigidSensitivity:
    """Derivatives of a rigid fold's final state with respect to its actuator targets.

    Attributes
    ----------
    drho_dt : (n_edges, n_act) float
        Fold angle of each pattern edge per actuator target (degree per degree; 0 for edges
        that cannot fold).
    dX_dt : (n_vertices, 3, n_act) float
        Vertex coordinates per actuator target (length per radian).
    condition : float or None
        With ``condition=True``: condition number of the reduced Hessian on the tangent
        space (large: the minimum is nearly degenerate and the derivatives ill-determined).
    """

    drho_dt: np.ndarray
    dX_dt: np.ndarray
    condition: float | None = None


def rigid_sensitivity(
    cp: CreasePattern,
    path: FoldPath,
    fold_stiffness: np.ndarray | float | None = None,
    *,
    triangulated: bool = False,
    diagonal_stiffness: float | None = None,
    condition: bool = False,
) -> RigidSensitivity:
    """Exact derivatives of the last state of ``path`` (a converged ``rigid_fold`` of ``cp``
    with the same ``fold_stiffness``) with respect to its final actuator targets.

    The fold angles come from the implicit-function theorem on the KKT system (one dense
    solve); the coordinates from differentiating the face-tree rebuild along each fold-angle
    derivative (central difference of the explicit rotation map, step 1e-6 rad, error
    ~1e-12; no re-solve). ``condition`` also returns the reduced Hessian's condition number.
    """
    from barhinge.kinematics.path import _spring_weights

    if path.kind != "rigid" or not path.converged:
        raise ConfigError("rigid_sensitivity needs a converged rigid_fold path")
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    if rc.triangulated != bool(path.meta.get("triangulated", False)):
        raise ConfigError("rigid_sensitivity: triangulated differs from the path's")
    src = rc.var_source_edge
    rho = np.zeros(rc.n_var)
    ok_var = src >= 0
    rho[ok_var] = np.radians(path.fold_angles_deg[-1][src[ok_var]])
    av = rc.var_of_source_edge[np.asarray(path.actuator_edges, dtype=np.int64)]
    t = np.radians(np.asarray(path.actuator_targets_deg[-1], dtype=float))
    W = _spring_weights(rc, fold_stiffness, diagonal_stiffness)
    compliant = bool(path.meta.get("compliant_actuators", False))
    soft = bool(path.meta.get("least_squares", False)) or compliant
    n, na = rc.n_var, len(av)
    c = rc.rho0.copy()
    w = W.copy()
    if soft:
        ws: float | np.ndarray = (
            np.asarray(path.meta["actuator_stiffness"], dtype=float)
            if compliant
            else 1e6 * float(W.max(initial=1.0))
        )
        c[av] = (w[av] * c[av] + ws * t) / (w[av] + ws)
        w[av] = w[av] + ws
        free = np.ones(n, bool)
    else:
        free = np.ones(n, bool)
        free[av] = False
    fi = np.flatnonzero(free)
    J = rc.jacobian(rho).toarray()
    g = w * (rho - c)
    lam = np.linalg.lstsq(J[:, fi].T, -g[fi], rcond=None)[0]
    H = np.diag(w) + rc.multiplier_hessian(rho, lam).toarray()
    m = J.shape[0]
    K = np.block([[H[np.ix_(fi, fi)], J[:, fi].T], [J[:, fi], np.zeros((m, m))]])
    if soft:
        rhs = np.zeros((len(fi) + m, na))
        rhs[av, np.arange(na)] = ws  # all variables free: row index = variable index
    else:
        rhs = -np.vstack([H[np.ix_(fi, av)], J[:, av]])
    sol = np.linalg.lstsq(K, rhs, rcond=None)[0]
    drho = np.zeros((n, na))
    drho[fi] = sol[: len(fi)]
    if not soft:
        drho[av, np.arange(na)] = 1.0
    cond = None
    if condition:  # of the reduced Hessian on the tangent space of the free creases
        import scipy.linalg as sla

        Z = sla.null_space(J[:, fi], rcond=1e-9)
        ev = np.linalg.eigvalsh(Z.T @ H[np.ix_(fi, fi)] @ Z) if Z.shape[1] else np.ones(1)
        cond = float(np.abs(ev).max() / max(np.abs(ev).min(), 1e-300))
    h = 1e-6
    dX = np.stack(
        [
            (rc.coordinates(rho + h * drho[:, j]) - rc.coordinates(rho - h * drho[:, j])) / (2 * h)
            for j in range(na)
        ],
        axis=-1,
    )[: cp.n_vertices]
    out = np.zeros((cp.n_edges, na))
    out[src[ok_var]] = drho[ok_var]
    return RigidSensitivity(drho_dt=out, dX_dt=dX, condition=cond)
