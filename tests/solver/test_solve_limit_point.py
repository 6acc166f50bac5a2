"""Load control stops at a limit point; arc length (MGDCM) passes it.

The structure is the shallow two-bar (von Mises) truss: supports at (+-b, 0, 0), apex at
(0, 0, h), a downward load on the apex. With the bar length ``l(w) = sqrt(b^2 + (h - w)^2)``
at apex deflection ``w`` and the engineering-strain law ``N = EA (l - l0) / l0``, vertical
equilibrium of the apex gives the load-deflection curve (e.g. Bazant & Cedolin 1991,
"Stability of Structures", Sec. 2.7; Crisfield 1991, Vol. 1, Sec. 9.1):

    F(w) = -2 N (h - w) / l = 2 EA (l0 - l) (h - w) / (l0 l)

whose first maximum is the snap-through (limit) load. The bars-only toy model below has an
analytic tangent (the solver is generic over the model).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import barhinge as bh
from barhinge.scene import Scene


class _Ev:
    def __init__(self, e: float, f: np.ndarray, K: sp.csr_matrix) -> None:
        self.energy_bars, self.energy_bend, self.energy_fold = e, 0.0, 0.0
        self.force, self.K = f, K


class TrussModel:
    """Bars only, engineering strain: E = sum EA (l - l0)^2 / (2 l0)."""

    def __init__(self, X0: np.ndarray, bars: np.ndarray, EA: float) -> None:
        self.X0 = np.asarray(X0, float)
        self.bars = np.asarray(bars)
        self.EA = EA
        self.L0 = np.linalg.norm(self.X0[self.bars[:, 1]] - self.X0[self.bars[:, 0]], axis=1)
        self.n_nodes = len(self.X0)
        self.hinges = np.zeros((0, 4), int)
        self.fold_hinge_of_edge = np.zeros(0, int)

    def evaluate(self, X: np.ndarray, tangent: bool = True) -> _Ev:
        X = np.asarray(X, float).reshape(-1, 3)
        n = X.size
        f = np.zeros(n)
        rows, cols, vals = [], [], []
        e = 0.0
        for (a, b), L0 in zip(self.bars, self.L0, strict=True):
            d = X[b] - X[a]
            L = np.linalg.norm(d)
            u = d / L
            N = self.EA * (L - L0) / L0
            e += 0.5 * self.EA * (L - L0) ** 2 / L0
            dofs = np.r_[3 * a : 3 * a + 3, 3 * b : 3 * b + 3]
            f[dofs] += N * np.r_[-u, u]
            k = self.EA / L0 * np.outer(u, u) + N / L * (np.eye(3) - np.outer(u, u))
            ke = np.block([[k, -k], [-k, k]])
            rows.append(np.repeat(dofs, 6))
            cols.append(np.tile(dofs, 6))
            vals.append(ke.ravel())
        K = sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
        )
        return _Ev(e, f, K)

    def tangent(self, X: np.ndarray) -> sp.csr_matrix:
        return self.evaluate(X).K

    def hinge_angles(self, X: np.ndarray) -> np.ndarray:
        return np.zeros(0)

    def crease_fold_angles_deg(self, X: np.ndarray) -> np.ndarray:
        return np.zeros(0)


B, H, EA = 1.0, 0.1, 1.0e3


def _curve(w: np.ndarray) -> np.ndarray:
    l0 = np.hypot(B, H)
    ll = np.hypot(B, H - w)
    return 2 * EA * (l0 - ll) * (H - w) / (l0 * ll)


def _truss_scene(load: float, control: str, steps: int) -> Scene:
    X0 = np.array([[-B, 0, 0], [B, 0, 0], [0, 0, H]])
    model = TrussModel(X0, np.array([[0, 2], [1, 2]]), EA)
    S = np.zeros((3, 3), bool)
    S[:2] = True
    S[2, :2] = True  # apex moves vertically only
    P = np.zeros((3, 3))
    P[2, 2] = -load
    return Scene(model, supports=S, loads=P, steps=steps, control=control)


F_LIMIT = float(_curve(np.linspace(0, H, 200001)).max())


def test_load_control_fails_at_limit_point():
    scene = _truss_scene(1.5 * F_LIMIT, "load", 10)
    with pytest.raises(bh.ConvergenceError) as info:
        bh.solve(scene)
    err = info.value
    # it stops at the step that crosses the limit load, with the converged part kept
    assert err.load_factor * 1.5 * F_LIMIT <= F_LIMIT * (1 + 1e-9)
    assert err.step == int(np.ceil(10 / 1.5))
    part = err.last_state
    assert isinstance(part, bh.FoldPath) and not part.converged
    assert part.n_states == err.step
    assert "did not converge" in str(err)


def test_arc_length_passes_limit_point():
    scene = _truss_scene(1.5 * F_LIMIT, "arc_length", 20)
    path = bh.solve(scene)
    lam = path.load_factor
    w = H - path.X[:, 2, 2]
    # every state lies on the closed-form equilibrium curve
    np.testing.assert_allclose(lam * 1.5 * F_LIMIT, _curve(w), rtol=0, atol=1e-6 * F_LIMIT)
    # the path goes over the limit point: the load factor falls after its maximum ...
    k = int(np.flatnonzero(np.diff(lam) < 0)[0])  # first maximum of the load factor
    assert lam[k] * 1.5 * F_LIMIT == pytest.approx(F_LIMIT, rel=2e-3)
    assert lam.min() < 0  # the unstable branch is followed through negative loads
    # ... and ends on the far, inverted branch at exactly the full load
    assert lam[-1] == pytest.approx(1.0, abs=1e-12)
    assert path.X[-1, 2, 2] < -H


def test_arc_length_line_search_damps_overshooting_correctors():
    """A long arc-length increment (4x the default) jumps over the limit point: plain MGDCM
    correctors overshoot and wander (28 iterations), the backtracking line search
    (``line_search``, which scales the load-factor part with the rest) takes a third of them,
    and both paths lie on the closed-form curve."""
    iterations = {}
    for ls in (0, 8):
        base = _truss_scene(1.5 * F_LIMIT, "arc_length", 10)
        scene = Scene(
            base.model, supports=base.supports, loads=base.loads, steps=10,
            control="arc_length",
            options={"line_search": ls, "arc_length_increment": 4.0, "max_cutbacks": 0},
        )  # fmt: skip
        path = bh.solve(scene)
        w = H - path.X[:, 2, 2]
        np.testing.assert_allclose(
            path.load_factor * 1.5 * F_LIMIT, _curve(w), rtol=0, atol=1e-6 * F_LIMIT
        )
        assert path.load_factor[-1] == pytest.approx(1.0, abs=1e-12)
        iterations[ls] = path.meta["newton"]["total_iterations"]
    assert iterations[8] * 2 < iterations[0]


def test_critical_ahead_of_the_last_stable_states_finds_the_limit_load():
    """The stable states before the truss's limit point, as a path whose increments failed
    there leaves them: the lowest tangent eigenvalue falls like ``sqrt(F_max - F)``, so the
    extrapolation of its square lands on the closed-form limit load and that of the
    eigenvalue itself beyond it (``critical_ahead`` brackets it)."""
    from barhinge.analysis.buckling import critical_ahead

    scene = _truss_scene(1.5 * F_LIMIT, "arc_length", 40)
    scene = Scene(scene.model, supports=scene.supports, loads=scene.loads, steps=40,
                  control="arc_length", options={"arc_stop_instability": True})  # fmt: skip
    path = bh.solve(scene)
    stable = np.asarray(path.meta["negative_eigenvalues"]) == 0
    X, lam = np.asarray(path.X)[stable], np.asarray(path.load_factor)[stable]
    ahead = critical_ahead(scene.model, scene.supports, X, lam)
    lam_max = F_LIMIT / (1.5 * F_LIMIT)
    assert ahead.estimate == pytest.approx(lam_max, rel=2e-3)
    assert lam[-1] < ahead.estimate and ahead.linear > lam_max


def test_a_state_that_left_its_branch_is_named():
    """A converged state farther from its predictor than the predictor from the start left
    the branch (arc length with a limit-point or instability stop refuses that increment,
    load control too); one within that distance did not."""
    from types import SimpleNamespace

    from barhinge.solver.stability import left_branch
    from barhinge.solver.state import State

    ctx = SimpleNamespace(opts=SimpleNamespace(tol_disp=1e-8), size=1.0)
    start = State(np.zeros(3), np.zeros(0), 0.0, 0.0)
    pred = np.array([1.0, 0.0, 0.0])
    near = State(np.array([1.0, 0.9, 0.0]), np.zeros(0), 0.5, 0.0)
    assert left_branch(ctx, start, pred, near) == ""
    far = State(np.array([1.0, 1.1, 0.0]), np.zeros(0), 0.5, 0.0)
    assert left_branch(ctx, start, pred, far) == "correction 1.1 > predictor step 1"
