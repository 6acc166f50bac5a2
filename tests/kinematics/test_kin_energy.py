"""The rigid limit with free DOF: exact constraint Hessian, energy minimisation, branch rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import BarhingeError
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.verify import degree4_pattern


@pytest.mark.parametrize("n", [2, 3])
def test_multiplier_hessian_matches_finite_differences(n):
    """Hessian of lam . r against central differences of J^T lam, at a random (unclosed)
    state, so the general formula (F != I) is checked, not only its closed-loop limit."""
    rc = RigidConstraints.from_pattern(bh.families.miura(n, n))
    rng = np.random.default_rng(1)
    rho = 0.5 * rng.normal(size=rc.n_var)
    lam = rng.normal(size=rc.n_eq)
    H = rc.multiplier_hessian(rho, lam).toarray()
    eps = 1e-6
    fd = np.empty_like(H)
    for i in range(rc.n_var):
        e = np.zeros(rc.n_var)
        e[i] = eps
        fd[:, i] = (rc.jacobian(rho + e).T @ lam - rc.jacobian(rho - e).T @ lam) / (2 * eps)
    np.testing.assert_allclose(H, fd, rtol=0, atol=1e-8 * np.abs(H).max())
    np.testing.assert_array_equal(H, H.T)


def _mmvm():
    return degree4_pattern().replaced(assignment=np.array(list("MMVMBBBB")))


def test_flat_start_takes_the_assigned_mode_of_a_degree4_vertex():
    """Sectors 70/50/110/130 deg, assignment MMVM: only mode 2 matches it. Its closed form
    (Huffman 1976; Lang, Twists Tilings and Tessellations, 2018, degree-4 vertex):
    rho_2 = -rho_0 and tan(rho_1 / 2) = q tan(rho_0 / 2), q = sin((a + b)/2) / sin((a - b)/2)
    with a = 70 deg, b = 50 deg the first two sectors."""
    path = bh.rigid_fold(_mmvm(), [0], targets_deg=[-40.0], steps=6)
    rho = path.fold_angles_deg[-1, :4]
    a, b = math.radians(70.0), math.radians(50.0)
    q = math.sin((a + b) / 2) / math.sin((a - b) / 2)
    r1 = math.degrees(2 * math.atan(q * math.tan(math.radians(-40.0) / 2)))
    np.testing.assert_allclose(rho, [-40.0, r1, 40.0, r1], rtol=0, atol=1e-9)
    assert path.meta["sign_conflicts"] == [] and not path.meta["mirrored"]


def test_actuator_against_the_assignment_mirrors_the_branch_and_says_so():
    cp = bh.families.miura(3, 3).replaced(fold_angles=np.zeros(bh.families.miura(3, 3).n_edges))
    z = int(bh.families.miura_layout(3, 3).interior_zigzag_edges[0])
    sign = 1.0 if cp.assignment[z] == "M" else -1.0  # against its assignment
    path = bh.rigid_fold(cp, [z], targets_deg=[sign * 50.0], steps=4)
    assert path.meta["mirrored"]
    assert any("mirror image" in ev for ev in path.meta["events"])
    asg = cp.assignment
    want = -np.where(asg == "V", 1.0, np.where(asg == "M", -1.0, 0.0))
    assert np.all(want * path.fold_angles_deg[-1] >= -1e-9)


def test_underactuated_miura_flat_start_matches_the_one_dof_path():
    """Miura 3x3 has 1 DOF once folded; from the flat state (10 infinitesimal DOF) one
    actuator must give the same path as the 1-DOF kinematics, whatever the weights."""
    cp = bh.families.miura(3, 3)
    z = int(bh.families.miura_layout(3, 3).interior_zigzag_edges[0])
    t = cp.fold_angles[z] / 2
    ref = bh.rigid_fold(cp, [z], [t], steps=5)
    w = np.random.default_rng(2).uniform(0.5, 2.0, cp.n_edges)
    other = bh.rigid_fold(cp, [z], [t], steps=5, fold_stiffness=w)
    np.testing.assert_allclose(other.fold_angles_deg, ref.fold_angles_deg, rtol=0, atol=1e-9)
    assert ref.meta["free_dof"] == 0


def test_energy_minimum_is_stationary_on_the_manifold():
    """Under-actuated Yoshimura: at the returned state the energy gradient has no component
    along the free motions (null space of the Jacobian with the actuators held), checked
    against an independent dense SVD."""
    cp = bh.families.yoshimura(4, 3)
    rep = bh.dof(cp)
    a = [int(rep.mechanism.actuators[0])]
    path = bh.rigid_fold(cp, a, targets_deg=[0.5 * cp.fold_angles[a[0]]], steps=4)
    assert path.meta["free_dof"] > 0
    rc = RigidConstraints.from_pattern(cp)
    rho = np.radians(path.fold_angles_deg[-1])[rc.var_source_edge]
    J = rc.jacobian(rho).toarray()
    av = rc.var_of_source_edge[a]
    free = np.setdiff1d(np.arange(rc.n_var), av)
    _, s, Vt = np.linalg.svd(J[:, free])
    Z = Vt[np.sum(s > 1e-8 * s[0]) :].T
    E = rc.pattern.edges[rc.crease_edge]
    w = np.linalg.norm(cp.vertices3d[E[:, 1]] - cp.vertices3d[E[:, 0]], axis=1)
    g = (w * rho)[free]
    assert Z.shape[1] == path.meta["free_dof"]
    # Newton stops once its corrections fall below RigidOptions.energy_tol = 1e-9 rad, so
    # the projected gradient left is about max(w) x 1e-9 (here ~1e-8 relative to |g|)
    assert np.abs(Z.T @ g).max() < 100 * 1e-9 * w.max()
    assert np.abs(Z.T @ g).max() < 1e-6 * np.abs(g).max()


@pytest.mark.parametrize(
    "cp", [bh.families.resch(3, 3), bh.families.waterbomb(3, 3)], ids=["resch", "waterbomb"]
)
def test_resch_and_waterbomb_fold_from_flat_or_fail_by_name(cp):
    rep = bh.dof(cp)
    for k in (1, 2, 3):
        a = [int(e) for e in rep.mechanism.actuators[:k]]
        try:
            path = bh.rigid_fold(cp, a, targets_deg=(0.5 * cp.fold_angles[a]).tolist(), steps=4)
        except BarhingeError:
            continue
        assert path.converged and path.meta["max_closure"] < 1e-10
        np.testing.assert_allclose(path.fold_angles_deg[-1, a], 0.5 * cp.fold_angles[a], atol=1e-9)


def test_underactuated_yoshimura_has_several_strict_energy_minima():
    """Why an under-actuated Yoshimura sheet has no single rigid limit to converge to: driven
    from flat by one crease (11 free motions), continuations with 3 and 6 steps end in two
    different states, each a strict local minimum of the fold-spring energy on the rigid
    manifold (projected gradient ~0 and positive reduced Hessian of the Lagrangian, both by
    dense linear algebra independent of the solver), with energies a few percent apart and
    over a dozen creases folding against their assignment in both (docs/solver.md)."""
    cp = bh.families.yoshimura(4, 3)
    a = [int(bh.dof(cp).mechanism.actuators[0])]
    rc = RigidConstraints.from_pattern(cp)
    E = rc.pattern.edges[rc.crease_edge]
    w = np.linalg.norm(cp.vertices3d[E[:, 1]] - cp.vertices3d[E[:, 0]], axis=1)
    free = np.setdiff1d(np.arange(rc.n_var), rc.var_of_source_edge[a])
    states, energies = [], []
    for steps in (3, 6):
        path = bh.rigid_fold(cp, a, targets_deg=0.5 * cp.fold_angles[a], steps=steps)
        rho = np.radians(path.fold_angles_deg[-1])[rc.var_source_edge]
        J = rc.jacobian(rho).toarray()[:, free]
        _, s, Vt = np.linalg.svd(J)
        Z = Vt[np.sum(s > 1e-8 * s[0]) :].T
        g = (w * rho)[free]
        lam = np.linalg.lstsq(J.T, -g, rcond=None)[0]
        H = np.diag(w[free]) + rc.multiplier_hessian(rho, lam).toarray()[np.ix_(free, free)]
        assert np.abs(Z.T @ g).max() < 1e-6 * np.abs(g).max()
        assert np.linalg.eigvalsh(Z.T @ H @ Z).min() > 0.1 * w.min()
        against = np.sign(cp.fold_angles) * path.fold_angles_deg[-1] < -1e-6
        assert against.sum() > 10
        states.append(path.fold_angles_deg[-1])
        energies.append(0.5 * float(w @ rho**2))
    assert np.abs(states[0] - states[1]).max() > 0.5  # deg (measured 1.08)
    assert abs(energies[0] - energies[1]) > 0.01 * min(energies)
