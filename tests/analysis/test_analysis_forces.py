"""Results at a state: reactions, bar forces, panel stress resultants, hinge moments."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.forces import (
    panel_membrane_resultants,
    path_state_results,
    results_summary,
    state_results,
)
from barhinge.analysis.stiffness import linear_response
from barhinge.pattern.crease import CreasePattern
from barhinge.scene import select_vertices, self_weight


def _triangle_truss(h: float = 0.75):
    cp = CreasePattern(
        np.array([[0.0, 0.0], [2.0, 0.0], [1.0, h]]),
        [[0, 1], [1, 2], [2, 0]],
        ["B", "B", "B"],
        faces=[[0, 1, 2]],
    )
    m = bh.BarHingeModel.from_pattern(cp, "N4B5", bh.Material(E=1e3, nu=0.3, t=0.1))
    S = np.zeros((3, 3), bool)
    S[0] = True
    S[1, 1:] = True
    S[2, 2] = True
    return m, S


def test_bar_forces_and_reactions_of_a_triangle_truss_match_statics():
    """Symmetric two-bar truss with a tie (method of joints): apex load P down gives
    N_inclined = -P / (2 sin a) and N_tie = P / (2 tan a), support reactions P / 2 up
    (Hibbeler, Structural Analysis, method of joints). Linear response at a load small
    enough that the change of geometry (strain ~ 1e-9) is below the tolerance."""
    h, P = 0.75, 1e-7
    m, S = _triangle_truss(h)
    F = np.zeros((3, 3))
    F[2, 1] = -P
    U, _ = linear_response(m, F, S)
    res = state_results(m, m.X0 + U, S, F)
    a = np.arctan2(h, 1.0)
    expect = {
        (0, 1): P / (2 * np.tan(a)),
        (1, 2): -P / (2 * np.sin(a)),
        (0, 2): -P / (2 * np.sin(a)),
    }
    for b, (i, j) in enumerate(np.sort(m.bars, axis=1)):
        assert res.bar_force[b] == pytest.approx(expect[(int(i), int(j))], rel=1e-6)
    assert res.reactions[0, 1] == pytest.approx(P / 2, rel=1e-6)
    assert res.reactions[1, 1] == pytest.approx(P / 2, rel=1e-6)
    # a linear solution: the nonlinear residual is of the order of the strain (~1e-8)
    assert res.equilibrium_error < 1e-6
    assert res.max_displacement_node == int(np.argmax(np.linalg.norm(U, axis=1)))
    assert res.max_displacement == pytest.approx(np.linalg.norm(U, axis=1).max(), rel=1e-12)


def _miura_scene(case: str):
    cp = bh.families.miura(3, 3, fold=50.0)
    m = bh.BarHingeModel.from_pattern(cp, "N5B8", bh.Material(E=1e6, nu=0.3, t=0.01))
    S = np.zeros((m.n_nodes, 3), bool)
    S[select_vertices(m, "left")] = True
    S[select_vertices(m, "right"), 2] = True
    point = np.zeros((m.n_nodes, 3))
    point[select_vertices(m, "top"), 2] = -0.02
    point[select_vertices(m, "bottom"), 0] = 0.01
    sw = self_weight(m, 0.02)
    loads = {"point": point, "self_weight": sw, "combination": 1.35 * sw + 1.5 * point}[case]
    groups = {"left": select_vertices(m, "left"), "right": select_vertices(m, "right")}
    return bh.Scene(m, supports=S, loads=loads, steps=4, control="load"), groups


@pytest.mark.parametrize("case", ["point", "self_weight", "combination"])
def test_reactions_balance_the_loads_at_solved_states(case):
    """Every converged state of a load-controlled nonlinear solve is in equilibrium: the
    reactions balance the applied loads to the residual the solver left. The out-of-balance
    of the totals is the sum of the free residual ``r_free`` over the nodes, at most
    sqrt(n_free) times its norm (Cauchy-Schwarz); the solver leaves ``|r_free|`` below 1e-6
    of the force scale (its quadratic-regime stop can end above ``tol_force``). The groups
    add up to the total and agree with the solver's own reactions."""
    scene, groups = _miura_scene(case)
    fp = bh.solve(scene)
    assert fp.converged
    n_free = int((~scene.supports).sum())
    for step in range(1, len(fp.X)):
        res = path_state_results(fp, scene, step, groups)
        lam = fp.load_factor[step]
        F_ref = max(np.linalg.norm(lam * scene.loads), np.linalg.norm(res.reactions))
        r = scene.model.internal_force(fp.X[step]) - lam * scene.loads.ravel()
        r_free = np.linalg.norm(r[~scene.supports.ravel()])
        assert r_free <= 1e-6 * F_ref
        out = np.linalg.norm(res.reaction_total + res.applied_total)
        assert out <= np.sqrt(n_free) * r_free * (1 + 1e-9) + 1e-14 * F_ref
        assert res.equilibrium_error < 1e-6
        total = sum(res.reaction_groups.values())
        np.testing.assert_allclose(total, res.reaction_total, rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            res.reactions, fp.reactions[step], rtol=0, atol=1e-9 * np.abs(res.reactions).max()
        )
    s = results_summary(res)
    assert s["equilibrium_error"] == res.equilibrium_error
    assert s["max_displacement"] > 0


