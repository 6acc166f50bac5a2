"""Rank and null space of sparse constraint Jacobians (dense SVD or sparse shift-invert)."""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["NullSpace", "null_space", "DENSE_LIMIT", "DENSE_TOL", "SPARSE_TOL"]

#: above this many columns the sparse method is used
DENSE_LIMIT = 600
#: singular values below DENSE_TOL * sigma_max count as zero (dense SVD)
DENSE_TOL = 1e-8
#: singular values below SPARSE_TOL * sigma_max count as zero (eigenvalues of J^T J)
SPARSE_TOL = 1e-6


@dataclasses.dataclass(frozen=True)
class NullSpace:
    """Numerical rank and null space of a matrix J (m, n).

    Attributes
    ----------
    rank : int
    basis : (n, n - rank) float, orthonormal columns spanning the null space.
    tolerance : float, absolute threshold on singular values.
    sigma_max : float, largest singular value (estimate for the sparse method).
    sigma_gap : float, smallest singular value counted as non-zero (nan if unknown).
    method : "svd" or "sparse-eigsh".
    """

    rank: int
    basis: np.ndarray
    tolerance: float
    sigma_max: float
    sigma_gap: float
    method: str


def null_space(
    J: sp.spmatrix | np.ndarray, tol: float | None = None, *, dense_limit: int = DENSE_LIMIT
) -> NullSpace:
    """Rank and null space of ``J`` (m, n).

    Small matrices (n <= ``dense_limit``): dense SVD; a singular value counts as zero below
    ``tol`` (relative to sigma_max; default ``DENSE_TOL`` = 1e-8). Large sparse matrices: the
    smallest eigenpairs of ``J^T J`` by shift-invert Lanczos (ARPACK, one sparse LU of
    ``J^T J + c I``), doubling the number asked for until a non-zero one appears; a singular
    value ``sqrt(lambda)`` counts as zero below ``tol`` (default ``SPARSE_TOL`` = 1e-6,
    coarser because squaring loses half the digits).
    """
    m, n = J.shape
    if n == 0:
        return NullSpace(0, np.zeros((0, 0)), 0.0, 0.0, np.nan, "svd")
    if n <= dense_limit or m == 0:
        A = J.toarray() if sp.issparse(J) else np.asarray(J, dtype=float)
        if m == 0:
            return NullSpace(0, np.eye(n), 0.0, 0.0, np.nan, "svd")
        _, s, Vt = sla.svd(A, full_matrices=True, lapack_driver="gesdd")
        smax = float(s[0]) if len(s) else 0.0
        rel = DENSE_TOL if tol is None else tol
        atol = rel * max(smax, 1e-300)
        rank = int(np.sum(s > atol))
        gap = float(s[rank - 1]) if rank > 0 else np.nan
        return NullSpace(rank, Vt[rank:].T.copy(), atol, smax, gap, "svd")
    J = sp.csr_matrix(J)
    N = (J.T @ J).tocsc()
    smax = float(np.sqrt(spla.eigsh(N, k=1, which="LA", return_eigenvectors=False, tol=1e-3)[0]))
    rel = SPARSE_TOL if tol is None else tol
    atol = rel * smax
    shift = 1e-10 * smax**2
    lu = spla.splu((N + shift * sp.identity(n, format="csc")).tocsc())
    op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    k = min(8, n - 1)
    while True:
        vals, vecs = spla.eigsh(N, k=k, sigma=-shift, which="LM", OPinv=op, tol=1e-12)
        order = np.argsort(vals)
        vals, vecs = vals[order], vecs[:, order]
        sig = np.sqrt(np.clip(vals, 0.0, None))
        zero = sig <= atol
        nz = int(zero.sum())
        if nz < k or k >= n - 1:
            break
        k = min(2 * k, n - 1)
    basis, _ = np.linalg.qr(vecs[:, zero]) if nz else (np.zeros((n, 0)), None)
    gap = float(sig[nz]) if nz < len(sig) else np.nan
    return NullSpace(n - nz, basis, atol, smax, gap, "sparse-eigsh")
