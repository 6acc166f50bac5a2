"""Linear buckling: stiffness split, a strut and a plate against their closed forms, named
errors."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.buckling import (
    critical_ahead,
    critical_between,
    linear_buckling,
    stiffness_parts,
)
from barhinge.errors import BucklingError
from barhinge.pattern.crease import CreasePattern
from barhinge.verify import rigid_link_strut


def test_stiffness_parts_sum_to_the_tangent():
    cp = bh.families.miura(2, 2, fold=50.0)
    m = bh.BarHingeModel.from_pattern(cp, "N5B8", bh.Material(E=1e3, nu=0.3, t=0.01))
    rng = np.random.default_rng(0)
    X = m.X0 + 0.01 * rng.standard_normal(m.X0.shape)
    Km, Kg = stiffness_parts(m, X)
    K = m.tangent(X)
    assert abs(Km + Kg - K).max() <= 1e-12 * abs(K).max()
    # at the stress-free reference the geometric part vanishes
    Km0, Kg0 = stiffness_parts(m, m.X0)
    assert abs(Kg0).max() <= 1e-12 * abs(Km0).max()


@pytest.mark.parametrize("n", [3, 5, 8])
def test_strut_of_rigid_links_buckles_at_the_closed_form(n):
    """Pinned-pinned chain of n rigid links of length l joined by rotational springs k,
    axial load P: the critical loads are ``P_j = (4 k / l) sin^2(j pi / (2 n))``, j = 1..n-1
    (the rigid-bar-spring column, e.g. Bazant & Cedolin 1991, Stability of Structures, ch. 1:
    energy ``k/(2 l^2) sum (w_(i+1) - 2 w_i + w_(i-1))^2 - P/(2 l) sum (w_i - w_(i-1))^2``,
    whose sine modes diagonalise the second difference; Euler's ``pi^2 k l / L^2`` as
    n -> oo). Panels 1e7 x stiffer than the creases: the links are rigid to ~1e-6."""
    ell, k = 1.0, 2.0
    m, S, P = rigid_link_strut(n, ell=ell, k=k)
    res = linear_buckling(m, P, S, n_modes=3)
    j = np.arange(1, min(3, n - 1) + 1)
    expect = 4 * k / ell * np.sin(j * np.pi / (2 * n)) ** 2
    np.testing.assert_allclose(res.factors[: len(j)], expect, rtol=1e-5)
    # the first mode is the half sine: the crease nodes move out of plane as sin(pi x / L)
    x = m.X0[: n + 1, 0]
    w = res.modes[0, : n + 1, 2]
    shape = np.sin(np.pi * x / (n * ell))
    np.testing.assert_allclose(w / w[np.argmax(np.abs(w))], shape / shape.max(), atol=1e-5)


def test_arc_length_stops_where_the_strut_bifurcates(monkeypatch):
    """The straight strut of rigid links (above) loaded along its axis by arc length with
    ``arc_stop_instability``: the path is the fundamental one (no lateral deflection), and
    it ends at the first state whose tangent has a negative eigenvalue, the first past the
    closed-form critical load ``P_1 = (4 k / l) sin^2(pi / (2 n))``."""
    from barhinge.analysis import buckling
    from barhinge.scene import Scene

    n, ell, k = 5, 1.0, 2.0
    m, S, P = rigid_link_strut(n, ell=ell, k=k)
    p1 = 4 * k / ell * np.sin(np.pi / (2 * n)) ** 2
    opts = {"arc_stop_instability": True, "arc_stop_load_factor": 3.0, "max_arc_steps": 200}
    path = bh.solve(Scene(m, supports=S, loads=P, control="arc_length", steps=20, options=opts))
    lam = np.asarray(path.load_factor)
    assert path.meta["arc_stop"]["criterion"] == "instability"
    assert lam[-2] < p1 <= lam[-1] < p1 + 0.2
    assert path.meta["negative_eigenvalues"][-1] == 1
    assert np.abs(np.asarray(path.X)[:, :, 2]).max() < 1e-9  # still straight
    # the tangent is linear in the load on the straight path: the interpolation is exact
    X = np.asarray(path.X)
    crit = critical_between(m, S, X[-2], X[-1], lam[-2], lam[-1])  # dense pencil
    assert crit == pytest.approx(p1, rel=1e-5)
    # the same by bisection on the inertia of the sparse factor (large systems)
    monkeypatch.setattr(buckling, "DENSE_PENCIL", 0)
    bisected = critical_between(m, S, X[-2], X[-1], lam[-2], lam[-1], rtol=1e-6)
    assert bisected == pytest.approx(p1, rel=1e-5)


def test_critical_ahead_of_the_last_stable_states_of_the_strut(monkeypatch):
    """The strut's straight path (above) without its first unstable state, as a path whose
    increments failed at the critical point leaves it: the lowest tangent eigenvalue of the
    last stable states falls linearly in the load (the tangent is linear in it), so its
    linear extrapolation lands on ``P_1 = (4 k / l) sin^2(pi / (2 n))`` and the extrapolation
    of its square (exact at a limit point) just below."""
    from barhinge.scene import Scene

    n, ell, k = 5, 1.0, 2.0
    m, S, P = rigid_link_strut(n, ell=ell, k=k)
    p1 = 4 * k / ell * np.sin(np.pi / (2 * n)) ** 2
    opts = {"arc_stop_instability": True, "arc_stop_load_factor": 3.0, "max_arc_steps": 200}
    path = bh.solve(Scene(m, supports=S, loads=P, control="arc_length", steps=20, options=opts))
    X, lam = np.asarray(path.X)[:-1], np.asarray(path.load_factor)[:-1]
    ahead = critical_ahead(m, S, X, lam)
    assert ahead.linear == pytest.approx(p1, rel=1e-5)
    assert lam[-1] < ahead.estimate < p1
    assert np.all(np.diff(ahead.lowest) < 0) and ahead.lowest[-1] > 0
    # far from the critical load the zero is out of reach: a named error
    with pytest.raises(BucklingError, match="farther ahead than the last increments"):
        critical_ahead(m, S, X[:4], lam[:4])
    # the same eigenvalues by shift-invert Lanczos (large systems)
    from barhinge.analysis import buckling

    monkeypatch.setattr(buckling, "DENSE_PENCIL", 0)
    sparse = critical_ahead(m, S, X, lam)
    # to round-off of the tangent, whose largest entries (the rigid panels) are ~1e7
    np.testing.assert_allclose(sparse.lowest, ahead.lowest, rtol=0, atol=1e-7)
    assert sparse.linear == pytest.approx(p1, rel=1e-5)


def test_critical_between_two_stable_states_is_a_named_error():
    from barhinge.scene import Scene

    m, S, P = rigid_link_strut(5)
    path = bh.solve(Scene(m, supports=S, loads=0.5 * P, control="load", steps=2))
    X = np.asarray(path.X)  # below the critical load 0.764: both states stable
    with pytest.raises(BucklingError, match="no loss of stability between the two states"):
        critical_between(m, S, X[0], X[-1], 0.0, 0.5)


def _plate_buckling_ratio(m: int) -> float:
    """First buckling load of a simply supported square plate (side 1 m, aluminium 2 mm)
    under uniform compression along x, cut into m x m cells with the coupled plate rule,
    over the closed form ``N_cr = 4 pi^2 D / b^2``."""
    from barhinge.model.plate_hinges import coupled_bending
    from barhinge.pattern.subdivide import subdivided

    mat = bh.Material(E=70e9, nu=0.33, t=2e-3)
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = CreasePattern(sq, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    cpm, _ = subdivided(cp, m)
    model = coupled_bending(
        bh.BarHingeModel.from_pattern(cpm, "N5B8", mat, bend_calibration="kirchhoff")
    )
    X = np.asarray(model.X0)
    corner = np.arange(model.n_nodes) < cpm.n_vertices  # centre nodes are never on an edge
    x0, x1 = corner & np.isclose(X[:, 0], 0.0), corner & np.isclose(X[:, 0], 1.0)
    edge = x0 | x1 | (corner & (np.isclose(X[:, 1], 0.0) | np.isclose(X[:, 1], 1.0)))
    S = np.zeros((model.n_nodes, 3), bool)
    S[edge, 2] = True  # simply supported: w = 0 on the four edges, rotations free
    S[x0, 0] = True  # the edge x = 0 held along x; one of its nodes along y
    S[np.flatnonzero(x0 & np.isclose(X[:, 1], 0.0)), 1] = True
    ids = np.flatnonzero(x1)
    ids = ids[np.argsort(X[ids, 1])]
    w = np.zeros(len(ids))  # tributary lengths: a uniform 1 N/m along x = 1
    w[:-1] += np.diff(X[ids, 1]) / 2
    w[1:] += np.diff(X[ids, 1]) / 2
    P = np.zeros((model.n_nodes, 3))
    P[ids, 0] = -w
    lam = linear_buckling(model, P, S, n_modes=1).factors[0]
    return float(lam / (4 * np.pi**2 * mat.bending_rigidity))


def test_refined_plate_buckles_at_the_closed_form():
    """The refined roofs' buckling factors (studies/roofs/refine.py) rest on this: a simply
    supported square plate under uniaxial compression buckles at ``N_cr = k pi^2 D / b^2``
    with ``k = (m b / a + a / (m b))^2 = 4`` for one half-wave (Timoshenko & Gere 1961,
    Theory of Elastic Stability, sec. 9.2). Cut into m x m cells with the coupled plate rule
    the bar-and-hinge plate converges to it at second order in the cell size (measured
    errors -2.8 % at m = 8, -0.70 % at m = 16)."""
    r8, r16 = _plate_buckling_ratio(8), _plate_buckling_ratio(16)
    assert abs(r16 - 1.0) < 0.01
    order = np.log2(abs(r8 - 1.0) / abs(r16 - 1.0))
    assert 1.8 < order < 2.2


def test_tension_only_has_no_buckling_factor():
    m, S, P = rigid_link_strut(3)
    with pytest.raises(BucklingError, match="nothing in compression"):
        linear_buckling(m, -P, S)


def test_mechanism_is_a_named_error():
    m, S, P = rigid_link_strut(3)
    S[:] = False
    S[0] = True
    with pytest.raises(BucklingError, match="singular|mechanism"):
        linear_buckling(m, P, S)


def test_modes_are_written_as_vtu(tmp_path):
    import meshio

    from barhinge.output.modes import write_mode_vtus

    m, S, P = rigid_link_strut(3)
    res = linear_buckling(m, P, S, n_modes=2)
    paths = write_mode_vtus(tmp_path, m, res.X, res.modes, res.factors)
    assert [p.name for p in paths] == ["buckling_mode_1.vtu", "buckling_mode_2.vtu"]
    back = meshio.read(paths[0])
    np.testing.assert_allclose(back.points, res.X, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back.point_data["mode"], res.modes[0], rtol=0, atol=1e-12)


def test_a_large_factor_released_while_the_geometric_stiffness_is_built_changes_nothing(
    monkeypatch,
):
    """Above ``RELEASE_FACTOR_ABOVE`` the stiffness's factor is freed while the geometric
    stiffness is assembled and factorised again for the eigensolver (peak memory): the
    buckling factors and modes are those of the one-factor route."""
    import barhinge.analysis.buckling as buckling
    from barhinge.linalg.backends import available_backends

    if "pardiso" not in available_backends():
        pytest.skip("the release applies to backends that report their factor's size")
    from barhinge.linalg.backends import PardisoBackend

    ref = _plate_buckling_ratio(4)
    calls = []
    release = PardisoBackend.release
    monkeypatch.setattr(PardisoBackend, "release", lambda self: calls.append(release(self)))
    monkeypatch.setattr(buckling, "RELEASE_FACTOR_ABOVE", -1)
    released = _plate_buckling_ratio(4)
    assert len(calls) == 1
    assert released == pytest.approx(ref, rel=1e-10)
