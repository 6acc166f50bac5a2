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

import dataclasses
import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from barhinge.errors import ConfigError, ConvergenceError
from barhinge.linalg.backends import SingularMatrixError, get_backend
from barhinge.linalg.threads import threads_for_sparse
from barhinge.results import FoldPath, Interrupted
from barhinge.solver.bordered import (
    BorderedSystem,
    Timer,
    actuator_terms,
    gdcm_scale,
    gdcm_sign,
)
from barhinge.solver.branch import (
    RigidGuide,
    conflicting_actuators,
    creases_against_assignment,
    is_flat,
    rigid_guide,
)
from barhinge.solver.diagnose import check as check_scene
from barhinge.solver.diagnose import check_finite_tangent
from barhinge.solver_options import displacement_stop_dof

if TYPE_CHECKING:
    from barhinge.scene import Scene

__all__ = ["Progress", "solve"]

log = logging.getLogger(__name__)

#: relative mismatch between the external work and the stored energy of a path above which
#: an event is recorded (``meta["work_balance"]``); the Simpson work integration is third
#: order, and the tests' coarsest paths (6-20 steps) stay below 1e-4 (docs/solver.md)
WORK_TOLERANCE = 1e-3

#: progress callback: (requested steps done, total steps, path parameter or load factor)
Progress = Callable[[int, int, float], None]


@dataclasses.dataclass
class _State:
    x: np.ndarray  # (n_dof,) coordinates, flattened
    mu: np.ndarray  # (n_act,) Lagrange multipliers (= -actuator moments)
    lam: float  # load factor
    t: float  # path parameter


@dataclasses.dataclass
class _Eval:
    """Everything computed at one iterate."""

    ev: Any
    terms: Any
    r: np.ndarray  # (n_dof,) f_int - lam P + G^T mu (all DOFs)
    c: np.ndarray  # (n_act,) rho - target


class _Failed(Exception):
    def __init__(self, why: str, residuals: list[float]) -> None:
        super().__init__(why)
        self.why = why
        self.residuals = residuals


