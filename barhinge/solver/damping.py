"""Damped Newton corrections (Levenberg-Marquardt) for a near-mechanism: increments off a
flat start that plain Newton fails (option ``damping``).

Near flat the folds resist a departure from the rigid fold at second order in the fold
angle and the bars only at fourth, so most of a large sheet is a near-mechanism: its tangent
has eigenvalues far below the fold springs' and the residual grows with the cube of the
motion along them. A plain Newton correction then overshoots along those modes by orders of
magnitude (residuals 0.16 -> 95 -> 0.026 -> 82 on a 100 x 100 Miura sheet; divergence at
200 x 200). The damped correction solves ``(K_t + delta I) dx = -r`` on the free DOFs (the
actuator rows as in plain Newton): a large ``delta`` turns it towards the residual (a short
step down the energy), a vanishing one gives back Newton's correction. ``delta`` starts at
``DAMPING_START`` times the mean free diagonal and follows the residual from correction to
correction (switched evolution relaxation: Mulder & van Leer 1985; Kelley & Keyes 1998,
SIAM J. Numer. Anal. 35, 508). A correction that raises the residual more than
``DAMPING_RISE`` times is redone from the same tangent with ``delta`` grown. Plain Newton
takes over (:meth:`Damping._hand_over`) once the residual has fallen to ``DAMPING_SWITCH`` of
its value after the increment's first kept correction, or once the damped corrections stop
gaining: near the equilibrium the soft modes' eigenvalues are far below any useful shift,
and damped corrections stagnate there (or alternate, where the panels bend). The progress is
measured from the first correction, not from the prediction: the prediction's residual is
mostly the stretch of its bars, which one correction takes out whatever the soft modes do.
On the second step of a 200 x 200 Miura fold (residual 1.1e4 predicted, 883 after the first
correction), Newton measured from the prediction took over at 6.3 and swung between 1.8 and
5e4 until it diverged eighteen corrections later; measured from the first correction it
takes over at 0.43 and the increment converges in 12 corrections.
"""

from __future__ import annotations

import numpy as np

from barhinge.solver.context import SolveContext
from barhinge.solver.convergence import Convergence
from barhinge.solver.state import Evaluation, IncrementFailed, State

__all__ = ["DAMPING_START", "Damping"]

#: first shift, as a fraction of the mean |diagonal| of the free tangent (the bars' axial
#: stiffness dominates it: 1e-5 of it is ~ the fold springs' scale in the quasi-rigid set)
DAMPING_START = 1e-5
#: growth of the shift after a rejected correction
DAMPING_GROW = 4.0
#: the residual ratio of kept corrections is clipped below at this before it scales the shift
DAMPING_FALL = 0.05
#: a correction may raise the residual this many times (non-monotone) before it is redone
DAMPING_RISE = 10.0
#: once the residual is this fraction of the one after the increment's first kept
#: correction, plain Newton corrections follow (near the solution the soft modes'
#: eigenvalues fall below any useful shift, and a damped correction stagnates)
DAMPING_SWITCH = 1e-3
#: plain Newton corrections follow as well once the best residual of this many kept
#: corrections is not below ``DAMPING_GAIN`` times the best before them (damped corrections
#: alternating without progress)
DAMPING_PATIENCE = 3
#: the fall of the best residual over ``DAMPING_PATIENCE`` kept corrections that counts as
#: progress (0.5 would hand over on the 200 x 200 Miura sheet's first step, whose
#: alternating lows halve)
DAMPING_GAIN = 0.6
#: a shift this many times the first one without a kept correction fails the increment
DAMPING_CEILING = 1e8


class Damping:
    """The shift of one increment's damped corrections (:meth:`reset` at its start)."""

    def __init__(self, ctx: SolveContext, conv: Convergence) -> None:
        self.ctx = ctx
        self.conv = conv
        self.start = 0.0  # force / length
        self.delta = 0.0
        self.kept: list[float] = []  # merits of the increment's kept corrections, force^2
        self.corrections = 0  # damped corrections kept, over the solve
        self.rejected = 0  # corrections redone with a larger shift, over the solve

    def reset(self, e: Evaluation) -> None:
        """First shift of an increment, from the free diagonal of ``e``'s tangent."""
        K = e.ev.K
        if K is None:
            raise ValueError("the damped increment starts from an evaluation with its tangent")
        d = np.abs(K.diagonal())[self.ctx.free]
        self.start = DAMPING_START * (float(d.mean()) if d.size and d.mean() > 0 else 1.0)
        self.delta = self.start
        self.kept = []

    def correction(
        self, st: State, e: Evaluation, res: list[float]
    ) -> tuple[State, Evaluation, np.ndarray, int]:
        """The kept damped correction from ``st``: (new state, its evaluation, the
        displacement correction, factorisations made). Raises IncrementFailed when no shift
        up to ``DAMPING_CEILING`` times the first keeps the residual's rise within
        ``DAMPING_RISE``."""
        ctx, conv = self.ctx, self.conv
        free = ctx.free
        m0 = conv.merit(e)
        n_fact = 0
        while True:
            ctx.factorize_or_fail(e, st, res, keep_operator=True, shift=self.delta)
            n_fact += 1
            dx, dmu = ctx.system.solve(-e.r[free], -e.c)
            trial = State(st.x.copy(), st.mu + dmu, st.lam, st.t)
            trial.x[free] += dx
            # with its tangent: a kept correction is followed by another one, mostly
            et = ctx.evaluate(trial)
            m1 = conv.merit(et)
            if np.isfinite(m1) and (m1 < DAMPING_RISE**2 * m0 or conv.passes(et, trial)):
                # switched evolution relaxation: the shift follows the residual
                ratio = float(np.sqrt(m1 / m0)) if m0 > 0 else DAMPING_FALL
                self.delta *= min(max(ratio, DAMPING_FALL), DAMPING_GROW)
                self.corrections += 1
                self.kept.append(m1)
                if self._hand_over():
                    self.delta = 0.0  # Newton's own rate from here
                return trial, et, dx, n_fact
            self.rejected += 1
            self.delta *= DAMPING_GROW
            if self.delta > DAMPING_CEILING * self.start:
                raise IncrementFailed(
                    f"damped Newton: every shift up to {DAMPING_CEILING:.0e} times the first "
                    f"raised the residual more than {DAMPING_RISE:g} times",
                    res,
                )

    def _hand_over(self) -> bool:
        """Whether plain Newton corrections follow the last kept one: its residual is
        ``DAMPING_SWITCH`` of the first kept correction's (the first takes out the
        prediction's bar stretch, so progress is measured from what it leaves), or the damped
        corrections stopped gaining (the best residual of the last ``DAMPING_PATIENCE`` is
        not below ``DAMPING_GAIN`` times the best before them)."""
        kept, n = self.kept, DAMPING_PATIENCE
        if kept[-1] < DAMPING_SWITCH**2 * kept[0]:
            return True
        return len(kept) > n and min(kept[-n:]) > DAMPING_GAIN**2 * min(kept[:-n])
