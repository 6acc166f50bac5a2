"""The Newton loops of arc-length control: one MGDCM increment (:func:`arc_increment`;
Leon et al. 2011), the correction onto a displacement stop (:func:`land_displacement`),
and the stop criteria read from the options (:func:`displacement_stop`,
:func:`stop_text`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from barhinge.errors import ConfigError
from barhinge.linalg.backends import SingularMatrixError
from barhinge.solver.bordered import gdcm_scale, gdcm_sign
from barhinge.solver.context import SolveContext
from barhinge.solver.convergence import Convergence
from barhinge.solver.stability import left_branch
from barhinge.solver.state import Evaluation, IncrementFailed, State
from barhinge.solver_options import displacement_stop_dof

__all__ = ["arc_increment", "displacement_stop", "land_displacement", "stop_text"]


def arc_increment(
    ctx: SolveContext,
    conv: Convergence,
    st: State,
    e: Evaluation,
    dl0: float,
    first_tan: np.ndarray | None,
    prev_tan: np.ndarray | None,
    sign: float,
    factored: bool = False,
    stay_on_branch: bool = False,
) -> tuple[State, Evaluation, list[float], np.ndarray, float]:
    """One MGDCM increment from ``st`` (``e`` its evaluation; ``factored``: the system
    holds the factorisation of its tangent): predictor with the GSP-scaled load
    increment, correctors with ``dlambda = -(du_1 . du_bar)/(du_1 . du_hat)`` (Leon et
    al. 2011). With ``stay_on_branch`` a converged state farther from the predictor than
    the predictor is from ``st`` is refused (IncrementFailed): the correctors left the
    branch and may have jumped over a limit point or a bifurcation unseen. Returns the
    state, its evaluation, the residual norms, the predictor's tangent and the sign of the
    load increment."""
    o = ctx.opts
    free = ctx.free
    res: list[float] = []
    if not factored:
        ctx.factorize_or_fail(e, st, res)
    zc = np.zeros(ctx.n_act)
    u_hat, mu_hat = ctx.system.solve(e.P[free], zc)
    sgn = gdcm_sign(prev_tan, u_hat, sign)
    base = first_tan if first_tan is not None else u_hat
    dlam = sgn * dl0 * gdcm_scale(base, prev_tan, u_hat)
    u_bar, mu_bar = ctx.system.solve(-e.r[free], -e.c)
    new = State(st.x.copy(), st.mu + dlam * mu_hat + mu_bar, st.lam + dlam, st.t)
    dx = dlam * u_hat + u_bar
    new.x[free] += dx
    x_pred = new.x.copy()
    tan1 = u_hat
    uh = u_hat  # K^-1 P of the factorisation at hand
    it = 1
    e = ctx.evaluate(new)
    while True:
        rf = float(np.linalg.norm(e.r[free]))
        res.append(rf)
        kind = "predictor" if it == 1 else "newton"
        ctx.iterate(rf, new.lam, correction=float(np.linalg.norm(dx)), kind=kind)
        if not np.isfinite(rf):
            raise IncrementFailed("non-finite residual", res)
        if it > 1 and conv.converged(e, new, dx, _arc_correction(ctx, e, uh, tan1)):
            jump = left_branch(ctx, st, x_pred, new) if stay_on_branch else ""
            if jump:
                raise IncrementFailed(f"the correctors left the branch ({jump})", res)
            return new, e, res, tan1, sgn
        if it >= o.max_iter:
            raise IncrementFailed(f"no convergence in {o.max_iter} iterations", res)
        if len(res) > 2 and rf > o.divergence_ratio * max(res[0], ctx.floor):
            raise IncrementFailed("residual diverged", res)
        ctx.factorize_or_fail(e, new, res)
        uh, mh = ctx.system.solve(e.P[free], zc)
        ub, mb = ctx.system.solve(-e.r[free], -e.c)
        dl = _arc_dlam(ub, uh, tan1)
        # a corrector scaled by the line search stays orthogonal to tan1 (its constraint)
        new, e, alpha = conv.line_search(new, e, dl * uh + ub, dl * mh + mb, dlam=dl)
        dx = alpha * (dl * uh + ub)
        it += 1


def _arc_dlam(ub: np.ndarray, uh: np.ndarray, tan1: np.ndarray) -> float:
    """Load-factor correction of an MGDCM corrector: the correction ``dl uh + ub`` stays
    orthogonal to the increment's first tangent ``tan1`` (Leon et al. 2011)."""
    return -float(tan1 @ ub) / float(tan1 @ uh)


def _landing_dlam(ub: np.ndarray, uh: np.ndarray, k: int) -> float:
    """Load-factor correction that holds free component ``k`` of ``dl uh + ub`` at 0."""
    return -float(ub[k]) / float(uh[k])


