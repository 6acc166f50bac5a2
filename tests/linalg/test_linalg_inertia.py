"""Inertia of symmetric matrices of one pattern: Cholesky while they are positive definite,
LDL^T otherwise (barhinge.linalg.inertia), checked against dense eigenvalues."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.linalg.backends import IndefiniteMatrixError, available_backends, get_backend
from barhinge.linalg.inertia import InertiaCounter

needs_pardiso = pytest.mark.skipif(
    "pardiso" not in available_backends(), reason="PARDISO (pypardiso) not installed"
)


def _symmetric(n: int, seed: int) -> sp.csr_matrix:
    """A sparse symmetric matrix with every diagonal entry stored (PARDISO's rule)."""
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.03, random_state=rng)
    return sp.csr_matrix(A + A.T + sp.identity(n))


def _shifted(A: sp.csr_matrix, n_neg: int) -> tuple[sp.csr_matrix, int]:
    """``A - s I`` with ``s`` between the n_neg-th and next eigenvalue (same pattern), and
    its number of negative eigenvalues by a dense eigensolver."""
    w = np.linalg.eigvalsh(A.toarray())
    s = w[0] - 1.0 if n_neg == 0 else 0.5 * (w[n_neg - 1] + w[n_neg])
    B = sp.csr_matrix(A - s * sp.identity(A.shape[0]))
    return B, int(np.sum(w < s))


@pytest.mark.parametrize("name", available_backends())
def test_inertia_counter_counts_like_dense_eigenvalues(name):
    A = _symmetric(120, 0)
    counter = InertiaCounter(get_backend(name))
    for n_neg in (0, 5, 5, 0, 0, 17):
        B, expected = _shifted(A, n_neg)
        got = counter.negative_eigenvalues(B)
        if got is None:  # a backend without inertia (SuperLU after off-diagonal pivots)
            continue
        assert got == expected == n_neg


@needs_pardiso
def test_inertia_counter_tries_cholesky_only_while_the_matrices_are_definite():
    A = _symmetric(120, 1)
    counter = InertiaCounter(get_backend("pardiso"))
    made = []
    for n_neg in (0, 0, 4, 4, 0, 0):
        B, _ = _shifted(A, n_neg)
        before = counter.factorizations
        counter.negative_eigenvalues(B)
        made.append(counter.factorizations - before)
    # definite: one Cholesky; the first indefinite one: a refused Cholesky and an LDL^T; the
    # next indefinite: LDL^T only; back to definite: LDL^T finds it, then Cholesky again
    assert made == [1, 1, 2, 1, 1, 1]


@needs_pardiso
def test_pardiso_cholesky_refuses_an_indefinite_matrix_and_keeps_its_analysis():
    from barhinge.linalg.backends import PardisoBackend

    A = _symmetric(150, 2)
    chol = PardisoBackend(definite=True)
    spd, _ = _shifted(A, 0)
    chol.factorize(spd)
    indefinite, _ = _shifted(A, 3)
    with pytest.raises(IndefiniteMatrixError):
        chol.factorize(indefinite)
    spd2 = sp.csr_matrix(spd + 0.5 * sp.identity(A.shape[0]))
    b = np.arange(150.0)
    x = chol.factorize(spd2).solve(b)
    np.testing.assert_allclose(spd2 @ x, b, rtol=1e-10, atol=1e-10)
