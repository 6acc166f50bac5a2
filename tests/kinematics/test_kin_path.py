"""Rigid folding paths: Miura-ori against Schenk & Guest (2013), constraint residuals and
panel edge lengths along a large path, schedules, and the one-line diagnostics."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.linalg.backends import available_backends


@pytest.fixture(scope="module")
def miura30_path():
    """30 x 30 cells (61 x 61 vertices, 7080 creases), driven by one zig-zag crease in the
    middle from flat to -150 deg (its mountain side) in 10 steps."""
    nx = ny = 30
    cp = bh.families.miura(nx, ny, a=1.0, b=1.3, alpha=55.0)
    lay = bh.families.miura_layout(nx, ny)
    zz = lay.interior_zigzag_edges
    e = int(zz[len(zz) // 2])
    sign = 1.0 if cp.assignment[e] == "V" else -1.0
    path = bh.rigid_fold(cp, [e], [sign * 150.0], steps=10)
    return cp, lay, e, sign, path


def test_miura_path_keeps_constraints_and_lengths(miura30_path):
    cp, _, _, _, path = miura30_path
    assert path.kind == "rigid" and path.converged
    assert path.X.shape == (11, cp.n_vertices, 3)
    assert path.fold_angles_deg.shape == (11, cp.n_edges)
    rc = RigidConstraints.from_pattern(cp)
    X0 = cp.vertices3d
    L0 = np.linalg.norm(X0[cp.edges[:, 1]] - X0[cp.edges[:, 0]], axis=1)
    for s in range(path.n_states):
        rho = np.radians(path.fold_angles_deg[s, rc.crease_edge])
        # residual recomputed from the stored angles (independent of the solver's record)
        assert np.abs(rc.residual(rho)).max() < 1e-10
        X = path.X[s]
        L = np.linalg.norm(X[cp.edges[:, 1]] - X[cp.edges[:, 0]], axis=1)
        assert np.abs(L - L0).max() < 1e-10
        # panel diagonals too (rigid, planar panels)
        for f in cp.faces[:: max(1, cp.n_faces // 200)]:
            d0 = np.linalg.norm(X0[f[2]] - X0[f[0]])
            assert abs(np.linalg.norm(X[f[2]] - X[f[0]]) - d0) < 1e-10


def test_miura_path_follows_schenk_guest(miura30_path):
    """Schenk & Guest (2013, PNAS 110(9):3276, Eq. 1) with facet angle theta = rho_z / 2:
    straight creases |rho_s| = 2 arctan(cos(gamma) tan(theta)); cell dimensions
    H = a sin(theta) sin(gamma), S = b cos(theta) tan(gamma) / sqrt(1 + cos^2 theta tan^2
    gamma), L = a sqrt(1 - sin^2 theta sin^2 gamma), V = b / sqrt(1 + cos^2 theta tan^2 gamma),
    measured on the rebuilt coordinates at every step."""
    cp, lay, e, sign, path = miura30_path
    a, b, g = 1.0, 1.3, np.radians(55.0)
    ni = lay.ni
    vid = lambda i, j: j * ni + i  # noqa: E731  (vertex id of grid point (i, j))
    for s in range(1, path.n_states):
        rho = path.fold_angles_deg[s]
        th = np.radians(sign * rho[e]) / 2
        ref = bh.families.miura_fold_angles(lay, 55.0, np.degrees(th))
        np.testing.assert_allclose(rho, ref, rtol=0, atol=1e-9)
        rs = np.radians(np.abs(rho[lay.interior_straight_edges]))
        np.testing.assert_allclose(rs, 2 * np.arctan(np.cos(g) * np.tan(th)), rtol=0, atol=1e-9)
        D = np.sqrt(1 + np.cos(th) ** 2 * np.tan(g) ** 2)
        H, S = a * np.sin(th) * np.sin(g), b * np.cos(th) * np.tan(g) / D
        L, V = a * np.sqrt(1 - np.sin(th) ** 2 * np.sin(g) ** 2), b / D
        X = path.X[s]
        for i, j in [(0, 0), (10, 20), (40, 50), (56, 2)]:
            p0, p2 = X[vid(i, j)], X[vid(i + 2, j)]
            assert abs(np.linalg.norm(p2 - p0) - 2 * L) < 1e-9
            assert abs(np.linalg.norm(X[vid(i, j + 2)] - p0) - 2 * S) < 1e-9
            # even-i vertices lie in one plane, odd-i ones at height H above it
            q = X[vid(i, j + 1)]
            n = np.cross(p2 - p0, q - p0)
            n /= np.linalg.norm(n)
            assert abs(abs(n @ (X[vid(i + 1, j)] - p0)) - H) < 1e-9
            # zig-zag offset V: component of (i, j)->(i, j+1) along the straight direction
            assert abs(abs((q - p0) @ (p2 - p0)) / (2 * L) - V) < 1e-9


def test_path_with_actuators_schedule_and_folded_start():
    """A table schedule from a folded start state; starts from the pattern's own geometry and
    returns the schedule's angles exactly."""
    cp = bh.families.miura(3, 2, fold=20.0)
    lay = bh.families.miura_layout(3, 2)
    e = int(lay.interior_straight_edges[3])
    start = cp.fold_angles[e]
    table = np.array([[start * 1.5], [start * 2.0], [start * 1.2]])
    act = bh.Actuators(edges=[e], table_deg=table)
    path = bh.rigid_fold(cp, act)
    assert path.n_states == 4
    np.testing.assert_allclose(path.fold_angles_deg[0], cp.fold_angles, atol=1e-9)
    np.testing.assert_allclose(path.fold_angles_deg[1:, e], table[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(path.actuator_targets_deg[1:, 0], table[:, 0])
    assert path.meta["dof"] == [1, 1, 1, 1]
    # the state at step 0 is the input geometry
    np.testing.assert_allclose(path.X[0], cp.vertices3d, atol=1e-12)


def test_actuator_that_is_not_a_crease_is_rejected():
    cp = bh.families.miura(2, 2)
    b = int(cp.boundary_edges[0])
    with pytest.raises(ConfigError, match=f"actuator edge {b} .* not a foldable"):
        bh.rigid_fold(cp, [b], [30.0], steps=2)


def test_under_determined_actuators_are_resolved_by_the_fold_energy():
    """Triangulated Miura: DOF = boundary edges - 3 (Tachi 2010) >> 1 actuator. The free
    motions are resolved by minimising the spring energy; as the diagonals stiffen the
    result must approach the rigid-panel path (an independent solve with 1 DOF, no energy)
    with error proportional to 1 / diagonal stiffness (log-log slope -1)."""
    cp = bh.families.miura(2, 2)
    act = [int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])]
    ref = bh.rigid_fold(cp, act, [-40.0], steps=4).fold_angles_deg[-1]
    ks = np.array([1e3, 1e4, 1e5])
    err = []
    for kd in ks:
        path = bh.rigid_fold(cp, act, [-40.0], steps=4, triangulated=True, diagonal_stiffness=kd)
        assert path.converged and path.meta["free_dof"] == 12
        assert path.meta["max_closure"] < 1e-10
        err.append(np.abs(path.fold_angles_deg[-1] - ref).max())
    slope = np.polyfit(np.log(ks), np.log(err), 1)[0]
    assert abs(slope + 1.0) < 0.05, (err, slope)


