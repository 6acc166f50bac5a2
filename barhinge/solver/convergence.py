"""Convergence of a Newton increment: the force scale and tests (:class:`Convergence`), the
forcing term of an inexact (GMRES) solve, and the backtracking line search on the merit
``|r_free|^2 + (s c)^2``."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from barhinge.solver.context import SolveContext
from barhinge.solver.state import Evaluation, State

__all__ = ["Convergence"]


class Convergence:
    """Convergence test, forcing term and line search of one :class:`SolveContext`."""

    def __init__(self, ctx: SolveContext) -> None:
        self.ctx = ctx
        self.tol_abs: float | None = None  # absolute force tolerance at the last test

    def force_ref(self, e: Evaluation, st: State) -> float:
        """Force scale of the convergence test."""
        ctx = self.ctx
        parts = [float(np.linalg.norm(st.lam * e.P)), float(ctx.floor)]
        f = np.asarray(e.ev.force, float).ravel()
        parts.append(float(np.linalg.norm(f[ctx.fixed])) if ctx.fixed.any() else 0.0)
        if ctx.n_act:
            parts.append(float(np.linalg.norm(e.terms.G.T @ st.mu)))
        return max(parts)

    def forcing(self, e: Evaluation, st: State, rf: float) -> float:
        """Relative tolerance of an inexact (GMRES) Newton solve: follows the relative
        residual (keeps the quadratic rate; Dembo, Eisenstat & Steihaug 1982), capped at
        1e-3, and never tighter than a tenth of what the convergence test needs."""
        ctx = self.ctx
        fref = self.force_ref(e, st)
        s = ctx.c_scale
        cmax = float(np.linalg.norm(e.c)) if ctx.n_act else 0.0
        bnorm = float(np.hypot(rf, s * cmax)) or 1.0
        need = min(ctx.opts.tol_force * fref + ctx.floor, s * ctx.opts.tol_angle)
        eta = min(1e-3, max(rf / fref, 0.1 * need / bnorm))
        return max(eta, 1e-13)

    def converged(
        self,
        e: Evaluation,
        st: State,
        dx: np.ndarray,
        next_correction: Callable[[], np.ndarray],
    ) -> bool:
        """Whether the iterate ``st`` passes the force, displacement (``dx``: the last
        correction) and actuator-angle tests.

        Where the force and actuator tests pass and ``dx`` is above the tolerance, the
        state is judged by ``next_correction`` (a back-substitution of the current residual
        with the last factorisation): below the tolerance it is accepted. That correction
        estimates this state's error, where ``dx`` measures the previous iterate's: along a
        soft mode a residual at the force floor can still hide a correction far above the
        tolerance (an imperfect strut near its buckling load), and a residual that reached
        the floor after a large correction needs no further factorisation."""
        ctx = self.ctx
        o = ctx.opts
        rf = float(np.linalg.norm(e.r[ctx.free]))
        self.tol_abs = self._force_tolerance(e, st)
        ok_f = rf <= self.tol_abs
        ok_c = self._actuators_ok(e)
        tol_x = o.tol_disp * ctx.size
        ok_x = float(np.linalg.norm(dx)) <= tol_x
        if ok_x or not (ok_f and ok_c):
            return bool(ok_f and ok_x and ok_c)
        return float(np.linalg.norm(next_correction())) <= tol_x

    def passes(self, e: Evaluation, st: State) -> bool:
        """Whether ``st`` passes the force and actuator tests (not the displacement one)."""
        rf = float(np.linalg.norm(e.r[self.ctx.free]))
        return rf <= self._force_tolerance(e, st) and self._actuators_ok(e)

    def _force_tolerance(self, e: Evaluation, st: State) -> float:
        """``tol_force * F_ref + force_floor`` at ``st``, force."""
        return self.ctx.opts.tol_force * self.force_ref(e, st) + self.ctx.floor

    def _actuators_ok(self, e: Evaluation) -> bool:
        """Whether every held actuator is within ``tol_angle`` of its target."""
        ctx = self.ctx
        return (not ctx.n_act) or float(np.max(np.abs(e.c))) <= ctx.opts.tol_angle

    def merit(self, e: Evaluation) -> float:
        """``|r_free|^2 + (s c)^2``, force^2."""
        free, s = self.ctx.free, self.ctx.c_scale
        return float(e.r[free] @ e.r[free]) + float((s * e.c) @ e.c * s)

    def expects_convergence(self, res: list[float]) -> bool:
        """Whether the next iterate will probably pass the force test: in the quadratic
        regime ``r_{k+1} ~ r_k^3 / r_{k-1}^2``. Then it is evaluated without the tangent
        (a quarter of the cost; the tangent follows if the guess was wrong)."""
        if len(res) < 2 or not res[-2] > 0 or self.tol_abs is None:
            return False
        q = res[-1] / res[-2]
        return bool(q < 0.1 and res[-1] * q * q <= 0.5 * self.tol_abs)

    def line_search(
        self,
        st: State,
        e: Evaluation,
        dx: np.ndarray,
        dmu: np.ndarray,
        light: bool = False,
        dlam: float = 0.0,
    ) -> tuple[State, Evaluation, float]:
        """Backtracking (Armijo) on the merit function along the correction ``(dx, dmu,
        dlam)`` (``dlam``: the load-factor part of an arc-length corrector, scaled with the
        rest so the correction keeps its arc-length constraint); the trial evaluation is
        reused (``light``: the full step is evaluated without the tangent). Returns the
        trial state, its evaluation and the step fraction taken."""
        ctx = self.ctx
        phi0 = self.merit(e)
        alpha = 1.0
        for k in range(ctx.opts.line_search + 1):
            trial = State(st.x.copy(), st.mu + alpha * dmu, st.lam + alpha * dlam, st.t)
            trial.x[ctx.free] += alpha * dx
            et = ctx.evaluate(trial, tangent=not (light and k == 0))
            phi = self.merit(et)
            if (np.isfinite(phi) and phi <= (1 - 1e-4 * alpha) * phi0) or k == ctx.opts.line_search:
                return trial, et, alpha
            alpha *= 0.5
        raise AssertionError("unreachable")
