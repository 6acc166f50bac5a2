"""Design from a target global form: the actuator fold angles that bring a sheet to target
principal curvatures, or to the form of a target surface (the inverse of the study's forward
map), by scipy.optimize.

Control: the actuators ``bh.dof`` suggests (as many as the DOF of the folded state, so every
set of their angles is met exactly by a rigid fold), their fold angles the design variables,
kept on the M/V branch (magnitudes 5-60 deg with the assignment's sign). Forward map: the
energy-minimising rigid limit (``transform.rigid_limit``) and one quadratic fitted through the
facet centroids, ``(k1 L, k2 L)`` with ``k1 >= k2``. A target surface ``z = f(x, y)`` is
reduced to the same descriptor: the quadratic fitted through its points above the flat
sheet's facet centroids (the form up to a rigid motion).

``scipy.optimize.least_squares`` (trust-region reflective) with the exact derivatives of the
rigid limit (``bh.rigid_sensitivity``: implicit-function theorem on its KKT system, then the
fit differentiated along each coordinate derivative) or, for comparison, forward differences
(``jac="fd"``: one more rigid fold per actuator and iteration).

``control="surface"`` designs the control instead of the actuator angles: three variables,
the base fold angle ``beta`` (deg) and the two curvatures ``(kx L, ky L)`` of a control
surface (``transform._targets`` with a parabola surface; the actuators are the creases of the
two middle section lines, driven to ``s_i beta + Phi_i(kx, ky)``). The actuators are
compliant (``transform.COMPLIANT_K``), so every control has one energy-minimising rigid
form, incompatible targets included. Derivatives by the chain rule: the exact sensitivities
of the rigid limit to the actuator targets times the derivatives of the targets to the
control (``s_i`` for beta; central differences of the explicit turning-angle map for the
curvatures, no rigid fold).

A trial the rigid limit cannot fold (a crease locked at +-180 deg, a fold that falls back to
the flat state) gets the residual ``TRIAL_PENALTY``: the trust region rejects the step and the
search goes on. The result lists those trials (``failed_trials``), and the reason of a design
that misses its target names them. A start that cannot be folded fails the run.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import transform as T

from barhinge.errors import BarhingeError

#: target surfaces ``z = f(x, y; kx, ky)`` (x, y from the sheet's centre; kx, ky 1/length)
SURFACES: dict[str, Callable[..., np.ndarray]] = {
    "paraboloid": lambda x, y, kx, ky: 0.5 * (kx * x * x + ky * y * y),
    # spherical cap of curvature kx (ky unused): not a quadratic, fitted like the sheet
    "cap": lambda x, y, kx, ky: np.sign(kx) * (1 / abs(kx) - np.sqrt(1 / kx**2 - x * x - y * y)),
}

#: reached: both principal curvatures within this fraction of max(|k1 L|, |k2 L|) of target
TOL = 0.05

#: scaled residual of a trial the rigid limit cannot fold (1 is a 100 % misfit): the
#: trust region rejects the step and shrinks, and the search goes on from the last point
TRIAL_PENALTY = 1e3


def _sheet(cp) -> tuple[np.ndarray, float]:
    V = np.asarray(cp.vertices, float)
    return V, float(np.ptp(V[:, 0]))


def _kL(cp, X: np.ndarray, L: float) -> np.ndarray:
    from barhinge.analysis.curvature import fit_quadratic, reference_points

    g = fit_quadratic(reference_points(X, cp))
    return np.array([g.k1 * L, g.k2 * L])


def surface_target(cp, surface: str, kx_L: float, ky_L: float) -> np.ndarray:
    """(k1 L, k2 L) of the quadratic fitted through the target surface ``surface`` above the
    flat sheet's facet centroids (``kx = kx_L / L``, ``ky = ky_L / L``)."""
    from barhinge.analysis.curvature import fit_quadratic, reference_points

    V, L = _sheet(cp)
    P = reference_points(np.column_stack([V[:, :2], np.zeros(len(V))]), cp)
    x, y = P[:, 0] - P[:, 0].mean(), P[:, 1] - P[:, 1].mean()
    z = SURFACES[surface](x, y, kx_L / L, ky_L / L)
    g = fit_quadratic(np.column_stack([x, y, z]))
    return np.array([g.k1 * L, g.k2 * L])


