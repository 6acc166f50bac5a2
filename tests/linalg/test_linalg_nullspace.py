"""Rank and null space of sparse constraint Jacobians: the sparse shift-invert method agrees
with the dense SVD (the matrices are rigid-origami loop-closure Jacobians)."""

from __future__ import annotations

import numpy as np

import barhinge as bh
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.kinematics.dof import folded_sample
from barhinge.linalg.nullspace import null_space


def test_sparse_rank_agrees_with_dense_svd():
    """The sparse shift-invert method used above 600 creases gives the dense SVD's rank and
    null space (flat Miura: first-order DOF 4n - 2 for n x n cells; folded: 1)."""
    n = 4
    cp = bh.families.miura(n, n)
    rc = RigidConstraints.from_pattern(cp)
    for rho in (rc.rho0, folded_sample(rc)):
        J = rc.jacobian(rho)
        dense = null_space(J, dense_limit=10**6)
        sparse = null_space(J, dense_limit=0)
        assert dense.method == "svd" and sparse.method == "sparse-inertia"
        assert dense.rank == sparse.rank
        # same subspace: projector difference
        Pd = dense.basis @ dense.basis.T
        Ps = sparse.basis @ sparse.basis.T
        assert np.abs(Pd - Ps).max() < 1e-6
    assert rc.n_var - null_space(rc.jacobian(rc.rho0)).rank == 4 * n - 2


def test_wide_null_space_without_basis_agrees_with_dense_svd_and_full_path():
    """Flat Yoshimura 14 x 14 (nullity ~ a third of the creases): with ``basis_limit`` below
    the nullity the sparse method skips the null vectors; its rank and its singular value
    above the cut (inertia bisection) agree with the dense SVD (independent) and with the
    full sparse path, and the gap ratio is the same certain cut."""
    cp = bh.families.FAMILIES["yoshimura"](nx=14, ny=14)
    rc = RigidConstraints.from_pattern(cp)
    J = rc.jacobian(rc.rho0)
    dense = null_space(J, dense_limit=10**6)
    full = null_space(J, dense_limit=0)
    wide = null_space(J, dense_limit=0, basis_limit=50)
    assert rc.n_var - dense.rank > 50  # the count-only path is taken
    assert wide.basis is None and full.basis is not None
    assert wide.rank == full.rank == dense.rank
    assert abs(wide.sigma_gap - dense.sigma_gap) <= 2e-4 * dense.sigma_gap
    assert abs(wide.sigma_gap - full.sigma_gap) <= 2e-4 * full.sigma_gap
    assert wide.certain and full.certain
    assert wide.sigma_below <= wide.tolerance
    assert abs(wide.gap_ratio - full.gap_ratio) <= 2e-4 * full.gap_ratio
    assert wide.rank_candidates == full.rank_candidates
