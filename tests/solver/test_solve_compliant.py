"""Compliant actuators in the bar-and-hinge solver: springs to their targets (closed form,
finite-difference tangent, convergence to the compliant rigid limit at rate 1/r)."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene, scene_from_dict
from barhinge.solver.branch import fold_weights
from barhinge.solver.context import SolveContext
from barhinge.solver.state import State

MAT = Material(E=1e6, nu=0.3, t=0.01)


def _single_fold(k: float) -> BarHingeModel:
    """A unit square with one valley crease along its diagonal (length sqrt 2)."""
    V = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]])
    cp = bh.CreasePattern(V, E, ["B", "B", "B", "B", "V"])
    return BarHingeModel.from_pattern(cp, "N4B5", Material(E=1e5, nu=0.3, t=0.01), fold_stiffness=k)


def test_single_fold_settles_where_the_springs_balance():
    """Actuator spring k_a in series with the fold spring k L: rho = k_a t / (k_a + k L) and
    the actuator moment k_a (t - rho) equals the fold moment k L rho (closed form)."""
    k, ka, t = 0.3, 0.5, np.radians(120.0)
    scene = Scene(
        _single_fold(k),
        actuators=bh.Actuators(edges=[4], targets_deg=[120.0], stiffness=ka),
        steps=6,
        options={"tol_force": 1e-13, "tol_disp": 1e-13},
    )
    path = bh.solve(scene)
    kl = k * np.sqrt(2.0)
    targets = np.linspace(0.0, t, 7)
    rho = np.radians(path.fold_angles_deg[:, 4])
    np.testing.assert_allclose(rho, ka * targets / (ka + kl), rtol=0, atol=1e-9)
    np.testing.assert_allclose(path.actuator_moments[:, 0], kl * rho, rtol=1e-8, atol=1e-12)
    assert path.meta["compliant_actuators"]
    np.testing.assert_allclose(
        path.meta["actuator_misfit_deg"], np.degrees(targets - rho), rtol=0, atol=1e-7
    )
    # the actuator's work is stored in the fold (its own spring is not part of the sheet)
    np.testing.assert_allclose(path.external_work, path.energy, rtol=1e-6, atol=1e-14)


def _miura_scene(ratio: float | None, ka_rel: float = 20.0, steps: int = 6):
    cp = bh.families.miura(3, 3)
    A = np.asarray(bh.dof(cp).mechanism.actuators)
    sign = np.where(cp.assignment[A] == "M", -1.0, 1.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", MAT, stiffness_ratio=ratio)
    w, _ = fold_weights(model)
    acts = bh.Actuators(edges=A, targets_deg=40.0 * sign, stiffness=ka_rel * w[A])
    return cp, model, w, acts


def test_compliant_tangent_matches_finite_differences():
    """The spring terms k g g^T + k (rho - t) H added to the free-DOF operator are the
    derivative of the residual (central differences, off equilibrium)."""
    cp, model, _, acts = _miura_scene(None)
    path = bh.solve(Scene(model, actuators=acts, steps=3))
    scene = Scene(model, actuators=acts, steps=3)
    ctx = SolveContext(scene)
    ctx.make_system()
    rng = np.random.default_rng(3)
    x = path.X[-1].ravel() + 1e-3 * rng.normal(size=path.X[-1].size)
    st = State(x, np.zeros(0), 0.0, 0.6)
    e = ctx.evaluate(st)
    ctx.factorize(e, st, keep_operator=True)
    A = ctx.system.A.toarray()
    free = np.flatnonzero(ctx.free)
    h = 1e-6
    cols = rng.choice(len(free), 40, replace=False)
    for j in cols:
        xp, xm = x.copy(), x.copy()
        xp[free[j]] += h
        xm[free[j]] -= h
        rp = ctx.evaluate(State(xp, np.zeros(0), 0.0, 0.6), tangent=False).r[free]
        rm = ctx.evaluate(State(xm, np.zeros(0), 0.0, 0.6), tangent=False).r[free]
        fd = (rp - rm) / (2 * h)
        np.testing.assert_allclose(A[:, j], fd, rtol=0, atol=2e-6 * np.abs(A).max())


def test_bar_hinge_converges_to_the_compliant_rigid_limit_at_rate_one_over_r():
    """Both models minimise the same fold-plus-actuator-spring energy; the bar-and-hinge
    model's panels of stiffness ratio r leave an O(1/r) distance to the rigid limit."""
    cp, _, w, acts = _miura_scene(None)
    rigid = bh.rigid_fold(cp, acts, steps=6, fold_stiffness=w)
    ref = rigid.fold_angles_deg[-1][cp.crease_edges]
    assert rigid.meta["actuator_misfit_deg"][-1] > 5.0  # the springs do stretch
    err = []
    for r in (1e3, 1e4):
        path = bh.solve(Scene(BarHingeModel.from_pattern(cp, "N5B8", MAT, stiffness_ratio=r),
                              actuators=acts, steps=6))  # fmt: skip
        err.append(float(np.abs(path.fold_angles_deg[-1][cp.crease_edges] - ref).max()))
    slope = np.log(err[1] / err[0]) / np.log(10.0)
    assert err[1] < 0.5 and slope == pytest.approx(-1.0, abs=0.1)


def test_scene_toml_takes_actuator_stiffness():
    scene = scene_from_dict(
        {
            "pattern": {"family": "miura", "params": {"nx": 2, "ny": 2}},
            "actuators": {"edges": [5], "targets_deg": [-30.0], "stiffness": 2.5},
            "solve": {"steps": 2},
        }
    )
    assert scene.actuators is not None and scene.actuators.compliant
    np.testing.assert_array_equal(scene.actuators.stiffness, [2.5])


def test_cli_fold_reports_compliant_actuators(tmp_path, monkeypatch):
    """`barhinge fold` on a scene whose actuators have a stiffness: the summary says they
    are compliant and gives the springs' stretch (the fold settles short of the target)."""
    from typer.testing import CliRunner

    from barhinge.cli import app

    monkeypatch.setenv("BARHINGE_PICTURES", "0")
    edge = int(bh.families.miura(2, 2, fold=5.0).crease_edges[0])
    scene = tmp_path / "compliant.toml"
    scene.write_text(
        f"""name = "compliant"
[pattern]
family = "miura"
params = {{ nx = 2, ny = 2, fold = 5.0 }}
[model]
scheme = "N4B5"
material = {{ E = 1.0e6, nu = 0.3, t = 0.01 }}
fold_stiffness = 1.0e-3
[actuators]
edges = [{edge}]
targets_deg = [40.0]
stiffness = 0.01
[solve]
steps = 4
"""
    )
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["fold", str(scene), "--out", str(out)])
    assert res.exit_code == 0, res.output
    import json

    acts = json.loads((out / "summary.json").read_text())["actuators"]
    assert acts["compliant"] and 0.5 < acts["misfit_deg"] < 35.0
    assert abs(acts["angle_deg"][0] + acts["misfit_deg"] - 40.0) < 1e-6
