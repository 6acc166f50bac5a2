"""Incremental Newton driver: fold-angle (actuator), displacement, load and arc-length control.

One path parameter ``t`` goes from 0 to 1 over ``scene.steps`` requested steps. Each requested
step may be split into smaller increments (cut-back on divergence, growth again after easy
increments, never past the next requested step), so results land exactly on the steps. Every
increment starts with a tangent predictor at the last converged state (the prescribed
displacements and the new actuator targets enter linearised), then Newton iterations with the
analytic tangent until both the force residual and the displacement correction are small.
See :mod:`barhinge.solver.bordered` for the bordered actuator system and docs/solver.md.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from barhinge.errors import ConfigError, ConvergenceError
from barhinge.linalg.extrapolation import EXTRAPOLATION_POINTS, extrapolate, lagrange
from barhinge.linalg.threads import threads_for_sparse
from barhinge.results import FoldPath, Interrupted
from barhinge.solver.arcrun import run_arc_length
from barhinge.solver.context import SolveContext
from barhinge.solver.convergence import Convergence
from barhinge.solver.damping import Damping
from barhinge.solver.diagnose import check as check_scene
from barhinge.solver.flatstart import FlatStart
from barhinge.solver.records import build_path, make_record
from barhinge.solver.stability import InertiaMonitor
from barhinge.solver.state import (
    Evaluation,
    IncrementFailed,
    IterationStatus,
    State,
    StepRecord,
    StepStats,
)
from barhinge.solver.work import WORK_TOLERANCE, WorkIntegrator
from barhinge.solver_options import SolverOptions

#: step of the central second difference of the geodesic acceleration, as a fraction of the
#: Newton correction (odd orders cancel, so the residual's cubic terms along a
#: near-mechanism, which make the chord correction blow up, do not enter)
ACCELERATION_H = 0.5
#: the acceleration is kept when |a| <= ACCELERATION_RATIO |v| (the step's second-order
#: part small against its first-order part)
ACCELERATION_RATIO = 0.5
#: option acceleration "auto": an increment that needed more Newton corrections than this
#: (or failed) has the next one accelerated from its first correction
AUTO_ACCELERATION_AFTER = 2
#: option corrector "chord": a chord correction is kept when it lowers the root of the merit
#: ``|r_free|^2 + (s c)^2`` at least 1 / CHORD_CONTRACTION times (or the state passes the
#: force and actuator tests); a chord contracting less would cost more back-substitutions
#: and force evaluations than the Newton correction (one assembly and factorisation) it saves
CHORD_CONTRACTION = 0.1
#: option predictor "polynomial" on a path off a flat start: after an increment that
#: converged in more than AUTO_ACCELERATION_AFTER corrections, the tangent step is a
#: candidate of the next whole step too
TANGENT_CANDIDATE = True
#: option predictor "polynomial": once the high-degree extrapolation has won the comparison
#: of candidates and its increment converged in one Newton correction (a smooth stretch of
#: the path), the next whole step starts from it alone, evaluated with its tangent at once:
#: the candidates' two force evaluations are saved (a 70 x 70 Miura fold: 0.2 of a
#: factorisation in every step after the flat start). A slower increment, a failure or a
#: cut-back brings the comparison back.
STEADY_EXTRAPOLATION = True

if TYPE_CHECKING:
    from barhinge.scene import Scene

__all__ = ["WORK_TOLERANCE", "IterationStatus", "Progress", "solve"]

log = logging.getLogger(__name__)

#: progress callback: (requested steps done, total steps, path parameter or load factor)
Progress = Callable[[int, int, float], None]

# the names the driver used before its parts moved to their own modules
_State = State
_Eval = Evaluation
_Failed = IncrementFailed


class _Driver:
    """Step control of one solve: the increments along the path parameter (fold-angle,
    displacement and load control) or the arc-length increments, their predictors and
    Newton correctors, and the records of the converged states."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        if not (~scene.fixed.ravel()).any():
            raise ConfigError("every DOF is fixed by supports or prescribed displacements")
        check_scene(scene)  # separate parts, free rigid-body motions, non-finite input
        opts = scene.options
        if (
            isinstance(opts, SolverOptions)
            and opts.has_arc_stop()
            and scene.control != "arc_length"
        ):
            raise ConfigError(
                "options.arc_stop_* apply to control = 'arc_length' only; this scene uses "
                f"control = {scene.control!r}"
            )
        self.ctx = ctx = SolveContext(scene)
        self.opts = ctx.opts
        self.free, self.fixed = ctx.free, ctx.fixed
        self.system = ctx.make_system()
        self.conv = Convergence(ctx)
        self.records: list[StepRecord] = []
        self.t_start = time.perf_counter()
        ctx.log.t0 = self.t_start  # the iterate log's clock is the states' own
        self.work = WorkIntegrator(ctx.P, ctx.fixed)
        self._prev: State | None = None
        self._prev2: State | None = None
        # converged states (t, [x, mu]) of the polynomial predictor, the last EXTRAPOLATION_POINTS
        self._hist: list[tuple[float, np.ndarray]] = []
        # the last increment failed or needed many corrections (option acceleration "auto")
        self._hard_last = False
        # the last increment converged, in more than AUTO_ACCELERATION_AFTER corrections
        self._slow_last = False
        self._pred_eval: Evaluation | None = None  # the predictor's evaluation, if it made one
        self._retry_tangent = False  # next increment: tangent predictor (after a failure)
        # the last prediction was the tangent step, taken as the extrapolation's rival
        self._pred_tangent = False
        # next increment: the extrapolation alone (its tangent-step candidate failed)
        self._retry_extrapolation = False
        self.n_iter_last = 0  # Newton corrections of the last converged increment
        # the last prediction was the high-degree extrapolation, chosen over the other
        # candidates or taken alone on a smooth stretch (STEADY_EXTRAPOLATION)
        self._pred_extrapolated = False
        # the next polynomial prediction may take the extrapolation alone (set by _predict)
        self._steady = False
        self.inertia = InertiaMonitor(ctx)
        # leaving a flat start: the first increment is predicted by the rigid fold
        # (barhinge.solver.branch); its record says which branch was taken
        self.flat = FlatStart(ctx)
        self.damping = Damping(ctx, self.conv)
        # the path parameter of the start state whose increments are solved damped (option
        # damping; None: none yet)
        self._damp_from: float | None = None
        # per recorded step (state 1 on): Newton iterations of its converged increments,
        # increments (converged, failed), factorisations (all, of them for the inertia)
        self.step_stats: list[StepStats] = []

    # ------------------------------------------------------------ one increment
    def increment(self, st: State, t1: float, lam1: float) -> tuple[State, Evaluation, list[float]]:
        """Newton from the converged state ``st`` to path parameter t1 (load factor lam1).

        Predictor (option ``predictor``): extrapolation through the last three (quadratic)
        or two (secant) converged states, otherwise a tangent step at ``st`` with the
        prescribed displacements and new targets linearised. Correctors: Newton with the
        analytic tangent and an optional backtracking line search on the merit
        ``|r_free|^2 + (s c)^2``. An iterate expected to pass the force test, or to be
        followed by a chord correction, is evaluated without the tangent first (assembled
        afterwards if a Newton correction needs it).
        """
        o, ctx = self.opts, self.ctx
        free = self.free
        res: list[float] = []
        self.system.inertia_seen = []
        self._pred_eval = None
        new = self._predict(st, t1, lam1, res)
        x_pred = new.x.copy()
        e = self._pred_eval if self._pred_eval is not None else ctx.evaluate(new)
        damped = self._damped(st)
        if damped:
            if e.ev.K is None:
                e = ctx.evaluate(new)
            self.damping.reset(e)
        dx_last: np.ndarray | None = None
        n_iter = 0  # Newton corrections (each factorises)
        n_chord = 0  # chord corrections kept (solved with the increment's factorisation)
        # what made the iterate, and the norm of its free displacement change (iterate log)
        kind, moved = "predictor", float(np.linalg.norm((new.x - st.x)[free]))
        while True:
            rf = float(np.linalg.norm(e.r[free]))
            res.append(rf)
            ctx.iterate(rf, correction=moved, kind=kind)
            if not np.isfinite(rf) or not np.all(np.isfinite(e.c)):
                raise IncrementFailed("non-finite residual", res)

            chord_step: list[tuple[np.ndarray, np.ndarray]] = []

            def next_correction(
                e: Evaluation = e, out: list[tuple[np.ndarray, np.ndarray]] = chord_step
            ) -> np.ndarray:
                out.append(self.system.solve(-e.r[free], -e.c))
                return out[-1][0]

            if dx_last is not None and self.conv.converged(e, new, dx_last, next_correction):
                self.n_iter_last = n_iter
                self._hard_last = self._slow_last = n_iter > AUTO_ACCELERATION_AFTER
                self.inertia.check_inertia(res)
                self.inertia.check_jump(st, x_pred, new, res)
                return new, e, res
            if n_iter + n_chord >= o.max_iter:
                raise IncrementFailed(f"no convergence in {o.max_iter} iterations", res)
            if len(res) > 2 and rf > o.divergence_ratio * max(res[0], ctx.floor):
                raise IncrementFailed("residual diverged", res)
            if damped:
                new, e, dx_last, n_fact = self.damping.correction(new, e, res)
                n_iter += n_fact
                damped = self.damping.delta > 0.0
                kind, moved = "damped", float(np.linalg.norm(dx_last))
                continue
            if n_iter and self._chord_allowed(res):
                chord = self._chord(new, e, chord_step[0] if chord_step else None)
                if chord is not None:
                    new, e, dx_last = chord
                    n_chord += 1
                    kind, moved = "chord", float(np.linalg.norm(dx_last))
                    continue
            # the first correction always factorises: the predictor's bar forces change the
            # tangent too much for the previous factorisation to precondition it
            ctx.factorize_or_fail(e, new, res, reuse=n_iter > 0)
            n_iter += 1
            rtol = self.conv.forcing(e, new, rf)
            dx, dmu = self.system.solve(-e.r[free], -e.c, rtol=rtol)
            kind = "newton"
            if self._accelerate(res):
                n_acc = ctx.timer.n_accelerated
                dx, dmu = self._accelerated(new, e, dx, dmu, rtol)
                kind = "accelerated" if ctx.timer.n_accelerated > n_acc else kind
            light = self._expects_convergence(res) or self._chord_next(res)
            new, e, alpha = self.conv.line_search(new, e, dx, dmu, light)
            dx_last = alpha * dx
            moved = float(np.linalg.norm(dx_last))

    def _off_flat(self) -> bool:
        """Whether the path leaves a flat start under fold-angle or displacement control
        (where option ``damping`` applies)."""
        return self.flat.active and not self.system.track_inertia

    def _damped(self, st: State) -> bool:
        """Whether the increment from ``st`` is solved by damped corrections (option
        ``damping``): an increment of a path off a flat start once plain Newton has failed
        it (:meth:`_retry`; ``"auto"``), or the first increment from the start
        (``"always"``)."""
        if not self._off_flat():
            return False
        return self._damp_from == st.t or (st.t == 0.0 and self.opts.damping == "always")

    def _may_damp(self, st: State) -> bool:
        """Whether a failed increment from ``st`` may be redone with damped corrections
        (``damping = "auto"``, a path off a flat start, increments from ``st`` not yet
        damped): the first increment at once, a later one once both predictors (the
        extrapolation and the tangent step) have failed it."""
        return (
            self.opts.damping == "auto"
            and self._off_flat()
            and self._damp_from != st.t
            and not self._predictor_retry_left()
        )

    def _tangent_retry_left(self) -> bool:
        """Whether a failed increment may still be retried with the tangent predictor: an
        extrapolating predictor made it, and no retry was made yet."""
        return (
            not self._retry_tangent
            and not self._retry_extrapolation
            and not self._pred_tangent
            and self._prev is not None
            and self.opts.predictor != "tangent"
        )

    def _extrapolation_retry_left(self) -> bool:
        """Whether a failed increment may still be retried with the extrapolation alone: the
        tangent step made it as the extrapolation's rival (not as a retry)."""
        return self._pred_tangent and not self._retry_tangent and not self._retry_extrapolation

    def _predictor_retry_left(self) -> bool:
        """Whether a failed increment has a predictor left to try at the same length."""
        return self._tangent_retry_left() or self._extrapolation_retry_left()

    def _chord_allowed(self, res: list[float]) -> bool:
        """Whether the next correction is first tried as a chord step (option
        ``corrector``): not where Newton's corrections are being accelerated (the
        near-mechanism, where the tangent changes fast), and only with a factorisation of
        the current increment's tangent at hand."""
        return (
            self.opts.corrector == "chord"
            and self.system.current_factored
            and not self._accelerate(res)
        )

    def _chord_next(self, res: list[float]) -> bool:
        """Whether the iterate after the Newton correction just solved needs no tangent
        unless its residual rises: it is tested for convergence (the next correction a
        back-substitution with this factorisation) and, failing the test, corrected by a
        chord step (option ``corrector = "chord"``, corrections not accelerated). Where the
        guess is wrong the tangent is assembled when it is factorised (a force evaluation
        lost, about a quarter of a tangent assembly); where it is right the iterate that ends an
        increment costs no tangent."""
        return self.opts.corrector == "chord" and not self._accelerate(res)

    def _chord(
        self,
        st: State,
        e: Evaluation,
        step: tuple[np.ndarray, np.ndarray] | None,
    ) -> tuple[State, Evaluation, np.ndarray] | None:
        """The chord correction from ``st`` (the residual solved with the increment's
        factorisation; ``step``: that solve, if the convergence test made it), its
        evaluation without the tangent, and the correction; None (the trial discarded)
        when it does not contract the merit by ``CHORD_CONTRACTION`` and the state does not
        pass the force and actuator tests."""
        ctx, conv = self.ctx, self.conv
        dx, dmu = step if step is not None else self.system.solve(-e.r[self.free], -e.c)
        trial = State(st.x.copy(), st.mu + dmu, st.lam, st.t)
        trial.x[self.free] += dx
        et = ctx.evaluate(trial, tangent=False)
        m0, m1 = conv.merit(e), conv.merit(et)
        if np.isfinite(m1) and (m1 <= CHORD_CONTRACTION**2 * m0 or conv.passes(et, trial)):
            ctx.timer.n_chord += 1
            return trial, et, dx
        ctx.timer.n_chord_rejected += 1
        return None

    def _accelerated(
        self, st: State, e: Evaluation, dx: np.ndarray, dmu: np.ndarray, rtol: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The Newton correction ``(dx, dmu)`` at ``st`` with its geodesic acceleration
        (option ``acceleration``): ``v + a / 2`` with ``K a = -r''[v, v]`` (central second
        difference, step ``ACCELERATION_H``), kept when ``2 |a| <= |v|``."""
        ctx, h = self.ctx, ACCELERATION_H
        ev = []
        for sign in (1.0, -1.0):
            trial = State(st.x.copy(), st.mu + sign * h * dmu, st.lam, st.t)
            trial.x[self.free] += sign * h * dx
            ev.append(ctx.evaluate(trial, tangent=False))
        r2 = (ev[0].r + ev[1].r - 2.0 * e.r) / (h * h)
        c2 = (ev[0].c + ev[1].c - 2.0 * e.c) / (h * h)
        if not (np.all(np.isfinite(r2)) and np.all(np.isfinite(c2))):
            return dx, dmu
        a, amu = self.system.solve(-r2[self.free], -c2, rtol=rtol)
        if float(np.linalg.norm(a)) > ACCELERATION_RATIO * float(np.linalg.norm(dx)):
            return dx, dmu  # the step is too long for the valley's curvature
        self.ctx.timer.n_accelerated += 1
        return dx + 0.5 * a, dmu + 0.5 * amu

    def _polynomial(self, st: State, t1: float, lam1: float) -> State:
        """Predictor ``"polynomial"``: the extrapolation of the last converged states of the
        degree they support (:func:`barhinge.linalg.extrapolation.extrapolate`) or the quadratic
        through the last three, whichever has the smaller residual ``|r_free|^2 + (s c)^2``
        (two force evaluations without the tangent; the chosen one is kept for the first
        iteration). Near a bifurcation or a change of branch the high degree can overshoot
        where the quadratic does not.

        On a path off a flat start, for a whole step after an increment that converged in
        more than ``AUTO_ACCELERATION_AFTER`` corrections, the tangent step at ``st`` is a
        third candidate: where the near-mechanism turns from step to step, the states
        behind extrapolate past the next one, and the tangent step starts Newton nearer to
        it (one force evaluation and one back-substitution with the last factorisation).
        Not after a failed increment or inside cut-backs, where the retries
        (:meth:`_retry`) are in charge.

        On a smooth stretch (``STEADY_EXTRAPOLATION``: the last increment started from the
        high-degree extrapolation and took one correction) the extrapolation is the start
        alone, unevaluated: the first iteration assembles its tangent anyway."""
        ctx, nx = self.ctx, len(st.x)
        whole = (t1 - st.t) * self.scene.steps >= 1.0 - 1e-9
        cands = [lagrange(self._hist[-3:], t1)]
        z = extrapolate(self._hist, t1)
        if z is not None and not np.array_equal(z, cands[0]):
            cands.insert(0, z)
            if STEADY_EXTRAPOLATION and self._steady and whole:
                # a smooth stretch: the extrapolation alone, its tangent assembled at once
                self._pred_extrapolated = True
                return self._unpacked(z, nx, t1, lam1)
        best: tuple[float, State, Evaluation] | None = None
        for i, z in enumerate(cands):
            new = self._unpacked(z, nx, t1, lam1)
            e = ctx.evaluate(new, tangent=False)
            m = self.conv.merit(e)
            if best is None or m < best[0]:
                best = (m, new, e)
                self._pred_extrapolated = i == 0 and len(cands) == 2
        assert best is not None
        if (
            TANGENT_CANDIDATE
            and self._slow_last
            and whole
            and self._off_flat()
            and not self._retry_extrapolation
        ):
            tangent = self._chord_tangent_step(st, t1, lam1)
            if tangent is not None:
                e = ctx.evaluate(tangent, tangent=False)
                m = self.conv.merit(e)
                log.debug("tangent step: merit %.3g against the extrapolation's %.3g", m, best[0])
                if m < best[0]:
                    best = (m, tangent, e)
                    self._pred_tangent = True
                    self._pred_extrapolated = False
        self._pred_eval = best[2]
        return best[1]

    def _chord_tangent_step(self, st: State, t1: float, lam1: float) -> State | None:
        """The tangent step at ``st`` solved with the last factorisation (that of the
        increment that ended at ``st``): one force evaluation and one back-substitution. None
        where no factorisation is at hand or prescribed displacements move (their
        ``-K_fc du_c`` needs the tangent)."""
        ctx, free, fixed = self.ctx, self.free, self.fixed
        if not self.system.current_factored:
            return None
        du_c = ctx.fixed_coords(t1) - st.x[fixed]
        if du_c.size and np.any(du_c):
            return None
        e = ctx.evaluate(st, tangent=False)
        rhs, c_pred = self._tangent_rhs(e, st, t1, lam1, None)
        dx, dmu = self.system.solve(rhs[free], -c_pred)
        return self._stepped(st, dx, dmu, t1, lam1)

    def _accelerate(self, res: list[float]) -> bool:
        """Whether the next correction is accelerated (option ``acceleration``): always,
        never, or ("auto") once the increment's residual has risen or after a hard
        increment."""
        mode = self.opts.acceleration
        if mode != "auto":
            return bool(mode)
        rose = any(later > earlier for earlier, later in zip(res, res[1:], strict=False))
        return self._hard_last or rose

    def _expects_convergence(self, res: list[float]) -> bool:
        return self.conv.expects_convergence(res)

    def _predict(self, st: State, t1: float, lam1: float, res: list[float]) -> State:
        """Predicted state at ``t1``: rigid fold off a flat start, extrapolation through
        the last converged states, or a tangent step at ``st``."""
        o, ctx = self.opts, self.ctx
        fixed = self.fixed
        prev = self._prev
        prev2 = self._prev2
        self._pred_tangent = False
        # a smooth stretch: the last increment started from the high-degree extrapolation
        # and converged in one correction, with no failure since
        self._steady = (
            self._pred_extrapolated
            and self.n_iter_last <= 1
            and not (self._slow_last or self._hard_last)
        )
        self._pred_extrapolated = False
        extrapolate = o.predictor != "tangent" and not self._retry_tangent
        guided = None
        if self.flat.active and not self._retry_tangent:
            guided = self.flat.prediction(st, t1, lam1)
        if guided is not None:
            return guided
        if prev is not None and prev.t < st.t and extrapolate:
            if o.predictor == "polynomial" and len(self._hist) >= 3:
                return self._polynomial(st, t1, lam1)
            if o.predictor != "secant" and prev2 is not None and prev2.t < prev.t:
                # Lagrange extrapolation through the last three converged states
                ta, tb, tc = prev2.t, prev.t, st.t
                la = (t1 - tb) * (t1 - tc) / ((ta - tb) * (ta - tc))
                lb = (t1 - ta) * (t1 - tc) / ((tb - ta) * (tb - tc))
                lc = (t1 - ta) * (t1 - tb) / ((tc - ta) * (tc - tb))
                x = la * prev2.x + lb * prev.x + lc * st.x
                mu = la * prev2.mu + lb * prev.mu + lc * st.mu
            else:
                f = (t1 - st.t) / (st.t - prev.t)
                x, mu = st.x + f * (st.x - prev.x), st.mu + f * (st.mu - prev.mu)
            new = State(x, mu, lam1, t1)
            new.x[fixed] = ctx.fixed_coords(t1)
            return new
        return self._tangent_step(st, t1, lam1, res)

    def _tangent_step(self, st: State, t1: float, lam1: float, res: list[float]) -> State:
        """The tangent predictor: one linear step at ``st`` to ``t1`` (load factor ``lam1``)
        with the prescribed displacements and the actuators' new targets linearised, solved
        with the last factorisation as preconditioner."""
        ctx, free, fixed = self.ctx, self.free, self.fixed
        e = ctx.evaluate(st)
        rhs, c_pred = self._tangent_rhs(e, st, t1, lam1, ctx.fixed_coords(t1) - st.x[fixed])
        ctx.factorize_or_fail(e, st, res, reuse=True)
        dx, dmu = self.system.solve(rhs[free], -c_pred, rtol=1e-6)
        return self._stepped(st, dx, dmu, t1, lam1)

    def _tangent_rhs(
        self, e: Evaluation, st: State, t1: float, lam1: float, du_c: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Right-hand sides (forces, constraints) of the tangent step at ``st`` (evaluated
        as ``e``) to ``t1``: the load increment, the prescribed displacements ``du_c`` of the
        fixed DOFs (``-K_fc du_c``; needs ``e``'s tangent, None: none), the actuators' new
        targets and, for compliant actuators, their springs' moved ends."""
        ctx = self.ctx
        rhs = -(e.r - (lam1 - st.lam) * e.P)
        if du_c is not None and du_c.size and np.any(du_c):
            dfull = np.zeros(ctx.n_dof)
            dfull[self.fixed] = du_c
            rhs = rhs - e.ev.K @ dfull
        c_pred = e.c + (ctx.targets(st.t) - ctx.targets(t1)) if ctx.n_act else e.c
        if ctx.k_act is not None:  # compliant actuators: their springs' ends move
            rhs = rhs + e.terms.G.T @ (ctx.k_act * (ctx.targets(t1) - ctx.targets(st.t)))
        return rhs, c_pred

    def _unpacked(self, z: np.ndarray, nx: int, t1: float, lam1: float) -> State:
        """The state ``[x, mu] = z`` (``nx`` coordinates first) at ``t1`` (load factor
        ``lam1``) with the fixed DOFs at their prescribed place."""
        new = State(z[:nx].copy(), z[nx:].copy(), lam1, t1)
        new.x[self.fixed] = self.ctx.fixed_coords(t1)
        return new

    def _stepped(self, st: State, dx: np.ndarray, dmu: np.ndarray, t1: float, lam1: float) -> State:
        """``st`` moved by ``(dx, dmu)`` on the free DOFs and multipliers, at ``t1`` (load
        factor ``lam1``) with the fixed DOFs at their prescribed place."""
        new = State(st.x.copy(), st.mu + dmu, lam1, t1)
        new.x[self.free] += dx
        new.x[self.fixed] = self.ctx.fixed_coords(t1)
        return new

    # ------------------------------------------------------------ records
    def record(
        self,
        st: State,
        e: Evaluation,
        iters: int,
        res: list[float],
        counts: tuple[int | None, int | None] = (None, None),
    ) -> None:
        """Append the converged state ``st`` (``counts``: negative eigenvalues of its
        free-DOF tangent with the actuators released and held, None if unknown)."""
        wall = time.perf_counter() - self.t_start
        self.records.append(make_record(self.ctx, st, e, iters, res, wall, self.work.work, *counts))

    def path(self, converged: bool = True, message: str = "") -> FoldPath:
        flat = self.flat.record
        if flat is not None and self.damping.corrections:
            # the damped corrections of the first increment (option damping)
            flat = {
                **flat,
                "damped_corrections": self.damping.corrections,
                "damped_redone": self.damping.rejected,
            }
        return build_path(
            self.ctx,
            self.records,
            self.step_stats,
            flat,
            self.flat.events(self.records),
            converged=converged,
            message=message,
        )

    def interrupted_path(self) -> FoldPath | None:
        """The converged part after a Ctrl-C (``meta["stopped"] = "interrupted"``); None
        before state 0."""
        if not self.records:
            return None
        n = len(self.records) - 1
        lam = float(self.records[-1].lam)
        msg = f"interrupted (Ctrl-C) after {n} converged steps, at load factor {lam:.6g}"
        path = self.path(converged=False, message=msg)
        path.meta["stopped"] = "interrupted"
        return path

    def fail(self, step: int, lam: float, why: str, res: list[float]) -> ConvergenceError:
        where = (
            f"arc-length increment {step}"
            if self.scene.control == "arc_length"
            else f"step {step} of {self.scene.steps}"
        )
        msg = (
            f"{where} did not converge at load factor {lam:.6g} "
            f"after {self.opts.max_cutbacks} cut-backs ({why})"
        )
        return ConvergenceError(
            msg,
            step=step,
            load_factor=lam,
            residuals=res,
            last_state=self.path(converged=False, message=msg),
        )

    # ------------------------------------------------------------ state 0
    def initial(self) -> tuple[State, Evaluation]:
        ctx = self.ctx
        st = State(ctx.X0.ravel().copy(), np.zeros(ctx.n_act), 0.0, 0.0)
        e = ctx.evaluate(st)
        if ctx.n_act:
            # multipliers that balance the initial state best (zero for a stress-free start)
            # least squares min |r_free + G^T mu| through the normal equations (n_act x n_act)
            G = e.terms.G[:, self.free]
            GGt = (G @ G.T).toarray()
            mu, *_ = np.linalg.lstsq(GGt, -(G @ e.r[self.free]), rcond=None)
            st.mu = mu
            e = ctx.evaluate(st)
        return st, e

    # ------------------------------------------------------------ parameter control
    def run_parameter(self, progress: Progress | None) -> FoldPath:
        """Fold-angle, displacement and load control: t (= load factor) from 0 to 1."""
        o, timer = self.opts, self.ctx.timer
        steps = self.scene.steps
        st, e = self.initial()
        self.record(st, e, 0, [], self.inertia.tangent_inertia(st, e, exact=True))
        self._hist.append((st.t, np.concatenate([st.x, st.mu])))
        e_new = e
        h0 = 1.0 / steps
        h = h0
        h_min = h0 * 0.5**o.max_cutbacks
        for s in range(1, steps + 1):
            t_goal = s / steps
            iters, res_all = 0, []
            n_inc = n_failed = 0
            fact0 = timer.n_factorizations
            chord0 = timer.n_chord
            critical = ""  # a limit-point diagnosis from any attempt since the last success
            while st.t < t_goal - 1e-12 * h0:
                h_try = min(h, t_goal - st.t)
                t1 = t_goal if h_try >= t_goal - st.t - 1e-12 * h0 else st.t + h_try
                self.inertia.inc_serial = timer.n_factorizations
                self.ctx.begin_increment(s, steps, t1, (t1 - st.t) / h0, n_failed)
                try:
                    new, e_new, res = self.increment(st, t1, t1)
                except IncrementFailed as f:
                    log.debug(
                        "step %d: increment to t=%.6g failed (%s); cutting back", s, t1, f.why
                    )
                    n_failed += 1
                    self._hard_last, self._slow_last = True, False
                    held = self._last_counts()[1]
                    critical = self.inertia.failure_text(f.why, held) or critical
                    if self._retry(st):
                        continue
                    self._retry_tangent = self._retry_extrapolation = False
                    h = h_try / 2
                    if h < h_min * (1 - 1e-9):
                        # near a critical point the smallest increments may simply find no
                        # solution; name the critical point if one was detected on the way
                        raise self.fail(s, st.lam, critical or f.why, f.residuals) from None
                    continue
                self._retry_tangent = self._retry_extrapolation = False
                self.work.add(self.records[0], new, e_new, None)
                critical = ""
                self._prev2, self._prev, st = self._prev, st, new
                self._hist.append((new.t, np.concatenate([new.x, new.mu])))
                del self._hist[:-EXTRAPOLATION_POINTS]
                self.inertia.inertia = self.system.negative_pivots
                iters += self.n_iter_last
                n_inc += 1
                res_all.extend(res)
                if self.n_iter_last <= o.grow_iters:
                    h = min(2 * h_try, h0)
            fact1 = timer.n_factorizations
            counts = self.inertia.state_inertia(st, e_new, self._last_counts())
            self.step_stats.append(
                StepStats(
                    iterations=iters,
                    increments=n_inc,
                    failed=n_failed,
                    factorizations=timer.n_factorizations - fact0,
                    inertia_factorizations=timer.n_factorizations - fact1,
                    chord=timer.n_chord - chord0,
                )
            )
            self.record(st, e_new, iters, res_all, counts)
            if progress is not None:
                progress(s, steps, st.t)
        return self.path()

    def _last_counts(self) -> tuple[int | None, int | None]:
        """Negative eigenvalues (released, held) of the last recorded state where each is
        known."""
        known = [(r.neg, r.neg_held) for r in reversed(self.records)]
        released = next((n for n, _ in known if n is not None), None)
        held = next((h for _, h in known if h is not None), None)
        return released, held

    def _retry(self, st: State) -> bool:
        """Whether a failed increment from ``st`` is retried at the same length: with the
        tangent predictor (sets the retry flag) or with damped corrections (option
        ``damping``; sets the start they apply to)."""
        rec = self.flat.record or {}
        if st.t == 0.0 and rec.get("least_squares") and not self._retry_tangent:
            # the rigid fold could only meet the targets in least squares (the
            # actuators conflict): the panels must bend, and Newton may not
            # reach that from the rigid prediction; retry from the tangent
            self._retry_tangent = True
            return True
        if self._may_damp(st):
            # plain Newton failed an increment off a flat start (the first, or a later one
            # from both predictors): the sheet is a near-mechanism there, and a shorter
            # increment lies farther from the rigid fold; the same increment is redone (and
            # any cut-back of it) with damped corrections from the first prediction
            self._damp_from = st.t
            self._retry_tangent = self._retry_extrapolation = False
            log.debug("increment from t=%.6g redone with damped corrections", st.t)
            return True
        if self._extrapolation_retry_left() and self._damp_from != st.t:
            # the tangent step, taken for its smaller residual, failed: retry the same
            # increment from the extrapolation before cutting back
            self._retry_extrapolation = True
            return True
        if self._tangent_retry_left() and self._damp_from != st.t:
            # an extrapolating predictor failed: retry the same increment once
            # with the tangent predictor before cutting back (near a soft mode
            # the extrapolated start can lie outside Newton's basin)
            self._retry_tangent = True
            return True
        return False

    # ------------------------------------------------------------ arc length
    def run_arc_length(self, progress: Progress | None) -> FoldPath:
        """MGDCM arc length (:func:`barhinge.solver.arcrun.run_arc_length`)."""
        return run_arc_length(self, progress)


@threads_for_sparse
def solve(
    scene: Scene,
    progress: Progress | None = None,
    on_iteration: Callable[[IterationStatus], None] | None = None,
) -> FoldPath:
    """Solve a scene along its path; returns a :class:`~barhinge.results.FoldPath`.

    Parameters
    ----------
    scene : Scene
    progress : callable (done, total, value) -> None, optional
        Called after every requested step (value = path parameter or load factor).
    on_iteration : callable (IterationStatus) -> None, optional
        Called at every iterate (the predictor and each correction) with the step, the
        increment's length, the iterate's number and its force residual: a live display
        of long steps (``barhinge fold`` shows it beside its progress bar).

    Returns
    -------
    FoldPath with ``kind="bar-hinge"``: states 0..steps (every increment under arc length),
    actuator moments (positive = driving the crease towards valley), reactions (force of
    the supports on the structure), energies, external work, iterations, residual norms.

    Raises
    ------
    ConvergenceError
        When a step does not converge after ``options.max_cutbacks`` halvings; its
        ``last_state`` is the partial FoldPath of the converged steps.
    Interrupted
        On Ctrl-C (a KeyboardInterrupt); its ``last_state`` is the converged part.
    ConfigError
        When the scene asks for an imperfection its model has not been seeded with.
    """
    if scene.imperfection is not None and "imperfection" not in getattr(scene.model, "meta", {}):
        raise ConfigError(
            "the scene asks for an imperfection its model does not have: seed it with "
            "barhinge.seed_imperfection(scene) before solving (barhinge fold does)"
        )
    d = _Driver(scene)
    d.ctx.on_iteration = on_iteration
    try:
        if scene.control == "arc_length":
            return d.run_arc_length(progress)
        return d.run_parameter(progress)
    except KeyboardInterrupt:
        raise Interrupted(last_state=d.interrupted_path()) from None
