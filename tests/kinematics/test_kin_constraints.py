"""Loop-closure constraints: exact Jacobian, coordinates from angles, nodal formulation.

Sources: Belcastro & Hull (2002) and Tachi (2009, "Simulation of rigid origami") for the loop
closure and its Jacobian (column k = crease k's axis in the current frame); finite differences
and the nodal (bar length + planarity) formulation as independent checks.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from hypothesis import given, settings
from hypothesis import strategies as st

import barhinge as bh
from barhinge.kinematics.constraints import NodalConstraints, RigidConstraints


def _fd_jacobian(f, x, h=1e-6):
    cols = []
    for k in range(len(x)):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.array(cols).T


def _nullity(A, rel=1e-8):
    s = sla.svd(A, compute_uv=False)
    return A.shape[1] - int(np.sum(s > rel * s[0]))


@pytest.mark.parametrize("triangulated", [False, True])
def test_jacobian_matches_finite_differences_off_the_manifold(triangulated):
    cp = bh.families.miura(2, 2, fold=35.0)
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    rng = np.random.default_rng(1)
    x = rc.rho0 + 0.2 * rng.standard_normal(rc.n_var)  # not a rigid state: F != I
    r, J = rc.evaluate(x)
    assert np.abs(r).max() > 1e-2
    Jfd = _fd_jacobian(rc.residual, x)
    # central differences: error O(h^2) ~ 1e-12 times third derivatives O(1)
    np.testing.assert_allclose(J.toarray(), Jfd, rtol=0, atol=1e-8)


def test_jacobian_columns_are_crease_axes_at_a_closed_state():
    """At F = I the column of crease k is its current unit axis (Tachi 2009)."""
    cp = bh.families.miura(2, 2, fold=50.0)
    rc = RigidConstraints.from_pattern(cp)
    J = rc.jacobian(rc.rho0).toarray()
    X = cp.vertices3d
    E = rc.pattern.edges
    for i, v in enumerate(rc.vertices):
        block = J[3 * i : 3 * i + 3]
        cols = np.flatnonzero(np.abs(block).sum(0) > 0)
        G = block[:, cols].T @ block[:, cols]  # Gram matrix is frame invariant
        dirs = []
        for k in cols:
            a, b = E[rc.crease_edge[k]]
            u = X[b] - X[a] if a == v else X[a] - X[b]
            dirs.append(u / np.linalg.norm(u))
        dirs = np.array(dirs)
        np.testing.assert_allclose(G, dirs @ dirs.T, rtol=0, atol=1e-13)


@settings(max_examples=15, deadline=None)
@given(theta=st.floats(1.0, 85.0), nx=st.integers(1, 3), ny=st.integers(1, 3))
def test_coordinates_rebuilt_from_exact_angles_reproduce_the_folded_sheet(theta, nx, ny):
    """Angles of the exact folded Miura (Schenk & Guest 2013 via bh.families) rebuild the
    same shape: all pairwise vertex distances agree, and the rebuilt state's measured fold
    angles equal the input."""
    flat = bh.families.miura(nx, ny)
    ref = bh.families.miura(nx, ny, fold=theta)
    rc = RigidConstraints.from_pattern(flat)
    rho = np.radians(ref.fold_angles[rc.crease_edge])
    assert rc.closure_error(rho).max() < 1e-12
    X = rc.coordinates(rho)
    Y = ref.vertices3d
    D1 = np.linalg.norm(X[:, None] - X[None], axis=2)
    D2 = np.linalg.norm(Y[:, None] - Y[None], axis=2)
    np.testing.assert_allclose(D1, D2, rtol=0, atol=1e-12)
    st_angles = flat.replaced(vertices=X, validate=False).state_fold_angles()
    np.testing.assert_allclose(st_angles, ref.fold_angles, rtol=0, atol=1e-10)


def test_nodal_jacobian_matches_finite_differences():
    cp = bh.families.miura(1, 1, fold=30.0)
    nc = NodalConstraints.from_pattern(cp)
    X = cp.vertices3d + 0.05 * np.random.default_rng(2).standard_normal(cp.vertices3d.shape)
    _, J = nc.evaluate(X)
    Jfd = _fd_jacobian(lambda x: nc.evaluate(x.reshape(-1, 3))[0], X.ravel())
    np.testing.assert_allclose(J.toarray(), Jfd, rtol=0, atol=1e-8)


@pytest.mark.parametrize("theta", [0.0, 40.0])
@pytest.mark.parametrize("triangulated", [False, True])
@pytest.mark.parametrize("n", [1, 2])
def test_nodal_and_angle_formulations_have_the_same_dof(n, triangulated, theta):
    """DOF(angles) = nullity(J_angle) and DOF(nodal) = nullity(J_nodal) - 6 agree, both at
    the flat state (first order) and at a folded state."""
    cp = bh.families.miura(n, n, fold=theta)
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    nc = NodalConstraints.from_pattern(cp, triangulated=triangulated)
    r, J = nc.evaluate(cp.vertices3d)
    assert np.abs(r).max() < 1e-12
    d_nodal = _nullity(J.toarray()) - 6
    d_angle = _nullity(rc.jacobian(rc.rho0).toarray())
    assert d_angle == d_nodal


def test_nodal_and_angle_dof_agree_for_single_vertices(vertex_pattern):
    for sectors in ([80, 100, 100, 80], [60] * 6, [45] * 8, [50, 70, 60, 80, 40, 60]):
        cp = vertex_pattern(sectors)
        rc = RigidConstraints.from_pattern(cp)
        nc = NodalConstraints.from_pattern(cp)
        d_angle = _nullity(rc.jacobian(rc.rho0).toarray())
        d_nodal = _nullity(nc.evaluate(cp.vertices3d)[1].toarray()) - 6
        assert d_angle == d_nodal == len(sectors) - 2  # flat: the out-of-plane row vanishes


def test_translation_part_is_automatic_at_a_vertex(vertex_pattern):
    """3 equations suffice at a vertex: any closed state (F = I) rebuilds panels that meet
    along every crease (all panel edges keep their length, no gap)."""
    cp = vertex_pattern([60] * 6)
    rc = RigidConstraints.from_pattern(cp)
    rng = np.random.default_rng(3)
    rho = 0.4 * rng.standard_normal(rc.n_var)
    for _ in range(30):  # Gauss-Newton onto F = I, min-norm steps
        r, J = rc.evaluate(rho)
        rho = rho - np.linalg.lstsq(J.toarray(), r, rcond=1e-12)[0]
    assert rc.closure_error(rho).max() < 1e-13
    X = rc.coordinates(rho)
    L0 = np.linalg.norm(cp.vertices3d[cp.edges[:, 1]] - cp.vertices3d[cp.edges[:, 0]], axis=1)
    L = np.linalg.norm(X[cp.edges[:, 1]] - X[cp.edges[:, 0]], axis=1)
    np.testing.assert_allclose(L, L0, rtol=0, atol=1e-13)


@pytest.mark.parametrize(
    "make",
    [
        lambda: RigidConstraints.from_pattern(bh.families.miura(3, 4, fold=30.0)),
        lambda: RigidConstraints.from_pattern(
            bh.families.miura(2, 2, fold=30.0), triangulated=True
        ),
        lambda: RigidConstraints.from_pattern(bh.families.waterbomb(2, 2)),
    ],
    ids=["miura", "miura-triangulated", "waterbomb"],
)
def test_normal_matrix_equals_the_jacobian_product(make):
    """The normal matrix summed vertex by vertex on its fixed pattern equals J^T J (scipy's
    sparse product) at a state off the manifold, stores every diagonal entry where it says,
    and any other matrix falls back to the sparse product."""
    import scipy.sparse as sp

    rc = make()
    x = rc.rho0 + 0.3 * np.random.default_rng(2).standard_normal(rc.n_var)
    _, J = rc.evaluate(x)
    ref = (J.T @ J).toarray()
    K, diag = rc.normal_matrix(J)
    np.testing.assert_allclose(K.toarray(), ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    rows = np.repeat(np.arange(rc.n_var), np.diff(K.indptr))
    np.testing.assert_array_equal(K.indices[diag], np.arange(rc.n_var))
    np.testing.assert_array_equal(rows[diag], np.arange(rc.n_var))
    K2, _ = rc.normal_matrix(J)
    assert K2.indptr is K.indptr  # the pattern is built once
    other = sp.csr_matrix(J.toarray() * (np.abs(J.toarray()) > 0.3))
    Ko, diag_o = rc.normal_matrix(other)
    np.testing.assert_allclose(Ko.toarray(), (other.T @ other).toarray(), rtol=0, atol=1e-13)
    np.testing.assert_allclose(Ko.data[diag_o], (other.T @ other).diagonal(), rtol=0, atol=1e-13)
    # the upper triangle alone (what PARDISO reads), on the fixed pattern and the fallback
    for M, full in ((J, ref), (other, (other.T @ other).toarray())):
        U, diag_u = rc.normal_matrix(M, upper=True)
        np.testing.assert_allclose(
            U.toarray(), np.triu(full), rtol=0, atol=1e-13 * np.abs(full).max()
        )
        rows_u = np.repeat(np.arange(rc.n_var), np.diff(U.indptr))
        np.testing.assert_array_equal(U.indices[diag_u], np.arange(rc.n_var))
        np.testing.assert_array_equal(rows_u[diag_u], np.arange(rc.n_var))
        assert np.all(np.diff(U.indices)[np.diff(rows_u) == 0] > 0)  # sorted within rows


def test_cos_sin_from_the_half_angle_tangent_match_libm():
    """``cos_sin`` (half-angle tangent) against NumPy's cos and sin, to a few units in the
    last place of 1, over several turns and at the angles where the tangent is largest."""
    from barhinge.kinematics.constraints import cos_sin

    x = np.concatenate(
        [np.linspace(-7.0, 7.0, 20001), [np.pi, -np.pi, 3 * np.pi, np.nextafter(np.pi, 0)]]
    )
    x = np.concatenate([x, [0.0, 1e-300, -1e-12, 0.5 * np.pi]])
    c, s = cos_sin(x)
    assert np.abs(c - np.cos(x)).max() <= 4 * np.finfo(float).eps
    assert np.abs(s - np.sin(x)).max() <= 4 * np.finfo(float).eps


def test_loop_products_equal_the_product_of_the_slot_rotations():
    """Each vertex's loop product is ``prod_j Rx(rho_j) Rz(alpha_j)`` over its slots (Belcastro
    & Hull 2002), computed here with explicit 3 x 3 matrices; the axes are ``T_{j-1} e_x``."""
    cp = bh.families.miura(3, 2, fold=30.0)
    rc = RigidConstraints.from_pattern(cp)
    rho = rc.rho0 + 0.3 * np.random.default_rng(7).standard_normal(rc.n_var)
    F, A = rc.loop_products(rho)

    def rx(t):
        return np.array([[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])

    def rz(t):
        return np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])

    for v in range(rc.loop_var.shape[0]):
        T = np.eye(3)
        for j, k in enumerate(rc.loop_var[v]):
            np.testing.assert_allclose(A[v, j], T[:, 0], atol=1e-14)
            T = T @ rx(rho[k] if k >= 0 else 0.0) @ rz(rc.loop_alpha[v, j])
        np.testing.assert_allclose(F[v], T, atol=1e-14)