def _incompatible_miura():
    cp = bh.families.miura(2, 2, fold=30.0)
    lay = bh.families.miura_layout(2, 2)
    z, s = int(lay.interior_zigzag_edges[0]), int(lay.interior_straight_edges[0])
    return cp, [z, s], [cp.fold_angles[z] * 1.5, cp.fold_angles[s] * 0.5]


def test_incompatible_over_determined_actuators_are_named_on_request():
    """Miura (1 DOF) driven at two creases with targets that contradict S&G's relation."""
    from barhinge.kinematics.path import RigidOptions

    cp, act, targets = _incompatible_miura()
    with pytest.raises(ConfigError, match=r"over-determine.*edges \[\d+\] follow from edges"):
        bh.rigid_fold(cp, act, targets, steps=4, options=RigidOptions(over_actuated="error"))


def test_incompatible_targets_are_met_in_least_squares():
    """Default: the two targets are met in least squares along the 1-DOF path. Independent
    check: minimise the same misfit over the 1-DOF path parametrised by one actuator alone
    (each point an ordinary one-actuator rigid fold) with a scalar minimiser."""
    from scipy.optimize import minimize_scalar

    cp, act, targets = _incompatible_miura()
    path = bh.rigid_fold(cp, act, targets, steps=4)
    assert path.converged and any("least squares" in ev for ev in path.meta["events"])
    got = path.fold_angles_deg[-1, act]

    def misfit(v):
        fa = bh.rigid_fold(cp, [act[0]], [v], steps=4).fold_angles_deg[-1, act]
        return float(np.sum(np.radians(fa - targets) ** 2))

    t0 = targets[0]
    best = minimize_scalar(misfit, bounds=(t0 - 30, t0 + 30), options={"xatol": 1e-7})
    ref = bh.rigid_fold(cp, [act[0]], [best.x], steps=4).fold_angles_deg[-1, act]
    # the fold springs (1e-6 of the actuator springs) shift the least-squares point by
    # O(1e-6) relative: ~1e-4 deg on angles of ~70 deg
    np.testing.assert_allclose(got, ref, rtol=0, atol=5e-4)
    assert path.meta["actuator_misfit_deg"][-1] == pytest.approx(
        np.abs(got - targets).max(), abs=1e-9
    )


