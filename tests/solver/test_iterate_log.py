"""The solver's iterate log (``FoldPath.meta["iterates"]``, ``iterations.csv``) against
records made independently of it: the residual histories of the increments (caught at the
increment's return or failure), the corrections of the line search and of the chord steps
(caught by wrapping them), the factorisations (a Newton correction factorises, a chord step
does not) and the states' own clock."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import barhinge as bh
import barhinge.solver.newton as newton
from barhinge.errors import ConvergenceError
from barhinge.model.model import BarHingeModel
from barhinge.output.run import ITERATIONS, write_run
from barhinge.scene import Scene
from barhinge.solver.convergence import Convergence
from barhinge.solver.damping import Damping
from barhinge.solver.trace import ITERATE_COLUMNS, ITERATE_KINDS


def _by_increment(log: dict, key: str) -> list[list]:
    """The column ``key`` of the log, split into its increments."""
    inc = np.asarray(log["increment"])
    return [list(np.asarray(log[key], dtype=object)[inc == i]) for i in np.unique(inc)]


def test_iterate_log_against_independent_records(monkeypatch, flat_miura):
    residuals: list[list[float]] = []  # every increment's residual history, failed ones too
    moves: list[tuple[str, float]] = []  # (kind, norm) of every correction taken
    orig_inc = newton._Driver.increment
    orig_search = Convergence.line_search
    orig_chord = newton._Driver._chord
    orig_damped = Damping.correction

    def increment(self, *a, **k):
        try:
            out = orig_inc(self, *a, **k)
        except newton._Failed as f:
            residuals.append(list(f.residuals))
            raise
        residuals.append(list(out[2]))
        return out

    def line_search(self, st, e, dx, dmu, light=False, dlam=0.0):
        out = orig_search(self, st, e, dx, dmu, light, dlam)
        moves.append(("newton", float(np.linalg.norm(out[2] * dx))))
        return out

    def chord(self, *a, **k):
        out = orig_chord(self, *a, **k)
        if out is not None:
            moves.append(("chord", float(np.linalg.norm(out[2]))))
        return out

    def damped(self, *a, **k):
        out = orig_damped(self, *a, **k)
        moves.append(("damped", float(np.linalg.norm(out[2]))))
        return out

    monkeypatch.setattr(newton._Driver, "increment", increment)
    monkeypatch.setattr(Convergence, "line_search", line_search)
    monkeypatch.setattr(newton._Driver, "_chord", chord)
    monkeypatch.setattr(Damping, "correction", damped)
    path = bh.solve(flat_miura())
    log = path.meta["iterates"]
    timing = path.meta["timing"]

    assert list(log) == list(ITERATE_COLUMNS)
    assert len(log["step"]) == timing["n_iterations"]
    assert set(log["kind"]) <= set(ITERATE_KINDS)
    # one list per increment, in order, failed increments included
    assert _by_increment(log, "residual") == residuals
    assert path.meta["newton"]["total_failed"] > 0  # the scene has failed increments
    kinds = _by_increment(log, "kind")
    assert all(k[0] == "predictor" and "predictor" not in k[1:] for k in kinds)
    assert all(list(it) == list(range(len(it))) for it in _by_increment(log, "iterate"))
    # the corrections, in order, as the line search, the chord and the damped steps took them
    rows = zip(log["kind"], log["correction"], strict=True)
    taken = [("newton" if k == "accelerated" else k, c) for k, c in rows if k != "predictor"]
    assert [k for k, _ in taken] == [k for k, _ in moves]
    np.testing.assert_allclose([c for _, c in taken], [c for _, c in moves], rtol=1e-12)
    assert {"chord", "accelerated", "damped"} <= set(log["kind"])
    assert log["kind"].count("accelerated") == timing["n_accelerated"]
    assert log["kind"].count("chord") == timing["n_chord"]
    # a Newton (or damped) correction factorises the tangent; a chord step reuses the
    # factorisation
    fact = np.asarray(log["factorizations"])
    for i, k in enumerate(log["kind"]):
        if k in ("newton", "accelerated", "damped"):
            assert fact[i] > fact[i - 1]
        elif k == "chord":
            assert fact[i] == fact[i - 1]
    assert fact[-1] <= timing["n_factorizations"]
    # the states' clock: every iterate comes before the state it converges to is recorded
    wall = np.asarray(log["wall_time_s"])
    assert np.all(np.diff(wall) >= 0.0) and 0.0 < wall[-1] <= path.wall_time[-1]
    # the steps: the last iterate of each step is its state's last residual
    steps = np.asarray(log["step"])
    for s in range(1, path.meta["steps"] + 1):
        assert log["residual"][np.flatnonzero(steps == s)[-1]] == path.residual_norms[s][-1]


def test_arc_length_log():
    cp = bh.families.miura(2, 2, alpha=60.0, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    P = np.zeros(model.X0.shape)
    P[np.argmax(model.X0[:, 2]), 2] = -1e-3
    path = bh.solve(Scene(model, loads=P, control="arc_length", steps=4))
    log = path.meta["iterates"]
    assert len(log["step"]) == path.meta["timing"]["n_iterations"]
    kinds = _by_increment(log, "kind")
    assert all(k[0] == "predictor" and set(k[1:]) <= {"newton"} for k in kinds)
    # the load factor of every iterate: every state's is the last of an increment (the
    # increment that passed the stop at 1 is redone onto it, as a landing increment)
    lam = np.asarray(log["value"])
    inc = np.asarray(log["increment"])
    last = lam[[np.flatnonzero(inc == i)[-1] for i in np.unique(inc)]]
    assert set(path.load_factor[1:]) <= set(last.tolist())
    assert last[-1] == path.load_factor[-1] == 1.0
    assert all(c > 0 for c in log["correction"])


def test_a_failed_solve_keeps_its_iterates(flat_miura):
    """Three steps are too long for the flat start: the error's partial path carries the log
    of every failed increment (what a user reads to see how Newton failed)."""
    with pytest.raises(ConvergenceError) as err:
        bh.solve(flat_miura(3))
    part = err.value.last_state
    log = part.meta["iterates"]
    assert len(log["step"]) == part.meta["timing"]["n_iterations"] > 0
    assert set(log["step"]) == {1}
    assert "after 8 cut-backs" in str(err.value)
    assert len(set(log["increment"])) >= 9  # the first try and its 8 cut-backs, at least
    assert all(k[0] == "predictor" for k in _by_increment(log, "kind"))


def test_iterations_csv_is_the_log(tmp_path, flat_miura):
    scene = flat_miura()
    path = bh.solve(scene)
    run = write_run(path, scene, tmp_path / "run", pictures="none", viewer=False)
    assert tmp_path / "run" / ITERATIONS in run.files
    with open(tmp_path / "run" / ITERATIONS, newline="") as fh:
        rows = list(csv.reader(fh))
    log = path.meta["iterates"]
    assert rows[0] == list(ITERATE_COLUMNS)
    assert len(rows) - 1 == len(log["step"])
    col = {c: [r[i] for r in rows[1:]] for i, c in enumerate(rows[0])}
    assert [float(v) for v in col["residual"]] == log["residual"]  # every digit
    assert col["kind"] == log["kind"]
    assert [int(v) for v in col["factorizations"]] == log["factorizations"]
    # the saved path keeps the log
    back = bh.FoldPath.load(path.save(tmp_path / "p.npz"))
    assert back.meta["iterates"] == log


def test_iterate_log_refuses_an_unknown_kind():
    from barhinge.solver.trace import IterateLog

    with pytest.raises(ValueError, match="iterate kind 'guess'"):
        IterateLog().add(1, 0, 0.1, 1.0, 1.0, 0.0, "guess", 0)
