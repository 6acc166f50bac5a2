"""Triangulation (N4B5 / N5B8 / polygons), hinge bookkeeping, rest angles and overrides."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import barhinge as bh
from barhinge.errors import ConfigError, PatternError
from barhinge.kernels.geometry import hinge_angle
from barhinge.model.calibrate import bend_stiffness
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern


def polygon(k: int, r: float = 1.0) -> CreasePattern:
    t = 2 * np.pi * np.arange(k) / k
    V = np.column_stack([r * np.cos(t), r * np.sin(t)])
    E = [[i, (i + 1) % k] for i in range(k)]
    return CreasePattern(V, E, ["B"] * k, faces=[list(range(k))])


@pytest.mark.parametrize(
    ("k", "scheme", "nodes", "bars", "bend"),
    [
        (3, "N4B5", 3, 3, 0),
        (4, "N4B5", 4, 5, 1),
        (4, "N5B8", 5, 8, 4),
        (6, "N4B5", 7, 12, 6),  # polygons: centre node in both schemes
        (6, "N5B8", 7, 12, 6),
    ],
)
def test_single_panel_counts(k: int, scheme: str, nodes: int, bars: int, bend: int) -> None:
    m = BarHingeModel.from_pattern(polygon(k), scheme)
    assert (m.n_nodes, m.n_bars, m.n_hinges) == (nodes, bars, bend)
    assert (m.hinge_kind == "bend").all() and (m.hinge_face == 0).all()
    assert (m.hinge_edge == -1).all()
    assert np.allclose(m.X0[: m.pattern.n_vertices], m.pattern.vertices3d)
    if nodes > k:  # centre node at the mean of the corners
        assert np.allclose(m.X0[k], m.pattern.vertices3d.mean(axis=0))


def test_n4b5_splits_along_the_shorter_diagonal() -> None:
    V = np.array([[0, 0], [3, 0], [3.5, 1], [0.5, 1]], float)  # diagonal 1-3 is shorter
    cp = CreasePattern(V, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    m = BarHingeModel.from_pattern(cp, "N4B5")
    assert sorted(m.hinges[0, :2].tolist()) == [1, 3]


def test_miura_counts_and_bookkeeping() -> None:
    nx, ny = 3, 2
    cp = bh.families.miura(nx, ny, fold=30.0)
    nf = cp.n_faces
    n_crease = len(cp.crease_edges)
    for scheme, extra_nodes, bars_per_face, bend_per_face in (("N4B5", 0, 1, 1), ("N5B8", 1, 4, 4)):
        m = BarHingeModel.from_pattern(cp, scheme)
        assert m.n_nodes == cp.n_vertices + extra_nodes * nf
        assert m.n_bars == cp.n_edges + bars_per_face * nf
        fold = m.hinge_kind == "fold"
        assert fold.sum() == n_crease
        assert (m.hinge_kind == "bend").sum() == bend_per_face * nf
        # every crease edge has exactly one fold hinge, lying on that edge
        assert sorted(m.hinge_edge[fold].tolist()) == sorted(cp.crease_edges.tolist())
        e = m.hinge_edge[fold]
        assert np.array_equal(m.hinges[fold, :2], cp.edges[e])
        assert (m.fold_hinge_of_edge[cp.boundary_edges] == -1).all()
        # bend hinges are inside their face: the axis joins two nodes of that face
        bend = np.flatnonzero(~fold)
        for h in bend[:10]:
            f = m.hinge_face[h]
            face_nodes = set(cp.faces[f]) | set(range(cp.n_vertices, m.n_nodes))
            assert set(m.hinges[h, :2].tolist()) <= face_nodes
        # rest angles = the state: fold hinges equal the pattern's state, bend hinges ~0
        assert np.allclose(np.degrees(m.rest_angle[fold]), cp.state_fold_angles()[e], atol=1e-9)
        assert np.abs(m.rest_angle[~fold]).max() < 1e-9
        assert np.allclose(m.rest_angle, hinge_angle(m.X0, m.hinges))


def test_nonplanar_quad_n5b8_rest_angles_take_the_state() -> None:
    """A twisted (non-planar) quad: the centre node is the mean of the corners and the
    bending hinges' rest angles are the state's, so the model is stress-free at X0."""
    V = np.array([[0, 0, 0], [1, 0, 0.1], [1, 1, 0], [0, 1, 0.1]], float)
    cp = CreasePattern(
        V, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]], validate=False
    )
    m = BarHingeModel.from_pattern(cp, "N5B8")
    assert np.allclose(m.X0[4], V.mean(0))
    assert np.abs(m.rest_angle).max() > 0.05
    ev = m.evaluate(m.X0)
    assert ev.energy < 1e-20 * m.bar_EA.max()
    assert np.abs(ev.force).max() < 1e-12 * m.bar_EA.max()


def test_stiffness_defaults_overrides_and_ratio() -> None:
    cp = bh.families.miura(2, 2)
    mat = Material(E=2e9, nu=0.3, t=1e-3)
    D = mat.bending_rigidity
    m = BarHingeModel.from_pattern(
        cp, "N5B8", mat, crease_length_scale=0.05, bend_calibration="filipov"
    )
    fold = m.hinge_kind == "fold"
    L = np.linalg.norm(m.X0[m.hinges[fold, 1]] - m.X0[m.hinges[fold, 0]], axis=1)
    # Filipov et al. 2017: k_F = L_F * D / L*
    assert np.allclose(m.hinge_k[fold], L * D / 0.05)
    m2 = BarHingeModel.from_pattern(cp, "N5B8", mat, fold_stiffness=0.7)
    assert np.allclose(m2.hinge_k[fold], 0.7 * L)
    # bending: C_B D (D_L / t)^(1/3), D_L the full diagonal through the centre
    bend = ~fold
    axis = np.linalg.norm(m.X0[m.hinges[bend, 1]] - m.X0[m.hinges[bend, 0]], axis=1)
    assert np.allclose(m.hinge_k[bend], 0.55 * D * np.cbrt(2 * axis / mat.t))
    assert np.allclose(m.hinge_k[bend], bend_stiffness(2 * axis, mat))
    m3 = BarHingeModel.from_pattern(cp, "N5B8", mat, bar_EA=5.0, bend_k=2.0, fold_k=0.1)
    assert (m3.bar_EA == 5.0).all() and (m3.hinge_k[bend] == 2.0).all()
    assert (m3.hinge_k[fold] == 0.1).all()
    m4 = BarHingeModel.from_pattern(
        cp, "N5B8", mat, crease_length_scale=0.05, stiffness_ratio=10.0, bend_calibration="filipov"
    )
    assert np.allclose(m4.bar_EA, 10 * m.bar_EA) and np.allclose(
        m4.hinge_k[bend], 10 * m.hinge_k[bend]
    )
    assert np.allclose(m4.hinge_k[fold], m.hinge_k[fold])
    m5 = m.stiffened(10.0)
    assert np.allclose(m5.bar_EA, m4.bar_EA) and np.allclose(m5.hinge_k, m4.hinge_k)
    assert m.with_(fold_law="penetration").fold_law == "penetration"


@pytest.mark.parametrize(
    "kwargs",
    [
        {"scheme": "N6B9"},
        {"fold_law": "cubic"},
        {"fold_stiffness": 1.0, "crease_length_scale": 1.0},
        {"fold_stiffness": -1.0},
        {"stiffness_ratio": 0.0},
        {"fold_limits_deg": (10.0, 120.0)},
        {"bar_EA": [1.0, 2.0]},
        {"strain": "log"},
    ],
)
def test_bad_options_raise_config_error(kwargs: dict) -> None:
    with pytest.raises(ConfigError):
        BarHingeModel.from_pattern(bh.families.miura(1, 1), **kwargs)


def test_bad_material_and_coordinates() -> None:
    with pytest.raises(ConfigError):
        Material(E=-1.0)
    with pytest.raises(ConfigError):
        Material(nu=0.6)
    m = BarHingeModel.from_pattern(bh.families.miura(1, 1))
    with pytest.raises(ConfigError):
        m.evaluate(np.zeros((3, 3)))


def test_degenerate_face_raises_pattern_error() -> None:
    V = np.array([[0, 0], [1, 0], [2, 0]], float)  # a triangle face with collinear corners
    cp = CreasePattern(V, [[0, 1], [1, 2], [2, 0]], ["B"] * 3, faces=[[0, 1, 2]], validate=False)
    with pytest.raises(PatternError, match="degenerate"):
        BarHingeModel.from_pattern(cp, "N5B8")


@settings(max_examples=20, deadline=None)
@given(
    k=st.integers(3, 8), seed=st.integers(0, 2**31 - 1), scheme=st.sampled_from(["N4B5", "N5B8"])
)
def test_random_convex_panel_is_stress_free_and_has_only_rigid_modes(
    k: int, seed: int, scheme: str
) -> None:
    """Any convex polygon, any scheme: zero energy and force at X0, and exactly six zero
    eigenvalues of the free tangent (3 in-plane + 3 out-of-plane rigid motions): the centre
    fan (or the N4B5 diagonal) leaves no in-plane or out-of-plane mechanism."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, k))
    t = t + np.linspace(0, 0.4, k)  # keep corners apart
    r = rng.uniform(0.8, 1.2)
    V = np.column_stack(
        [r * np.cos(t * 2 * np.pi / (t[-1] + 0.4)), r * np.sin(t * 2 * np.pi / (t[-1] + 0.4))]
    )
    cp = CreasePattern(V, [[i, (i + 1) % k] for i in range(k)], ["B"] * k, faces=[list(range(k))])
    m = BarHingeModel.from_pattern(cp, scheme, Material(E=1.0, nu=0.3, t=0.05))
    ev = m.evaluate(m.X0)
    assert ev.energy < 1e-25 and np.abs(ev.force).max() < 1e-13
    w = np.linalg.eigvalsh(ev.K.toarray())
    assert int((np.abs(w) < 1e-9 * w.max()).sum()) == 6
