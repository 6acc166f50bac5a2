"""Rank and null space of sparse constraint Jacobians, with the doubt of the rank stated.

* Small matrices: dense SVD.
* Large sparse matrices: the nullity is the **inertia** of ``JᵀJ − τ²I`` (one sparse
  symmetric indefinite LDLᵀ, PARDISO or SuperLU in symmetric mode): by Sylvester's law of
  inertia its negative pivots count the singular values of ``J`` below τ. The null vectors
  and the singular values on both sides of the cut come from block shift-invert (subspace)
  iteration on the same factorisation followed by Rayleigh-Ritz (the eigenvalues of ``JᵀJ``
  nearest τ² dominate). No ARPACK: nothing here can fail to converge silently; a failure of a
  numerical library becomes a :class:`RankError` (a ``ConvergenceError``: CLI exit code 3).

The cut is clear-cut when the gap ratio ``σ_above / σ_below`` (smallest singular value
counted non-zero over largest counted zero, the latter floored at the method's noise level) is
at least ``GAP_CERTAIN``; below that the report gives the two candidate ranks.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from barhinge.errors import ConvergenceError

__all__ = [
    "NullSpace",
    "RankError",
    "null_space",
    "DENSE_LIMIT",
    "DENSE_TOL",
    "SPARSE_TOL",
    "GAP_CERTAIN",
]

log = logging.getLogger(__name__)

#: above this many columns the sparse method is used
DENSE_LIMIT = 600
#: singular values below DENSE_TOL * sigma_max count as zero (dense SVD)
DENSE_TOL = 1e-8
#: singular values below SPARSE_TOL * sigma_max count as zero (inertia of J^T J - tau^2 I;
#: coarser because J^T J squares the singular values and loses half the digits)
SPARSE_TOL = 1e-6
#: a rank cut whose gap ratio is below this is reported as uncertain
GAP_CERTAIN = 1e3
#: noise floor of the singular values below the cut, relative to sigma_max (dense, sparse)
_FLOOR = {"svd": 1e-14, "sparse-inertia": 1e-8}  # sparse: sqrt(eps), JᵀJ squares
#: extra vectors of the block iteration beyond the nullity (singular values above the cut)
_EXTRA = 8


class RankError(ConvergenceError):
    """The rank could not be determined (a factorisation or iteration failed)."""


@dataclasses.dataclass(frozen=True)
class NullSpace:
    """Numerical rank and null space of a matrix J (m, n).

    Attributes
    ----------
    rank : int
    basis : (n, n - rank) float or None
        Orthonormal columns spanning the null space; None when the nullity exceeded the
        ``basis_limit`` asked of :func:`null_space` (rank and gap from the inertia alone).
    tolerance : float, absolute threshold on singular values (the cut).
    sigma_max : float, largest singular value (estimate for the sparse method).
    sigma_gap : float, smallest singular value counted as non-zero (nan if none).
    method : "svd" or "sparse-inertia".
    sigma_below : float
        Largest singular value counted as zero (0.0 if none).
    gap_ratio : float
        ``sigma_gap / max(sigma_below, floor)`` with ``floor`` the method's noise level
        (1e-14 sigma_max dense, 1e-8 sparse: ``JᵀJ`` cannot separate singular values below
        sqrt(eps) sigma_max); inf if one side of the cut is empty.
    certain : bool
        ``gap_ratio >= GAP_CERTAIN``.
    rank_candidates : (int, int)
        Smallest and largest plausible rank: ``(rank, rank)`` when certain; else this cut and
        the cut at the largest gap ratio among the computed singular values.
    sigmas : (k,) float
        The computed singular values nearest the cut, ascending (all of them dense).
    """

    rank: int
    basis: np.ndarray | None
    tolerance: float
    sigma_max: float
    sigma_gap: float
    method: str
    sigma_below: float = 0.0
    gap_ratio: float = float("inf")
    certain: bool = True
    rank_candidates: tuple[int, int] = (0, 0)
    sigmas: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))


def null_space(
    J: sp.spmatrix | np.ndarray,
    tol: float | None = None,
    *,
    dense_limit: int = DENSE_LIMIT,
    gap_certain: float = GAP_CERTAIN,
    basis_limit: int | None = None,
) -> NullSpace:
    """Rank and null space of ``J`` (m, n), with the gap at the cut.

    Small matrices (n <= ``dense_limit``): dense SVD; a singular value counts as zero below
    ``tol`` (relative to sigma_max; default ``DENSE_TOL`` = 1e-8). Large sparse matrices: the
    nullity from the inertia of ``JᵀJ − τ²I`` (τ = ``tol`` sigma_max, default ``SPARSE_TOL``
    = 1e-6) and the null space by shift-invert subspace iteration on that factorisation.

    ``basis_limit``: when the sparse method counts more null vectors than this, the basis is
    not computed (``basis`` is None; forming it costs n x nullity² flops): the singular value
    above the cut comes from the inertia at shifts bisected between τ and sigma_max, those
    below it from a small shift-invert block. An uncertain cut still computes the basis.

    Raises
    ------
    RankError
        A factorisation failed or the iteration did not reach the null space.
    """
    m, n = J.shape
    if n == 0:
        return NullSpace(0, np.zeros((0, 0)), 0.0, 0.0, np.nan, "svd")
    try:
        if n <= dense_limit or m == 0:
            return _dense(J, tol, gap_certain)
        return _sparse(sp.csr_matrix(J), tol, gap_certain, basis_limit)
    except RankError:
        raise
    except (np.linalg.LinAlgError, RuntimeError, ValueError, MemoryError) as exc:
        msg = f"rank of the {m} x {n} Jacobian failed: {type(exc).__name__}: {exc}"
        raise RankError(msg) from exc


def _judge(
    s: np.ndarray, nz: int, smax: float, method: str, gap_certain: float, n: int
) -> tuple[float, float, float, bool, tuple[int, int]]:
    """sigma_gap, sigma_below, gap ratio, certainty and rank candidates from the ascending
    singular values ``s`` nearest the cut, of which the first ``nz`` count as zero.

    The ratio of a cut after ``j`` values is ``s[j] / max(s[j-1], floor)``; values at or
    below the floor are zero for certain. An uncertain cut gives the range between the
    nearest clear cuts (ratio >= ``gap_certain``) on either side, or the ends of the
    computed values (the rank is then at least / at most that)."""
    floor = _FLOOR[method] * max(smax, 1e-300)
    below = float(s[nz - 1]) if nz > 0 else 0.0
    gap = float(s[nz]) if nz < len(s) else np.nan

    def ratio(j: int) -> float:
        if j >= len(s):
            return np.inf
        return float(s[j] / max(s[j - 1] if j > 0 else 0.0, floor))

    r = ratio(nz)
    certain = bool(r >= gap_certain)
    if certain:
        return gap, below, r, certain, (n - nz, n - nz)
    j_min = int(np.sum(s <= floor))
    j_hi = next((j for j in range(nz - 1, j_min - 1, -1) if ratio(j) >= gap_certain), j_min)
    j_lo = next((j for j in range(nz + 1, len(s) + 1) if ratio(j) >= gap_certain), len(s))
    return gap, below, r, certain, (n - j_lo, n - j_hi)


def _dense(J, tol: float | None, gap_certain: float) -> NullSpace:
    m, n = J.shape
    A = J.toarray() if sp.issparse(J) else np.asarray(J, dtype=float)
    if m == 0:
        return NullSpace(0, np.eye(n), 0.0, 0.0, np.nan, "svd", 0.0, np.inf, True, (0, 0))
    _, s, Vt = sla.svd(A, full_matrices=True, lapack_driver="gesdd")
    smax = float(s[0]) if len(s) else 0.0
    rel = DENSE_TOL if tol is None else tol
    atol = rel * max(smax, 1e-300)
    rank = int(np.sum(s > atol))
    full = np.zeros(n)
    full[: len(s)] = s
    asc = full[::-1]  # n values, ascending (missing ones are exact zeros)
    nz = n - rank
    gap, below, ratio, certain, cand = _judge(asc, nz, smax, "svd", gap_certain, n)
    return NullSpace(
        rank, Vt[rank:].T.copy(), atol, smax, gap, "svd", below, ratio, certain, cand, asc
    )


def _sigma_max(N: sp.csr_matrix, iters: int = 40) -> float:
    """Largest singular value of J from ``N = JᵀJ`` by power iteration (deterministic start;
    from below, a few per cent low after 40 steps: enough for a relative threshold)."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(N.shape[0])
    lam = 0.0
    for _ in range(iters):
        y = N @ x
        nrm = float(np.linalg.norm(y))
        if nrm == 0.0:
            return 0.0
        lam = float(x @ y) / float(x @ x)
        x = y / nrm
    return float(np.sqrt(max(lam, 0.0)))


