"""Per-step Newton statistics (``FoldPath.meta["newton"]``) against independent counts:
factorisations counted by wrapping the bordered system's factorisation, per step through the
progress callback; failed increments counted by wrapping the increment itself."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
import barhinge.solver.newton as newton
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene
from barhinge.solver.bordered import BorderedSystem


def test_newton_stats_match_independent_counts(monkeypatch, flat_miura):
    count = {"fact": 0, "failed": 0}
    orig_fact = BorderedSystem._factorize_current
    orig_inc = newton._Driver.increment

    def fact(self, *a, **k):
        count["fact"] += 1
        return orig_fact(self, *a, **k)

    def inc(self, *a, **k):
        try:
            return orig_inc(self, *a, **k)
        except newton._Failed:
            count["failed"] += 1
            raise

    monkeypatch.setattr(BorderedSystem, "_factorize_current", fact)
    monkeypatch.setattr(newton._Driver, "increment", inc)
    at_step = []
    path = bh.solve(flat_miura(), progress=lambda done, total, t: at_step.append(count["fact"]))
    nw = path.meta["newton"]
    steps = path.meta["steps"]
    assert nw["iterations"] == path.iterations[1:].tolist()
    assert len(nw["factorizations"]) == steps
    # state 0's inertia is one factorisation; every later one belongs to a step
    np.testing.assert_array_equal(np.diff([1] + at_step), nw["factorizations"])
    assert (
        nw["total_factorizations"] + 1 == count["fact"] == path.meta["timing"]["n_factorizations"]
    )
    assert nw["total_failed"] == count["failed"]
    assert count["failed"] > 0  # the scene exercises the cut-backs
    assert sum(nw["increments"]) >= steps
    assert all(
        0 <= i <= f for i, f in zip(nw["inertia_factorizations"], nw["factorizations"], strict=True)
    )


def test_arc_length_lists_iterations():
    cp = bh.families.miura(2, 2, alpha=60.0, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    P = np.zeros(model.X0.shape)
    top = np.argmax(model.X0[:, 2])
    P[top, 2] = -1e-3
    sc = Scene(model, loads=P, control="arc_length", steps=4)
    path = bh.solve(sc)
    nw = path.meta["newton"]
    assert nw["iterations"] == path.iterations[1:].tolist()
    assert nw["total_iterations"] == int(path.iterations.sum())


def test_clock_counts_match_independent_counts(monkeypatch, flat_miura):
    """The solver clock's counts (``FoldPath.meta["timing"]``, what benchmarks/bench_steps.py
    reads) against counts made by wrapping the model and the factor: every evaluation of the
    model with its tangent is one ``n_tangent`` and every one without it one
    ``n_force_only``; every back-substitution with the factor one ``n_solves``; the seconds
    of the tangent evaluations are a part of the assembly's."""
    from barhinge.linalg.backends import _PardisoFactor

    count = {"tangent": 0, "force": 0, "solve": 0}
    orig_eval = BarHingeModel.evaluate
    orig_solve = _PardisoFactor.solve

    def evaluate(self, X, tangent=True):
        count["tangent" if tangent else "force"] += 1
        return orig_eval(self, X, tangent=tangent)

    def solve(self, b):
        count["solve"] += 1
        return orig_solve(self, b)

    scene = flat_miura()  # the model's plate calibration evaluates it too: built first
    scene = scene.with_(options={**scene.options.__dict__, "linear_solver": "pardiso"})
    monkeypatch.setattr(BarHingeModel, "evaluate", evaluate)
    monkeypatch.setattr(_PardisoFactor, "solve", solve)
    path = bh.solve(scene)
    tm = path.meta["timing"]
    assert path.converged
    assert tm["n_tangent"] == count["tangent"] > 0
    assert tm["n_force_only"] == count["force"] > 0
    # the bordered solves of the saddle-point factor, one PARDISO solve each (the Schur
    # complement of the actuators comes with the factorisation, not as solves)
    assert tm["n_solves"] == count["solve"] > 0
    assert 0.0 < tm["assembly_tangent"] <= tm["assembly"]


