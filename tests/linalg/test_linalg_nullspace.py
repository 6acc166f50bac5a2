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
    cp = bh.patterns.miura(n, n)
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