class _Inertia:
    """One LDLᵀ of a symmetric matrix that reports its negative pivots."""

    def __init__(self, A: sp.csr_matrix) -> None:
        self.neg: int | None = None
        self.factor = None
        self.name = ""
        errors: list[str] = []
        for name in ("pardiso", "superlu"):
            try:
                fac = _backend(name).factorize(A)
            except Exception as exc:  # any library failure: try the next one
                errors.append(f"{name}: {exc}")
                continue
            neg = fac.negative_pivots() if hasattr(fac, "negative_pivots") else None
            if neg is None:
                errors.append(f"{name}: no inertia (non-symmetric pivoting)")
                continue
            self.neg, self.factor, self.name = int(neg), fac, name
            return
        raise RankError("no factorisation of JᵀJ − τ²I reported its inertia: " + "; ".join(errors))


def _backend(name: str):
    from barhinge.linalg.backends import BACKENDS, PardisoBackend, _importable

    if name == "pardiso":
        if not _importable("pypardiso"):
            raise RankError("pypardiso not installed")

        class _Tight(PardisoBackend):
            # pivots are perturbed only below 1e-13 (default 1e-8): the shifted normal
            # matrix has pivots near -tau^2 ~ 1e-12 sigma_max^2 that must stay as they are
            IPARM = {**PardisoBackend.IPARM, 10: 13}

        return _Tight()
    return BACKENDS[name][1]()


