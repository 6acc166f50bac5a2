"""The model the solver needs (``barhinge._protocols.SolverModel``): the bar-and-hinge model is
one, and an object that lacks a member the solver reads is not."""

from __future__ import annotations

import dataclasses

import barhinge as bh
from barhinge._protocols import SolverModel


def test_bar_hinge_model_is_a_solver_model():
    model = bh.BarHingeModel.from_pattern(bh.families.miura(1, 1, fold=30.0))
    assert isinstance(model, SolverModel)
    ev = model.evaluate(model.X0)
    assert ev.force.shape == (model.n_dof,) and ev.K.shape == (model.n_dof, model.n_dof)


def test_an_object_without_evaluate_is_not():
    @dataclasses.dataclass
    class NoEvaluate:
        X0: object = None

    assert not isinstance(NoEvaluate(), SolverModel)