def forward(cp, acts, steps: int, jac: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """(k1 L, k2 L) of the rigid-limit form under the actuators ``acts`` and, with ``jac``,
    its exact derivative (2, n_act) per degree of each actuator target."""
    import barhinge as bh

    edges = np.asarray(acts.edges)
    _, L = _sheet(cp)
    path = T.rigid_limit(cp, acts, steps)
    X = path.X[-1][: cp.n_vertices]
    k = _kL(cp, X, L)
    if not jac:
        return k, None
    sens = bh.rigid_sensitivity(cp, path, T.rigid_weights(cp))
    # the fit is an explicit function of X: central differences along each exact dX/dt
    h = 1e-6 * max(float(np.max(np.abs(sens.dX_dt))), 1e-12) ** -1 * L
    dk = np.stack(
        [
            (_kL(cp, X + h * sens.dX_dt[..., j], L) - _kL(cp, X - h * sens.dX_dt[..., j], L))
            / (2 * h)
            for j in range(len(edges))
        ],
        axis=1,
    )
    return k, dk * (np.pi / 180.0)


def forward_control(
    cp, control: np.ndarray, steps: int, jac: bool
) -> tuple[np.ndarray, np.ndarray | None]:
    """(k1 L, k2 L) of the rigid-limit form under the control ``(beta deg, kx L, ky L)``
    (compliant actuators on a parabola control surface) and, with ``jac``, its derivative
    (2, 3) by the chain rule."""
    beta, kx, ky = (float(v) for v in control)
    acts, _, _ = T._targets(cp, 1, "parabola", kx, ky, base_deg=beta, actuator_k=T.COMPLIANT_K)
    k, dk_dt = forward(cp, acts, steps, jac)
    if not jac:
        return k, None
    assert dk_dt is not None
    A = np.asarray(acts.edges)
    dt = np.zeros((len(A), 3))
    dt[:, 0] = np.where(cp.assignment[A] == "M", -1.0, 1.0)  # d target / d beta
    h = 1e-6
    for j, (dx, dy) in ((1, (h, 0.0)), (2, (0.0, h))):
        p, _, _ = T._targets(cp, 1, "parabola", kx + dx, ky + dy, base_deg=beta)
        m, _, _ = T._targets(cp, 1, "parabola", kx - dx, ky - dy, base_deg=beta)
        if not np.array_equal(p.edges, A) or not np.array_equal(m.edges, A):
            raise RuntimeError("the control surface's actuators changed under a curvature step")
        dt[:, j] = (np.asarray(p.targets_deg) - np.asarray(m.targets_deg)) / (2 * h)
    return k, dk_dt @ dt


def _show(v: float) -> str:
    return "0" if abs(v) < 1e-9 else f"{v:.2g}"


def design(
    pattern: str,
    target_k1L: float | None = None,
    target_k2L: float | None = None,
    surface: str | None = None,
    kx_L: float | None = None,
    ky_L: float | None = None,
    jac: str = "exact",
    quick: bool = True,
    steps: int = 4,
    max_nfev: int | None = None,
    control: str = "actuators",
) -> dict:
    """Fold angles of the ``bh.dof`` actuators (``control="actuators"``), or the base fold and
    control-surface curvatures (``control="surface"``, see the module docstring), that reach
    target principal curvatures ``(k1 L, k2 L)``, or those of the target ``surface`` (a name
    of :data:`SURFACES` with ``kx_L``, ``ky_L``); reached when both are within 5 % of
    ``max(|k1 L|, |k2 L|)``. ``jac``: ``"exact"`` (``bh.rigid_sensitivity``) or ``"fd"``
    (forward differences). ``max_nfev``: rigid-limit evaluations allowed (default 40 for
    the actuator angles, 100 for the three control variables, whose misfit is flatter)."""
    from scipy.optimize import least_squares

    import barhinge as bh

    if jac not in ("exact", "fd"):
        raise ValueError(f"jac must be 'exact' or 'fd', got {jac!r}")
    if control not in ("actuators", "surface"):
        raise ValueError(f"control must be 'actuators' or 'surface', got {control!r}")
    cp = T.make_pattern(pattern, quick)
    if control == "surface":
        # variables: beta (deg), kx L, ky L; the map is the control's, the sign is in it
        A = T._targets(cp, 1, "parabola", 0.0, 0.0)[0].edges
        s = np.ones(3)
        x0, bounds = np.array([30.0, 0.0, 0.0]), ([5.0, -3.0, -3.0], [60.0, 3.0, 3.0])

        def fwd(m: np.ndarray, want: bool):
            return forward_control(cp, m, steps, want)
    else:
        A = np.asarray(bh.dof(cp).mechanism.actuators, dtype=np.int64)
        s = np.where(cp.assignment[A] == "M", -1.0, 1.0)
        x0, bounds = np.full(len(A), 30.0), (5.0, 60.0)

        def fwd(m: np.ndarray, want: bool):
            return forward(cp, bh.Actuators(edges=A, targets_deg=s * m), steps, want)

    if surface is not None:
        t = surface_target(cp, surface, float(kx_L), float(ky_L))
    else:
        t = np.sort([float(target_k1L), float(target_k2L)])[::-1]
    scale = max(float(np.max(np.abs(t))), 1e-3)
    n_eval = [0]
    seen_K: list[float] = []
    cache: dict = {}
    failed: list[str] = []  # trials the rigid limit cannot fold, with the reason

    def evaluate(m: np.ndarray, want_jac: bool):
        key = m.tobytes()
        if key not in cache or (want_jac and cache[key][1] is None and cache[key][0] is not None):
            n_eval[0] += 1
            cache.clear()
            try:
                cache[key] = fwd(m, want_jac)
            except BarhingeError as exc:
                if n_eval[0] == 1:
                    raise  # the start itself: nothing to search from
                at = f" at {np.round(m, 3).tolist()}" if len(m) <= 3 else ""
                failed.append(f"{at}: {str(exc).splitlines()[0]}")
                cache[key] = (None, None)
                return cache[key]
            k = cache[key][0]
            seen_K.append(float(k[0] * k[1]))
        return cache[key]

    def residual(m: np.ndarray) -> np.ndarray:
        k = evaluate(m, jac == "exact")[0]
        return np.full(2, TRIAL_PENALTY) if k is None else (k - t) / scale

    def jacobian(m: np.ndarray) -> np.ndarray:
        return evaluate(m, True)[1] * s / scale

    t0 = time.perf_counter()
    sol = least_squares(
        residual,
        x0,
        jac=jacobian if jac == "exact" else "2-point",
        bounds=bounds,
        diff_step=1e-4,
        max_nfev=max_nfev or (40 if control == "actuators" else 100),
        xtol=1e-10,
        ftol=1e-10,
        gtol=1e-10,
    )
    seconds = time.perf_counter() - t0
    k = evaluate(sol.x, False)[0]
    err = float(np.max(np.abs(k - t)) / scale)
    reached = err <= TOL
    if reached:
        reason = None
    elif float(np.max(np.abs(sol.jac))) < 1e-8:
        reason = (
            "the global form does not respond to the actuators: every rigid fold of this "
            f"pattern has (k1 L, k2 L) = ({_show(k[0])}, {_show(k[1])})"
        )
    elif max(abs(v) for v in seen_K) < 1e-9 * scale**2 and abs(t[0] * t[1]) > 1e-6 * scale**2:
        reason = (
            "every rigid fold met has K = 0 (one principal curvature stays 0: a developable "
            f"global form), the target K L^2 = {_show(float(t[0] * t[1]))}"
        )
    else:
        reason = "a local minimum of the misfit: the target lies outside the forms reached"
    if failed and reason is not None:
        reason += f" ({len(failed)} trial(s) could not be folded; the first{failed[0]})"
    label = "rigid limit (energy-minimising)"
    if control == "surface":
        label += f", compliant actuators {T.COMPLIANT_K:g} x stiffest fold"
    return {
        "model_label": label,
        "control": control,
        "variables": (
            {"beta_deg": float(sol.x[0]), "kx_L": float(sol.x[1]), "ky_L": float(sol.x[2])}
            if control == "surface"
            else None
        ),
        "n_actuators": len(A),
        "n_vertices": cp.n_vertices,
        "jac": jac,
        "target": t,
        "achieved": k,
        "relative_error": err,
        "reached": bool(reached),
        "reason": reason,
        "angles_deg": np.round(s * sol.x, 6) if control == "actuators" else None,
        "evaluations": n_eval[0],
        "failed_trials": failed,
        "iterations": int(sol.nfev),
        "seconds": seconds,
        "optimizer": sol.message,
    }
