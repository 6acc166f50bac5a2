"""Stability along the path: the inertia of the free-DOF tangent (its number of negative
eigenvalues) at the converged states, the checks that reject an increment which crossed a
critical point under load or displacement control (:class:`InertiaMonitor`), and the
events read from the inertia of the recorded states (:func:`stability_events`)."""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np

from barhinge.linalg.backends import SingularMatrixError
from barhinge.solver.context import SolveContext
from barhinge.solver.state import Evaluation, IncrementFailed, State, StepRecord

__all__ = ["InertiaMonitor", "held_stability_events", "left_branch", "stability_events"]

log = logging.getLogger("barhinge.solver.newton")


def left_branch(ctx: SolveContext, st: State, x_pred: np.ndarray, new: State) -> str:
    """Why the converged state ``new`` left the branch of its increment from ``st``: it lies
    farther from the predictor ``x_pred`` than the predictor from ``st`` (length), so Newton
    may have jumped a critical point to a distant equilibrium; "" when it did not."""
    step = float(np.linalg.norm(x_pred - st.x))
    corr = float(np.linalg.norm(new.x - x_pred))
    if corr > step + ctx.opts.tol_disp * ctx.size:
        return f"correction {corr:.3g} > predictor step {step:.3g}"
    return ""


class InertiaMonitor:
    """Inertia of the tangent of one :class:`SolveContext` (its system's pivots)."""

    def __init__(self, ctx: SolveContext) -> None:
        self.ctx = ctx
        control = ctx.scene.control
        self.inertia: int | None = None  # negative pivots at the last converged state
        ctx.system.track_inertia = control in ("load", "displacement")
        # every increment of parameter control factorises before it solves: a large bordered
        # factor can go before the released tangent is factorised for its count
        ctx.system.release_before_count = control != "arc_length"
        # what a change of the free-DOF tangent's inertia means under this control: a load
        # maximum (load control) or a turning point of the controlled displacement
        self.critical = "limit point" if control == "load" else "snap-back"
        # stability monitoring: inertia of the free-DOF tangent at every recorded state
        self.exact = ctx.opts.exact_inertia(control)
        self.inc_serial = 0  # factorisations made before the current increment

    def check_inertia(self, res: list[float]) -> None:
        """Under load control an increment must not cross a critical point: the number of
        negative pivots of the tangent (its negative eigenvalues) must not change. A change
        means a limit point (or bifurcation) lies inside the increment and Newton jumped to
        another branch; the increment is rejected (and cut back until the cap)."""
        sysm = self.ctx.system
        if not sysm.track_inertia:
            return
        seen = [n for n in sysm.inertia_seen if n is not None]
        sysm.inertia_seen = []
        if self.inertia is None and seen:
            self.inertia = seen[0]
        bad = [n for n in seen if n != self.inertia]
        if bad:
            raise IncrementFailed(
                f"{self.critical}: the tangent's negative eigenvalues went from "
                f"{self.inertia} to {bad[0]} inside the increment (use control = 'arc_length' "
                "to pass it)",
                res,
            )

    def check_jump(self, st: State, x_pred: np.ndarray, new: State, res: list[float]) -> None:
        """Under load control the Newton correction must stay smaller than the predictor
        step (``|x - x_pred| <= |x_pred - x_start|``); a larger one means Newton left the
        branch (snapped over a limit point to a distant equilibrium)."""
        ctx = self.ctx
        if not ctx.system.track_inertia:
            return
        jump = left_branch(ctx, st, x_pred, new)
        if jump:
            raise IncrementFailed(
                f"{self.critical}: Newton left the branch ({jump}; use control = "
                "'arc_length' to pass it)",
                res,
            )

    def failure_text(self, why: str, held_before: int | None = None) -> str:
        """The critical point a failed increment met while iterating ("" if none); under
        fold-angle control the instability of the driven structure its iterates met, when
        the state it started from was stable with the actuators held (``held_before``
        negative eigenvalues: 0)."""
        sysm = self.ctx.system
        if why.startswith(self.critical):
            return why
        if sysm.track_inertia and self.inertia is not None:
            seen = [n for n in sysm.inertia_seen if n is not None]
            bad = [n for n in seen if n != self.inertia]
            if bad:
                return (
                    f"{self.critical}: the tangent's negative eigenvalues went from "
                    f"{self.inertia} to {bad[0]} while iterating ({why}); use "
                    "control = 'arc_length' to pass it"
                )
        unstable = [n for n in sysm.inertia_seen if n]
        if self.ctx.n_act and not sysm.track_inertia and held_before == 0 and unstable:
            # fold-angle control from a stable state: say what the iterates met
            return (
                f"{why}; the iterates' tangent was unstable with the actuators held (up to "
                f"{max(unstable)} negative eigenvalues): Newton met states no actuator can hold"
            )
        return ""

    def tangent_inertia(
        self, st: State, e: Evaluation, exact: bool
    ) -> tuple[int | None, int | None]:
        """Negative eigenvalues of the free-DOF tangent at the converged state ``st``:
        (actuators released, :meth:`BorderedSystem.tangent_negative_eigenvalues`; held
        actuators held, :meth:`BorderedSystem.held_negative_eigenvalues`, None without held
        actuators).

        ``exact``: factorise the tangent at ``st`` (one factorisation). Otherwise the counts
        of the last factorisation Newton made since :attr:`inc_serial` (the tangent one
        iterate before convergence), None if there was none."""
        ctx = self.ctx
        if exact:
            try:
                ctx.factorize(e, st)
            except SingularMatrixError as exc:
                log.debug("tangent at load factor %.6g not factorised: %s", st.lam, exc)
                return None, None
        elif ctx.timer.n_factorizations <= self.inc_serial:
            return None, None
        # the held count first: the released count may release the bordered factor
        held = ctx.system.held_negative_eigenvalues() if ctx.n_act else None
        return ctx.system.tangent_negative_eigenvalues(), held

    def state_inertia(
        self, st: State, e: Evaluation, prev: tuple[int | None, int | None]
    ) -> tuple[int | None, int | None]:
        """Inertia of a converged state for its record, (released, held) as
        :meth:`tangent_inertia` (option ``stability_check``): exact, or the counts of the
        increment's last factorisation, confirmed by an exact one when either differs from
        the previous state's (``prev``) or is unknown. The iterate before convergence can
        lie on the other side of a soft mode whose eigenvalue is small against the
        tangent's change over one Newton correction (measured: -0.25 against 1.4e5 on a
        seeded degree-4 vertex), so an unconfirmed change would be a false event; a true
        change the last iterate did not see is reported one step late."""
        if self.exact:
            return self.tangent_inertia(st, e, exact=True)
        n, held = self.tangent_inertia(st, e, exact=False)
        changed = n is None or n != prev[0]
        if self.ctx.n_act:
            changed = changed or held is None or held != prev[1]
        if changed:
            return self.tangent_inertia(st, e, exact=True)
        return n, held


