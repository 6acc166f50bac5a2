"""Factorisation backends: solutions agree with a dense solve; the reused ordering too."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.errors import ConfigError
from barhinge.linalg.backends import (
    EXTENDED,
    SingularMatrixError,
    SuperLUBackend,
    available_backends,
    get_backend,
)


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


def test_superlu_block_solve_in_either_memory_order():
    """A C-ordered block of right-hand sides is solved like a Fortran-ordered one (the
    factor converts it; SuperLU itself is ~20x slower on C order)."""
    A = _spd(70, 4)
    B = np.random.default_rng(0).random((70, 5))
    f = get_backend("superlu").factorize(A)
    ref = np.linalg.solve(A.toarray(), B)
    np.testing.assert_allclose(f.solve(np.ascontiguousarray(B)), ref, rtol=1e-10)
    np.testing.assert_allclose(f.solve(np.asfortranarray(B)), ref, rtol=1e-10)


needs_pardiso = pytest.mark.skipif(
    "pardiso" not in available_backends(), reason="pypardiso (MKL) not installed here"
)


def _sym_indefinite(n: int, n_neg: int, seed: int) -> sp.csr_matrix:
    """Q diag(d) Q^T made sparse-ish: a symmetric matrix with exactly ``n_neg`` negative
    eigenvalues (Q from a sparse orthogonal product of Givens rotations)."""
    rng = np.random.default_rng(seed)
    d = np.concatenate([-rng.uniform(1, 2, n_neg), rng.uniform(1, 2, n - n_neg)])
    M = sp.diags(d).tocsr()
    for _ in range(3 * n):
        i, j = rng.choice(n, 2, replace=False)
        c, s = np.cos(rng.uniform(0, np.pi)), np.sin(rng.uniform(0, np.pi))
        R = sp.identity(n, format="lil")
        R[i, i], R[j, j], R[i, j], R[j, i] = c, c, -s, s
        M = (R.tocsr() @ M @ R.T.tocsr()).tocsr()
    return sp.csr_matrix(0.5 * (M + M.T))


@needs_pardiso
def test_pardiso_refactorises_same_pattern_and_counts_inertia():
    """Numeric refactorisation with the stored analysis (same pattern, new values) solves
    like a dense solve; the reported negative pivots are the negative eigenvalues
    (Sylvester's law of inertia), checked against numpy's eigvalsh."""
    backend = get_backend("pardiso")
    A = _sym_indefinite(40, 7, 0)
    f1 = backend.factorize(A)
    b = np.arange(40.0)
    np.testing.assert_allclose(f1.solve(b), np.linalg.solve(A.toarray(), b), rtol=1e-9)
    assert f1.negative_pivots() == int(np.sum(np.linalg.eigvalsh(A.toarray()) < 0)) == 7
    A2 = A.copy()
    A2.data = A2.data * (1 + 0.05 * np.cos(np.arange(A2.nnz)))
    A2 = sp.csr_matrix(0.5 * (A2 + A2.T))
    f2 = backend.factorize(A2)
    np.testing.assert_allclose(f2.solve(b), np.linalg.solve(A2.toarray(), b), rtol=1e-9)
    assert f2.negative_pivots() == int(np.sum(np.linalg.eigvalsh(A2.toarray()) < 0))
    with pytest.raises(RuntimeError, match="replaced"):
        f1.solve(b)  # PARDISO keeps one factor: the old one must not answer silently


@needs_pardiso
def test_pardiso_factorises_a_saddle_point_matrix():
    """[A G^T; G 0] with a zero (explicitly stored) diagonal block: the solution equals a
    dense solve; inertia = n positive + m negative (A > 0, G full row rank)."""
    rng = np.random.default_rng(5)
    A = _spd(50, 6)
    G = sp.random(4, 50, density=0.2, random_state=rng) + sp.eye(4, 50)
    Z = sp.csr_matrix((np.zeros(4), (np.arange(4), np.arange(4))), shape=(4, 4))
    K = sp.bmat([[A, G.T], [G, Z]], format="csr")
    f = get_backend("pardiso").factorize(K)
    b = rng.random(54)
    np.testing.assert_allclose(f.solve(b), np.linalg.solve(K.toarray(), b), rtol=1e-8)
    assert f.negative_pivots() == 4


def _bordered_upper(A: sp.csr_matrix, G: sp.csr_matrix) -> sp.csr_matrix:
    """Upper triangle (CSR, sorted, every diagonal entry stored) of ``[A G^T; G 0]``."""
    m = G.shape[0]
    Z = sp.csr_matrix((np.zeros(m), (np.arange(m), np.arange(m))), shape=(m, m))
    U = sp.triu(sp.bmat([[A, G.T], [G, Z]], format="csr"), format="csr")
    U.sort_indices()
    return U


@needs_pardiso
def test_pardiso_schur_complement_of_the_trailing_rows():
    """``factorize(U, upper=True, schur=m)`` on ``B = [A G^T; G 0]`` (A indefinite, 7
    negative eigenvalues): the Schur complement it returns is ``-G A^-1 G^T`` (dense
    solve), the factor still solves with B, its inertia is B's, and Haynsworth's formula
    ``In(B) = In(A) + In(-G A^-1 G^T)`` gives A's 7 from it. The same backend then factorises
    plain, a refactorisation, and a Schur factorisation again (each analysis starts afresh:
    a Schur analysis leaves PARDISO's "user permutation" flag set, which crashed MKL on the
    next plain one)."""
    rng = np.random.default_rng(3)
    A = _sym_indefinite(40, 7, 1)
    G = sp.csr_matrix(sp.random(5, 40, density=0.3, random_state=rng) + sp.eye(5, 40))
    Bd = sp.bmat([[A, G.T], [G, None]]).toarray()
    backend = get_backend("pardiso")
    b = rng.random(45)
    factors = []
    for schur in (5, 0, 5):
        for scale in (1.0, 1.3):  # analysis, then a numeric refactorisation
            U = _bordered_upper((scale * A).tocsr(), G)
            f = backend.factorize(U, upper=True, schur=schur)
            factors.append(f)
            Bs = Bd.copy()
            Bs[:40, :40] *= scale
            np.testing.assert_allclose(f.solve(b), np.linalg.solve(Bs, b), rtol=1e-8)
            assert f.negative_pivots() == int(np.sum(np.linalg.eigvalsh(Bs) < 0))
            S = f.schur_complement()
            if not schur:
                assert S is None
                continue
            Gd = G.toarray()
            want = -Gd @ np.linalg.solve(scale * A.toarray(), Gd.T)
            np.testing.assert_allclose(S, want, rtol=1e-9, atol=1e-12 * np.abs(want).max())
            released = f.negative_pivots() - int(np.sum(np.linalg.eigvalsh(S) < 0))
            assert released == 7
    for old in factors[:-1]:  # every analysis freed the handle: no solve with a freed factor
        with pytest.raises(RuntimeError, match="replaced"):
            old.solve(b)


@needs_pardiso
def test_pardiso_rejects_a_missing_diagonal_and_singular():
    M = sp.csr_matrix(np.array([[0.0, 1.0], [1.0, 0.0]]))  # no stored diagonal
    with pytest.raises(SingularMatrixError, match="diagonal"):
        get_backend("pardiso").factorize(M)
    # singular (a stored zero pivot): PARDISO would perturb it and solve approximately; the
    # backend hands such a matrix to SuperLU, which says it is singular
    S = sp.csr_matrix(
        (np.array([2.0, 1.0, 1.0, 1.0, 0.0]), np.array([0, 1, 0, 1, 2]), np.array([0, 2, 4, 5])),
        shape=(3, 3),
    )
    assert S.nnz == 5 and S.diagonal()[2] == 0.0
    with pytest.raises(SingularMatrixError):
        get_backend("pardiso").factorize(S)


@needs_pardiso
def test_pardiso_refuses_non_finite_matrices_and_keeps_factorising():
    """A tangent of NaN or infinite entries is refused by name (MKL would factorise NaN
    into NaN solves, and crashed analysing infinite values after a NaN factorisation)."""
    A = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]]))
    backend = get_backend("pardiso")
    for bad, upper in ((np.nan, False), (np.inf, True)):
        B = sp.triu(A, format="csr") if upper else A.copy()
        B.data[1] = bad
        with pytest.raises(SingularMatrixError, match="non-finite"):
            backend.factorize(B, upper=upper)
    b = np.ones(3)
    np.testing.assert_allclose(backend.factorize(A).solve(b), np.linalg.solve(A.toarray(), b))


@pytest.mark.parametrize(("given", "want"), [(None, "AUTO"), ("COMPATIBLE", "COMPATIBLE")])
def test_pardiso_asks_mkl_for_reproducible_results(given, want):
    """MKL reads MKL_CBWR when it loads: the PARDISO backend sets it (unless the user did)
    before pypardiso loads MKL. Without it two identical runs of a compliant 20 x 20 Miura
    fold differed by up to 0.2 in intermediate states; with it they are bit-identical
    (docs/solver.md, "Threads and reproducibility")."""
    import os
    import subprocess
    import sys

    pytest.importorskip("pypardiso")
    env = {k: v for k, v in os.environ.items() if k != "MKL_CBWR"}
    if given is not None:
        env["MKL_CBWR"] = given
    code = (
        "import os; from barhinge.linalg.backends import get_backend; "
        "get_backend('pardiso'); print(os.environ.get('MKL_CBWR'))"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == want


def _resident_mb() -> float:
    """Resident memory of this process (Linux ``/proc/self/statm``), MB."""
    import os

    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


@needs_pardiso
@pytest.mark.skipif(not __import__("os").path.exists("/proc/self/statm"), reason="Linux only")
def test_pardiso_frees_its_factor_with_the_backend():
    """MKL keeps PARDISO's factor in its own memory; a dropped backend must free it. A 2-D
    Laplacian of 14 400 unknowns factorised by 12 fresh backends in turn: the process grows
    by ~8 MB per factor when they leak, and by nothing once the first one is made."""
    import gc

    n = 120
    T = sp.diags([-1.0, -1.0], [-1, 1], (n, n))
    I = sp.identity(n)  # noqa: E741
    A = (sp.kron(I, T) + sp.kron(T, I) + 4.01 * sp.identity(n * n)).tocsr()
    b = np.ones(n * n)
    get_backend("pardiso").factorize(A).solve(b)  # MKL's own start-up memory
    gc.collect()
    before = _resident_mb()
    for _ in range(12):
        x = get_backend("pardiso").factorize(A).solve(b)
        gc.collect()
    assert np.allclose(A @ x, b)
    assert _resident_mb() - before < 30.0


@needs_pardiso
def test_a_pardiso_backend_that_never_factorised_is_dropped_quietly():
    b = get_backend("pardiso")
    del b


@needs_pardiso
def test_pardiso_cholesky_solves_normal_equations_like_a_dense_solve():
    """The definite mode (Cholesky, two-level factorisation), as the rigid corrector uses it,
    solves ``J^T J x = b`` from its upper triangle like numpy's dense solve, refactorises the
    same pattern with new values, is not offered bordered (saddle-point) matrices, and names
    a singular normal matrix (a column of ``J`` zero: its pivot is exactly 0) as not
    positive definite."""
    from barhinge.linalg.backends import IndefiniteMatrixError, PardisoBackend

    rng = np.random.default_rng(3)
    backend = PardisoBackend(definite=True)
    assert backend.saddle_point is False and PardisoBackend.saddle_point is True
    J = sp.random(90, 60, density=0.08, random_state=rng) + sp.eye(90, 60)
    b = rng.random(60)
    for scale in (1.0, 2.5):
        K = sp.csr_matrix((scale * J).T @ (scale * J))
        K.setdiag(K.diagonal())
        U = sp.triu(K, format="csr")
        U.sort_indices()
        f = backend.factorize(U, upper=True)
        np.testing.assert_allclose(f.solve(b), np.linalg.solve(K.toarray(), b), rtol=1e-9)
    Js = sp.hstack([J[:, :59], sp.csr_matrix((90, 1))]).tocsr()
    Ks = sp.csr_matrix(Js.T @ Js)
    Ks.setdiag(Ks.diagonal())
    with pytest.raises(IndefiniteMatrixError):
        backend.factorize(Ks)


@pytest.mark.skipif(EXTENDED is None, reason="numpy's longdouble is a double here")
@pytest.mark.parametrize("backend", ["superlu", "auto"])
def test_refined_solve_in_extended_precision_solves_a_system_whose_double_residual_floors(
    backend, monkeypatch, beam_fourth_difference
):
    """The 3000-node fourth difference (cond ~ 1.7e13, like a finely meshed plate): any
    double vector's residual is held near ``eps |A| |x| / |b|`` ~ 4e-4 by the rounding of
    the products, above the 1e-4 the linear response accepts. Residuals accumulated in
    extended precision let refinement converge to the closed-form solution (Higham 2002,
    ch. 12: mixed-precision refinement, forward error ~ cond * eps_extended)."""
    from barhinge.linalg.backends import extended_residual, get_backend, refined_solve

    A, w = beam_fourth_difference(3000)
    b = np.ones(len(w))
    assert np.all(extended_residual(A, w, b) == 0.0)  # the closed form solves it exactly
    factor = get_backend(backend).factorize(A)
    x1 = np.asarray(factor.solve(b))
    floor = np.finfo(float).eps * np.linalg.norm(abs(A) @ abs(w)) / np.linalg.norm(b)
    assert floor > 1e-4
    assert np.linalg.norm(A @ x1 - b) / np.linalg.norm(b) > 1e-4  # double: over the bar
    err1 = np.abs(x1 - w).max() / np.abs(w).max()
    assert err1 > 1e-6
    x, rel = refined_solve(factor, A, b)
    assert rel < floor / 1000  # the extended-precision floor is 2048x lower
    err = np.abs(x - w).max() / np.abs(w).max()
    assert err < 1e-9 and err < err1 / 1e4
    # the residual in chunks of rows equals the one in a single block
    from barhinge.linalg import backends

    whole = extended_residual(A, x1, b)
    monkeypatch.setattr(backends, "_RESIDUAL_CHUNK_NNZ", 997)  # chunks of many rows
    np.testing.assert_array_equal(extended_residual(A, x1, b), whole)


def test_refined_solve_recovers_the_accuracy_of_an_inexact_factor():
    """Iterative refinement (Higham 2002, ch. 12) with the factor of a nearby matrix ``A + E``
    converges to the solution of ``A x = b`` when ``|A^-1 E| < 1``, at the rate
    ``|A^-1 E|`` per step; a factor far from A (no contraction) stops at once."""
    from barhinge.linalg.backends import refined_solve

    rng = np.random.default_rng(11)
    A = _spd(80, 5)
    b = rng.random(80)
    x_true = np.linalg.solve(A.toarray(), b)
    near = SuperLUBackend().factorize(sp.csr_matrix(A * (1.0 + 1e-3)))
    x1 = np.asarray(near.solve(b))
    assert np.linalg.norm(x1 - x_true) > 1e-4 * np.linalg.norm(x_true)  # one solve: off
    x, rel = refined_solve(near, A, b)
    np.testing.assert_allclose(x, x_true, rtol=1e-11)
    assert rel < 1e-13
    # the factor of 3 A: each step leaves 2/3 of the residual, so one step is kept (the
    # residual 2/3 -> 4/9 of b) and refinement stops there (less than halved)
    far = SuperLUBackend().factorize(sp.csr_matrix(A * 3.0))
    x, rel = refined_solve(far, A, b)
    np.testing.assert_allclose(x, x_true * 5.0 / 9.0, rtol=1e-10)
    assert rel == pytest.approx(4.0 / 9.0, rel=1e-10)
    # a factor that makes things worse (of -A: the residual doubles) keeps the first solve
    worse = SuperLUBackend().factorize(sp.csr_matrix(-A))
    x, rel = refined_solve(worse, A, b)
    np.testing.assert_allclose(x, -x_true, rtol=1e-10)
    assert rel == pytest.approx(2.0, rel=1e-10)
