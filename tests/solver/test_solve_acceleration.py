"""Geodesic acceleration of the Newton corrections (option ``acceleration``): the same
converged path as plain Newton, reached with fewer corrections on a near-mechanism."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_solver import miura_scene  # noqa: E402


def _solve(n: int, material: str, acceleration: bool | str, steps: int = 50):
    sc = miura_scene(n, 0.0, steps, material=material)
    # Newton corrections alone: the acceleration acts on them (chord corrections are
    # tested in test_solve_chord)
    opts = {**sc.options.__dict__, "acceleration": acceleration, "corrector": "newton"}
    return bh.solve(sc.with_(options=opts))


@pytest.fixture(scope="module")
def compliant_pair():
    logging.disable(logging.WARNING)  # the compliant sheet's stability events
    try:
        return _solve(10, "compliant", False), _solve(10, "compliant", True)
    finally:
        logging.disable(logging.NOTSET)


@pytest.fixture(scope="module")
def compliant_auto():
    logging.disable(logging.WARNING)
    try:
        return _solve(10, "compliant", "auto")
    finally:
        logging.disable(logging.NOTSET)


def test_accelerated_newton_converges_to_the_same_path(compliant_pair) -> None:
    """Both solves meet the same tolerances on the same branch: equal energies (1e-9
    relative; measured 4e-13), the same stability counts, and fold angles within 1e-4 deg.
    The sheet's near-mechanism is so soft that the force tolerance leaves its fold angles
    free at the 1e-6 deg level (measured 7.6e-6 deg between the two, the same at a force
    tolerance of 1e-12), which is why the angles are compared more loosely than the
    energies."""
    plain, acc = compliant_pair
    assert plain.converged and acc.converged

    def energy(p):
        return np.asarray(p.energy_bars) + np.asarray(p.energy_bend) + np.asarray(p.energy_fold)

    e_plain, e_acc = energy(plain), energy(acc)
    assert np.abs(e_acc - e_plain).max() <= 1e-9 * e_plain.max()
    assert acc.meta["negative_eigenvalues"] == plain.meta["negative_eigenvalues"]
    np.testing.assert_allclose(acc.fold_angles_deg, plain.fold_angles_deg, rtol=0, atol=1e-4)


def test_acceleration_saves_corrections_on_a_near_mechanism(compliant_pair) -> None:
    """On the compliant Miura sheet (panels only ~100x stiffer than the folds) plain Newton
    alternates between the soft mode's valley and stretched iterates; the accelerated
    corrections follow the valley: at least 10 % fewer Newton iterations (measured 185 ->
    157 on this sheet), and the counter says how many corrections were accelerated."""
    plain, acc = compliant_pair
    n_plain = plain.meta["newton"]["total_iterations"]
    n_acc = acc.meta["newton"]["total_iterations"]
    assert n_acc <= 0.9 * n_plain
    assert acc.meta["timing"]["n_accelerated"] > 0
    assert plain.meta["timing"]["n_accelerated"] == 0


def test_auto_acceleration_reaches_the_same_path_with_fewer_factorisations(
    compliant_pair, compliant_auto
) -> None:
    """``acceleration = "auto"`` (the default) accelerates only where the residual rose or
    after a hard increment: on the compliant sheet the same energies as plain Newton (1e-9
    relative) and fewer factorisations, with some but not all corrections accelerated."""
    plain, _ = compliant_pair
    auto = compliant_auto
    e = [np.asarray(p.energy_bars) + np.asarray(p.energy_bend) + np.asarray(p.energy_fold)
         for p in (plain, auto)]  # fmt: skip
    assert np.abs(e[1] - e[0]).max() <= 1e-9 * e[0].max()
    assert auto.meta["negative_eigenvalues"] == plain.meta["negative_eigenvalues"]
    assert auto.meta["timing"]["n_factorizations"] < plain.meta["timing"]["n_factorizations"]
    n_acc = auto.meta["timing"]["n_accelerated"]
    assert 0 < n_acc < auto.meta["newton"]["total_iterations"]


def test_auto_acceleration_leaves_a_stiff_smooth_fold_plain() -> None:
    """On the quasi-rigid sheet the steps past the flat start converge without a rising
    residual: "auto" accelerates at most as many corrections as the first ten steps made,
    and ends where plain Newton ends, within the displacement tolerance (1e-8 of the
    sheet's size)."""
    auto = _solve(6, "quasi-rigid", "auto", steps=30)
    plain = _solve(6, "quasi-rigid", False, steps=30)
    assert auto.meta["timing"]["n_accelerated"] <= sum(auto.meta["newton"]["iterations"][:10])
    size = float(np.ptp(plain.X[0], axis=0).max())
    assert np.abs(auto.X[-1] - plain.X[-1]).max() <= 1e-8 * size


def test_acceleration_option_is_checked() -> None:
    from barhinge.errors import ConfigError
    from barhinge.solver_options import SolverOptions

    with pytest.raises(ConfigError, match="options.acceleration"):
        SolverOptions(acceleration="yes")  # type: ignore[arg-type]
