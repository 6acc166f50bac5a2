"""External work along the path: Simpson integration of ``F . dq`` over the converged
increments (:class:`WorkIntegrator`) and its balance against the stored energy
(:func:`work_balance`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from barhinge.solver.state import Evaluation, State, StepRecord

__all__ = ["WORK_TOLERANCE", "WorkIntegrator", "work_balance"]

#: relative mismatch between the external work and the stored energy of a path above which
#: an event is recorded (``meta["work_balance"]``); the Simpson work integration is third
#: order, and the tests' coarsest paths (6-20 steps) stay below 1e-4 (docs/solver.md)
WORK_TOLERANCE = 1e-3

#: (path coordinate, generalised coordinates q, generalised forces F)
Sample = tuple[float, np.ndarray, np.ndarray]


class WorkIntegrator:
    """Work of the loads, reactions and actuator moments along the path (force x length).

    ``P`` (n_dof,) reference load, ``fixed`` (n_dof,) mask of the supported DOFs."""

    def __init__(self, P: np.ndarray, fixed: np.ndarray) -> None:
        self.P = P
        self.fixed = fixed
        self.work = 0.0
        self._samples: list[Sample] = []

    def sample(self, t: float, st: State, e: Evaluation) -> Sample:
        """(t, q, F): generalised coordinates (x, actuator angles) and the forces doing work
        on them (loads + reactions, actuator moments)."""
        R = np.zeros(self.P.size)
        R[self.fixed] = e.r[self.fixed]
        q = np.concatenate([st.x, e.terms.rho])
        F = np.concatenate([st.lam * e.P + R, -e.mu_act])
        return t, q, F

    def add(self, first: StepRecord, new: State, e_new: Evaluation, s: float | None) -> None:
        """Work of the increment ending at ``new`` (``first``: the record of state 0):
        ``int F . dq`` with F and q interpolated quadratically in the path parameter (t, or
        ``s`` when given: the chord length under arc length) through the last three
        converged increments and Simpson's rule on the last interval (exact for the cubic
        integrand: third-order accurate); the trapezoidal rule on the first increment."""
        if not self._samples:
            x0, mu0 = first.X.ravel(), -first.moments
            R0 = first.R.ravel()
            self._samples.append(
                (
                    0.0,
                    np.concatenate([x0, first.rho]),
                    np.concatenate([first.lam * self.P + R0, -mu0]),
                )
            )
        self._samples.append(self.sample(new.t if s is None else s, new, e_new))
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


def work_balance(
    records: Sequence[StepRecord], force_floor: float, size: float
) -> tuple[dict[str, float], str | None]:
    """External work against the change of stored energy over the recorded path; the
    mismatch relative to the largest work or energy change met along the path (a path
    that returns to a stress-free state has both near zero at its end). ``force_floor``
    (force) times ``size`` (length) is the round-off floor of both. Returns the balance
    and an event text when the mismatch passes :data:`WORK_TOLERANCE`."""
    energy = np.array([r.eb + r.ebend + r.efold for r in records])
    works = np.array([r.work for r in records])
    work, de = float(works[-1]), float(energy[-1] - energy[0])
    scale = float(max(np.abs(works).max(), np.abs(energy - energy[0]).max()))
    # below the energy of the force floor over the model's size the two are round-off
    floor = float(force_floor or 0.0) * size
    rel = abs(work - de) / scale if scale > 0 and abs(work - de) > floor else 0.0
    bal = {"work": work, "energy": de, "rel_mismatch": rel, "tolerance": WORK_TOLERANCE}
    if rel <= WORK_TOLERANCE:
        return bal, None
    return bal, (
        f"work balance: external work {work:.6g} against stored energy {de:.6g} "
        f"(relative mismatch {rel:.2g} > {WORK_TOLERANCE:g}): steps too coarse for the "
        "work integration, or a state off equilibrium"
    )