class _Driver:
    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.model = model = scene.model
        self.opts = scene.options
        self.X0 = np.asarray(model.X0, float)
        self.n_dof = self.X0.size
        self.fixed = scene.fixed.ravel()
        self.free = ~self.fixed
        if not self.free.any():
            raise ConfigError("every DOF is fixed by supports or prescribed displacements")
        check_scene(scene)  # separate parts, free rigid-body motions, non-finite input
        if self.opts.has_arc_stop() and scene.control != "arc_length":
            raise ConfigError(
                "options.arc_stop_* apply to control = 'arc_length' only; this scene uses "
                f"control = {scene.control!r}"
            )
        self.P = scene.loads.ravel()
        pres = scene.prescribed.ravel()
        self.u_pres = np.where(np.isfinite(pres), pres, 0.0)
        self.hinges = scene.actuator_hinges()
        self.n_act = len(self.hinges)
        self.schedule = np.radians(scene.actuator_schedule_deg())  # (steps+1, n_act)
        self.timer = Timer()
        ext = np.ptp(self.X0, axis=0)
        self.size = float(np.linalg.norm(ext)) or 1.0
        self.backend = get_backend(self.opts.linear_solver)
        terms0 = actuator_terms(model, self.X0, self.hinges)
        self.system = BorderedSystem(
            self.backend,
            self.free,
            terms0.dofs,
            self.timer,
            reuse=self.opts.reuses_factorization(scene.control),
            krylov_max=self.opts.krylov_max,
        )
        self.force_floor = self.opts.force_floor
        self.penalty: float | None = None
        self.records: list[dict[str, Any]] = []
        self.t_start = time.perf_counter()
        self.work = 0.0
        self._prev: _State | None = None
        self._prev2: _State | None = None
        self._retry_tangent = False  # next increment: tangent predictor (after a failure)
        self._samples: list[tuple[float, np.ndarray, np.ndarray]] = []
        self.c_scale = 1.0
        self.n_iter_last = 0  # Newton corrections of the last converged increment
        self._tol_abs: float | None = None  # absolute force tolerance at the last test
        self._inertia: int | None = None
        self.system.track_inertia = scene.control in ("load", "displacement")
        # what a change of the free-DOF tangent's inertia means under this control: a load
        # maximum (load control) or a turning point of the controlled displacement
        self._critical = "limit point" if scene.control == "load" else "snap-back"
        # leaving a flat start: the first increment is predicted by the rigid fold
        # (barhinge.solver.branch); its record says which branch was taken
        self._flat_start = bool(self.n_act and self.opts.flat_start == "rigid" and is_flat(model))
        self.flat_start_record: dict[str, Any] | None = None
        self._guide: RigidGuide | None = None
        # a folded start: conflicting actuators are named before solving (flat starts: by
        # the rigid predictor)
        clash = (
            None if self._flat_start else conflicting_actuators(model, scene.actuators, scene.steps)
        )
        self._start_events = [clash] if clash else []
        for ev in self._start_events:
            log.warning("%s: %s", scene.name or "solve", ev)
        # stability monitoring: inertia of the free-DOF tangent at every recorded state
        self.exact_inertia = self.opts.exact_inertia(scene.control)
        self._inc_serial = 0  # factorisations made before the current increment
        self._arc_s = 0.0  # chord length along the arc-length path (work integration)
        # per recorded step (state 1 on): Newton iterations of its converged increments,
        # increments (converged, failed), factorisations (all, of them for the inertia)
        self.step_stats: list[dict[str, int]] = []

    # ------------------------------------------------------------ schedules
    def targets(self, t: float) -> np.ndarray:
        """Actuator target angles (rad) at path parameter t (linear between rows)."""
        if not self.n_act:
            return np.zeros(0)
        s = t * self.scene.steps
        i = min(int(np.floor(s)), self.scene.steps - 1)
        f = s - i
        return (1 - f) * self.schedule[i] + f * self.schedule[i + 1]

    def fixed_coords(self, t: float) -> np.ndarray:
        return self.X0.ravel()[self.fixed] + t * self.u_pres[self.fixed]

    # ------------------------------------------------------------ evaluation
    def evaluate(self, st: _State, tangent: bool = True) -> _Eval:
        """Residual, constraints and (unless ``tangent`` is False) the tangent at ``st``."""
        t0 = time.perf_counter()
        X = st.x.reshape(-1, 3)
        tangent = tangent or self.force_floor is None or self.penalty is None
        ev = self.model.evaluate(X, tangent=tangent)
        self.timer.n_force_only += not tangent
        terms = actuator_terms(self.model, X, self.hinges)
        self.timer.assembly += time.perf_counter() - t0
        r = np.asarray(ev.force, float).ravel() - st.lam * self.P
        if self.n_act:
            r = r + terms.G.T @ st.mu
        c = terms.rho - self.targets(st.t) if self.n_act else np.zeros(0)
        if self.n_act:
            c = (c + np.pi) % (2 * np.pi) - np.pi
        if self.force_floor is None:
            d = np.abs(ev.K.diagonal())
            self.force_floor = 1e-12 * float(d.max() if d.size else 1.0) * self.size
        if self.penalty is None:
            self.penalty = self._auto_penalty(ev.K, terms)
        return _Eval(ev, terms, r, c)

    def _auto_penalty(self, K, terms) -> float:
        a = self.opts.augmentation
        self.c_scale = 1.0
        d = np.abs(K.diagonal())
        if not self.n_act:
            return 0.0
        dd = d[terms.dofs.ravel()]
        kd = float(np.mean(dd)) if dd.size and np.mean(dd) > 0 else 1.0
        g2 = float(np.mean(np.sum(terms.grad**2, axis=1)))
        self.c_scale = kd / np.sqrt(g2) if g2 > 0 else kd
        if a != "auto":
            return float(a)
        return kd / g2 if g2 > 0 else kd

    def factorize(self, e: _Eval, st: _State, reuse: bool = False) -> None:
        """Make the tangent at ``st`` the operator of the bordered system and factorise it
        (``reuse``: unless the system keeps an earlier factorisation as GMRES
        preconditioner)."""
        self.system.row_scale = self.c_scale
        check_finite_tangent(e.ev.K)  # NaN / inf never reach the factorisation
        self.system.set_operator(e.ev.K, e.terms, st.mu, self.penalty or 0.0, factorize=not reuse)

    def forcing(self, e: _Eval, st: _State, rf: float) -> float:
        """Relative tolerance of an inexact (GMRES) Newton solve: follows the relative
        residual (keeps the quadratic rate; Dembo, Eisenstat & Steihaug 1982), capped at
        1e-3, and never tighter than a tenth of what the convergence test needs."""
        fref = self.force_ref(e, st)
        s = self.c_scale
        cmax = float(np.linalg.norm(e.c)) if self.n_act else 0.0
        bnorm = float(np.hypot(rf, s * cmax)) or 1.0
        need = min(self.opts.tol_force * fref + self.force_floor, s * self.opts.tol_angle)
        eta = min(1e-3, max(rf / fref, 0.1 * need / bnorm))
        return max(eta, 1e-13)

    def force_ref(self, e: _Eval, st: _State) -> float:
        """Force scale of the convergence test."""
        parts = [float(np.linalg.norm(st.lam * self.P)), float(self.force_floor)]
        f = np.asarray(e.ev.force, float).ravel()
        parts.append(float(np.linalg.norm(f[self.fixed])) if self.fixed.any() else 0.0)
        if self.n_act:
            parts.append(float(np.linalg.norm(e.terms.G.T @ st.mu)))
        return max(parts)

    def converged(self, e: _Eval, st: _State, dx: np.ndarray, res: list[float]) -> bool:
        o = self.opts
        rf = float(np.linalg.norm(e.r[self.free]))
        self._tol_abs = o.tol_force * self.force_ref(e, st) + self.force_floor
        ok_f = rf <= self._tol_abs
        ok_x = float(np.linalg.norm(dx)) <= o.tol_disp * self.size
        if not ok_x and len(res) >= 2 and rf < 1e-3 * res[-2]:
            ok_x = True
        if not ok_x and ok_f and len(res) >= 2 and rf <= 0.5 * res[-2]:
            # contracting iteration (ratio q): the remaining error is at most about
            # |dx| q / (1 - q) (linear rate; less in the quadratic regime). Saves the
            # confirming iterations at the round-off floor of the force residual.
            q = rf / res[-2]
            ok_x = float(np.linalg.norm(dx)) * q / (1 - q) <= o.tol_disp * self.size
        ok_c = (not self.n_act) or float(np.max(np.abs(e.c))) <= o.tol_angle
        return ok_f and ok_x and ok_c

    # ------------------------------------------------------------ one increment
    def increment(self, st: _State, t1: float, lam1: float) -> tuple[_State, _Eval, list[float]]:
        """Newton from the converged state ``st`` to path parameter t1 (load factor lam1).

        Predictor (option ``predictor``): extrapolation through the last three (quadratic)
        or two (secant) converged states, otherwise a tangent step at ``st`` with the
        prescribed displacements and new targets linearised. Correctors: Newton with the
        analytic tangent and an optional backtracking line search on the merit
        ``|r_free|^2 + (s c)^2``. An iterate expected to pass the force test is evaluated
        without the tangent first (assembled afterwards if it does not pass).
        """
        o = self.opts
        free, fixed = self.free, self.fixed
        res: list[float] = []
        self.system.inertia_seen = []
        prev = self._prev
        prev2 = self._prev2
        extrapolate = o.predictor in ("secant", "quadratic") and not self._retry_tangent
        guided = self._guided_prediction(st, t1, lam1)
        if guided is not None:
            new = guided
        elif prev is not None and prev.t < st.t and extrapolate:
            if o.predictor == "quadratic" and prev2 is not None and prev2.t < prev.t:
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
            new = _State(x, mu, lam1, t1)
            new.x[fixed] = self.fixed_coords(t1)
        else:
            e = self.evaluate(st)
            du_c = self.fixed_coords(t1) - st.x[fixed]
            rhs = -(e.r - (lam1 - st.lam) * self.P)
            if du_c.size and np.any(du_c):
                dfull = np.zeros(self.n_dof)
                dfull[fixed] = du_c
                rhs = rhs - e.ev.K @ dfull
            c_pred = e.c + (self.targets(st.t) - self.targets(t1)) if self.n_act else e.c
            self._factorize_or_fail(e, st, res, reuse=True)
            dx, dmu = self.system.solve(rhs[free], -c_pred, rtol=1e-6)
            new = _State(st.x.copy(), st.mu + dmu, lam1, t1)
            new.x[free] += dx
            new.x[fixed] = self.fixed_coords(t1)
        x_pred = new.x.copy()
        e = self.evaluate(new)
        dx_last: np.ndarray | None = None
        n_iter = 0
        while True:
            rf = float(np.linalg.norm(e.r[free]))
            res.append(rf)
            self.timer.n_iterations += 1
            if not np.isfinite(rf) or not np.all(np.isfinite(e.c)):
                raise _Failed("non-finite residual", res)
            if dx_last is not None and self.converged(e, new, dx_last, res):
                self.n_iter_last = n_iter
                self._check_inertia(res)
                self._check_jump(st, x_pred, new, res)
                return new, e, res
            if n_iter >= o.max_iter:
                raise _Failed(f"no convergence in {o.max_iter} iterations", res)
            if len(res) > 2 and rf > o.divergence_ratio * max(res[0], self.force_floor):
                raise _Failed("residual diverged", res)
            if e.ev.K is None:  # evaluated without tangent (convergence was expected)
                e = self.evaluate(new)
            # the first correction always factorises: the predictor's bar forces change the
            # tangent too much for the previous factorisation to precondition it
            self._factorize_or_fail(e, new, res, reuse=n_iter > 0)
            n_iter += 1
            dx, dmu = self.system.solve(-e.r[free], -e.c, rtol=self.forcing(e, new, rf))
            new, e, alpha = self._line_search(new, e, dx, dmu, self._expects_convergence(res))
            dx_last = alpha * dx

    def _guided_prediction(self, st: _State, t1: float, lam1: float) -> _State | None:
        """Rigid-fold prediction of the increment to ``t1`` (None: use the usual predictor).

        Off a flat start the first increment is always predicted by the rigid fold of the
        schedule (:func:`barhinge.solver.branch.rigid_guide`). Where the actuators leave free
        motions, the increments that follow are predicted along it too,
        ``x = X_rigid(t1) + (x - X_rigid(t))``, so the model follows the branch of least
        fold-spring energy that the rigid fold chose instead of the first equilibrium its
        own extrapolation meets."""
        if not self._flat_start or self._retry_tangent:
            return None
        if self._guide is None and self.flat_start_record is None:
            target = self.X0.ravel().copy()
            target[self.fixed] = self.fixed_coords(0.0)
            self._guide = rigid_guide(
                self.model,
                self.scene.actuators,
                self.scene.steps,
                self.fixed.reshape(-1, 3),
                target.reshape(-1, 3),
            )
            self.flat_start_record = (
                self._guide.record
                if self._guide is not None
                else {"predictor": "tangent (no rigid fold found)"}
            )
        g = self._guide
        if g is None or t1 > g.t_max + 1e-12:
            return None
        if st.t > 0.0 and not g.record.get("free_dof"):
            return None
        x = g.at(t1).ravel() + (st.x - g.at(st.t).ravel())
        new = _State(x, st.mu.copy(), lam1, t1)
        new.x[self.fixed] = self.fixed_coords(t1)
        return new

    def branch_events(self) -> list[str]:
        """Events of the flat start: the rigid predictor's, and creases of the last state
        that fold against their M/V assignment."""
        rec = self.flat_start_record
        if not self.records or not (self.n_act and is_flat(self.model)):
            return list(self._start_events)
        rec = rec or {}
        events = list(rec.get("events", []))
        bad = creases_against_assignment(
            self.model, self.records[-1]["fold"], mirrored=bool(rec.get("mirrored", False))
        )
        if bad:
            events.append(
                f"{len(bad)} crease(s) fold against their M/V assignment by more than 1 deg "
                f"(edges {bad[:10]}{' ...' if len(bad) > 10 else ''}): the panels bend "
                "instead of following the assigned mode (stiffer panels or more actuators "
                "follow it)"
            )
        return events

    def _check_inertia(self, res: list[float]) -> None:
        """Under load control an increment must not cross a critical point: the number of
        negative pivots of the tangent (its negative eigenvalues) must not change. A change
        means a limit point (or bifurcation) lies inside the increment and Newton jumped to
        another branch; the increment is rejected (and cut back until the cap)."""
        sysm = self.system
        if not sysm.track_inertia:
            return
        seen = [n for n in sysm.inertia_seen if n is not None]
        sysm.inertia_seen = []
        if self._inertia is None and seen:
            self._inertia = seen[0]
        bad = [n for n in seen if n != self._inertia]
        if bad:
            raise _Failed(
                f"{self._critical}: the tangent's negative eigenvalues went from "
                f"{self._inertia} to {bad[0]} inside the increment (use control = 'arc_length' "
                "to pass it)",
                res,
            )

    def _check_jump(self, st: _State, x_pred: np.ndarray, new: _State, res: list[float]) -> None:
        """Under load control the Newton correction must stay smaller than the predictor
        step (``|x - x_pred| <= |x_pred - x_start|``); a larger one means Newton left the
        branch (snapped over a limit point to a distant equilibrium)."""
        if not self.system.track_inertia:
            return
        step = float(np.linalg.norm(x_pred - st.x))
        corr = float(np.linalg.norm(new.x - x_pred))
        if corr > step + self.opts.tol_disp * self.size:
            raise _Failed(
                f"{self._critical}: Newton left the branch (correction {corr:.3g} > predictor step "
                f"{step:.3g}; use control = 'arc_length' to pass it)",
                res,
            )

    def _tangent_inertia(self, st: _State, e: _Eval, exact: bool) -> int | None:
        """Negative eigenvalues of the free-DOF tangent at the converged state ``st``
        (actuators released; :meth:`BorderedSystem.tangent_negative_eigenvalues`).

        ``exact``: factorise the tangent at ``st`` (one factorisation). Otherwise the count
        of the last factorisation Newton made since :attr:`_inc_serial` (the tangent one
        iterate before convergence), None if there was none."""
        if exact:
            if e.ev.K is None:  # evaluated without the tangent (force-only)
                e = self.evaluate(st)
            try:
                self.factorize(e, st)
            except SingularMatrixError as exc:
                log.debug("tangent at load factor %.6g not factorised: %s", st.lam, exc)
                return None
        elif self.timer.n_factorizations <= self._inc_serial:
            return None
        return self.system.tangent_negative_eigenvalues()

    def _state_inertia(self, st: _State, e: _Eval) -> int | None:
        """Inertia of a converged state for its record (option ``stability_check``): exact,
        or the free count of the increment's last factorisation, confirmed by an exact one
        when it differs from the previous state's (or is unknown). The iterate before
        convergence can lie on the other side of a soft mode whose eigenvalue is small
        against the tangent's change over one Newton correction (measured: -0.25 against
        1.4e5 on a seeded degree-4 vertex), so an unconfirmed change would be a false
        event; a true change the last iterate did not see is reported one step late."""
        if self.exact_inertia:
            return self._tangent_inertia(st, e, exact=True)
        n = self._tangent_inertia(st, e, exact=False)
        prev = next((r["neg"] for r in reversed(self.records) if r["neg"] is not None), None)
        if n is None or n != prev:
            return self._tangent_inertia(st, e, exact=True)
        return n

    def _stability_events(self) -> list[str]:
        """Events where the free-DOF tangent's number of negative eigenvalues changes between
        consecutive recorded states. Under arc length a change where the load factor has an
        extremum is a limit point, one without a bifurcation (or the start of a
        negative-stiffness branch); under the other controls it marks a negative-stiffness
        branch entered or left."""
        rec = self.records
        lam = np.array([r["lam"] for r in rec])
        known = [(i, r["neg"]) for i, r in enumerate(rec) if r.get("neg") is not None]
        events = []
        for (j, a), (i, b) in zip(known, known[1:], strict=False):
            if a == b:
                continue
            change = f"negative eigenvalues of the tangent {a} -> {b}"
            if self.scene.control == "arc_length":
                win = lam[max(j - 1, 0) : i + 2]
                d = np.diff(win)
                d = d[d != 0]
                turns = np.flatnonzero(np.sign(d[1:]) != np.sign(d[:-1]))
                if turns.size and d[turns[0]] > 0:
                    what, at = "limit point (load maximum)", float(win.max())
                elif turns.size:
                    what, at = "limit point (load minimum)", float(win.min())
                else:
                    what, at = "bifurcation (or negative-stiffness branch)", float(lam[i])
                events.append(f"{what} at load factor {at:.6g} (state {i}: {change})")
            else:
                what = "entered" if b > a else "left"
                where = f"step {i}" if i == j + 1 else f"between steps {j} and {i}"
                events.append(
                    f"negative-stiffness branch {what} at {where}, load factor "
                    f"{lam[i]:.6g} ({change})"
                )
        return events

    def _work_balance(self) -> tuple[dict[str, float], str | None]:
        """External work against the change of stored energy over the recorded path; the
        mismatch relative to the largest work or energy change met along the path (a path
        that returns to a stress-free state has both near zero at its end)."""
        rec = self.records
        energy = np.array([r["eb"] + r["ebend"] + r["efold"] for r in rec])
        works = np.array([r["work"] for r in rec])
        work, de = float(works[-1]), float(energy[-1] - energy[0])
        scale = float(max(np.abs(works).max(), np.abs(energy - energy[0]).max()))
        # below the energy of the force floor over the model's size the two are round-off
        floor = float(self.force_floor or 0.0) * self.size
        rel = abs(work - de) / scale if scale > 0 and abs(work - de) > floor else 0.0
        bal = {"work": work, "energy": de, "rel_mismatch": rel, "tolerance": WORK_TOLERANCE}
        if rel <= WORK_TOLERANCE:
            return bal, None
        return bal, (
            f"work balance: external work {work:.6g} against stored energy {de:.6g} "
            f"(relative mismatch {rel:.2g} > {WORK_TOLERANCE:g}): steps too coarse for the "
            "work integration, or a state off equilibrium"
        )

    def _merit(self, e: _Eval) -> float:
        return float(e.r[self.free] @ e.r[self.free]) + float(
            (self.c_scale * e.c) @ e.c * self.c_scale
        )

    def _expects_convergence(self, res: list[float]) -> bool:
        """Whether the next iterate will probably pass the force test: in the quadratic
        regime ``r_{k+1} ~ r_k^3 / r_{k-1}^2``. Then it is evaluated without the tangent
        (a quarter of the cost; the tangent follows if the guess was wrong)."""
        if len(res) < 2 or not res[-2] > 0 or self._tol_abs is None:
            return False
        q = res[-1] / res[-2]
        return q < 0.1 and res[-1] * q * q <= 0.5 * self._tol_abs

    def _line_search(
        self, st: _State, e: _Eval, dx: np.ndarray, dmu: np.ndarray, light: bool = False
    ):
        """Backtracking (Armijo) on the merit function; the trial evaluation is reused
        (``light``: the full step is evaluated without the tangent)."""
        phi0 = self._merit(e)
        alpha = 1.0
        for k in range(self.opts.line_search + 1):
            trial = _State(st.x.copy(), st.mu + alpha * dmu, st.lam, st.t)
            trial.x[self.free] += alpha * dx
            et = self.evaluate(trial, tangent=not (light and k == 0))
            phi = self._merit(et)
            if (
                np.isfinite(phi) and phi <= (1 - 1e-4 * alpha) * phi0
            ) or k == self.opts.line_search:
                return trial, et, alpha
            alpha *= 0.5
        raise AssertionError("unreachable")

    def _factorize_or_fail(
        self, e: _Eval, st: _State, res: list[float], reuse: bool = False
    ) -> None:
        try:
            self.factorize(e, st, reuse)
        except SingularMatrixError as exc:
            raise _Failed(f"singular tangent ({exc})", res) from None

    # ------------------------------------------------------------ records
    def record(
        self, st: _State, e: _Eval, iters: int, res: list[float], neg: int | None = None
    ) -> None:
        """Append the converged state ``st`` (``neg``: negative eigenvalues of its free-DOF
        tangent, None if unknown)."""
        X = st.x.reshape(-1, 3)
        ev = e.ev
        R = np.zeros(self.n_dof)
        R[self.fixed] = e.r[self.fixed]  # f_int + G^T mu - lam P at supports
        moments = -st.mu
        self.records.append(
            {
                "X": X.copy(),
                "fold": np.asarray(self.model.crease_fold_angles_deg(X), float),
                "targets": np.degrees(self.targets(st.t)),
                "moments": moments.copy(),
                "rho": e.terms.rho.copy(),
                "eb": float(ev.energy_bars),
                "ebend": float(ev.energy_bend),
                "efold": float(ev.energy_fold),
                "R": R.reshape(-1, 3),
                "lam": st.lam,
                "iters": iters,
                "res": tuple(res),
                "wall": time.perf_counter() - self.t_start,
                "work": self.work,
                "neg": neg,
            }
        )

    def path(self, converged: bool = True, message: str = "") -> FoldPath:
        rec = self.records
        acts = self.scene.actuators
        edges = acts.edges if acts is not None else np.zeros(0, np.int64)
        meta = {
            "scene": self.scene.name,
            "control": self.scene.control,
            "steps": self.scene.steps,
            "scheme": str(getattr(self.model, "scheme", "")),
            "n_dof": int(self.n_dof),
            "n_free": int(self.free.sum()),
            "linear_solver": self.backend.name,
            "auto_restrained": bool(self.scene.auto_restrained),
            "timing": self.timer.as_dict(),
            "flat_start": self.flat_start_record,
            "branch_events": self.branch_events(),
            "newton": self._newton_summary(),
        }
        meta["negative_eigenvalues"] = [r.get("neg") for r in rec]
        events = meta["branch_events"] + self._stability_events()
        meta["work_balance"], unbalanced = self._work_balance()
        if unbalanced:
            events.append(unbalanced)
        for ev in events:
            log.warning("%s: %s", self.scene.name or "solve", ev)
        meta["events"] = events
        return FoldPath(
            X=np.stack([r["X"] for r in rec]),
            fold_angles_deg=np.stack([r["fold"] for r in rec]),
            actuator_edges=edges,
            actuator_targets_deg=np.stack([r["targets"] for r in rec]).reshape(len(rec), -1),
            actuator_moments=np.stack([r["moments"] for r in rec]).reshape(len(rec), -1),
            energy_bars=np.array([r["eb"] for r in rec]),
            energy_bend=np.array([r["ebend"] for r in rec]),
            energy_fold=np.array([r["efold"] for r in rec]),
            reactions=np.stack([r["R"] for r in rec]),
            load_factor=np.array([r["lam"] for r in rec]),
            iterations=np.array([r["iters"] for r in rec]),
            residual_norms=tuple(r["res"] for r in rec),
            wall_time=np.array([r["wall"] for r in rec]),
            external_work=np.array([r["work"] for r in rec]),
            converged=converged,
            message=message,
            kind="bar-hinge",
            meta=meta,
        )

    def _newton_summary(self) -> dict[str, Any]:
        """Step control per recorded step (``FoldPath.meta["newton"]``): lists over the
        states 1.. of Newton iterations (converged increments only), increments, failed
        increments (redone shorter), factorisations (all) and those made to confirm the
        tangent's inertia at the state; totals alongside. Under arc length every state is
        one increment and only the iterations are listed."""
        if not self.step_stats:
            its = [int(r["iters"]) for r in self.records[1:]]
            return {"iterations": its, "total_iterations": int(sum(its))}
        keys = ("iterations", "increments", "failed", "factorizations", "inertia_factorizations")
        out: dict[str, Any] = {k: [d[k] for d in self.step_stats] for k in keys}
        for k in keys:
            out[f"total_{k}"] = int(sum(out[k]))
        return out

    def interrupted_path(self) -> FoldPath | None:
        """The converged part after a Ctrl-C (``meta["stopped"] = "interrupted"``); None
        before state 0."""
        if not self.records:
            return None
        n = len(self.records) - 1
        lam = float(self.records[-1]["lam"])
        msg = f"interrupted (Ctrl-C) after {n} converged steps, at load factor {lam:.6g}"
        path = self.path(converged=False, message=msg)
        path.meta["stopped"] = "interrupted"
        return path

    def fail(self, step: int, lam: float, why: str, res: list[float]) -> ConvergenceError:
        msg = (
            f"step {step} of {self.scene.steps} did not converge at load factor {lam:.6g} "
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
    def initial(self) -> tuple[_State, _Eval]:
        st = _State(self.X0.ravel().copy(), np.zeros(self.n_act), 0.0, 0.0)
        e = self.evaluate(st)
        if self.n_act:
            # multipliers that balance the initial state best (zero for a stress-free start)
            # least squares min |r_free + G^T mu| through the normal equations (n_act x n_act)
            G = e.terms.G[:, self.free]
            GGt = (G @ G.T).toarray()
            mu, *_ = np.linalg.lstsq(GGt, -(G @ e.r[self.free]), rcond=None)
            st.mu = mu
            e = self.evaluate(st)
        return st, e

    # ------------------------------------------------------------ drivers
    def run_parameter(self, progress: Progress | None) -> FoldPath:
        """Fold-angle, displacement and load control: t (= load factor) from 0 to 1."""
        o = self.opts
        steps = self.scene.steps
        st, e = self.initial()
        self.record(st, e, 0, [], neg=self._tangent_inertia(st, e, exact=True))
        h0 = 1.0 / steps
        h = h0
        h_min = h0 * 0.5**o.max_cutbacks
        for s in range(1, steps + 1):
            t_goal = s / steps
            iters, res_all = 0, []
            n_inc = n_failed = 0
            fact0 = self.timer.n_factorizations
            critical = ""  # a limit-point diagnosis from any attempt since the last success
            while st.t < t_goal - 1e-12 * h0:
                h_try = min(h, t_goal - st.t)
                t1 = t_goal if h_try >= t_goal - st.t - 1e-12 * h0 else st.t + h_try
                self._inc_serial = self.timer.n_factorizations
                try:
                    new, e_new, res = self.increment(st, t1, t1)
                except _Failed as f:
                    log.debug(
                        "step %d: increment to t=%.6g failed (%s); cutting back", s, t1, f.why
                    )
                    n_failed += 1
                    if f.why.startswith(self._critical):
                        critical = f.why
                    elif self.system.track_inertia and self._inertia is not None:
                        seen = [n for n in self.system.inertia_seen if n is not None]
                        bad = [n for n in seen if n != self._inertia]
                        if bad:
                            critical = (
                                f"{self._critical}: the tangent's negative eigenvalues went from "
                                f"{self._inertia} to {bad[0]} while iterating ({f.why}); use "
                                "control = 'arc_length' to pass it"
                            )
                    rec = self.flat_start_record or {}
                    if st.t == 0.0 and rec.get("least_squares") and not self._retry_tangent:
                        # the rigid fold could only meet the targets in least squares (the
                        # actuators conflict): the panels must bend, and Newton may not
                        # reach that from the rigid prediction; retry from the tangent
                        self._retry_tangent = True
                        continue
                    if (
                        not self._retry_tangent
                        and self._prev is not None
                        and (self.opts.predictor != "tangent")
                    ):
                        # an extrapolating predictor failed: retry the same increment once
                        # with the tangent predictor before cutting back (near a soft mode
                        # the extrapolated start can lie outside Newton's basin)
                        self._retry_tangent = True
                        continue
                    self._retry_tangent = False
                    h = h_try / 2
                    if h < h_min * (1 - 1e-9):
                        # near a critical point the smallest increments may simply find no
                        # solution; name the critical point if one was detected on the way
                        raise self.fail(s, st.lam, critical or f.why, f.residuals) from None
                    continue
                self._retry_tangent = False
                self._work_simpson(new, e_new)
                critical = ""
                self._prev2, self._prev, st = self._prev, st, new
                self._inertia = self.system.negative_pivots
                iters += self.n_iter_last
                n_inc += 1
                res_all.extend(res)
                if self.n_iter_last <= o.grow_iters:
                    h = min(2 * h_try, h0)
            fact1 = self.timer.n_factorizations
            neg = self._state_inertia(st, e_new)
            self.step_stats.append(
                {
                    "iterations": iters,
                    "increments": n_inc,
                    "failed": n_failed,
                    "factorizations": self.timer.n_factorizations - fact0,
                    "inertia_factorizations": self.timer.n_factorizations - fact1,
                }
            )
            self.record(st, e_new, iters, res_all, neg=neg)
            if progress is not None:
                progress(s, steps, st.t)
        return self.path()

    def _work_sample(self, t: float, st: _State, e: _Eval) -> tuple[float, np.ndarray, np.ndarray]:
        """(t, q, F): generalised coordinates (x, actuator angles) and the forces doing work
        on them (loads + reactions, actuator moments)."""
        R = np.zeros(self.n_dof)
        R[self.fixed] = e.r[self.fixed]
        q = np.concatenate([st.x, e.terms.rho])
        F = np.concatenate([st.lam * self.P + R, -st.mu])
        return t, q, F

    def _work_simpson(self, new: _State, e_new: _Eval, s: float | None = None) -> None:
        """Work of the increment ending at ``new``: ``int F . dq`` with F and q interpolated
        quadratically in the path parameter (t, or ``s`` when given: the chord length under
        arc length) through the last three converged increments and Simpson's rule on the
        last interval (exact for the cubic integrand: third-order accurate); the
        trapezoidal rule on the first increment."""
        if not self._samples:
            st0 = _State(
                self.records[0]["X"].ravel(),
                -self.records[0]["moments"],
                self.records[0]["lam"],
                0.0,
            )
            R0 = self.records[0]["R"].ravel()
            self._samples.append(
                (
                    0.0,
                    np.concatenate([st0.x, self.records[0]["rho"]]),
                    np.concatenate([st0.lam * self.P + R0, -st0.mu]),
                )
            )
        self._samples.append(self._work_sample(new.t if s is None else s, new, e_new))
        self._samples = self._samples[-3:]
        if len(self._samples) == 2:
            (_, q0, F0), (_, q1, F1) = self._samples
            self.work += 0.5 * float((F0 + F1) @ (q1 - q0))
            return
        (ta, qa, Fa), (tb, qb, Fb), (tc, qc, Fc) = self._samples
        h = tc - tb
        w = 0.0
        for s_, wt in ((tb, 1.0), (0.5 * (tb + tc), 4.0), (tc, 1.0)):
            la = (s_ - tb) * (s_ - tc) / ((ta - tb) * (ta - tc))
            lb = (s_ - ta) * (s_ - tc) / ((tb - ta) * (tb - tc))
            lc = (s_ - ta) * (s_ - tb) / ((tc - ta) * (tc - tb))
            da = (2 * s_ - tb - tc) / ((ta - tb) * (ta - tc))
            db = (2 * s_ - ta - tc) / ((tb - ta) * (tb - tc))
            dc = (2 * s_ - ta - tb) / ((tc - ta) * (tc - tb))
            F = la * Fa + lb * Fb + lc * Fc
            dq = da * qa + db * qb + dc * qc
            w += wt * float(F @ dq)
        self.work += h / 6.0 * w

    def run_arc_length(self, progress: Progress | None) -> FoldPath:
        """MGDCM arc length (Leon et al. 2011): states at every increment until a stop
        criterion is met (``options.arc_stop_*``; by default the load factor 1). The
        increment that passes a load-factor or displacement stop is replaced by a correction
        onto exactly that value (from the state before it, else back from the state past
        it); a limit-point stop ends at the first state past the last limit point counted.
        Raises ConvergenceError when an increment fails after its cut-backs, when the step
        cap comes first, or when a landing fails: a path that did not reach its stop is
        never returned as converged."""
        o = self.opts
        steps = self.scene.steps
        max_steps = o.max_arc_steps or 10 * steps
        dl0 = o.arc_length_increment or 1.0 / steps
        lam_stop = o.arc_stop_lambda()
        disp = self._displacement_stop()
        st, e = self.initial()
        self.record(st, e, 0, [])
        first_tan: np.ndarray | None = None
        prev_tan: np.ndarray | None = None
        sign = 1.0
        n = 0
        limit_points = 0
        prev_dlam = 0.0
        stop: dict[str, Any] | None = None
        while stop is None and n < max_steps:
            n += 1
            # the tangent at the converged state: its inertia for the record, and the
            # factorisation of this increment's first attempt
            e = self.evaluate(st)
            try:
                self.factorize(e, st)
                factored = True
                self.records[-1]["neg"] = self.system.tangent_negative_eigenvalues()
            except SingularMatrixError:
                factored = False  # the attempt raises its own failure
            scale = dl0
            for _cut in range(o.max_cutbacks + 1):
                try:
                    new, e_new, res, tan, sgn = self._arc_increment(
                        st, e, scale, first_tan, prev_tan, sign, factored
                    )
                    break
                except _Failed as f:
                    factored = False
                    scale /= 2
                    last = f
            else:
                raise self.fail(n, st.lam, last.why, last.residuals)
            if first_tan is None:
                first_tan = tan
            prev_tan, sign = tan, sgn
            dlam = new.lam - st.lam
            if prev_dlam * dlam < 0.0:
                limit_points += 1  # the load factor turned between the last two increments
            prev_dlam = dlam if dlam != 0.0 else prev_dlam
            new, e_new, res, stop = self._arc_stop(st, new, e_new, res, lam_stop, disp)
            if stop is None and o.arc_stop_limit_points is not None:
                if limit_points >= o.arc_stop_limit_points:
                    stop = {"criterion": "limit_points", "value": limit_points}
            self._arc_s += float(np.linalg.norm(new.x - st.x))
            self._work_simpson(new, e_new, s=self._arc_s)
            st = new
            self.record(st, e_new, len(res) + 1, res)
            if progress is not None:
                progress(min(max(int(st.lam * steps), 0), steps), steps, st.lam)
        self.records[-1]["neg"] = self._tangent_inertia(st, e_new if n else e, exact=True)
        if stop is None:
            msg = (
                f"arc length stopped at its step cap (max_arc_steps = {max_steps}) at load "
                f"factor {st.lam:.6g} {self._arc_stop_text(lam_stop, disp)}"
            )
            raise ConvergenceError(
                msg, step=n, load_factor=st.lam, residuals=[],
                last_state=self.path(converged=False, message=msg),
            )  # fmt: skip
        path = self.path()
        path.meta["arc_stop"] = stop
        return path

    def _displacement_stop(self) -> tuple[int, float] | None:
        """(global DOF, target coordinate) of the displacement stop, checked against the
        model; None without one."""
        spec = self.opts.arc_stop_displacement
        if spec is None:
            return None
        if spec["node"] >= self.model.n_nodes:
            raise ConfigError(
                f"options.arc_stop_displacement.node = {spec['node']}; the model has "
                f"{self.model.n_nodes} nodes (0 to {self.model.n_nodes - 1})"
            )
        dof = displacement_stop_dof(spec)
        if not self.free[dof]:
            raise ConfigError(
                f"options.arc_stop_displacement: {spec['axis']} of node {spec['node']} is "
                "fixed by a support or a prescribed displacement; choose a free component"
            )
        return dof, float(self.X0.ravel()[dof] + spec["value"])

    def _arc_stop_text(self, lam_stop: float | None, disp: tuple[int, float] | None) -> str:
        """What the run was asked to reach, for the step-cap message."""
        if lam_stop is not None and disp is None and self.opts.arc_stop_limit_points is None:
            return f"of {lam_stop:g}"
        parts = [f"load factor {lam_stop:g}"] if lam_stop is not None else []
        if disp is not None:
            spec = self.opts.arc_stop_displacement
            parts.append(f"displacement {spec['axis']} = {spec['value']:g} of node {spec['node']}")
        if self.opts.arc_stop_limit_points is not None:
            parts.append(f"{self.opts.arc_stop_limit_points} limit point(s)")
        return "before reaching " + " or ".join(parts)

    def _arc_stop(self, st, new, e_new, res, lam_stop, disp):
        """Whether the increment ``st`` -> ``new`` passed a load-factor or displacement
        stop; if so the state landed exactly on it. Returns (state, evaluation, residuals,
        stop record or None)."""

        def crossed(a: float, b: float) -> bool:
            return a != 0.0 and (a * b < 0.0 or b == 0.0)

        candidates = []
        if lam_stop is not None and crossed(st.lam - lam_stop, new.lam - lam_stop):
            frac = (lam_stop - st.lam) / (new.lam - st.lam)
            candidates.append((frac, "load_factor"))
        if disp is not None:
            dof, target = disp
            if crossed(st.x[dof] - target, new.x[dof] - target):
                frac = (target - st.x[dof]) / (new.x[dof] - st.x[dof])
                candidates.append((frac, "displacement"))
        if not candidates:
            return new, e_new, res, None
        _, which = min(candidates)
        if which == "load_factor":
            if new.lam != lam_stop:
                new, e_new, res = self._land(st, new, lam_stop)
            return new, e_new, res, {"criterion": "load_factor", "value": lam_stop}
        dof, target = disp
        if new.x[dof] != target:
            new, e_new, res = self._land_displacement(st, new, dof, target)
        u = target - float(self.X0.ravel()[dof])
        return new, e_new, res, {"criterion": "displacement", "value": u}

    def _land(
        self, st: _State, past: _State, lam: float = 1.0
    ) -> tuple[_State, _Eval, list[float]]:
        """Correct onto load factor exactly ``lam`` by load control: from ``st`` (before
        it), else from ``past`` (the arc-length state beyond it) back. Raises
        ConvergenceError with the path up to ``st`` when both fail."""
        whys = []
        for start in (st, past):
            try:
                return self.increment(start, start.t, lam)
            except _Failed as f:
                whys.append(f.why)
        msg = (
            f"arc length passed load factor {lam:g} (from {st.lam:.6g} to {past.lam:.6g}) "
            f"but the correction onto {lam:g} failed ({whys[0]}; from the far side: {whys[1]})"
        )
        raise ConvergenceError(
            msg, step=len(self.records), load_factor=st.lam, residuals=[],
            last_state=self.path(converged=False, message=msg),
        )  # fmt: skip

    def _land_displacement(
        self, st: _State, past: _State, dof: int, target: float
    ) -> tuple[_State, _Eval, list[float]]:
        """Correct onto coordinate ``target`` of the global DOF ``dof`` (displacement
        control of that component, the load factor free), starting from the linear
        interpolation between ``st`` and ``past``. Raises ConvergenceError with the path up
        to ``st`` when Newton fails."""
        o = self.opts
        free = self.free
        k = int(np.count_nonzero(free[:dof]))  # position of dof among the free DOFs
        frac = (target - st.x[dof]) / (past.x[dof] - st.x[dof])
        new = _State(
            st.x + frac * (past.x - st.x),
            st.mu + frac * (past.mu - st.mu),
            st.lam + frac * (past.lam - st.lam),
            st.t,
        )
        new.x[dof] = target
        zc = np.zeros(self.n_act)
        res: list[float] = []
        dx = np.zeros(int(free.sum()))
        why = f"no convergence in {o.max_iter} iterations"
        for it in range(1, o.max_iter + 1):
            e = self.evaluate(new)
            rf = float(np.linalg.norm(e.r[free]))
            res.append(rf)
            self.timer.n_iterations += 1
            if not np.isfinite(rf):
                why = "non-finite residual"
                break
            if it > 1 and self.converged(e, new, dx, res):
                return new, e, res
            try:
                self.factorize(e, new)
            except SingularMatrixError as exc:
                why = f"singular tangent ({exc})"
                break
            uh, mh = self.system.solve(self.P[free], zc)
            ub, mb = self.system.solve(-e.r[free], -e.c)
            if uh[k] == 0.0:
                why = "the load does not move the stopping component"
                break
            dl = -float(ub[k]) / float(uh[k])
            dx = dl * uh + ub
            new.x[free] += dx
            new.mu = new.mu + dl * mh + mb
            new.lam += dl
        msg = f"arc length passed its displacement stop but the correction onto it failed ({why})"
        raise ConvergenceError(
            msg, step=len(self.records), load_factor=st.lam, residuals=res,
            last_state=self.path(converged=False, message=msg),
        )  # fmt: skip

    def _arc_increment(self, st, e, dl0, first_tan, prev_tan, sign, factored=False):
        """One MGDCM increment from ``st`` (``e`` its evaluation; ``factored``: the system
        holds the factorisation of its tangent): predictor with the GSP-scaled load
        increment, correctors with ``dlambda = -(du_1 . du_bar)/(du_1 . du_hat)`` (Leon et
        al. 2011)."""
        o = self.opts
        free = self.free
        res: list[float] = []
        if not factored:
            try:
                self.factorize(e, st)
            except SingularMatrixError as exc:
                raise _Failed(f"singular tangent ({exc})", res) from None
        zc = np.zeros(self.n_act)
        u_hat, mu_hat = self.system.solve(self.P[free], zc)
        sgn = gdcm_sign(prev_tan, u_hat, sign)
        base = first_tan if first_tan is not None else u_hat
        dlam = sgn * dl0 * gdcm_scale(base, prev_tan, u_hat)
        u_bar, mu_bar = self.system.solve(-e.r[free], -e.c)
        new = _State(st.x.copy(), st.mu + dlam * mu_hat + mu_bar, st.lam + dlam, st.t)
        dx = dlam * u_hat + u_bar
        new.x[free] += dx
        tan1 = u_hat
        it = 1
        while True:
            e = self.evaluate(new)
            rf = float(np.linalg.norm(e.r[free]))
            res.append(rf)
            self.timer.n_iterations += 1
            if not np.isfinite(rf):
                raise _Failed("non-finite residual", res)
            if it > 1 and self.converged(e, new, dx, res):
                return new, e, res, tan1, sgn
            if it >= o.max_iter:
                raise _Failed(f"no convergence in {o.max_iter} iterations", res)
            try:
                self.factorize(e, new)
            except SingularMatrixError as exc:
                raise _Failed(f"singular tangent ({exc})", res) from None
            uh, mh = self.system.solve(self.P[free], zc)
            ub, mb = self.system.solve(-e.r[free], -e.c)
            dl = -float(tan1 @ ub) / float(tan1 @ uh)
            dx = dl * uh + ub
            new.x[free] += dx
            new.mu = new.mu + dl * mh + mb
            new.lam += dl
            it += 1


@threads_for_sparse
def solve(scene: Scene, progress: Progress | None = None) -> FoldPath:
    """Solve a scene along its path; returns a :class:`~barhinge.results.FoldPath`.

    Parameters
    ----------
    scene : Scene
    progress : callable (done, total, value) -> None, optional
        Called after every requested step (value = path parameter or load factor).

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
    """
    d = _Driver(scene)
    try:
        if scene.control == "arc_length":
            return d.run_arc_length(progress)
        return d.run_parameter(progress)
    except KeyboardInterrupt:
        raise Interrupted(last_state=d.interrupted_path()) from None