def test_step_clock_benchmark_groups_add_up_to_the_fold():
    """benchmarks/bench_steps.py: its groups of steps partition the schedule, and their
    rows (differences of the clock read after each step) add up to the whole fold's clock,
    whose factorisations are the per-step counts of ``meta["newton"]``."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import bench_steps

    assert bench_steps.groups(50, [1, 5, 10]) == [(1, 1), (2, 5), (6, 10), (11, 50)]
    assert bench_steps.groups(4, [1, 5, 10]) == [(1, 1), (2, 4)]
    run = bench_steps.fold_steps(3, 4, "quasi-rigid")
    rows = [bench_steps.group_row(run, a, b) for a, b in bench_steps.groups(4, [1, 2])]
    last = run["snaps"][-1]
    for key in ("wall", "factorize", "n_factorizations", "n_tangent", "n_solves"):
        assert sum(r[key] for r in rows) == pytest.approx(last[key])
    assert sum(r["share"] for r in rows) == pytest.approx(1.0)
    assert all(r["per_step_refac"] > 0 for r in rows)
    # the corrections by kind (the iterate log) add up over the groups, and every Newton,
    # accelerated or damped correction is one of the group's factorisations at least
    log = run["iterates"]
    counts = [bench_steps.correction_counts(run, a, b) for a, b in bench_steps.groups(4, [1, 2])]
    for kind in bench_steps.CORRECTIONS:
        assert sum(c[kind] for c in counts) == log["kind"].count(kind)
    for c, r in zip(counts, rows, strict=True):
        assert c["newton"] + c["accelerated"] + c["damped"] <= r["n_factorizations"]
    assert sum(c["failed"] for c in counts) == 0 == sum(run["failed"])
    # with one increment a step, the residual histories the driver recorded for the states
    # say which corrections raised the residual
    assert run["increments"] == [1] * 4
    rose = sum(int(np.sum(np.diff(h) > 0)) for h in run["residuals"])
    assert sum(c["rose"] for c in counts) == rose > 0
    assert bench_steps.hardest_step(run, 4) == int(np.argmax(run["factorizations"])) + 1
    # the unit of the last column: the fold's own factorisations (the steps with exactly one,
    # by the driver's own count, step 1 with state 0's; else every step's seconds per
    # factorisation)
    per_step = [run["factorizations"][0] + 1, *run["factorizations"][1:]]
    samples = run["fold_factorisation_samples"]
    assert len(samples) == (per_step.count(1) or sum(f > 0 for f in per_step))
    assert run["fold_factorisation"] == pytest.approx(float(np.median(samples)))
    total = last["factorize"]
    assert min(samples) > 0.0 and max(samples) <= total


def test_ten_million_estimate_compares_timings_of_one_run():
    """benchmarks/scaling.py: the 10 M DOF paragraph fits the refactorisation's exponent on
    timings of the same run. A row kept from an earlier run gives way to the pieces of that
    sheet measured now; with too few fresh timings every row is used, and the paragraph says
    which. The exponent is the log-log slope of the two largest sheets."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import scaling

    def row(n: int, dof: int, refac: float) -> dict:
        return {"material": "quasi-rigid", "n": n, "dof": dof, "refactorisation": refac,
                "fold_peak_mb": 100.0 + dof / 1000.0}  # fmt: skip

    rows = [row(70, 1000, 1.0), row(100, 2000, 2.0), row(200, 8000, 4.0)]
    big = {"dof": 8000, "fact": 8.0}  # the 200 x 200 pieces, timed in this run
    text = " ".join(scaling.ten_million_lines(big, rows, 50, frozenset({200})))
    # fresh: 2000 -> 2.0 s and 8000 -> 8.0 s (the pieces, not the kept row's 4.0 s)
    assert "DOF^1.00 (from 2000 to 8000 DOF, both timed in this run)" in text
    text = " ".join(scaling.ten_million_lines(None, rows, 50, frozenset({100, 200})))
    # one fresh timing only: all rows, 2000 -> 2.0 s and 8000 -> 4.0 s, slope 0.5
    assert "DOF^0.50 (from 2000 to 8000 DOF, timed in different runs)" in text
    text = " ".join(scaling.ten_million_lines(big, rows, 50))
    # nothing kept: the full fold's own floor stands (4.0 s)
    assert "DOF^0.50 (from 2000 to 8000 DOF, both timed in this run)" in text