def _arc_correction(
    ctx: SolveContext, e: Evaluation, uh: np.ndarray, tan1: np.ndarray
) -> Callable[[], np.ndarray]:
    """The next arc-length correction from the residual of ``e`` with the factorisation at
    hand (``uh = K^-1 P`` of it), for :meth:`Convergence.converged` to judge a state that
    passes the force test."""

    def correction() -> np.ndarray:
        ub, _ = ctx.system.solve(-e.r[ctx.free], -e.c)
        return _arc_dlam(ub, uh, tan1) * uh + ub

    return correction


def _landing_correction(
    ctx: SolveContext, e: Evaluation, uh: np.ndarray, k: int
) -> Callable[[], np.ndarray]:
    """The next correction of :func:`land_displacement` (free component ``k`` held)."""

    def correction() -> np.ndarray:
        ub, _ = ctx.system.solve(-e.r[ctx.free], -e.c)
        return _landing_dlam(ub, uh, k) * uh + ub if uh[k] != 0.0 else ub

    return correction


def land_displacement(
    ctx: SolveContext, conv: Convergence, st: State, past: State, dof: int, target: float
) -> tuple[State, Evaluation, list[float]]:
    """Correct onto coordinate ``target`` (length) of the global DOF ``dof``
    (displacement control of that component, the load factor free), starting from the
    linear interpolation between ``st`` and ``past``. Raises IncrementFailed when Newton
    fails."""
    o = ctx.opts
    free = ctx.free
    k = int(np.count_nonzero(free[:dof]))  # position of dof among the free DOFs
    frac = (target - st.x[dof]) / (past.x[dof] - st.x[dof])
    new = State(
        st.x + frac * (past.x - st.x),
        st.mu + frac * (past.mu - st.mu),
        st.lam + frac * (past.lam - st.lam),
        st.t,
    )
    new.x[dof] = target
    zc = np.zeros(ctx.n_act)
    res: list[float] = []
    dx = np.zeros(int(free.sum()))
    uh = np.zeros_like(dx)  # K^-1 P of the factorisation at hand (from the first correction)
    why = f"no convergence in {o.max_iter} iterations"
    ctx.begin_landing(new.lam)
    for it in range(1, o.max_iter + 1):
        e = ctx.evaluate(new)
        rf = float(np.linalg.norm(e.r[free]))
        res.append(rf)
        moved = np.linalg.norm((new.x - st.x)[free] if it == 1 else dx)
        ctx.iterate(rf, new.lam, correction=float(moved), kind="predictor" if it == 1 else "newton")
        if not np.isfinite(rf):
            why = "non-finite residual"
            break
        if it > 1 and conv.converged(e, new, dx, _landing_correction(ctx, e, uh, k)):
            return new, e, res
        try:
            ctx.factorize(e, new)
        except SingularMatrixError as exc:
            why = f"singular tangent ({exc})"
            break
        uh, mh = ctx.system.solve(e.P[free], zc)
        ub, mb = ctx.system.solve(-e.r[free], -e.c)
        if uh[k] == 0.0:
            why = "the load does not move the stopping component"
            break
        dl = _landing_dlam(ub, uh, k)
        dx = dl * uh + ub
        new.x[free] += dx
        new.mu = new.mu + dl * mh + mb
        new.lam += dl
    raise IncrementFailed(why, res)


def displacement_stop(ctx: SolveContext) -> tuple[int, float] | None:
    """(global DOF, target coordinate) of the displacement stop, checked against the
    model; None without one."""
    spec = ctx.opts.arc_stop_displacement
    if spec is None:
        return None
    n_nodes = ctx.model.n_nodes
    if spec["node"] >= n_nodes:
        raise ConfigError(
            f"options.arc_stop_displacement.node = {spec['node']}; the model has "
            f"{n_nodes} nodes (0 to {n_nodes - 1})"
        )
    dof = displacement_stop_dof(spec)
    if not ctx.free[dof]:
        raise ConfigError(
            f"options.arc_stop_displacement: {spec['axis']} of node {spec['node']} is "
            "fixed by a support or a prescribed displacement; choose a free component"
        )
    return dof, float(ctx.X0.ravel()[dof] + spec["value"])


def stop_text(ctx: SolveContext, lam_stop: float | None, disp: tuple[int, float] | None) -> str:
    """What the run was asked to reach, for the step-cap message."""
    o = ctx.opts
    if lam_stop is not None and disp is None and not o.has_arc_stop():
        return f"of {lam_stop:g}"
    parts = [f"load factor {lam_stop:g}"] if lam_stop is not None else []
    spec = o.arc_stop_displacement
    if disp is not None and spec is not None:
        parts.append(f"displacement {spec['axis']} = {spec['value']:g} of node {spec['node']}")
    if o.arc_stop_limit_points is not None:
        parts.append(f"{o.arc_stop_limit_points} limit point(s)")
    if o.arc_stop_instability:
        parts.append("a loss of stability")
    return "before reaching " + " or ".join(parts)
