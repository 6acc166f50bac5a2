"""Factorisation backends: solutions agree with a dense solve; the reused ordering too."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.errors import ConfigError
from barhinge.solve.linear import SingularMatrixError, available_backends, get_backend


def _spd(n: int, seed: int) -> sp.csc_matrix:
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.05, random_state=rng)
    return sp.csc_matrix(A @ A.T + n * sp.identity(n))


@pytest.mark.parametrize("name", available_backends())
def test_backend_solves_like_dense(name):
    backend = get_backend(name)
    for seed in (0, 1):
        A = _spd(60, seed)
        b = np.arange(60.0)
        x = backend.factorize(A).solve(b)
        np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-10)
        B = np.column_stack([b, -b])
        X = backend.factorize(A).solve(B)
        np.testing.assert_allclose(X[:, 1], -x, rtol=1e-10)


def test_superlu_reuses_the_ordering_of_the_same_pattern():
    backend = get_backend("superlu")
    A = _spd(80, 3)
    f1 = backend.factorize(A)
    A2 = A.copy()
    A2.data = A2.data * (1 + 0.1 * np.sin(np.arange(A2.nnz)))  # same pattern, new values
    A2 = sp.csc_matrix(0.5 * (A2 + A2.T))
    f2 = backend.factorize(A2)  # pre-permuted with the first ordering
    assert f2._perm is not None and f1._perm is None
    b = np.ones(80)
    np.testing.assert_allclose(f2.solve(b), np.linalg.solve(A2.toarray(), b), rtol=1e-10)
    # an indefinite symmetric matrix: the negative pivots count its negative eigenvalues
    D = sp.diags([1.0, -2.0, 3.0, -4.0, 5.0]).tocsc()
    assert get_backend("superlu").factorize(D).negative_pivots() == 2


def test_singular_and_unknown():
    with pytest.raises(SingularMatrixError):
        get_backend("superlu").factorize(sp.csc_matrix((3, 3)))
    with pytest.raises(ConfigError, match="unknown"):
        get_backend("mumps")