def test_compatible_over_determined_actuators_are_accepted():
    """Two creases of the same family driven alike stay compatible."""
    cp = bh.families.miura(2, 2, fold=30.0)
    zz = bh.families.miura_layout(2, 2).interior_zigzag_edges
    z = [int(k) for k in zz if cp.fold_angles[k] > 0][:2]
    path = bh.rigid_fold(cp, z, [100.0, 100.0], steps=4)
    assert path.converged
    np.testing.assert_allclose(path.fold_angles_deg[-1, z], [100.0, 100.0], atol=1e-9)


def test_locking_threshold_stops_the_path():
    cp = bh.families.miura(2, 2)
    e = int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])
    sign = 1.0 if cp.assignment[e] == "V" else -1.0
    from barhinge.kinematics.path import RigidOptions

    opt = RigidOptions(lock_deg=120.0)
    with pytest.raises(bh.ConvergenceError, match="locked") as info:
        bh.rigid_fold(cp, [e], [sign * 150.0], steps=5, options=opt)
    assert info.value.last_state.kind == "rigid"


def test_corrector_converges_quadratically():
    """Gauss-Newton on a consistent system with an exact Jacobian, solved inexactly with
    forcing term eta_k ~ |r_k| (Dembo, Eisenstat & Steihaug 1982): r_{k+1} <= C r_k^2."""
    from barhinge.kinematics.path import RigidOptions, RigidSolver

    cp = bh.families.miura(4, 4, fold=40.0)
    rc = RigidConstraints.from_pattern(cp)
    e = int(bh.families.miura_layout(4, 4).interior_zigzag_edges[3])
    act = rc.var_of_source_edge[[e]]
    solver = RigidSolver(rc, act, RigidOptions(tol=1e-15, max_iter=10))
    x = rc.rho0 + 3e-3 * np.random.default_rng(0).standard_normal(rc.n_var)
    x[act] = rc.rho0[act]
    out, hist, ok = solver.corrector(x)
    assert ok and len(hist) <= 6
    h = np.array(hist)
    big = h[:-1] > 1e-14
    assert np.all(h[1:][big] <= 50.0 * h[:-1][big] ** 2)
    np.testing.assert_allclose(out, rc.rho0, rtol=0, atol=1e-12)  # the 1-DOF state is unique


