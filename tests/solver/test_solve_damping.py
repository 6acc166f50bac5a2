"""Damped Newton corrections of the first increment off a flat start (option ``damping``,
:mod:`barhinge.solver.damping`): the shifted operator, and the equilibrium they reach
against plain Newton's."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.solver.context import SolveContext
from barhinge.solver.damping import Damping
from barhinge.solver.newton import _Driver
from barhinge.solver.state import IncrementFailed, State
from barhinge.solver_options import SolverOptions


def _line_fold(n: int, steps: int, damping: str) -> bh.Scene:
    """A flat n x n Miura sheet (60 deg) folded to 60 deg by its central crease line, in the
    benchmarks' quasi-rigid set (bars EA 1e5, folds 0.1 and panels 1e4 per unit length)."""
    cp = bh.families.miura(n, n, alpha=60.0)
    folded = bh.families.miura(n, n, alpha=60.0, fold=60.0)
    probe = bh.BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5)
    h = probe.hinges[probe.hinge_kind == "bend"]
    length = np.linalg.norm(probe.X0[h[:, 1]] - probe.X0[h[:, 0]], axis=1)
    model = bh.BarHingeModel.from_pattern(
        cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5, bend_k=1e4 * length
    )
    edges = miura_line_creases(cp)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(folded.fold_angles)[edges])
    return bh.Scene(model, actuators=acts, steps=steps, options={"damping": damping})


def test_shifted_operator_adds_the_shift_on_the_free_diagonal_only():
    scene = _line_fold(2, 4, "auto")
    ctx = SolveContext(scene)
    e = ctx.evaluate(State(ctx.X0.ravel().copy(), np.zeros(ctx.n_act), 0.0, 0.0))
    K = e.ev.K.tocsr()
    before = K.data.copy()
    shifted = ctx._shifted(K, 2.5)
    want = K.toarray() + np.diag(np.where(ctx.free, 2.5, 0.0))
    np.testing.assert_array_equal(shifted.toarray(), want)
    np.testing.assert_array_equal(K.data, before)  # the tangent itself is left unshifted
    # the bordered system's scatter maps stay valid: the very pattern arrays
    assert shifted.indices is K.indices and shifted.indptr is K.indptr


def test_damped_first_increment_reaches_plain_newtons_equilibrium():
    """The damped corrections only change the way to the equilibrium, not the equilibrium:
    every state of the fold equals plain Newton's (both converged to tol 1e-8)."""
    damped = bh.solve(_line_fold(6, 10, "always"))
    plain = bh.solve(_line_fold(6, 10, "off"))
    assert damped.converged and plain.converged
    assert damped.meta["flat_start"]["damped_corrections"] >= 1
    assert "damped_corrections" not in plain.meta["flat_start"]
    size = float(np.ptp(damped.X[0], axis=0).max())
    assert float(np.abs(damped.X - plain.X).max()) < 1e-6 * size
    np.testing.assert_allclose(damped.fold_angles_deg, plain.fold_angles_deg, atol=1e-5)


def test_failed_first_increment_is_redone_damped_before_a_cut_back(monkeypatch):
    """``damping = "auto"``: when plain Newton fails the first increment off the flat
    start, the same increment (not a shorter one) is redone with damped corrections; where
    plain Newton succeeds nothing is damped."""
    calls: list[tuple[float, float, bool]] = []
    real = _Driver.increment

    def failing_once(self, st, t1, lam1):
        calls.append((st.t, t1, self._damped(st)))
        if len(calls) == 1:
            raise IncrementFailed("residual diverged", [1.0])
        return real(self, st, t1, lam1)

    monkeypatch.setattr(_Driver, "increment", failing_once)
    path = bh.solve(_line_fold(4, 5, "auto"))
    assert path.converged
    assert calls[0] == (0.0, 0.2, False) and calls[1] == (0.0, 0.2, True)
    assert not any(damped for _, _, damped in calls[2:])  # only the first increment
    assert path.meta["flat_start"]["damped_corrections"] >= 1
    assert path.meta["newton"]["failed"][0] == 1
    monkeypatch.setattr(_Driver, "increment", real)
    plain = bh.solve(_line_fold(4, 5, "auto"))
    assert "damped_corrections" not in plain.meta["flat_start"]
    np.testing.assert_allclose(path.fold_angles_deg, plain.fold_angles_deg, atol=1e-5)


def test_damping_option_is_checked():
    with pytest.raises(bh.ConfigError, match=r"options\.damping"):
        SolverOptions(damping="levenberg")


def test_later_increment_failed_by_both_predictors_is_redone_damped(monkeypatch):
    """``damping = "auto"``: a later increment of a fold from flat that the extrapolating
    and then the tangent predictor fail is redone damped at the same length (not cut back),
    and reaches the equilibrium plain Newton reaches without the failures."""
    calls: list[tuple[float, float, bool, bool]] = []
    real = _Driver.increment

    def failing_twice_in_step_3(self, st, t1, lam1):
        calls.append((st.t, t1, self._retry_tangent, self._damped(st)))
        if st.t == pytest.approx(0.4) and sum(c[0] == pytest.approx(0.4) for c in calls) <= 2:
            raise IncrementFailed("residual diverged", [1.0])
        return real(self, st, t1, lam1)

    monkeypatch.setattr(_Driver, "increment", failing_twice_in_step_3)
    path = bh.solve(_line_fold(4, 5, "auto"))
    assert path.converged
    from_step_3 = [c for c in calls if c[0] == pytest.approx(0.4)]
    assert [c[2:] for c in from_step_3] == [(False, False), (True, False), (False, True)]
    assert all(c[1] == pytest.approx(0.6) for c in from_step_3)  # the same length, no cut-back
    assert not any(damped for t, _, _, damped in calls if t != pytest.approx(0.4))
    assert path.meta["flat_start"]["damped_corrections"] >= 1
    assert path.meta["newton"]["failed"][2] == 2
    monkeypatch.setattr(_Driver, "increment", real)
    plain = bh.solve(_line_fold(4, 5, "auto"))
    np.testing.assert_allclose(path.fold_angles_deg, plain.fold_angles_deg, atol=1e-5)


def test_damped_corrections_hand_over_to_newton_on_progress_or_stagnation():
    """The hand-over rule of :class:`Damping` on residual sequences of real runs: a
    residual a thousandth of the first kept correction's (merits are squared residuals),
    or three kept corrections whose best is not below 0.6 times the best before them;
    progress keeps the corrections damped, even where they alternate."""
    damping = Damping.__new__(Damping)

    def hands_over(residuals: list[float]) -> bool:
        damping.kept = [r * r for r in residuals]
        return damping._hand_over()

    # the second step of a 200 x 200 Miura fold
    steady = [883.0, 71.8, 54.7, 12.2, 6.29, 14.2]
    assert not any(hands_over(steady[:k]) for k in range(1, len(steady) + 1))
    assert hands_over([*steady, 0.43])  # below 883 / 1000
    # the first half of its first step: alternating, but the lows halve
    halving = [21.55, 2.279, 17.56, 1.013, 3.496, 0.4928, 3.523, 0.2585, 1.507, 0.0368, 0.183]
    assert not any(hands_over(halving[:k]) for k in range(1, len(halving) + 1))
    assert hands_over([*halving, 0.00586])
    # alternation on a plateau: a 6 x 6 sheet whose panels bend under one actuator
    plateau = [1.415, 0.890, 1.333, 0.846, 1.340]
    assert not any(hands_over(plateau[:k]) for k in range(1, 5))
    assert hands_over(plateau)
