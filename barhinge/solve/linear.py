"""Sparse linear solvers behind the Newton iterations (factorisation backends).

A backend turns a square sparse matrix into a :class:`Factor` whose ``solve`` accepts one or
many right-hand sides. Backends keep what can be reused between Newton iterations of the same
sparsity pattern (the fill-reducing ordering, the symbolic analysis).

* ``"superlu"`` (default, always available): scipy's SuperLU with the symmetric settings
  ``permc_spec="MMD_AT_PLUS_A"``, ``diag_pivot_thresh=0`` and ``SymmetricMode`` (LU of a
  symmetric matrix with diagonal pivots; zero diagonals still fall back to partial pivoting).
  The column ordering of the first factorisation is kept and re-applied to later matrices of
  the same pattern (``permc_spec="NATURAL"`` on the pre-permuted matrix), so the ordering is
  computed once per solve.
* ``"cholmod"`` (scikit-sparse, if importable): supernodal Cholesky; symbolic analysis done
  once. Only for symmetric positive definite matrices: when a matrix is not positive definite
  (past a limit point) the factor falls back to SuperLU for that matrix and says so in the log.
* ``"pardiso"`` (pypardiso, if importable): MKL PARDISO.

``get_backend("auto")`` picks CHOLMOD, then PARDISO, then SuperLU, whichever imports first.
"""

from __future__ import annotations

import importlib.util
import logging
from collections.abc import Callable
from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.errors import ConfigError

__all__ = [
    "BACKENDS",
    "Factor",
    "LinearBackend",
    "SingularMatrixError",
    "SuperLUBackend",
    "available_backends",
    "get_backend",
]

log = logging.getLogger(__name__)


class SingularMatrixError(RuntimeError):
    """The matrix could not be factorised (exactly or numerically singular)."""


