"""Symmetric matrices held as their upper triangle: products, residuals in extended
precision, factorisation, against the full matrix and a closed form."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.linalg import backends
from barhinge.linalg.backends import (
    EXTENDED,
    SingularMatrixError,
    available_backends,
    extended_residual,
    factorize_symmetric,
    get_backend,
    refined_solve,
)
from barhinge.linalg.symmetric import UpperSymmetric


def _random_symmetric(n: int = 200, seed: int = 0) -> sp.csr_matrix:
    """A symmetric, diagonally dominant sparse matrix with some explicit zeros stored."""
    R = sp.random(n, n, density=0.04, random_state=seed, format="coo")
    A = (R + R.T + 10.0 * sp.eye(n)).tocoo()
    z = np.arange(0, n - 1, 7)  # explicit zeros at symmetric positions (i, i+1), (i+1, i)
    rows = np.concatenate([A.row, z, z + 1])
    cols = np.concatenate([A.col, z + 1, z])
    data = np.concatenate([A.data, np.zeros(2 * len(z))])
    A = sp.coo_matrix((data, (rows, cols)), shape=(n, n)).tocsr()
    A.sort_indices()
    return A


def test_the_upper_triangle_gives_back_the_matrix_and_its_products():
    A = _random_symmetric()
    S = UpperSymmetric.from_full(A)
    assert S.nnz == (A.nnz + A.shape[0]) // 2  # the diagonal once, each pair once
    F = S.full()  # the same pattern, explicit zeros included, and the same values
    np.testing.assert_array_equal(F.indptr, A.indptr)
    np.testing.assert_array_equal(F.indices, A.indices)
    np.testing.assert_array_equal(F.data, A.data)
    rng = np.random.default_rng(1)
    x, X = rng.standard_normal(A.shape[0]), rng.standard_normal((A.shape[0], 3))
    np.testing.assert_allclose(S @ x, A @ x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(S @ X, A @ X, rtol=0, atol=1e-12)
    np.testing.assert_allclose(S.operator().matvec(x), A @ x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(S.scaled(-2.0) @ x, -2.0 * (A @ x), rtol=0, atol=1e-12)
    assert S.stores_diagonal()
    no_diag = UpperSymmetric.from_full(sp.csr_matrix(np.array([[0.0, 1.0], [1.0, 0.0]])))
    assert not no_diag.stores_diagonal()


@pytest.mark.skipif(EXTENDED is None, reason="numpy's longdouble is a double here")
def test_extended_residual_of_the_triangle_is_that_of_the_full_matrix(monkeypatch):
    """The triangle's chunked residual (rows and their mirrors) agrees with the full matrix's
    to the extended precision's rounding; on the closed-form system it is exactly zero."""
    A = _random_symmetric(seed=3)
    S = UpperSymmetric.from_full(A)
    rng = np.random.default_rng(2)
    x, b = rng.standard_normal(A.shape[0]), rng.standard_normal(A.shape[0])
    whole = extended_residual(A, x, b)
    monkeypatch.setattr(backends, "_RESIDUAL_CHUNK_NNZ", 97)  # chunks of a few rows
    chunked = extended_residual(S, x, b)
    assert chunked.dtype == EXTENDED
    scale = float(np.abs(abs(A) @ abs(x)).max())
    assert float(np.abs(chunked - whole).max()) < 1e3 * np.finfo(EXTENDED).eps * scale


@pytest.mark.skipif(EXTENDED is None, reason="numpy's longdouble is a double here")
@pytest.mark.parametrize("backend", available_backends())
def test_refinement_with_the_triangle_reaches_the_closed_form(backend, beam_fourth_difference):
    """The 3000-node fourth difference (cond ~1.7e13) under a unit load has an exact quartic
    solution (see ``test_linalg_backends``): factorised and refined from its upper triangle
    alone, the solution is within 1e-9 of it."""
    A, w = beam_fourth_difference(3000)
    S = UpperSymmetric.from_full(A)
    b = np.ones(len(w))
    factor = factorize_symmetric(get_backend(backend), S)
    x, rel = refined_solve(factor, S, b)
    floor = np.finfo(float).eps * np.linalg.norm(abs(A) @ abs(w)) / np.linalg.norm(b)
    assert rel < floor / 1000  # below double's rounding floor: extended residuals
    assert np.abs(x - w).max() / np.abs(w).max() < 1e-9


@pytest.mark.parametrize("backend", available_backends())
def test_a_singular_matrix_is_refused(backend):
    """The free-free second difference (a chain of springs with nothing held) is singular:
    its rigid translation is a null vector."""
    n = 50
    L = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    L[0, 0] = L[n - 1, n - 1] = 1.0
    assert np.allclose(L @ np.ones(n), 0.0)
    with pytest.raises(SingularMatrixError):
        factorize_symmetric(get_backend(backend), UpperSymmetric.from_full(L.tocsr()))
