"""Inertia (the number of negative eigenvalues) of a sequence of symmetric sparse matrices of
one pattern that are usually positive definite: the released tangents of a path's states.

A Cholesky factorisation decides positive definiteness for about two thirds of the cost of
the symmetric indefinite LDL^T that counts negative pivots (PARDISO on a Miura tangent of
38 877 DOF: 0.081 s against 0.120 s). :class:`InertiaCounter` therefore tries Cholesky while
the last matrix was positive definite and counts with LDL^T after one that was not (and
whenever Cholesky refuses), so a stable path pays Cholesky only and an unstable stretch pays
LDL^T only; each change between the two costs one refused Cholesky. Sylvester's law of
inertia makes the count independent of the factorisation used.

Only the count is kept. A large factor (above :attr:`InertiaCounter.release_above`, PARDISO's
own measure of its factor) is released as soon as it is counted, PARDISO keeping the ordering
and analysis: between matrices the counter then holds no second factor beside the solver's
own. The next factorisation allocates its factor again, which costs 14-21 % of a numeric
factorisation (a 40 x 40 and a 70 x 70 Miura tangent), so small factors are kept.
"""

from __future__ import annotations

import scipy.sparse as sp

from barhinge.linalg.backends import IndefiniteMatrixError, LinearBackend, PardisoBackend

__all__ = ["InertiaCounter"]


class InertiaCounter:
    """Negative eigenvalues of symmetric matrices of one sparsity pattern.

    Parameters
    ----------
    backend : LinearBackend
        The backend of the solve; a PARDISO backend gets a Cholesky companion, any other a
        fresh instance of its own type (whose factor counts its negative pivots, or gives
        no inertia).
    release_above : float, optional
        Factors larger than this (bytes) are released after their count (default
        :attr:`RELEASE_ABOVE`).
    """

    #: default factor size (bytes) above which a counted factor is released: 256 MB, the
    #: factor of a Miura sheet of about 150 000 DOF
    RELEASE_ABOVE = 256 * 2**20

    def __init__(self, backend: LinearBackend, release_above: float | None = None) -> None:
        self.release_above = self.RELEASE_ABOVE if release_above is None else release_above
        self._ldlt: LinearBackend = type(backend)()
        self._cholesky: PardisoBackend | None = (
            PardisoBackend(definite=True) if isinstance(backend, PardisoBackend) else None
        )
        self._last_definite = True
        #: factorisations made, refused Cholesky attempts included
        self.factorizations = 0

    def negative_eigenvalues(self, A: sp.csr_matrix) -> int | None:
        """Number of negative eigenvalues of the symmetric matrix ``A``; None when the
        backend gives no inertia. Raises SingularMatrixError for a singular ``A``."""
        if self._cholesky is not None and self._last_definite:
            self.factorizations += 1
            try:
                self._cholesky.factorize(A)
                return 0
            except IndefiniteMatrixError:
                pass
            finally:  # the count is all that is kept (a refused attempt holds memory too)
                self._release(self._cholesky)
        self.factorizations += 1
        factor = self._ldlt.factorize(A)
        neg = getattr(factor, "negative_pivots", None)
        count = neg() if neg is not None else None
        self._release(self._ldlt)
        self._last_definite = count == 0
        return count

    def _release(self, backend: LinearBackend) -> None:
        """Release ``backend``'s factor when it is larger than ``release_above``."""
        size = getattr(backend, "factor_bytes", None)
        if size is not None and size() > self.release_above:
            backend.release()  # type: ignore[attr-defined]