class Factor(Protocol):
    """A factorised matrix."""

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for ``b`` of shape (n,) or (n, k)."""
        ...


class LinearBackend(Protocol):
    """Something that factorises sparse matrices of a fixed pattern repeatedly."""

    name: str

    def factorize(self, A: sp.spmatrix) -> Factor:
        """Factorise the square sparse matrix ``A`` (n, n)."""
        ...


# ----------------------------------------------------------------------------- SuperLU
class _SuperLUFactor:
    def __init__(self, lu: spla.SuperLU, perm: np.ndarray | None) -> None:
        self._lu = lu
        self._perm = perm  # symmetric pre-permutation (None when SuperLU ordered itself)

    def negative_pivots(self) -> int | None:
        """Number of negative pivots = negative eigenvalues of a symmetric A (Sylvester's law
        of inertia) when SuperLU kept the symmetric diagonal pivots; None otherwise."""
        lu = self._lu
        if not np.array_equal(lu.perm_r, lu.perm_c):
            return None
        return int(np.count_nonzero(lu.U.diagonal() < 0))

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if self._perm is None:
            return self._lu.solve(b)
        p = self._perm
        y = self._lu.solve(b[p])
        x = np.empty_like(y)
        x[p] = y
        return x


class SuperLUBackend:
    """scipy SuperLU with symmetric settings; the ordering is computed once and reused.

    Parameters
    ----------
    reuse_ordering : bool
        Keep the first factorisation's column ordering for later matrices of the same
        sparsity pattern (skips the minimum-degree ordering in every Newton iteration).
    """

    name = "superlu"

    def __init__(self, reuse_ordering: bool = True) -> None:
        self.reuse_ordering = reuse_ordering
        self._key: tuple[int, int, int] | None = None
        self._perm: np.ndarray | None = None

    def factorize(self, A: sp.spmatrix) -> _SuperLUFactor:
        A = sp.csc_matrix(A)
        A.sort_indices()
        key = (A.shape[0], A.nnz, hash(A.indices[:: max(1, A.nnz // 997)].tobytes()))
        opts = {"SymmetricMode": True}
        try:
            if self.reuse_ordering and self._perm is not None and key == self._key:
                p = self._perm
                Ap = A[p][:, p].tocsc()
                lu = spla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=0.0, options=opts)
                return _SuperLUFactor(lu, p)
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=opts)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise SingularMatrixError(str(exc)) from exc
        if self.reuse_ordering:
            self._key = key
            # perm_c maps original to permuted columns: the ordering is its inverse
            self._perm = np.argsort(np.asarray(lu.perm_c, dtype=np.int64))
        return _SuperLUFactor(lu, None)


# ----------------------------------------------------------------------------- CHOLMOD
class _CholmodFactor:
    def __init__(self, factor) -> None:
        self._f = factor

    def negative_pivots(self) -> int:
        """A Cholesky factor exists only for a positive definite matrix: no negative pivot."""
        return 0

    def solve(self, b: np.ndarray) -> np.ndarray:
        return np.asarray(self._f(np.asarray(b, dtype=float)))

    def half_solve(self, B: np.ndarray) -> np.ndarray:
        """``W = L^-1 P B`` for ``A = P^T L L^T P``, so that ``B^T A^-1 B = W^T W``
        (forward substitution only: half the cost of ``A^-1 B``)."""
        W = self._f.solve_L(
            self._f.apply_P(np.asarray(B, dtype=float)), use_LDLt_decomposition=False
        )
        return np.asarray(W)


class CholmodBackend:
    """CHOLMOD supernodal Cholesky (scikit-sparse); falls back to SuperLU when A is not SPD."""

    name = "cholmod"

    def __init__(self) -> None:
        from sksparse.cholmod import analyze  # noqa: F401  (import check)

        self._symbolic = None
        self._key: tuple[int, int] | None = None
        self._fallback = SuperLUBackend()

    def factorize(self, A: sp.spmatrix) -> Factor:
        from sksparse.cholmod import CholmodError, analyze

        A = sp.csc_matrix(A)
        key = (A.shape[0], A.nnz)
        try:
            if self._symbolic is None or key != self._key:
                self._symbolic = analyze(A, mode="supernodal")
                self._key = key
            factor = self._symbolic.cholesky(A)
            return _CholmodFactor(factor)
        except CholmodError as exc:
            log.debug("CHOLMOD refused the matrix (%s); using SuperLU for this one", exc)
            return self._fallback.factorize(A)


# ----------------------------------------------------------------------------- PARDISO
class _PardisoFactor:
    def __init__(self, solver, A: sp.csr_matrix) -> None:
        self._solver = solver
        self._A = A

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._solver.solve(self._A, np.asarray(b, dtype=float))


class PardisoBackend:
    """MKL PARDISO through pypardiso (real nonsymmetric mode; works for indefinite K)."""

    name = "pardiso"

    def __init__(self) -> None:
        import pypardiso

        self._solver = pypardiso.PyPardisoSolver()
        self._solver.set_statistical_info_off()

    def factorize(self, A: sp.spmatrix) -> Factor:
        A = sp.csr_matrix(A)
        A.sort_indices()
        self._solver.factorize(A)
        return _PardisoFactor(self._solver, A)


BACKENDS: dict[str, tuple[str | None, Callable[[], LinearBackend]]] = {
    "superlu": (None, SuperLUBackend),
    "cholmod": ("sksparse", CholmodBackend),
    "pardiso": ("pypardiso", PardisoBackend),
}


def available_backends() -> list[str]:
    """Names of the backends whose libraries import here, fastest first."""
    out = [name for name in ("cholmod", "pardiso") if _importable(BACKENDS[name][0] or "")]
    return [*out, "superlu"]


def _importable(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # ValueError: sys.modules[module] is None
        return False


def get_backend(name: str = "auto") -> LinearBackend:
    """A fresh backend instance: ``"auto"``, ``"superlu"``, ``"cholmod"`` or ``"pardiso"``."""
    if name == "auto":
        for cand in available_backends():
            try:
                return BACKENDS[cand][1]()
            except Exception as exc:  # a broken optional install must not stop a solve
                log.debug("backend %s unavailable: %s", cand, exc)
        return SuperLUBackend()
    if name not in BACKENDS:
        raise ConfigError(f"linear solver {name!r} is unknown; expected auto or {list(BACKENDS)}")
    module = BACKENDS[name][0]
    if module is not None and not _importable(module):
        raise ConfigError(f"linear solver {name!r} needs the package {module!r}, not installed")
    return BACKENDS[name][1]()
