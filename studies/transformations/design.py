"""Design from a target global form: the actuator fold angles that bring a sheet to target
principal curvatures (the inverse of the study's forward map), by scipy.optimize.

Control: the actuators ``bh.dof`` suggests (as many as the DOF of the folded state, so every
set of their angles is met exactly by a rigid fold), their fold angles the design variables,
kept on the M/V branch (magnitudes 5-60 deg with the assignment's sign). Forward map: the
energy-minimising rigid limit (``transform.rigid_limit``) and one quadratic fitted through the
facet centroids, ``(k1 L, k2 L)`` with ``k1 >= k2``. ``scipy.optimize.least_squares``
(trust-region reflective) with forward-difference derivatives of the forward map (the
rigid-limit solver does not expose parameter sensitivities yet).
"""

from __future__ import annotations

import numpy as np
import transform as T


def principal_curvatures(cp, edges: np.ndarray, angles_deg: np.ndarray, steps: int) -> np.ndarray:
    """(k1 L, k2 L), k1 >= k2, of the rigid-limit form with ``edges`` at ``angles_deg``."""
    import barhinge as bh

    path = T.rigid_limit(cp, bh.Actuators(edges=edges, targets_deg=angles_deg), steps)
    g = bh.gaussian_curvature(path, pattern=cp).global_fit
    L = float(np.ptp(np.asarray(cp.vertices, float)[:, 0]))
    return np.sort([float(g.k1) * L, float(g.k2) * L])[::-1]


def _show(v: float) -> str:
    return "0" if abs(v) < 1e-9 else f"{v:.2g}"


def design(
    pattern: str,
    target_k1L: float,
    target_k2L: float,
    quick: bool = True,
    steps: int = 4,
    max_nfev: int = 30,
) -> dict:
    """Fold angles of the ``bh.dof`` actuators that reach ``(k1 L, k2 L)``; reached when both
    are within 5 % of ``max(|k1 L|, |k2 L|)`` of the target."""
    from scipy.optimize import least_squares

    import barhinge as bh

    cp = T.make_pattern(pattern, quick)
    A = np.asarray(bh.dof(cp).mechanism.actuators, dtype=np.int64)
    s = np.where(cp.assignment[A] == "M", -1.0, 1.0)
    t = np.sort([float(target_k1L), float(target_k2L)])[::-1]
    scale = max(float(np.max(np.abs(t))), 1e-3)
    n_eval = [0]

    def residual(m: np.ndarray) -> np.ndarray:
        n_eval[0] += 1
        return (principal_curvatures(cp, A, s * m, steps) - t) / scale

    sol = least_squares(
        residual, np.full(len(A), 30.0), bounds=(5.0, 60.0), diff_step=1e-4, max_nfev=max_nfev
    )
    k = principal_curvatures(cp, A, s * sol.x, steps)
    err = float(np.max(np.abs(k - t)) / scale)
    if err <= 0.05:
        reason = None
    elif float(np.max(np.abs(sol.jac))) < 1e-8:
        reason = (
            "the global form does not respond to the actuators: every rigid fold of this "
            f"pattern has (k1 L, k2 L) = ({_show(k[0])}, {_show(k[1])})"
        )
    else:
        reason = "a local minimum of the misfit: the target lies outside the forms reached"
    return {
        "model_label": "rigid limit (energy-minimising)",
        "n_actuators": len(A),
        "target": t,
        "achieved": k,
        "relative_error": err,
        "reached": bool(err <= 0.05),
        "reason": reason,
        "angles_deg": np.round(s * sol.x, 6),
        "evaluations": n_eval[0],
        "optimizer": sol.message,
    }
