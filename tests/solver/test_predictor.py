"""The polynomial predictor (option ``predictor = "polynomial"``, the default): the same
converged path as the quadratic predictor, reached with fewer Newton corrections, and the
quadratic's start kept wherever the high degree would start further off."""

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


def _solve(predictor: str) -> bh.FoldPath:
    sc = miura_scene(6, 0.0, STEPS, material="quasi-rigid")
    # Newton corrections counted alone (a chord corrector would hide their number)
    opts = {**sc.options.__dict__, "predictor": predictor, "corrector": "newton"}
    return bh.solve(sc.with_(options=opts))


@pytest.fixture(scope="module")
def pair() -> tuple[bh.FoldPath, bh.FoldPath]:
    return _solve("quadratic"), _solve("polynomial")


def test_polynomial_predictor_reaches_the_quadratic_path(pair) -> None:
    """Both solves meet the same tolerances on the same branch: every state's coordinates
    within the displacement tolerance (1e-8 of the sheet's size on the last correction;
    measured 4e-10) and
    energies within 1e-8 relative."""
    quad, poly = pair
    size = float(np.ptp(quad.X[0], axis=0).max())
    assert np.abs(poly.X - quad.X).max() <= 1e-8 * size
    np.testing.assert_allclose(poly.energy, quad.energy, rtol=1e-8, atol=1e-12 * quad.energy.max())


def test_polynomial_predictor_needs_one_correction_per_smooth_step(pair) -> None:
    """Past the flat start (the first ten steps) the quasi-rigid sheet's path is smooth:
    the polynomial start needs one Newton correction in most steps, where the quadratic's
    needs two or more in every step, and fewer factorisations in all."""
    quad, poly = pair
    it_q = np.asarray(quad.meta["newton"]["iterations"])[10:]
    it_p = np.asarray(poly.meta["newton"]["iterations"])[10:]
    assert it_q.min() >= 2
    assert np.mean(it_p == 1) >= 0.8
    assert poly.meta["timing"]["n_factorizations"] < quad.meta["timing"]["n_factorizations"]


def test_a_worse_high_degree_start_is_not_taken(monkeypatch, pair) -> None:
    """The high-degree candidate is compared with the quadratic by their residuals: an
    extrapolation thrown far off (every coordinate moved by the sheet's size) is never the
    start, so the solve follows the quadratic predictor's path."""
    quad, _ = pair
    real = newton.extrapolate

    def far_off(hist, s_new):
        z = real(hist, s_new)
        return None if z is None else z + 5.0

    monkeypatch.setattr(newton, "extrapolate", far_off)
    poly = _solve("polynomial")
    size = float(np.ptp(quad.X[0], axis=0).max())
    assert np.abs(poly.X - quad.X).max() <= 1e-9 * size
    assert list(poly.meta["newton"]["iterations"]) == list(quad.meta["newton"]["iterations"])
