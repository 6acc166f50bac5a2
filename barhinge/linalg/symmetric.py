"""Symmetric sparse matrices held as their upper triangle.

A linear analysis of a large model holds its supported stiffness beside the factor (for the
residuals of iterative refinement, or as the mass-like matrix of a buckling eigenproblem).
PARDISO reads only the upper triangle, so holding the full matrix as well stores every
off-diagonal entry three times. :class:`UpperSymmetric` keeps the upper triangle alone, the
array the factorisation reads, and multiplies with it as ``U x + U^T x - diag(U) x``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["UpperSymmetric", "upper_triangle_map"]


def upper_triangle_map(A: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the upper triangle of the CSR matrix ``A`` (sorted indices) lies in its values:
    ``(positions, indices, indptr)``, so that ``csr_matrix((A.data[positions], indices,
    indptr))`` is the triangle (explicit zeros kept). Index arrays in ``A``'s index type."""
    n = A.shape[0]
    rows = np.repeat(np.arange(n, dtype=A.indices.dtype), np.diff(A.indptr))
    keep = A.indices >= rows
    counts = np.bincount(rows[keep], minlength=n)
    del rows
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(A.indptr.dtype)
    return np.flatnonzero(keep), A.indices[keep], indptr


class UpperSymmetric:
    """The symmetric matrix ``A = U + U^T - diag(U)`` of the CSR upper triangle ``U``
    (sorted indices; explicit zeros kept). Products with vectors and blocks of vectors, in
    double or extended precision, use ``U`` alone."""

    def __init__(self, upper: sp.csr_matrix) -> None:
        U = sp.csr_matrix(upper)
        if U.shape[0] != U.shape[1]:
            raise ValueError(f"a symmetric matrix is square, got {U.shape}")
        if not U.has_sorted_indices:
            U.sort_indices()
        self.upper = U
        self.shape: tuple[int, int] = U.shape
        self.dtype = U.dtype
        self._diagonal = U.diagonal()

    @classmethod
    def from_full(cls, A: sp.spmatrix) -> UpperSymmetric:
        """The upper triangle of the symmetric matrix ``A`` (its lower triangle is not read;
        entries stored in ``A``, zeros included, stay stored)."""
        A = sp.csr_matrix(A)
        if not A.has_sorted_indices:
            A.sort_indices()
        pos, indices, indptr = upper_triangle_map(A)
        U = sp.csr_matrix((A.data[pos], indices, indptr), shape=A.shape)
        U.has_sorted_indices = True
        return cls(U)

    @property
    def nnz(self) -> int:
        """Entries stored (the upper triangle's)."""
        return int(self.upper.nnz)

    def diagonal(self) -> np.ndarray:
        return self._diagonal.copy()

    def stores_diagonal(self) -> bool:
        """Whether every row stores its diagonal entry (PARDISO's rule for symmetric types)."""
        U = self.upper
        if np.any(np.diff(U.indptr) == 0):
            return False
        return bool(np.all(U.indices[U.indptr[:-1]] == np.arange(U.shape[0])))

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        """``A x`` for x of shape (n,) or (n, k), in x's precision."""
        U = self.upper
        d = self._diagonal.astype(np.result_type(x, U.dtype))
        y = U @ x + U.T @ x
        return y - (d * x if np.ndim(x) == 1 else d[:, None] * x)

    def dot(self, x: np.ndarray) -> np.ndarray:
        return self @ x

    def operator(self) -> spla.LinearOperator:
        """``A`` as a scipy LinearOperator (for eigsh, cg, ...)."""
        return spla.LinearOperator(
            self.shape,
            matvec=self.__matmul__,
            matmat=self.__matmul__,
            rmatvec=self.__matmul__,
            dtype=self.dtype,
        )

    def full(self) -> sp.csr_matrix:
        """``A`` with both triangles stored (CSR; the entries stored in the triangle, zeros
        included, and their mirrors: the pattern of the matrix it was taken from)."""
        C = self.upper.tocoo()
        off = C.row != C.col
        A = sp.csr_matrix(
            (
                np.concatenate([C.data, C.data[off]]),
                (np.concatenate([C.row, C.col[off]]), np.concatenate([C.col, C.row[off]])),
            ),
            shape=self.shape,
        )
        A.sort_indices()
        return A

    def scaled(self, factor: float) -> UpperSymmetric:
        """``factor * A`` (its own values; the pattern shared)."""
        U = self.upper
        return UpperSymmetric(sp.csr_matrix((factor * U.data, U.indices, U.indptr), shape=U.shape))
