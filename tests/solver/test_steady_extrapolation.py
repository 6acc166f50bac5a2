"""The polynomial predictor on a smooth stretch (``newton.STEADY_EXTRAPOLATION``): once the
high-degree extrapolation has won the comparison of candidates and its step took one
Newton correction, the next step starts from it alone, without the candidates' force
evaluations. The same converged path, the same factorisations, fewer force evaluations."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.solver import newton

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_solver import miura_scene  # noqa: E402

STEPS = 30


def _fold(steady: bool) -> bh.FoldPath:
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(newton, "STEADY_EXTRAPOLATION", steady)
        return bh.solve(miura_scene(10, 0.0, STEPS, material="quasi-rigid"))


@pytest.fixture(scope="module")
def pair() -> tuple[bh.FoldPath, bh.FoldPath]:
    return _fold(True), _fold(False)


def test_the_same_converged_path(pair) -> None:
    """Both folds meet the same tolerances on the same branch: every state within the
    displacement tolerance (1e-8 of the sheet's size) and energies within 1e-8 relative."""
    steady, compared = pair
    assert steady.converged and compared.converged
    size = float(np.ptp(compared.X[0], axis=0).max())
    assert np.abs(steady.X - compared.X).max() <= 1e-8 * size
    np.testing.assert_allclose(
        steady.energy, compared.energy, rtol=1e-8, atol=1e-12 * compared.energy.max()
    )


def test_two_force_evaluations_saved_per_smooth_step(pair) -> None:
    """Past the flat start every step of the quasi-rigid sheet takes one correction, so the
    candidates' two force evaluations (the extrapolation and the quadratic) are saved in
    nearly every step, with no factorisation more."""
    steady, compared = pair
    ts, tc = steady.meta["timing"], compared.meta["timing"]
    assert ts["n_factorizations"] <= tc["n_factorizations"]
    assert list(steady.meta["newton"]["iterations"]) == list(compared.meta["newton"]["iterations"])
    smooth = int(np.sum(np.asarray(compared.meta["newton"]["iterations"])[10:] == 1))
    assert smooth >= 15
    saved = tc["n_force_only"] - ts["n_force_only"]
    assert saved >= 2 * (smooth - 2)
    # the tangent assemblies stay one per factorisation and state
    assert ts["n_tangent"] <= tc["n_tangent"]


def test_a_slow_step_brings_the_comparison_back() -> None:
    """An increment that needed more than one correction (or failed) is not a smooth stretch:
    the next prediction compares the candidates again."""
    drv = newton._Driver(miura_scene(4, 0.0, 10, material="quasi-rigid"))
    for n_iter, slow, hard, expected in (
        (1, False, False, True),
        (2, False, False, False),
        (1, True, False, False),
        (1, False, True, False),
    ):
        drv._pred_extrapolated = True
        drv.n_iter_last, drv._slow_last, drv._hard_last = n_iter, slow, hard
        st = drv.initial()[0]
        drv._predict(st, 0.1, 0.1, [])
        assert drv._steady is expected
