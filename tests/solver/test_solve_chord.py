"""Chord corrections (option ``corrector``): after an increment's first Newton correction,
corrections solved with that factorisation are kept while they contract the residual; the
path is the one full Newton finds, with fewer factorisations."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.solver import newton
from barhinge.solver_options import SolverOptions

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_solver import miura_scene  # noqa: E402


def _solve(n: int, material: str, corrector: str, steps: int = 50) -> bh.FoldPath:
    sc = miura_scene(n, 0.0, steps, material=material)
    logging.disable(logging.WARNING)  # the compliant sheet's stability events
    try:
        return bh.solve(sc.with_(options={**sc.options.__dict__, "corrector": corrector}))
    finally:
        logging.disable(logging.NOTSET)


@pytest.fixture(scope="module", params=["quasi-rigid", "compliant"])
def pair(request) -> tuple[bh.FoldPath, bh.FoldPath]:
    return _solve(10, request.param, "newton"), _solve(10, request.param, "chord")


def _energy(p: bh.FoldPath) -> np.ndarray:
    return np.asarray(p.energy_bars) + np.asarray(p.energy_bend) + np.asarray(p.energy_fold)


def test_chord_corrections_reach_the_states_full_newton_reaches(pair) -> None:
    """Every recorded state agrees with full Newton's: energies to 1e-9 relative (measured
    ~1e-14), the stability counts exactly, fold angles within 1e-4 deg (the compliant
    sheet's near-mechanism leaves its angles free at the 1e-6 deg level under the force
    tolerance, see test_solve_acceleration)."""
    full, chord = pair
    assert full.converged and chord.converged
    e_full, e_chord = _energy(full), _energy(chord)
    assert np.abs(e_chord - e_full).max() <= 1e-9 * e_full.max()
    assert chord.meta["negative_eigenvalues"] == full.meta["negative_eigenvalues"]
    assert chord.meta["negative_eigenvalues_held"] == full.meta["negative_eigenvalues_held"]
    np.testing.assert_allclose(chord.fold_angles_deg, full.fold_angles_deg, rtol=0, atol=1e-4)


def test_chord_corrections_save_factorisations_and_are_counted(pair) -> None:
    """The chord corrector factorises less (measured 60 -> 55 quasi-rigid, 74 -> 69
    compliant on this 10 x 10 sheet), says how many chord corrections it kept per step,
    and full Newton keeps none."""
    full, chord = pair
    nw_full, nw_chord = full.meta["newton"], chord.meta["newton"]
    assert nw_chord["total_factorizations"] < nw_full["total_factorizations"]
    assert nw_chord["total_chord"] == sum(nw_chord["chord"]) > 0
    assert nw_chord["total_chord"] == chord.meta["timing"]["n_chord"]
    assert nw_full["total_chord"] == 0 and full.meta["timing"]["n_chord_rejected"] == 0


def test_a_chord_that_does_not_contract_is_discarded(monkeypatch) -> None:
    """With a contraction no chord can meet, a chord is kept only where its state passes
    the force and actuator tests; every other trial is discarded for a Newton correction
    from the same iterate, and the path is still full Newton's."""
    monkeypatch.setattr(newton, "CHORD_CONTRACTION", 1e-300)
    strict = _solve(6, "quasi-rigid", "chord", steps=10)
    full = _solve(6, "quasi-rigid", "newton", steps=10)
    assert strict.converged
    assert strict.meta["timing"]["n_chord_rejected"] > 0
    e_full, e_strict = _energy(full), _energy(strict)
    assert np.abs(e_strict - e_full).max() <= 1e-9 * e_full.max()


def test_unknown_corrector_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match=r"options\.corrector"):
        SolverOptions(corrector="broyden")
