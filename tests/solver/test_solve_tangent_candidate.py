"""The tangent step as a candidate of the polynomial predictor for a whole step after a slow
increment off a flat start (:meth:`barhinge.solver.newton._Driver._polynomial`): the same
equilibria, reached without the failed increments of extrapolation."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.solver import newton

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_solver import miura_scene  # noqa: E402

#: steps of the compliant 20 x 20 fold where the extrapolated start fails Newton
FIRST_STEPS = 6


def _fold(monkeypatch: pytest.MonkeyPatch, candidate: bool) -> bh.FoldPath:
    monkeypatch.setattr(newton, "TANGENT_CANDIDATE", candidate)
    logging.disable(logging.WARNING)  # the compliant sheet's stability events
    try:
        return bh.solve(miura_scene(20, 0.0, 50, material="compliant"))
    finally:
        logging.disable(logging.NOTSET)


@pytest.fixture(scope="module")
def folds() -> tuple[bh.FoldPath, bh.FoldPath]:
    with pytest.MonkeyPatch.context() as mp:
        with_candidate = _fold(mp, True)
        without = _fold(mp, False)
    return with_candidate, without


def test_the_candidate_reaches_the_same_equilibria(folds) -> None:
    """Both folds meet the same tolerances on the same branch: equal energies (1e-9
    relative), the same stability counts, fold angles within 1e-4 deg (the near-mechanism
    leaves them free at the 1e-5 deg level under the force tolerance;
    test_solve_acceleration)."""
    cand, plain = folds
    assert cand.converged and plain.converged

    def energy(p: bh.FoldPath) -> np.ndarray:
        return np.asarray(p.energy_bars) + np.asarray(p.energy_bend) + np.asarray(p.energy_fold)

    assert np.abs(energy(cand) - energy(plain)).max() <= 1e-9 * energy(plain).max()
    assert cand.meta["negative_eigenvalues"] == plain.meta["negative_eigenvalues"]
    np.testing.assert_allclose(cand.fold_angles_deg, plain.fold_angles_deg, rtol=0, atol=1e-4)


def test_the_candidate_saves_the_failed_increments_near_flat(folds) -> None:
    """On the compliant 20 x 20 sheet the extrapolation of steps 4-6 overshoots the turning
    near-mechanism: without the candidate, increments of the first steps fail and are
    redone (measured 2, at steps 4 and 5); with it, none fails and the first steps need
    fewer factorisations (measured 70 -> 44 in steps 1-6, 136 -> 110 over the fold)."""
    cand, plain = folds
    f_cand = cand.meta["newton"]["failed"][:FIRST_STEPS]
    f_plain = plain.meta["newton"]["failed"][:FIRST_STEPS]
    assert sum(f_plain) >= 1
    assert sum(f_cand) == 0
    assert sum(cand.meta["newton"]["factorizations"][:FIRST_STEPS]) < sum(
        plain.meta["newton"]["factorizations"][:FIRST_STEPS]
    )


def test_a_failed_tangent_start_is_retried_from_the_extrapolation(monkeypatch) -> None:
    """An increment whose start was the tangent step (the candidate, for its smaller
    residual) is retried once from the extrapolation before it is damped or cut back, and
    that retry takes no candidate; a failed extrapolated start is retried with the tangent
    step, as before."""
    sc = miura_scene(4, 0.0, 10, material="compliant")
    drv = newton._Driver(sc)
    st = drv.initial()[0]
    drv._prev = st  # a history: the extrapolating predictors apply
    drv._pred_tangent = True  # the failed increment started from the tangent step
    assert drv._extrapolation_retry_left() and not drv._tangent_retry_left()
    assert not drv._may_damp(st)  # a predictor is left to try first
    assert drv._retry(st) and drv._retry_extrapolation
    drv._pred_tangent = False  # the retry: the extrapolation alone
    assert not drv._predictor_retry_left()
    assert drv._may_damp(st) == (drv.opts.damping == "auto" and drv._off_flat())
    drv._retry_extrapolation = False
    assert drv._tangent_retry_left()  # an extrapolated start that failed: tangent retry
    assert drv._retry(st) and drv._retry_tangent
