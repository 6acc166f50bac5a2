"""Bar and hinge geometry kernels: finite differences, oracle, sign convention, full range."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from barhinge.kernels.geometry import (
    TRIU12,
    bar_lengths,
    bar_strain,
    bar_strain_derivatives,
    hinge_angle,
    hinge_angle_derivatives,
    hinge_angle_gradient,
    hinge_angle_gradient_t,
    hinge_angle_hessian_packed,
)
from barhinge.kernels.reference import bar_reference, hinge_reference, hinge_with_angle
from barhinge.pattern.crease import CreasePattern

H4 = np.array([[0, 1, 2, 3]])


def make_hinge(rho: float, rng: np.random.Generator) -> np.ndarray:
    return hinge_with_angle(rho, rng)


def fd_hinge(X: np.ndarray, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Central differences of rho (unwrapped) and of its analytic gradient."""
    G = np.zeros(12)
    HH = np.zeros((12, 12))
    for c in range(12):
        Xp, Xm = X.copy(), X.copy()
        Xp[c // 3, c % 3] += h
        Xm[c // 3, c % 3] -= h
        rp, gp = hinge_angle_gradient(Xp, H4)
        rm, gm = hinge_angle_gradient(Xm, H4)
        G[c] = np.angle(np.exp(1j * (rp[0] - rm[0]))) / (2 * h)
        HH[c] = (gp[0] - gm[0]) / (2 * h)
    return G, HH


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


ANGLES = [0.0, 1e-7, -1e-7, 0.3, -1.2, 2.5, np.radians(179.3), -np.radians(179.6)]


@pytest.mark.parametrize("rho", ANGLES)
def test_hinge_angle_gradient_hessian_match_central_differences(rho: float) -> None:
    rng = np.random.default_rng(abs(hash(rho)) % 2**32)
    for _ in range(3):
        X = make_hinge(rho, rng)
        r, g, H = hinge_angle_derivatives(X, H4)
        assert r[0] == pytest.approx(rho, abs=1e-12)
        G, HH = fd_hinge(X)
        assert rel(g[0], G) <= 1e-6
        assert rel(H[0], HH) <= 1e-6
        assert np.array_equal(H[0], H[0].T)


@settings(max_examples=60, deadline=None)
@given(
    rho=st.floats(-np.pi + 1e-9, np.pi - 1e-9),
    seed=st.integers(0, 2**32 - 1),
)
def test_hinge_angle_recovers_construction_over_full_range(rho: float, seed: int) -> None:
    X = make_hinge(rho, np.random.default_rng(seed))
    # atan2 form: absolute accuracy ~1e-15 rad at every angle, flat and fully folded included
    assert hinge_angle(X, H4)[0] == pytest.approx(rho, abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_vectorised_hinge_equals_liu_paulino_oracle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 7
    X = rng.normal(size=(4 * n, 3))
    hinges = np.arange(4 * n).reshape(n, 4)
    rho, g, H = hinge_angle_derivatives(X, hinges)
    r2, gp, Hp = hinge_angle_hessian_packed(X, hinges)
    for e in range(n):
        ro, go, Ho = hinge_reference(*X[hinges[e]])
        assert abs(rho[e] - ro) <= 1e-12 * max(1.0, abs(ro))
        assert rel(g[e], go) <= 1e-12
        assert rel(H[e], Ho) <= 1e-12
        # the packed fast path is the same matrix
        assert rel(Hp[:, e], Ho[TRIU12]) <= 1e-12
        assert rel(gp[:, e], go) <= 1e-12
    assert np.array_equal(r2, rho)
    r3, g3 = hinge_angle_gradient_t(X, hinges, chunk=3)  # several chunks
    assert np.array_equal(r3, rho) and rel(g3.T, g) <= 1e-14


@pytest.mark.parametrize("measure", ["green", "engineering"])
def test_bar_strain_derivatives_match_fd_and_oracle(measure: str) -> None:
    rng = np.random.default_rng(3)
    X = rng.normal(size=(10, 3))
    bars = np.array([[0, 1], [2, 3], [4, 5], [6, 7], [8, 9], [1, 4]])
    L0 = bar_lengths(X, bars) * rng.uniform(0.8, 1.2, len(bars))
    eps, d, B = bar_strain_derivatives(X, bars, L0, measure)
    assert np.allclose(eps, bar_strain(X, bars, L0, measure), rtol=0, atol=1e-15)
    h = 1e-6
    for e, (a, b) in enumerate(bars):
        ro, go, Ho = bar_reference(X[a], X[b], L0[e], measure)
        assert eps[e] == pytest.approx(ro, abs=1e-14)
        g = np.concatenate([-d[e], d[e]])
        Hf = np.block([[B[e], -B[e]], [-B[e], B[e]]])
        assert rel(g, go) <= 1e-12 and rel(Hf, Ho) <= 1e-12
        for c in range(6):
            node, ax = (a, b)[c // 3], c % 3
            Xp, Xm = X.copy(), X.copy()
            Xp[node, ax] += h
            Xm[node, ax] -= h
            ep = bar_strain(Xp, bars[e : e + 1], L0[e : e + 1], measure)[0]
            em = bar_strain(Xm, bars[e : e + 1], L0[e : e + 1], measure)[0]
            assert (ep - em) / (2 * h) == pytest.approx(g[c], rel=1e-6, abs=1e-9)
            _, dp, _ = bar_strain_derivatives(Xp, bars[e : e + 1], L0[e : e + 1], measure)
            _, dm, _ = bar_strain_derivatives(Xm, bars[e : e + 1], L0[e : e + 1], measure)
            gp = np.concatenate([-dp[0], dp[0]])
            gm = np.concatenate([-dm[0], dm[0]])
            assert rel((gp - gm) / (2 * h), Hf[c]) <= 1e-6 or np.abs(Hf[c]).max() < 1e-12


def test_sign_matches_pattern_state_on_hand_folded_strip() -> None:
    """Three square faces in a strip; the first crease folded as a valley (+50 deg) and the
    second as a mountain (-70 deg) by hand; the hinge quadruple oriented as the model does
    (axis edges[e,0] -> edges[e,1], wing k in the left face) gives the pattern's own
    state_fold_angles (crease.py, Newell normals) -- an independent computation."""
    # flat: x from 0..3, y from 0..1; vertices (x, y)
    V = np.array([[x, y, 0.0] for y in (0, 1) for x in (0, 1, 2, 3)])  # 0..3 bottom, 4..7 top
    faces = [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6]]
    edges = [[0, 1], [1, 2], [2, 3], [4, 5], [5, 6], [6, 7], [0, 4], [1, 5], [2, 6], [3, 7]]
    asg = ["B"] * 6 + ["B", "V", "M", "B"]
    # fold: rotate faces 1 and 2 about crease 1-5 (the y axis at x=1) so that they come up
    # (+z, the side of the normals): a valley of 50 deg (rotation by -50 deg about +y)
    Xf = V.copy()
    R1 = Rotation.from_rotvec([0.0, -np.radians(50), 0.0])
    for v in (2, 3, 6, 7):
        Xf[v] = R1.apply(V[v] - V[1]) + V[1]
    # then face 2 about crease 2-6 by +70 deg about the axis 2 -> 6: away from the normal side
    # of face 1, a mountain of 70 deg
    axis = (Xf[6] - Xf[2]) / np.linalg.norm(Xf[6] - Xf[2])
    R2 = Rotation.from_rotvec(axis * np.radians(70))
    for v in (3, 7):
        Xf[v] = R2.apply(Xf[v] - Xf[2]) + Xf[2]
    cp = CreasePattern(Xf, edges, asg, faces=faces)
    state = cp.state_fold_angles()
    assert state[7] == pytest.approx(50.0, abs=1e-9)
    assert state[8] == pytest.approx(-70.0, abs=1e-9)
    # hinge of edge 7 (1 -> 5): left face 0 (wing 0), right face 1 (wing 2)
    # hinge of edge 8 (2 -> 6): left face 1 (wing 1), right face 2 (wing 3)
    hinges = np.array([[1, 5, 0, 2], [2, 6, 1, 3]])
    assert np.degrees(hinge_angle(Xf, hinges)) == pytest.approx([50.0, -70.0], abs=1e-9)


def test_sign_matches_folded_miura_state() -> None:
    """Fold hinges of a rigidly folded Miura (patterns helper's closed form) reproduce the
    pattern's state fold angles, with valleys positive."""
    pytest.importorskip("barhinge.families.miura")
    import barhinge as bh
    from barhinge.model.model import BarHingeModel

    cp = bh.families.miura(2, 2, fold=35.0)
    for scheme in ("N4B5", "N5B8"):
        m = BarHingeModel.from_pattern(cp, scheme=scheme)
        state = cp.state_fold_angles()
        got = m.crease_fold_angles_deg(m.X0)
        has = m.fold_hinge_of_edge >= 0
        assert np.allclose(got[has], state[has], rtol=0, atol=1e-9)
        V = cp.assignment == "V"
        assert (got[V] > 0).all() and (got[cp.assignment == "M"] < 0).all()