def test_hinge_moments_are_the_energy_derivative():
    """``M = dW/d rho = k (rho - rho0)``: central differences of each hinge's energy against
    its angle along a random direction (error O(h^2) ~ 1e-10 relative)."""
    cp = bh.families.miura(2, 2, fold=40.0)
    m = bh.BarHingeModel.from_pattern(cp, "N5B8", bh.Material(E=1e6, nu=0.3, t=0.01))
    rng = np.random.default_rng(3)
    X = m.X0 + 0.02 * rng.standard_normal(m.X0.shape)
    S = np.zeros((m.n_nodes, 3), bool)
    res = state_results(m, X, S)
    np.testing.assert_allclose(
        res.hinge_moment, m.hinge_k * (m.hinge_angles(X) - m.rest_angle), rtol=1e-12, atol=0
    )
    v = rng.standard_normal(X.shape)
    h = 1e-6
    _, Wp = m.element_energies(X + h * v)
    _, Wm = m.element_energies(X - h * v)
    dr = m.hinge_angles(X + h * v) - m.hinge_angles(X - h * v)
    fd = (Wp - Wm) / dr
    scale = np.abs(res.hinge_moment).max()
    np.testing.assert_allclose(fd, res.hinge_moment, rtol=0, atol=1e-6 * scale)
    # per crease: the fold hinge of each edge, NaN elsewhere
    h_of_e = m.fold_hinge_of_edge
    has = h_of_e >= 0
    np.testing.assert_array_equal(res.crease_moment[has], res.hinge_moment[h_of_e[has]])
    assert np.isnan(res.crease_moment[~has]).all()


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_panel_resultants_of_a_homogeneous_deformation_are_exact(scheme):
    """Under ``x = F X0`` every panel carries the Green strain ``P^T (F^T F - I) P / 2``
    (``P`` its frame); the resultant must be the plane-stress ``t C E`` exactly (closed form,
    Timoshenko & Goodier, plane stress), also for a folded sheet and with bars whose own
    calibration is not exact. Two deformations of one model: the second is served by the
    model's cached fit."""
    cp = bh.families.miura(2, 2, fold=35.0)
    mat = bh.Material(E=2e5, nu=0.3, t=0.02)
    m = bh.BarHingeModel.from_pattern(cp, scheme, mat)
    rng = np.random.default_rng(1)
    for _ in range(2):
        Fd = np.eye(3) + 1e-3 * rng.standard_normal((3, 3))
        _check_homogeneous_resultants(m, Fd)


def _check_homogeneous_resultants(m: bh.BarHingeModel, Fd: np.ndarray) -> None:
    cp, mat = m.pattern, m.material
    X = m.X0 @ Fd.T
    N, Ng = panel_membrane_resultants(m, X)
    E3 = 0.5 * (Fd.T @ Fd - np.eye(3))
    C = mat.E / (1 - mat.nu**2) * np.array([[1, mat.nu, 0], [mat.nu, 1, 0], [0, 0, 1 - mat.nu]])
    from barhinge.model.calibrate import face_frames

    for f in range(cp.n_faces):
        e1, e2, _ = face_frames(np.asarray(m.X0), cp.faces, np.array([f]))
        e1, e2 = e1[0], e2[0]
        E = np.array([e1 @ E3 @ e1, e2 @ E3 @ e2, e1 @ E3 @ e2])
        want = mat.t * C @ E
        np.testing.assert_allclose(N[f], want, rtol=0, atol=1e-9 * np.abs(want).max())
        Pm = np.stack([e1, e2])
        np.testing.assert_allclose(
            Pm @ Ng[f] @ Pm.T,
            [[want[0], want[2]], [want[2], want[1]]],
            rtol=0,
            atol=1e-9 * np.abs(want).max(),
        )


def test_support_groups_are_the_connected_support_lines():
    """A 3 x 2 grid of square panels pinned along x = 0 and x = 3: two groups."""
    xs, ys = np.meshgrid(np.arange(4.0), np.arange(3.0))
    V = np.column_stack([xs.ravel(), ys.ravel()])
    vid = lambda i, j: 4 * j + i  # noqa: E731
    faces = [
        [vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
        for j in range(2)
        for i in range(3)
    ]
    edges = sorted({tuple(sorted((f[k], f[(k + 1) % 4]))) for f in faces for k in range(4)})
    cp = CreasePattern(V, edges, ["F"] * len(edges), faces=faces).replaced(
        assignment=[
            "B" if (V[a, 0] == V[b, 0] in (0, 3)) or (V[a, 1] == V[b, 1] in (0, 2)) else "F"
            for a, b in edges
        ]
    )
    m = bh.BarHingeModel.from_pattern(cp, "N4B5")
    S = np.zeros((m.n_nodes, 3), bool)
    S[np.flatnonzero(np.isin(V[:, 0], [0.0, 3.0]))] = True
    from barhinge.analysis.forces import support_groups

    g = support_groups(m, S)
    assert [sorted(v.tolist()) for v in g.values()] == [[0, 4, 8], [3, 7, 11]]
