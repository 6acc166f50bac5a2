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
* ``"pardiso"`` (pypardiso, if importable): MKL PARDISO, symmetric indefinite mode, analysis
  once per pattern; 3-4x faster than SuperLU on the Miura tangents (see docs/solver.md).

``get_backend("auto")`` picks PARDISO, then CHOLMOD, then SuperLU, whichever imports first
(measured on the Miura tangents of ``benchmarks/bench_solver.py``: PARDISO 40 ms, SuperLU
120 ms, CHOLMOD 105-150 ms at 9 837 DOF; CHOLMOD's speed depends on the BLAS it is linked
to).
"""

from __future__ import annotations

import ctypes
import glob
import importlib.util
import logging
import os
import sys
from collections.abc import Callable
from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.errors import ConfigError
from barhinge.linalg.symmetric import UpperSymmetric, upper_triangle_map

__all__ = [
    "EXTENDED",
    "BACKENDS",
    "Factor",
    "IndefiniteMatrixError",
    "LinearBackend",
    "SingularMatrixError",
    "SuperLUBackend",
    "available_backends",
    "extended_residual",
    "factorize_symmetric",
    "get_backend",
    "refined_solve",
]

log = logging.getLogger(__name__)


class IndefiniteMatrixError(RuntimeError):
    """A Cholesky factorisation met a pivot that is not positive: the matrix is not positive
    definite (raised by the definite mode of :class:`PardisoBackend`)."""


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
        # SuperLU solves column by column of a Fortran-ordered copy; a C-ordered (n, k)
        # block is ~20x slower at k = 40 (measured 1.0 s vs 0.05 s, 9843 DOF)
        b = np.asfortranarray(b, dtype=float)
        if self._perm is None:
            return self._lu.solve(b)
        p = self._perm
        y = self._lu.solve(np.asfortranarray(b[p]))
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
    def __init__(self, backend: PardisoBackend, A: sp.csr_matrix, generation: int) -> None:
        self._backend = backend
        self._A = A
        self._generation = generation
        iparm = backend._solver.iparm
        self._negative = int(iparm[22])  # iparm(23): negative eigenvalues (symmetric modes)
        self._perturbed = int(iparm[13])  # iparm(14): pivots perturbed (singular to 1e-8)
        self._schur: np.ndarray | None = None

    def schur_complement(self) -> np.ndarray | None:
        """The dense Schur complement ``A_22 - A_21 A_11^-1 A_12`` of the trailing block
        (``factorize(..., schur=k)``: the last ``k`` rows), symmetrised; None when none
        was asked."""
        return self._schur

    def perturbed_pivots(self) -> int:
        """Pivots PARDISO had to perturb: nonzero means A is singular or nearly so to working
        precision, and solves are only approximate."""
        return self._perturbed

    def negative_pivots(self) -> int:
        """Number of negative eigenvalues of A (PARDISO's inertia, iparm(23))."""
        return self._negative

    def solve(self, b: np.ndarray) -> np.ndarray:
        if self._generation != self._backend._generation:
            raise RuntimeError("this PARDISO factor was replaced by a newer factorisation")
        # solve with the stored factor (skips pypardiso's matrix comparison)
        return _call_pardiso(self._backend._solver, 33, self._A, b)


def _call_pardiso(solver, phase: int, A: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
    """One call of MKL's ``pardiso`` through pypardiso's solver handle ``solver`` (its
    ``pt``, ``iparm``, ``perm``), with ``A``'s own zero-based CSR index arrays
    (``iparm(35) = 1``): pypardiso's ``_call_pardiso`` makes one-based int32 copies of both on
    every call (52 ms and 480 MB at the 60 M entries of a 200 x 200 Miura's bordered matrix).
    Returns the solution for the solve phases (C order); raises pypardiso's error."""
    from pypardiso.pardiso_wrapper import PyPardisoError

    ia = A.indptr if A.indptr.dtype == np.int32 else A.indptr.astype(np.int32)
    ja = A.indices if A.indices.dtype == np.int32 else A.indices.astype(np.int32)
    data = np.ascontiguousarray(A.data, dtype=float)
    b = np.asfortranarray(b, dtype=float)
    x = np.zeros_like(b)
    err = ctypes.c_int32(0)
    i32, f64 = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
    solver._mkl_pardiso(
        solver.pt.ctypes.data_as(ctypes.POINTER(solver._pt_type[0])),
        ctypes.byref(ctypes.c_int32(1)),  # maxfct
        ctypes.byref(ctypes.c_int32(1)),  # mnum
        ctypes.byref(ctypes.c_int32(solver.mtype)),
        ctypes.byref(ctypes.c_int32(phase)),
        ctypes.byref(ctypes.c_int32(A.shape[0])),
        data.ctypes.data_as(f64),
        ia.ctypes.data_as(i32),
        ja.ctypes.data_as(i32),
        solver.perm.ctypes.data_as(i32),
        ctypes.byref(ctypes.c_int32(1 if b.ndim == 1 else b.shape[1])),  # nrhs
        solver.iparm.ctypes.data_as(i32),
        ctypes.byref(ctypes.c_int32(solver.msglvl)),
        b.ctypes.data_as(f64),
        x.ctypes.data_as(f64),
        ctypes.byref(err),
    )
    if err.value != 0:
        raise PyPardisoError(err.value)
    return np.ascontiguousarray(x)


def _point_pypardiso_at_mkl() -> None:
    """Tell pypardiso where MKL's runtime library is when it sits in the environment's
    ``lib`` (pip wheels): its own fallback is a recursive glob over ``sys.prefix`` that
    takes ~1 s per solver."""
    if os.environ.get("PYPARDISO_MKL_RT"):
        return
    for lib in sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len):
        os.environ["PYPARDISO_MKL_RT"] = lib
        return


class PardisoBackend:
    """MKL PARDISO through pypardiso, real symmetric indefinite mode (``mtype = -2``:
    Bunch-Kaufman pivoting, so indefinite tangents past a limit point and saddle-point
    (bordered) matrices work, and the inertia is reported). Symmetric scaling and weighted
    matching (``iparm(11) = iparm(13) = 1``, Intel's advice for saddle-point matrices) avoid
    perturbed pivots. The upper triangle is passed; the ordering and symbolic analysis are
    made once per sparsity pattern and only the numeric factorisation (phase 22) is
    repeated. One factor is alive at a time (PARDISO keeps it internally)."""

    name = "pardiso"
    saddle_point = True  # factorises symmetric indefinite bordered matrices directly
    schur_complement = True  # ``factorize(..., schur=k)``

    #: iparm (1-based) set on top of PARDISO's defaults: user values, METIS ordering,
    #: iterative refinement only after perturbed pivots (two steps always cost 2.5x the
    #: solve and gained a factor 2 in residual, 2e-8 -> 1e-8 on a 38 963-row Miura KKT),
    #: pivot threshold 1e-8, symmetric scaling, weighted matching, 1x1 and 2x2
    #: Bunch-Kaufman pivots; zero-based indices (iparm(35) = 1, :func:`_call_pardiso`)
    IPARM = {1: 1, 2: 2, 8: 0, 10: 8, 11: 1, 13: 1, 21: 1, 35: 1}

    #: iparm(36) with ``factorize(..., schur=k)``: the Schur complement of the last k rows
    #: computed with the factorisation (MKL's "partial" mode, 2), which keeps the whole
    #: factor for solves and reports the whole matrix's inertia; 1 (the Schur complement
    #: alone) reports the leading block's inertia but cannot solve
    SCHUR_MODE = 2

    #: iparm of the definite mode (``mtype = 2``, Cholesky): no pivoting, so no matching,
    #: scaling or Bunch-Kaufman settings; MKL's two-level factorisation (iparm(24) = 1), 2
    #: MKL threads: on a Miura tangent of 118 437 free DOFs a factorisation takes 0.33 s
    #: against 0.36 s and a solve 21 ms against 48 ms; on the rigid corrector's normal
    #: matrix of a 70 x 70 Miura sheet 9.0 ms against 16.6 ms and 0.9 ms against 7.0 ms
    IPARM_DEFINITE = {1: 1, 2: 2, 8: 0, 24: 1, 35: 1}

    def __init__(self, definite: bool = False) -> None:
        """``definite``: Cholesky (``mtype = 2``) for matrices expected to be positive
        definite; a matrix that is not raises :class:`IndefiniteMatrixError` (the analysis
        is kept for the next matrix of the pattern). About 1.5x faster than the indefinite
        mode on a Miura tangent (0.081 s against 0.120 s at 38 877 DOF). Such a backend is
        not offered bordered (saddle-point) matrices."""
        _point_pypardiso_at_mkl()  # before the import: pypardiso makes a solver on import
        # reproducible results (MKL's conditional numerical reproducibility): without it MKL
        # picks code paths by memory alignment, and two identical runs of a sheet through a
        # negative-stiffness stretch differed by up to 0.2 in intermediate states; "AUTO"
        # keeps the fastest code path of the machine (no measured cost). MKL reads it when
        # it loads, so a user's own MKL_CBWR is kept.
        os.environ.setdefault("MKL_CBWR", "AUTO")
        # MKL's OpenMP threads sleep as soon as a factorisation or a solve ends, instead of
        # spinning for 200 ms (the OpenMP runtime's default): the tangent assembled next
        # runs its kernels on the same cores. On a 40 x 40 Miura fold (2 cores) the spin
        # took a core from every tangent evaluation (81 ms single-threaded against 98 ms
        # with it) and burned a quarter of the fold's CPU time for no gain in wall time.
        # Read when MKL loads, so a user's own KMP_BLOCKTIME is kept.
        os.environ.setdefault("KMP_BLOCKTIME", "0")
        import pypardiso

        self.definite = definite
        if definite:
            self.saddle_point = False
            self.schur_complement = False
        self._solver = pypardiso.PyPardisoSolver(mtype=2 if definite else -2)
        self._solver.set_statistical_info_off()
        for i, v in (self.IPARM_DEFINITE if definite else self.IPARM).items():
            self._solver.set_iparm(i, v)
        self._iparm0 = self._solver.iparm.copy()
        self._key: tuple | None = None
        self._upper_key: tuple | None = None
        self._upper_map: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._generation = 0
        self._held = False  # a numeric factor is in PARDISO's memory
        self._fallback = SuperLUBackend()

    def __del__(self) -> None:
        # PARDISO keeps its factor and analysis in MKL's memory, which pypardiso never frees
        # on its own: without this, every backend dropped leaks its factor (a study that
        # solves many models ran out of memory). Its factors hold the backend, so it is
        # only dropped with the last of them.
        solver = getattr(self, "_solver", None)
        if solver is not None:
            try:
                solver.free_memory(everything=True)
            except Exception:  # interpreter shutdown: MKL may be unloaded already
                pass

    def factor_bytes(self) -> int:
        """Memory of the current numeric factor (bytes; PARDISO's ``iparm(17)``, the memory
        of its numeric factorisation and solution); 0 when none is held."""
        if not self._held:
            return 0
        return 1024 * int(self._solver.iparm[16])

    def analysis_bytes(self) -> int:
        """Permanent memory of the ordering and symbolic analysis PARDISO keeps beside the
        factor (bytes; its ``iparm(16)``); 0 before an analysis."""
        if self._key is None:
            return 0
        return 1024 * int(self._solver.iparm[15])

    def release(self) -> None:
        """Free the numeric factor PARDISO holds (phase 0), keeping the ordering and analysis
        of the pattern: the next factorisation of the pattern is numeric only. Factors made
        before can no longer solve. For a backend whose factor is only read once (an inertia
        count), this returns a factor's worth of memory between factorisations."""
        if not self._held:
            return
        self._solver.free_memory(everything=False)  # phase 0: L and U of the matrix only
        self._generation += 1
        self._held = False

    def _upper(self, A: sp.spmatrix) -> sp.csr_matrix:
        """Upper triangle of A in CSR (explicit zeros kept), through a map built once per
        pattern. Every row must store its diagonal (PARDISO's rule for symmetric types)."""
        A = sp.csr_matrix(A)
        if not A.has_sorted_indices:
            A.sort_indices()
        n = A.shape[0]
        sample = A.indices[:: max(1, A.nnz // 997)]
        key = (n, A.nnz, hash(A.indptr.tobytes()), hash(sample.tobytes()))
        if key != self._upper_key:
            pos, indices, indptr = upper_triangle_map(A)
            if np.any(np.diff(indptr) == 0) or np.any(indices[indptr[:-1]] != np.arange(n)):
                raise SingularMatrixError("matrix does not store every diagonal entry")
            self._upper_map = (pos, indices.astype(np.int32), indptr.astype(np.int32))
            self._upper_key = key
        pos, indices, indptr = self._upper_map
        U = sp.csr_matrix((A.data[pos], indices, indptr), shape=A.shape)
        U.has_sorted_indices = True
        return U

    def factorize(self, A: sp.spmatrix, upper: bool = False, schur: int = 0) -> Factor:
        """Factorise the symmetric matrix A (``upper``: A is already its upper triangle in
        CSR with sorted indices and every diagonal entry stored; the caller then checks
        ``perturbed_pivots``). A full matrix whose factorisation needed perturbed pivots is
        handed to SuperLU instead (exact, or SingularMatrixError).

        ``schur`` = k > 0 (indefinite mode, ``upper`` only): the last k rows are ordered
        last and the factor also holds the dense Schur complement of that trailing block
        (:meth:`_PardisoFactor.schur_complement`) for little more than the factorisation
        (Miura bordered matrices: 0.40 s either way at 118 443 rows and 140 multipliers,
        7.7 s against 6.7 s at 962 403 rows and 400). Its leading block is eliminated
        first, so a singular leading block perturbs pivots."""
        if upper:
            U = A
            sample = U.indices[:: max(1, U.nnz // 997)]
            key = (U.shape[0], U.nnz, hash(U.indptr.tobytes()), hash(sample.tobytes()), schur)
        else:
            U = self._upper(A)
            key = self._upper_key
            schur = 0
        if not np.isfinite(U.data).all():
            # MKL factorises NaN into NaN solves and crashed analysing infinite values
            # after a factorisation of NaN: refused before it reaches PARDISO
            raise SingularMatrixError("PARDISO: the matrix has non-finite entries")
        s = self._solver
        N = U.shape[0]
        # the Schur complement is written into the first k^2 entries of the output
        work = np.zeros((N, max(1, -(-schur * schur // N))))
        try:
            if key != self._key:
                # the trailing rows of a Schur complement: set before the analysis. PARDISO
                # writes into iparm (a Schur analysis sets iparm(5), "user permutation"),
                # so every analysis starts from this backend's own settings, and one with or
                # after a Schur analysis from a fresh handle (MKL crashed reusing a Schur
                # handle for a plain analysis, and returned a zero Schur complement from a
                # handle of a plain one)
                if schur or int(s.iparm[35]):
                    s.free_memory(everything=True)
                    self._generation += 1  # earlier factors must not solve with it
                    self._held = False
                s.iparm[:] = self._iparm0
                s.set_iparm(36, self.SCHUR_MODE if schur else 0)
                s.perm = np.zeros(N if schur else 0, np.int32)
                s.perm[N - schur :] = 1
                # phase 12: analysis + numeric factorisation (called directly: pypardiso's
                # ``factorize`` keeps a copy of the matrix, which the factor holds already)
                x = _call_pardiso(s, 12, U, work)
                s.factorized_A = U
                self._key = key
            else:
                # numeric factorisation with the stored analysis
                x = _call_pardiso(s, 22, U, work)
                s.factorized_A = U  # built here, never modified: no copy needed
        except Exception as exc:  # pypardiso.PyPardisoError: zero pivot, singular matrix
            if self.definite and getattr(exc, "value", None) == -4:
                # Cholesky met a pivot that is not positive; a numeric phase leaves the
                # analysis of the pattern standing (only a failed first one is redone)
                if self._key != key:
                    self._key = None
                # the refused attempt replaced the last factor and holds its memory
                self._generation += 1
                self._held = self._key is not None
                raise IndefiniteMatrixError(f"PARDISO Cholesky: {exc}") from exc
            self._key = None
            raise SingularMatrixError(f"PARDISO: {exc}") from exc
        self._generation += 1
        self._held = True
        factor = _PardisoFactor(self, U, self._generation)
        if schur:
            # column-major output: its first k^2 values are the k x k complement
            S = np.asarray(x).T.ravel()[: schur * schur].reshape(schur, schur)
            factor._schur = 0.5 * (S + S.T)
        if not upper and factor.perturbed_pivots() > 0:
            # nearly singular to working precision: PARDISO's solves would be approximate.
            # SuperLU's exact LU of this matrix either solves it or says it is singular.
            log.debug("PARDISO perturbed %d pivots; SuperLU for this matrix", factor._perturbed)
            return self._fallback.factorize(A)
        return factor


BACKENDS: dict[str, tuple[str | None, Callable[[], LinearBackend]]] = {
    "superlu": (None, SuperLUBackend),
    "cholmod": ("sksparse", CholmodBackend),
    "pardiso": ("pypardiso", PardisoBackend),
}


#: numpy's ``longdouble`` where it carries more digits than float64 (80-bit x87 on x86-64
#: Linux and macOS on Intel: a 64-bit mantissa), else None (Windows, ARM: a plain double)
EXTENDED: type[np.floating] | None = (
    np.longdouble if np.finfo(np.longdouble).eps < np.finfo(np.float64).eps else None
)
#: nonzeros converted to extended precision at a time by :func:`extended_residual`
_RESIDUAL_CHUNK_NNZ = 4_000_000


def extended_residual(A: sp.spmatrix | UpperSymmetric, x: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``b - A x`` accumulated in extended precision (:data:`EXTENDED`), in chunks of rows
    so that only about 4 M nonzeros are held in the wider type at a time. In double
    precision the rounding of the products alone leaves a residual of about
    ``eps |A| |x|``, which on stiff, finely meshed plates exceeds the residual of the
    solution itself; the 64-bit mantissa moves that floor down by a factor of 2048. A
    symmetric ``A`` held as its upper triangle (:class:`UpperSymmetric`) adds each chunk's
    rows and their mirrors."""
    dtype = EXTENDED or np.float64
    symmetric = isinstance(A, UpperSymmetric)
    M = A.upper if isinstance(A, UpperSymmetric) else sp.csr_matrix(A)
    xe = np.asarray(x, dtype=dtype)
    r = np.asarray(b, dtype=dtype).copy()
    indptr = M.indptr
    n_rows = M.shape[0]
    cuts = np.searchsorted(indptr, np.arange(0, indptr[-1], _RESIDUAL_CHUNK_NNZ), side="right")
    bounds = np.unique(np.concatenate([[0], cuts - 1, [n_rows]]).clip(0, n_rows))
    for r0, r1 in zip(bounds[:-1], bounds[1:], strict=True):
        lo, hi = indptr[r0], indptr[r1]
        block = sp.csr_matrix(
            (M.data[lo:hi].astype(dtype), M.indices[lo:hi], indptr[r0 : r1 + 1] - lo),
            shape=(int(r1 - r0), M.shape[1]),
        )
        r[r0:r1] -= block @ xe
        if symmetric:  # the mirrored entries, less the diagonal counted twice
            r -= block.T @ xe[r0:r1]
            r[r0:r1] += block.diagonal(k=int(r0)) * xe[r0:r1]
    return r


def refined_solve(
    factor: Factor, A: sp.spmatrix | UpperSymmetric, b: np.ndarray, max_steps: int = 10
) -> tuple[np.ndarray, float]:
    """Solve ``A x = b`` with a factor of ``A`` and mixed-precision iterative refinement
    (Wilkinson; Higham 2002, Accuracy and Stability of Numerical Algorithms, ch. 12):
    the solution carried and the residuals accumulated in extended precision
    (:func:`extended_residual`), the corrections solved with the double-precision factor,
    each kept where it shrinks the residual, until one shrinks it by less than half or after
    ``max_steps``. Where ``cond(A) eps < 1`` this converges to the solution of the double
    precision system although the residual of any double vector is held at ``eps |A| |x|``
    (a fine plate mesh's stiffness reaches 1e12-1e13); it also recovers the accuracy of a
    factor that solves only approximately (perturbed pivots, a nearby matrix). Returns
    ``(x, |b - A x| / |b|)``: the residual of the refined solution before it is rounded to
    double (the rounding moves each entry by at most half a unit in its last place). Without
    an extended type (:data:`EXTENDED` None) the same steps run in double precision.
    ``A`` may be held as its upper triangle (:class:`UpperSymmetric`)."""
    if not isinstance(A, UpperSymmetric):
        A = sp.csr_matrix(A)
    dtype = EXTENDED or np.float64
    x = np.asarray(factor.solve(b), dtype=dtype)
    bn = max(float(np.linalg.norm(b)), 1e-300)
    r = extended_residual(A, x, b)
    rel = float(np.linalg.norm(r)) / bn
    for _ in range(max_steps):
        if not np.isfinite(rel) or rel < 1e-14:
            break
        x_new = x + np.asarray(factor.solve(np.asarray(r, dtype=np.float64)), dtype=dtype)
        r_new = extended_residual(A, x_new, b)
        rel_new = float(np.linalg.norm(r_new)) / bn
        if not rel_new < rel:  # no gain: the last solution stands
            break
        fast = rel_new < 0.5 * rel
        x, r, rel = x_new, r_new, rel_new
        if not fast:
            break
    return np.asarray(x, dtype=np.float64), rel


#: a symmetric factor whose smallest pivot is below this fraction of its largest is
#: numerically singular (:func:`factorize_symmetric`): a strut of rigid links left free to
#: turn as a mechanism factorises with 6e-17, the supported strut with 4e-8 (1 / its
#: condition number, roughly; double precision solves nothing beyond 1 / eps = 4.5e15)
SINGULAR_PIVOT_RATIO = 1e-15


def factorize_symmetric(backend: LinearBackend, A: UpperSymmetric) -> Factor:
    """Factorise the symmetric matrix held as its upper triangle. PARDISO reads the upper
    triangle itself (no copy is made; the factor keeps a reference to it); a factorisation
    that needed perturbed pivots (nearly singular to working precision), a triangle that
    does not store every diagonal entry, and the other backends are given the full matrix.
    A SuperLU factor whose smallest pivot is below :data:`SINGULAR_PIVOT_RATIO` times its
    largest raises SingularMatrixError: its solve would only be a rounding of a mechanism's
    motion."""
    if isinstance(backend, PardisoBackend) and not backend.definite and A.stores_diagonal():
        factor = backend.factorize(A.upper, upper=True)
        if factor.perturbed_pivots() == 0:  # type: ignore[attr-defined]
            return factor
        log.debug("PARDISO perturbed pivots; SuperLU for this matrix")
        del factor
        backend.release()
        factor = SuperLUBackend().factorize(A.full())
    else:
        factor = backend.factorize(A.full())
    if isinstance(factor, _SuperLUFactor):
        pivots = np.abs(factor._lu.U.diagonal())
        if pivots.size and not pivots.min() > SINGULAR_PIVOT_RATIO * pivots.max():
            raise SingularMatrixError(
                f"numerically singular: pivots from {pivots.min():.1e} to {pivots.max():.1e}"
            )
    return factor


def available_backends() -> list[str]:
    """Names of the backends whose libraries import here, fastest first."""
    out = [name for name in ("pardiso", "cholmod") if _importable(BACKENDS[name][0] or "")]
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
