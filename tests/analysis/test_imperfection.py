"""Initial geometric imperfections: the imperfect model is stress-free at its moved reference,
and an imperfect strut amplifies its imperfection by the closed form ``1 / (1 - P / P_1)``."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.buckling import linear_buckling
from barhinge.analysis.imperfection import imperfect
from barhinge.errors import ConfigError
from barhinge.scene import Scene
from barhinge.solver_options import SolverOptions
from barhinge.verify import rigid_link_strut


def _strut_deflection(a: float, alpha: float) -> tuple[float, float]:
    """Lateral deflection, beyond the imperfection, of the node of largest mode amplitude of a
    5-link strut with a first-mode imperfection of amplitude ``a`` under ``alpha P_1``;
    and the closed form ``a alpha / (1 - alpha)``."""
    m, S, P = rigid_link_strut(5)
    res = linear_buckling(m, P, S, n_modes=1)
    p1, phi = float(res.factors[0]), res.modes[0]
    mi = imperfect(m, phi, a, loads=P)
    path = bh.solve(Scene(mi, supports=S, loads=alpha * p1 * P, control="load", steps=10))
    i = int(np.argmax(np.abs(phi[:, 2])))
    X = np.asarray(path.X)
    seeded = mi.X0[i, 2] - m.X0[i, 2]
    w = X[-1, i, 2] - X[0, i, 2]
    return float(w / np.sign(seeded)), a * alpha / (1.0 - alpha)


def test_imperfect_model_is_stress_free_at_its_reference():
    m, S, P = rigid_link_strut(5)
    phi = linear_buckling(m, P, S, n_modes=1).modes[0]
    mi = imperfect(m, phi, 0.05)
    moved = np.linalg.norm(mi.X0 - m.X0, axis=1)
    assert moved.max() == pytest.approx(0.05, rel=1e-12)
    ev = mi.evaluate(mi.X0)
    assert np.abs(ev.force).max() <= 1e-14 * np.abs(m.bar_EA).max()
    assert mi.meta["imperfection"] == {"amplitude": 0.05}
    assert "imperfection" not in m.meta  # the perfect model is left as it was


@pytest.mark.parametrize("alpha", [0.25, 0.5, 0.75])
def test_strut_amplifies_its_imperfection_by_the_closed_form(alpha):
    """A pinned strut of rigid links with an initial imperfection in its first buckling mode
    deflects, under the axial load ``alpha P_1``, by ``a alpha / (1 - alpha)`` more (the
    amplification factor of an initially crooked column, Timoshenko & Gere 1961, Theory of
    Elastic Stability, sec. 1.12; exact for the first mode of the linearised discrete column,
    whose modes diagonalise both stiffnesses). The closed form is linearised: the solver's
    nonlinear deflection departs from it by O(a / l), so a ten times smaller imperfection
    agrees at least five times better."""
    big, expect_big = _strut_deflection(1e-2, alpha)
    small, expect_small = _strut_deflection(1e-3, alpha)
    err_big = abs(big / expect_big - 1.0)
    err_small = abs(small / expect_small - 1.0)
    assert err_small < 2e-3
    assert err_small < err_big / 5.0 or err_small < 1e-4


def test_imperfection_sign_follows_the_loads():
    m, S, P = rigid_link_strut(5)
    phi = linear_buckling(m, P, S, n_modes=1).modes[0]
    down = np.zeros_like(P)
    down[:, 2] = -1.0
    for s in (phi, -phi):
        mi = imperfect(m, s, 0.01, loads=down)
        assert float(np.sum(down * (mi.X0 - m.X0))) > 0.0


@pytest.mark.parametrize(
    ("shape", "amplitude", "match"),
    [
        (np.zeros((3, 3)), 0.1, "must have shape"),
        (None, -1.0, "amplitude"),
        (None, float("nan"), "amplitude"),
        ("zero", 0.1, "zero everywhere"),
        ("nan", 0.1, "non-finite"),
    ],
)
def test_bad_imperfections_are_named(shape, amplitude, match):
    m, _, _ = rigid_link_strut(3)
    s = np.ones((m.n_nodes, 3))
    if isinstance(shape, np.ndarray):
        s = shape
    elif shape == "zero":
        s = np.zeros((m.n_nodes, 3))
    elif shape == "nan":
        s[0, 0] = np.nan
    with pytest.raises(ConfigError, match=match):
        imperfect(m, s, amplitude)


@pytest.mark.parametrize("predictor", ["quadratic", "polynomial"])
def test_soft_mode_of_the_imperfect_strut_converges_to_the_displacement_tolerance(predictor):
    """Near its buckling load (0.75 P_1) the crooked strut's lateral mode is soft: a force
    residual at the floor of the rigid links' stiffness still hides a lateral error. The
    converged state must not depend on the path to it: 10 and 40 load steps, each with the
    default tolerances, end within a few tol_disp * size of each other (the last correction
    is confirmed by a back-substitution of the final residual; before that check the
    10-step run ended 3 tolerances off with the quadratic predictor and 360 with the
    polynomial one)."""
    m, S, P = rigid_link_strut(5)
    res = linear_buckling(m, P, S, n_modes=1)
    mi = imperfect(m, res.modes[0], 1e-3, loads=P)
    ends = []
    for steps in (10, 40):
        scene = Scene(mi, supports=S, loads=0.75 * float(res.factors[0]) * P, control="load",
                      steps=steps, options={"predictor": predictor})  # fmt: skip
        ends.append(np.asarray(bh.solve(scene).X)[-1])
    size = float(np.linalg.norm(np.ptp(mi.X0, axis=0)))
    tol = SolverOptions().tol_disp * size
    assert np.abs(ends[0] - ends[1]).max() <= 3 * tol


def test_soft_mode_of_the_imperfect_strut_converges_under_arc_length():
    """The same crooked strut followed by arc length to 0.75 P_1 (the run lands on load
    factor 1 of those loads): from a first increment of 1/10 and of 1/40 the end states
    agree within a few tol_disp * size. (The arc-length corrector confirms a state accepted
    by the residual's rate with its next correction, the arc constraint kept; this strut
    passed before that check as well: it guards the arc path, it does not show the fix.)"""
    m, S, P = rigid_link_strut(5)
    res = linear_buckling(m, P, S, n_modes=1)
    mi = imperfect(m, res.modes[0], 1e-3, loads=P)
    ends = []
    for steps in (10, 40):
        scene = Scene(mi, supports=S, loads=0.75 * float(res.factors[0]) * P,
                      control="arc_length", steps=steps)  # fmt: skip
        path = bh.solve(scene)
        assert path.load_factor[-1] == pytest.approx(1.0, abs=1e-12)
        ends.append(np.asarray(path.X)[-1])
    size = float(np.linalg.norm(np.ptp(mi.X0, axis=0)))
    tol = SolverOptions().tol_disp * size
    assert np.abs(ends[0] - ends[1]).max() <= 3 * tol
