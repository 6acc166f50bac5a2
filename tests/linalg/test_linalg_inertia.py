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


def _mkl_bytes(backend) -> int:
    """Bytes MKL's memory manager holds now (``MKL_Mem_Stat``: PARDISO's factors and analyses)."""
    import ctypes

    stat = backend._solver.libmkl.MKL_Mem_Stat
    stat.restype = ctypes.c_int64
    stat.argtypes = [ctypes.POINTER(ctypes.c_int)]
    return int(stat(ctypes.byref(ctypes.c_int(0))))


@needs_pardiso
@pytest.mark.parametrize("definite", [True, False])
def test_pardiso_release_frees_the_factor_and_keeps_the_analysis(definite):
    """``release`` (PARDISO phase 0) returns the numeric factor's memory to MKL; factors made
    before refuse to solve, and the next factorisation of the pattern (numeric only, the
    analysis kept) solves and takes the same memory again."""
    from barhinge.linalg.backends import PardisoBackend

    n = 300  # 2-D Laplacian on n x n points: a factor of some 20 MB
    L = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    Id = sp.identity(n)
    A = sp.csr_matrix(sp.kron(L, Id) + sp.kron(Id, L) + 1e-3 * sp.identity(n * n))
    backend = PardisoBackend(definite=definite)
    old = backend.factorize(A)
    b = np.ones(n * n)
    np.testing.assert_allclose(A @ old.solve(b), b, rtol=1e-9, atol=1e-9)
    held = _mkl_bytes(backend)
    size = backend.factor_bytes()
    backend.release()
    released = _mkl_bytes(backend)
    # PARDISO's measure of its factor is what MKL's memory manager returns
    assert held - released == pytest.approx(size, rel=0.1)
    assert size > 10 * 2**20 and backend.factor_bytes() == 0
    with pytest.raises(RuntimeError, match="replaced"):
        old.solve(b)
    A2 = sp.csr_matrix(2.0 * A)
    x = backend.factorize(A2).solve(b)
    np.testing.assert_allclose(A2 @ x, b, rtol=1e-9, atol=1e-9)
    assert _mkl_bytes(backend) == held  # the same factor again, on the kept analysis


@needs_pardiso
def test_inertia_counter_holds_no_factor_between_matrices():
    """Each count releases the factor it made: between matrices MKL holds no more than
    the counter's analyses (the memory after a count equals that after a release)."""
    A = _symmetric(400, 3)
    counter = InertiaCounter(get_backend("pardiso"), release_above=0)
    for n_neg in (0, 6, 6, 0):
        B, expected = _shifted(A, n_neg)
        assert counter.negative_eigenvalues(B) == expected
        after_count = _mkl_bytes(counter._ldlt)
        for be in (counter._cholesky, counter._ldlt):
            be.release()
        assert _mkl_bytes(counter._ldlt) == after_count


@needs_pardiso
def test_inertia_counter_keeps_a_small_factor():
    """Below ``release_above`` the factor stays (its next factorisation reuses the memory)."""
    A = _symmetric(200, 4)
    counter = InertiaCounter(get_backend("pardiso"))
    B, expected = _shifted(A, 0)
    assert counter.negative_eigenvalues(B) == expected
    assert 0 < counter._cholesky.factor_bytes() < counter.release_above