def stability_events(records: Sequence[StepRecord], control: str) -> list[str]:
    """Events where the free-DOF tangent's number of negative eigenvalues changes between
    consecutive recorded states. Under arc length a change where the load factor has an
    extremum is a limit point, one without a bifurcation (or the start of a
    negative-stiffness branch); under the other controls it marks a negative-stiffness
    branch entered or left."""
    lam = np.array([r.lam for r in records])
    known = [(i, r.neg) for i, r in enumerate(records) if r.neg is not None]
    events = []
    for (j, a), (i, b) in zip(known, known[1:], strict=False):
        if a == b:
            continue
        change = f"negative eigenvalues of the tangent {a} -> {b}"
        if control == "arc_length":
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
                f"negative-stiffness branch {what} at {where}, load factor {lam[i]:.6g} ({change})"
            )
    return events


def held_stability_events(records: Sequence[StepRecord], control: str) -> list[str]:
    """Events where the equilibrium becomes unstable with the held actuators held (the
    tangent on the motions that keep every actuator angle has a negative eigenvalue: the
    driven structure itself would leave the state, whatever the actuators' moments), and
    where it is stable again. The count of the first state enters when it is nonzero."""
    known = [(i, r.neg_held) for i, r in enumerate(records) if r.neg_held is not None]
    events = []
    before = 0
    for i, n in known:
        if (n > 0) == (before > 0):
            before = n
            continue
        where = (
            "at the start"
            if i == 0
            else f"at {'state' if control == 'arc_length' else 'step'} {i}, load factor "
            f"{records[i].lam:.6g}"
        )
        change = f"negative eigenvalues of the tangent with the actuators held {before} -> {n}"
        if n > 0:
            events.append(
                f"unstable equilibrium with the actuators held {where} ({change}): the driven "
                "structure would leave this state, and the path from here follows an unstable "
                "branch"
            )
        else:
            events.append(f"stable again with the actuators held {where} ({change})")
        before = n
    return events
