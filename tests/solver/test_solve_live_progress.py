"""The live report of every iterate (``bh.solve(..., on_iteration=...)``) against the solve's
own records: the residuals of the converged increments are the ones the FoldPath keeps per
state, failed increments are counted and redone shorter, and every iterate is reported once
(the solver's own iteration count)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.model.model import BarHingeModel
from barhinge.output.summary import iterate_text
from barhinge.scene import Scene
from barhinge.solver.state import IterationStatus
from barhinge.verify import von_mises_limit_load, von_mises_model


def cut_back_scene() -> Scene:
    """A 3 x 3 Miura sheet folded from flat to 60 deg in six steps with few iterations
    allowed: its first increments fail and are redone shorter (as in test_newton_stats)."""
    cp0 = bh.families.miura(3, 3, alpha=60.0, fold=0.0)
    cp1 = bh.families.miura(3, 3, alpha=60.0, fold=60.0)
    edges = miura_line_creases(cp0)
    model = BarHingeModel.from_pattern(cp0, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    return Scene(model, actuators=acts, steps=6, options={"max_iter": 8})


def von_mises_scene() -> Scene:
    """The von Mises truss of barhinge.verify under 1.5 times its limit load, by arc length
    to an apex displacement past both limit points (as in test_arc_stop)."""
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -1.5 * von_mises_limit_load()
    stop = {"node": int(apex), "axis": "z", "value": -0.5}
    options = {"max_arc_steps": 400, "arc_stop_displacement": stop}
    return Scene(model, supports=S, loads=P, control="arc_length", steps=20, options=options)


def _increments(statuses: list[IterationStatus]) -> list[list[IterationStatus]]:
    """The reported iterates split into increments (each starts with its predictor)."""
    out: list[list[IterationStatus]] = []
    for s in statuses:
        if s.iteration == 0:
            out.append([])
        out[-1].append(s)
    return out


def test_iterates_of_a_fold_with_cut_backs_match_its_records():
    seen: list[IterationStatus] = []
    path = bh.solve(cut_back_scene(), on_iteration=seen.append)
    steps = path.meta["steps"]
    assert len(seen) == path.meta["timing"]["n_iterations"]
    assert sum(len(r) for r in path.residual_norms) <= len(seen)
    incs = _increments(seen)
    assert all([s.iteration for s in inc] == list(range(len(inc))) for inc in incs)
    n_failed = 0
    for step, group in itertools.groupby(incs, key=lambda inc: inc[0].step):
        group = list(group)
        assert all(s.step == step and s.steps == steps for inc in group for s in inc)
        fails = [inc[0].failed for inc in group]
        # an increment failed when the next one of its step counts one more failure
        failed = [b > a for a, b in zip(fails, fails[1:], strict=False)] + [False]
        assert fails == sorted(fails) and fails[0] == 0
        n_failed += fails[-1]
        kept = [inc for inc, f in zip(group, failed, strict=True) if not f]
        # the converged increments' residuals are the state's record, in order
        assert tuple(s.residual for inc in kept for s in inc) == path.residual_norms[step]
        # they cover the step: lengths (halved on failure) add to one step, each aims at
        # the path parameter its increment reached
        assert sum(inc[0].length for inc in kept) == pytest.approx(1.0, abs=1e-12)
        dyadic = [np.log2(inc[0].length) for inc in group]  # a step halved on failure
        assert np.allclose(dyadic, np.round(dyadic), atol=1e-9), dyadic
        assert kept[-1][-1].value == pytest.approx(step / steps, abs=1e-12)
    assert n_failed == path.meta["newton"]["total_failed"] > 0


def test_iterates_of_arc_length_report_their_load_factor():
    seen: list[IterationStatus] = []
    path = bh.solve(von_mises_scene(), on_iteration=seen.append)
    assert path.converged and len(seen) == path.meta["timing"]["n_iterations"]
    for k in range(1, len(path.X)):
        mine = [s for s in seen if s.step == k]
        # the state's record is the last residual history of its increment (the landing
        # correction replaces the increment's own where a stop is crossed)
        assert mine[-1].residual == path.residual_norms[k][-1]
        assert mine[-1].value == pytest.approx(path.load_factor[k], abs=1e-14)


def test_no_listener_changes_nothing():
    cp = bh.families.miura(2, 2, alpha=60.0, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    P = np.zeros(model.X0.shape)
    P[np.argmax(model.X0[:, 2]), 2] = -1e-3
    sc = Scene(model, loads=P, steps=3)
    a = bh.solve(sc)
    b = bh.solve(sc, on_iteration=lambda s: None)
    np.testing.assert_array_equal(a.X, b.X)
    assert a.residual_norms == b.residual_norms


def test_iterate_text_names_the_shortened_increment_and_the_failures():
    s = IterationStatus(step=3, steps=50, value=0.05, length=0.25, iteration=5,
                        residual=32.0, failed=2)  # fmt: skip
    assert (
        iterate_text(s)
        == "increment 1/4 of a step, iterate 5, residual 3.2e+01, after 2 failed increments"
    )
    whole = IterationStatus(3, 50, 0.06, 1.0, 0, 1.5e-3, 0)
    assert iterate_text(whole) == "predictor, residual 1.5e-03"
    arc = IterationStatus(7, 20, 0.4, 0.9 * 0.5, 2, 1e-9, 1)
    assert (
        iterate_text(arc)
        == "increment 0.45 of a step, iterate 2, residual 1.0e-09, after 1 failed increment"
    )