@pytest.mark.skipif("pardiso" not in available_backends(), reason="pypardiso not installed")
def test_large_sheet_backend_gives_the_same_path(monkeypatch):
    """Above PARDISO_MIN_VARS crease variables the corrector factorises with the fastest
    backend. Forced onto a small folded Miura sheet, PARDISO's path equals SuperLU's: the
    closure is solved to 1e-13 either way and the state is unique off the flat state, so
    fold angles and coordinates agree to round-off of the corrector."""
    from barhinge.kinematics import path as rigid_path

    cp = bh.families.miura(4, 4, fold=20.0)
    lay = bh.families.miura_layout(4, 4)
    e = int(lay.interior_straight_edges[2])
    act = bh.Actuators(edges=[e], targets_deg=[2.5 * cp.fold_angles[e]])
    ref = bh.rigid_fold(cp, act, steps=5)
    monkeypatch.setattr(rigid_path, "PARDISO_MIN_VARS", 0)
    fast = bh.rigid_fold(cp, act, steps=5)
    np.testing.assert_allclose(fast.fold_angles_deg, ref.fold_angles_deg, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.X, ref.X, rtol=0, atol=1e-10)


def _schenk_guest(rho_z: np.ndarray, gamma: float = np.radians(60.0)) -> np.ndarray:
    """Fold angles (rho_s, rho_z) of a Miura cell against its zig-zag fold angle (Schenk &
    Guest 2013: rho_z = 2 theta, rho_s = 2 arctan(cos gamma tan theta))."""
    return np.array([2.0 * np.arctan(np.cos(gamma) * np.tan(rho_z / 2.0)), rho_z])


def test_rigid_steps_take_one_corrector_iteration_once_the_predictor_has_states():
    """Miura 12 x 12 flat -> 120 deg in 30 steps: with the high-order predictor the steps
    after the fifth reach the closure tolerance (1e-13) in one Newton iteration, bar a
    few (the cubic predictor of earlier versions needed two in every step)."""
    n = 12
    cp = bh.families.miura(n, n)
    zz = bh.families.miura_layout(n, n).interior_zigzag_edges
    e = int(zz[len(zz) // 2])
    sign = 1.0 if cp.assignment[e] == "V" else -1.0
    from barhinge.kinematics.path import RigidOptions

    path = bh.rigid_fold(cp, [e], [sign * 120.0], steps=30, options=RigidOptions(check_rank=False))
    later = np.asarray(path.iterations[6:])
    assert np.all(later >= 1)
    assert later.sum() <= len(later) + 3
    assert max(float(np.max(h)) for h in path.residual_norms[1:] if len(h)) < 1e-3
    assert path.meta["max_closure"] <= 1e-13


@pytest.mark.skipif("pardiso" not in available_backends(), reason="pypardiso not installed")
def test_a_normal_matrix_singular_to_working_precision_goes_to_the_exact_lu(monkeypatch):
    """The corrector factorises the upper triangle with PARDISO; where PARDISO has to perturb
    pivots (here: no actuator held on a 1-DOF folded Miura sheet, so J^T J has a null
    vector), the factor is SuperLU's exact LU of the full matrix, never PARDISO's
    approximate solve."""
    from barhinge.kinematics import path as rigid_path
    from barhinge.kinematics.constraints import RigidConstraints
    from barhinge.linalg.backends import PardisoBackend

    monkeypatch.setattr(rigid_path, "PARDISO_MIN_VARS", 0)
    rc = RigidConstraints.from_pattern(bh.families.miura(4, 4, fold=20.0))
    solver = rigid_path.RigidSolver(rc, np.zeros(0, np.int64), rigid_path.RigidOptions())
    assert isinstance(solver._backend, PardisoBackend)
    solver.underactuated = False  # no regularisation: the matrix stays singular
    _, J = rc.evaluate(rc.rho0)
    solver._factor(J)
    assert type(solver._lu).__name__ == "_SuperLUFactor"
    # held by one actuator the matrix is regular: PARDISO's own factor, solving J^T J
    act = rc.var_of_source_edge[[int(bh.families.miura_layout(4, 4).interior_zigzag_edges[0])]]
    held = rigid_path.RigidSolver(rc, act, rigid_path.RigidOptions())
    held.underactuated = False
    held._factor(J)
    assert type(held._lu).__name__ == "_PardisoFactor"
    b = np.where(held.free, np.random.default_rng(0).random(rc.n_var), 0.0)
    x = held._solve(b)
    free = held.free
    K = (J.T @ J).toarray()[np.ix_(free, free)]
    np.testing.assert_allclose(K @ x[free], b[free], rtol=0, atol=1e-9 * np.abs(b).max())