def _sparse(
    J: sp.csr_matrix, tol: float | None, gap_certain: float, basis_limit: int | None = None
) -> NullSpace:
    m, n = J.shape
    N = (J.T @ J).tocsr()
    smax = _sigma_max(N)
    if smax == 0.0:
        return NullSpace(0, np.eye(n), 0.0, 0.0, np.nan, "sparse-inertia", 0.0, np.inf, True,
                         (0, 0), np.zeros(n))  # fmt: skip
    rel = SPARSE_TOL if tol is None else tol
    atol = rel * smax
    tau2 = atol**2
    A = (N - tau2 * sp.identity(n, format="csr")).tocsr()
    A.sort_indices()
    inert = _Inertia(A)
    nz = inert.neg
    if nz >= n:
        raise RankError(f"the inertia says all {n} singular values are below the cut")
    if basis_limit is not None and nz > basis_limit:
        ns = _count_only(J, N, inert, nz, smax, atol, gap_certain)
        if ns is not None:
            return ns
    b = min(n, nz + _EXTRA)
    rng = np.random.default_rng(1)
    X = rng.standard_normal((n, b))
    resid = np.inf if nz else 0.0
    solve = inert.factor.solve

    def ritz(Y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        Q = np.linalg.qr(Y)[0]
        NQ = N @ Q
        H = Q.T @ NQ
        theta, W = np.linalg.eigh(0.5 * (H + H.T))
        return theta, Q @ W, NQ @ W

    # 1. the whole block until the null vectors converge (the contamination shrinks by
    #    tau^2 / (sigma^2 - tau^2) per solve above the cut: one or two iterations)
    for it in range(40):  # noqa: B007 (it is logged)
        theta, X, NX = ritz(np.asarray(solve(X)).reshape(n, b))
        if nz:
            resid = float(np.abs(NX[:, :nz] - X[:, :nz] * theta[:nz]).max())
        if resid <= 1e-3 * tau2:
            break
    # 2. the vectors above the cut, orthogonal to the locked null vectors, until the two
    #    smallest (the gap) settle to 1e-4: a Ritz value approaches its eigenvalue from
    #    above, so the gap is known to about 0.1 % (the ratio is judged against 1e3)
    Xn, Z, th = X[:, :nz], X[:, nz:], theta[nz:]
    k = Z.shape[1]
    for _ in range(80 if k else 0):
        Y = np.asarray(solve(Z)).reshape(n, k)
        for _ in range(2):  # project out the locked vectors (twice: to working precision)
            Y -= Xn @ (Xn.T @ Y)
        th_new, Z, _ = ritz(Y)
        m = min(2, k)
        settled = np.all(np.abs(th_new[:m] - th[:m]) <= 1e-4 * np.abs(th_new[:m]))
        th = th_new
        if settled:
            break
    X = np.hstack([Xn, Z])
    sig = np.linalg.norm(J @ X, axis=0)  # Rayleigh quotients of J: accurate below the cut
    order = np.argsort(sig)
    sig, X = sig[order], X[:, order]
    counted = int(np.sum(sig[:nz] <= atol)) if nz else 0
    if nz and (counted != nz or resid > 1e-2 * tau2):
        raise RankError(
            f"the shift-invert iteration found {counted} of the {nz} singular values below the "
            f"cut {atol:.1e} that the inertia counts (residual {resid:.1e})"
        )
    basis = X[:, :nz] if nz else np.zeros((n, 0))  # Ritz vectors: orthonormal already
    gap, below, ratio, certain, cand = _judge(sig, nz, smax, "sparse-inertia", gap_certain, n)
    log.debug(
        "sparse rank: nullity %d by %s inertia, gap ratio %.2e, %d block iterations",
        nz, inert.name, ratio, it + 1,
    )  # fmt: skip
    return NullSpace(n - nz, basis, atol, smax, gap, "sparse-inertia", below, ratio, certain,
                     cand, sig)  # fmt: skip


def _count_at(N: sp.csr_matrix, s: float) -> int:
    """Number of singular values of J below ``s`` (inertia of ``JᵀJ − s²I``)."""
    A = (N - s * s * sp.identity(N.shape[0], format="csr")).tocsr()
    A.sort_indices()
    return int(_Inertia(A).neg or 0)  # _Inertia raises when no inertia is reported


def _count_only(
    J: sp.csr_matrix,
    N: sp.csr_matrix,
    inert: _Inertia,
    nz: int,
    smax: float,
    atol: float,
    gap_certain: float,
    rel_gap: float = 1e-4,
) -> NullSpace | None:
    """Rank and gap without the null basis (a wide null space): the smallest singular value
    above the cut by geometric bisection of the inertia count between ``atol`` (``nz`` below)
    and ``1.01 sigma_max`` (all below) to ``rel_gap``; the largest below the cut from the
    Rayleigh quotients of a 16-vector shift-invert block (its Ritz values below τ² are the
    singular values nearest the cut from below). None when the cut is uncertain (the caller
    then computes everything)."""
    m, n = J.shape
    lo, hi = atol, 1.01 * smax
    if _count_at(N, hi) <= nz:
        return None  # the power-iteration sigma_max is too low to bracket the gap
    while hi > lo * (1.0 + rel_gap):
        mid = float(np.sqrt(lo * hi))
        if _count_at(N, mid) > nz:
            hi = mid
        else:
            lo = mid
    gap = hi  # lo <= sigma_gap <= hi
    b = min(nz, 16)
    rng = np.random.default_rng(1)
    X = rng.standard_normal((n, b))
    for _ in range(4):
        X = np.linalg.qr(np.asarray(inert.factor.solve(X)).reshape(n, b))[0]
    below = np.sort(np.linalg.norm(J @ X, axis=0))
    if np.any(below > atol):
        return None
    sig = np.concatenate([below, [gap]])
    floor = _FLOOR["sparse-inertia"] * smax
    ratio = float(gap / max(below[-1], floor))
    if ratio < gap_certain:
        return None
    log.debug("sparse rank without basis: nullity %d, gap ratio %.2e", nz, ratio)
    return NullSpace(n - nz, None, atol, smax, gap, "sparse-inertia", float(below[-1]), ratio,
                     True, (n - nz, n - nz), sig)  # fmt: skip
