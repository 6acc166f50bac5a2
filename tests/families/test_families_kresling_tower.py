"""Folded Kresling towers (families.kresling(fold=1 | 2)) against the closed-form stable
states of the truss model (Cai, Deng, Zhou, Feng & Tu 2015, J. Mech. Des. 137(6):061406)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from barhinge import families
from barhinge.errors import PatternError
from barhinge.families.kresling import kresling_states
from barhinge.model.model import BarHingeModel


def _lengths(cp):
    X = cp.vertices3d
    return np.linalg.norm(X[cp.edges[:, 1]] - X[cp.edges[:, 0]], axis=1)


@pytest.mark.parametrize(("n", "height", "shift"), [(6, 1.6, 0.3), (8, 2.5, 0.2), (5, 1.5, 0.2)])
@pytest.mark.parametrize("fold", [1, 2])
def test_tower_keeps_every_crease_length_of_the_flat_pattern(n, height, shift, fold):
    """Both states are stress-free for bars: the tower's edges take exactly the three lengths
    of the flat pattern (polygon side a, slanted crease b, diagonal c), n of each per story
    and polygon."""
    flat = families.kresling(n, 2, height=height, shift=shift)
    tower = families.kresling(n, 2, height=height, shift=shift, fold=fold)
    want = np.unique(np.round(_lengths(flat), 12))
    assert len(want) == 3
    got = _lengths(tower)
    assert np.abs(got[:, None] - want[None, :]).min(axis=1).max() < 1e-12
    assert tower.n_vertices == 3 * n and tower.n_edges == 3 * n * 2 + n
    # fold angles and assignment are those of the state
    np.testing.assert_allclose(tower.fold_angles, tower.state_fold_angles(), atol=1e-12)
    F, A = tower.fold_angles, tower.assignment
    assert np.all(F[A == "V"] > 0) and np.all(F[A == "M"] < 0) and np.all(F[A == "B"] == 0)


def test_states_match_the_closed_form_measured_from_the_vertices():
    """sin(phi + pi/n) = (c^2 - b^2) / (4 R^2 sin(pi/n)); H^2 = b^2 - 2 R^2 (1 - cos phi):
    the turn and rise of each story read back from the coordinates, two roots."""
    n, a, h, s = 6, 1.0, 1.6, 0.3
    R = a / (2 * math.sin(math.pi / n))
    b2, c2 = s**2 + h**2, (1 + s) ** 2 + h**2
    q = (c2 - b2) / (4 * R**2 * math.sin(math.pi / n))
    phis = (math.asin(q) - math.pi / n, math.pi - math.asin(q) - math.pi / n)
    st = kresling_states(n, a, h, s)
    for k, phi in enumerate(phis):
        H = math.sqrt(b2 - 2 * R**2 * (1 - math.cos(phi)))
        assert st.phi[k] == pytest.approx(phi, abs=1e-14)
        assert st.H[k] == pytest.approx(H, rel=1e-14)
        X = families.kresling(n, 3, height=h, shift=s, fold=k + 1).vertices3d.reshape(4, n, 3)
        turn = np.diff(np.unwrap(np.arctan2(X[:, 0, 1], X[:, 0, 0])))
        np.testing.assert_allclose(turn, phi, atol=1e-13)
        np.testing.assert_allclose(np.diff(X[:, :, 2], axis=0), H, atol=1e-13)
        np.testing.assert_allclose(np.linalg.norm(X[:, :, :2], axis=2), R, rtol=1e-13)
    assert st.H[0] > st.H[1] > 0


def test_second_state_is_stress_free_for_a_model_built_on_the_first():
    """Bars carry no energy in the other stable state (truss bistability); only the folds do."""
    cp1 = families.kresling(6, 1, height=1.6, shift=0.3, fold=1)
    cp2 = families.kresling(6, 1, height=1.6, shift=0.3, fold=2)
    m = BarHingeModel.from_pattern(cp1, bar_EA=1.0, fold_k=0.0)
    assert m.energy(cp2.vertices3d) < 1e-25
    assert BarHingeModel.from_pattern(cp1, bar_EA=1.0, fold_k=1.0).energy(cp2.vertices3d) > 0.1


def test_patterns_without_two_states_are_rejected():
    with pytest.raises(PatternError, match="does not close"):
        families.kresling(6, 1, height=1.6, shift=0.6, fold=1)
    with pytest.raises(PatternError, match="no height"):
        families.kresling(6, 1, height=0.8, shift=0.3, fold=2)
    with pytest.raises(PatternError, match="expected None"):
        families.kresling(6, 1, height=1.6, shift=0.3, fold=3)
    assert families.kresling(6, 1, height=1.6, shift=0.3, fold=2.0).n_vertices == 12  # TOML float


def test_bistable_scene_reaches_the_second_state_over_a_barrier():
    """data/scenes/kresling_bistable.toml: its prescribed drop is H2 - H1 of the closed form;
    solved, the bars' energy rises to a barrier and returns to (almost) zero in the short
    state, where the top has turned by phi_2 (free, found by the solver)."""
    from pathlib import Path

    import barhinge as bh

    path_toml = Path(__file__).resolve().parents[2] / "data" / "scenes" / "kresling_bistable.toml"
    scene = bh.load_scene(path_toml)
    st = kresling_states(6, 1.0, 1.6, 0.3)
    top = np.flatnonzero(np.isfinite(scene.prescribed[:, 2]))
    assert len(top) == 6
    np.testing.assert_allclose(scene.prescribed[top, 2], st.H[1] - st.H[0], rtol=1e-15)
    path = bh.solve(scene)
    m = scene.model
    bars = np.array([m.element_energies(X)[0].sum() for X in path.X])
    k = int(np.argmax(bars))
    assert 0 < k < len(bars) - 1 and bars[k] > 1e3 * bars[-1]
    # the folds (rest angles of the tall state) load the bars a little: O(k_fold / EA),
    # measured 6e-10 of the barrier
    assert bars[-1] < 1e-8 * bars[k]
    X = path.X[-1, top]
    turn = np.arctan2(X[:, 1], X[:, 0]) - 2 * np.pi * np.arange(6) / 6
    np.testing.assert_allclose(
        np.remainder(turn + np.pi, 2 * np.pi) - np.pi, st.phi[1], atol=1e-5
    )  # fold moments: measured 2.3e-6
