"""Linear buckling of a bar-and-hinge state: ``(K_E + lambda K_G(dS)) phi = 0``.

The tangent of the model is split by the kernels' own derivatives (exact, no differencing):

* material part ``K_M = sum_bars S'(eps) d d^T + sum_hinges M'(rho) g g^T`` (``d`` the bar
  strain gradient, ``g`` the fold-angle gradient);
* geometric part ``K_G(S, M) = sum_bars S B + sum_hinges M d^2 rho / dX^2`` for given bar
  forces ``S = dW/d eps`` and hinge moments ``M`` (linear in them, at fixed geometry).

Linear buckling at a state ``X`` (default the stress-free reference) under the reference load
``P``: solve ``K_T(X) du = P`` on the free DOFs, take the stress increments it causes
(``dS = S' d . du``, ``dM = M' g . du``), and find the smallest positive ``lambda`` with
``(K_T(X) + lambda K_G(dS, dM)) phi = 0`` (``K_E = K_T(X)``: at the stress-free reference this
is the material stiffness; at a loaded state the initial stresses stay in it). Solved as
``-K_G phi = mu K_E phi``, ``lambda = 1 / mu`` for the largest ``mu`` (ARPACK Lanczos,
``scipy.sparse.linalg.eigsh`` with ``K_E`` factorised: shift-invert at ``lambda = 0``), so
``lambda P`` is the first bifurcation load of the linearised pre-buckling state (Bazant &
Cedolin 1991, Stability of Structures, ch. 2; Bathe 2014, Sec. 6.8.2). A limit point of a
shallow structure is not a bifurcation: check it with arc length.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge.analysis.stiffness import make_room_for_factor
from barhinge.errors import BucklingError, ConfigError
from barhinge.kernels.geometry import (
    bar_strain_derivatives,
    hinge_angle_gradient,
    hinge_energy_hessian_packed,
)
from barhinge.linalg.backends import (
    SingularMatrixError,
    factorize_symmetric,
    get_backend,
    refined_solve,
)
from barhinge.linalg.symmetric import UpperSymmetric
from barhinge.linalg.threads import threads_for_sparse

__all__ = [
    "Buckling",
    "CriticalAhead",
    "critical_ahead",
    "critical_between",
    "linear_buckling",
    "stiffness_parts",
    "geometric_stiffness",
]


@dataclasses.dataclass(frozen=True, eq=False)
class Buckling:
    """Linear buckling factors and modes of a state.

    Attributes
    ----------
    factors : (n_modes,) float
        Load factors ``lambda`` (ascending, > 0): the reference load times ``lambda``
        buckles the linearised structure.
    modes : (n_modes, n_nodes, 3) float
        Mode shapes, scaled to a largest nodal amplitude of 1 (zero at fixed DOFs).
    X : (n_nodes, 3) float
        The state.
    prebuckling : (n_nodes, 3) float
        Linear displacement under the reference load.
    """

    factors: np.ndarray
    modes: np.ndarray
    X: np.ndarray
    prebuckling: np.ndarray


def _bar_blocks(a: np.ndarray, S: np.ndarray, d: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(nb, 6, 6) bar matrices ``[[k, -k], [-k, k]]``, ``k = a d d^T + S B``."""
    k = a[:, None, None] * d[:, :, None] * d[:, None, :] + S[:, None, None] * B
    return np.block([[k, -k], [-k, k]])


def _hinge_packed(model: Any, X: np.ndarray, M: np.ndarray, Kt: np.ndarray) -> np.ndarray:
    z = np.zeros(len(M))

    def law(rho: np.ndarray, sl: slice):
        return M[sl], Kt[sl], z[sl]

    *_, Hp = hinge_energy_hessian_packed(X, model.hinges, law)
    return Hp


def geometric_stiffness(
    model: Any, X: np.ndarray, bar_S: np.ndarray, hinge_M: np.ndarray
) -> sp.csr_matrix:
    """(n_dof, n_dof) geometric stiffness at ``X`` of the bar forces ``bar_S = dW/d eps``
    (n_bars,) and hinge moments ``hinge_M`` (n_hinges,)."""
    X = np.asarray(X, float).reshape(-1, 3)
    _, d, B = bar_strain_derivatives(X, model.bars, model.bar_L0, model.strain)
    nb = len(model.bars)
    Kb = _bar_blocks(np.zeros(nb), np.asarray(bar_S, float), d, B)
    asm = model.assembler
    iu, ju = asm.triu[0]
    Hp = _hinge_packed(model, X, np.asarray(hinge_M, float), np.zeros(model.n_hinges))
    return asm.matrix_packed([Kb[:, iu, ju].T, Hp])


def stiffness_parts(model: Any, X: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """(material part, geometric part) of the tangent at ``X``; they sum to
    ``model.tangent(X)``."""
    X = np.asarray(X, float).reshape(-1, 3)
    eps, d, B = bar_strain_derivatives(X, model.bars, model.bar_L0, model.strain)
    S, dS, _ = model.bar_law(eps)
    rho = model.hinge_angles(X)
    M, Kt, _ = model._hinge_law(rho)
    asm = model.assembler
    iu, ju = asm.triu[0]
    nb = len(model.bars)
    Km_b = _bar_blocks(dS, np.zeros(nb), d, B)
    Kg = geometric_stiffness(model, X, S, M)
    if len(getattr(model, "hinge_pairs", ())) or len(getattr(model, "bar_pairs", ())):
        # couplings: their cross terms are material
        return (model.evaluate(X).K - Kg).tocsr(), Kg
    Km = asm.matrix_packed([Km_b[:, iu, ju].T, _hinge_packed(model, X, np.zeros_like(M), Kt)])
    return Km, Kg


#: a factor larger than this (bytes) is released while the geometric stiffness is assembled
#: and made again after it: the two are never held together (a refined roof of 444 099 DOF
#: peaked at 5.7 GB with both, 4.5 GB without, its factor 2.2 GB), for one more numeric
#: factorisation
RELEASE_FACTOR_ABOVE = 2**30


@threads_for_sparse
def linear_buckling(
    model: Any,
    loads: np.ndarray,
    fixed: np.ndarray,
    X: np.ndarray | None = None,
    n_modes: int = 4,
) -> Buckling:
    """Linear buckling factors and modes of the state ``X`` under the reference ``loads``.

    Parameters
    ----------
    loads : (n_nodes, 3) float
        Reference load ``P``.
    fixed : (n_nodes, 3) bool
        Supported DOFs.
    X : (n_nodes, 3) float, optional
        The state (default ``model.X0``).
    n_modes : int
        How many factors to find (fewer are returned if fewer are positive).

    Raises
    ------
    BucklingError
        If the supported stiffness is singular (a mechanism), the load puts nothing in
        compression, or the eigensolver fails; the message says which.
    """
    import scipy.sparse.linalg as spla

    n = model.n_nodes
    X = np.asarray(model.X0 if X is None else X, float).reshape(n, 3)
    P = np.asarray(loads, float)
    F = np.asarray(fixed, bool)
    if P.shape != (n, 3) or F.shape != (n, 3):
        raise ConfigError(f"loads and fixed must have shape ({n}, 3), got {P.shape}, {F.shape}")
    if not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ConfigError(f"n_modes = {n_modes!r}; expected an integer >= 1")
    free = np.flatnonzero(~F.ravel())
    if len(free) < 2:
        raise ConfigError("linear buckling needs at least two free DOFs")
    # the supported stiffness as its upper triangle (the array PARDISO reads); the full
    # tangent is not kept
    Kff = UpperSymmetric.from_full(model.tangent(X)[free][:, free])
    make_room_for_factor(model)
    backend = get_backend("auto")
    try:
        lu = factorize_symmetric(backend, Kff)  # PARDISO, else SuperLU
    except SingularMatrixError as exc:
        raise BucklingError(
            "linear buckling: the supported stiffness is singular (a mechanism); add supports"
        ) from exc
    du = np.zeros(3 * n)
    pf = P.ravel()[free]
    du[free], residual = refined_solve(lu, Kff, pf)  # residual: |Kff du - pf| / |pf|
    if not np.all(np.isfinite(du)):
        raise BucklingError("linear buckling: the pre-buckling solve is not finite (mechanism)")
    if residual > 1e-4:
        # a (nearly) singular stiffness solved only approximately: the load moves a mechanism
        raise BucklingError(
            "linear buckling: the supported stiffness is singular (a mechanism); add supports"
        )
    U = du.reshape(n, 3)
    eps, d, _ = bar_strain_derivatives(X, model.bars, model.bar_L0, model.strain)
    _, dSde, _ = model.bar_law(eps)
    deps = np.einsum("bi,bi->b", d, U[model.bars[:, 1]] - U[model.bars[:, 0]])
    dS = dSde * deps
    if len(getattr(model, "bar_pairs", ())):  # the couplings' forces change too
        dS = dS + model._bar_C @ deps
    rho, g = _rho_grad(model, X)
    _, Kt, _ = model._hinge_law(rho)
    drho = np.einsum("hk,hk->h", g, du[_hinge_dofs(model)])
    dM = Kt * drho
    if len(getattr(model, "hinge_pairs", ())):  # the couplings' moments change too
        dM = dM + model._pair_C @ drho
    size = getattr(backend, "factor_bytes", None)
    release = size is not None and size() > RELEASE_FACTOR_ABOVE
    if release:  # the geometric stiffness is assembled without the factor beside it
        del lu
        backend.release()  # type: ignore[attr-defined]
    A = UpperSymmetric.from_full(geometric_stiffness(model, X, dS, dM)[free][:, free])
    A = A.scaled(-1.0)
    if release:  # numeric only: the ordering is kept
        make_room_for_factor(model)
        lu = factorize_symmetric(backend, Kff)
    k = min(int(n_modes), len(free) - 1)
    Kinv = spla.LinearOperator(Kff.shape, matvec=lu.solve, dtype=float)
    try:
        mu, vec = spla.eigsh(A.operator(), k=k, M=Kff.operator(), Minv=Kinv, which="LA", tol=1e-10)
    except (spla.ArpackNoConvergence, spla.ArpackError, RuntimeError, ValueError) as exc:
        raise BucklingError(f"linear buckling: the eigensolver failed ({exc})") from exc
    pos = mu > 1e-12 * max(float(np.abs(mu).max()), 1e-300)
    if not pos.any():
        raise BucklingError(
            "linear buckling: the reference load puts nothing in compression "
            "(no positive buckling factor)"
        )
    mu, vec = mu[pos], vec[:, pos]
    order = np.argsort(-mu)
    factors = 1.0 / mu[order]
    modes = np.zeros((len(order), 3 * n))
    modes[:, free] = vec[:, order].T
    modes /= np.abs(modes).max(axis=1, keepdims=True)
    return Buckling(factors=factors, modes=modes.reshape(-1, n, 3), X=X, prebuckling=U)


#: free DOFs up to which :func:`critical_between` solves its pencil densely
DENSE_PENCIL = 50


@threads_for_sparse
def critical_between(
    model: Any,
    fixed: np.ndarray,
    X_a: np.ndarray,
    X_b: np.ndarray,
    lam_a: float,
    lam_b: float,
    rtol: float = 1e-5,
) -> float:
    """Load factor at which stability is lost between two equilibrium states of a path.

    The free tangent is interpolated linearly between a stable state ``X_a`` (load factor
    ``lam_a``) and the next state ``X_b`` (``lam_b``), whose tangent has more negative
    eigenvalues: ``K(alpha) = K_a + alpha (K_b - K_a)``. The first ``alpha`` in (0, 1] at
    which ``K(alpha)`` gains a negative eigenvalue gives ``lam_a + alpha (lam_b - lam_a)``:
    exact where the tangent is linear in the load factor between the two states (a perfect
    strut on its straight path), and within the bracket otherwise (across a limit point the
    load factor is not linear in the state, so there only within it; the secant estimate of
    a critical point at the last stable state, e.g. Wriggers, Wagner & Miehe 1988, Comput.
    Methods Appl. Mech. Eng. 70:329). Small systems (up to ``DENSE_PENCIL`` free DOFs) solve
    the pencil ``(K_a - K_b, K_a)`` densely; larger ones bisect ``alpha`` on the inertia of
    the sparse LDL^T factor of ``K(alpha)`` (Sylvester's law) to ``rtol`` of the bracket.

    Raises
    ------
    BucklingError
        If ``K_b`` has no more negative eigenvalues than ``K_a`` (no loss of stability
        between them), or the factorisation reports no inertia.
    """
    n = model.n_nodes
    free = np.flatnonzero(~np.asarray(fixed, bool).ravel())
    Ka = sp.csr_matrix(model.tangent(np.asarray(X_a, float).reshape(n, 3))[free][:, free])
    Kb = sp.csr_matrix(model.tangent(np.asarray(X_b, float).reshape(n, 3))[free][:, free])
    none = BucklingError(
        "critical_between: no loss of stability between the two states (the second state's "
        "tangent has no more negative eigenvalues than the first's)"
    )
    if len(free) <= DENSE_PENCIL:
        import scipy.linalg

        try:  # K(alpha) singular <=> (K_a - K_b) phi = (1 / alpha) K_a phi
            theta = scipy.linalg.eigh((Ka - Kb).toarray(), Ka.toarray(), eigvals_only=True)[-1]
        except np.linalg.LinAlgError as exc:
            raise BucklingError(
                "critical_between: the tangent at the first state is not positive definite"
            ) from exc
        if not theta > 1.0 - 1e-9:
            raise none
        return float(lam_a + min(1.0, 1.0 / float(theta)) * (lam_b - lam_a))
    D = (Kb - Ka).tocsr()
    backend = get_backend("auto")

    def negative(alpha: float) -> int:
        try:
            count = backend.factorize((Ka + alpha * D).tocsr()).negative_pivots()
        except SingularMatrixError:  # singular at alpha: count it as lost, from above
            return n_a + 1
        if count is None:
            raise BucklingError("critical_between: the factorisation reports no inertia")
        return int(count)

    n_a = 0  # read by negative() when K(0) itself is singular
    n_a = negative(0.0)
    if negative(1.0) <= n_a:
        raise none
    lo, hi = 0.0, 1.0
    while hi - lo > rtol:
        mid = 0.5 * (lo + hi)
        if negative(mid) > n_a:
            hi = mid
        else:
            lo = mid
    return float(lam_a + 0.5 * (lo + hi) * (lam_b - lam_a))


@dataclasses.dataclass(frozen=True)
class CriticalAhead:
    """A loss of stability just ahead of a path's last state (:func:`critical_ahead`).

    Attributes
    ----------
    estimate : float
        Load factor where the squared lowest eigenvalue, extrapolated linearly in the load
        factor, reaches zero: exact at a limit point (``mu ~ sqrt(lam_c - lam)``), slightly
        early at a bifurcation (``mu ~ lam_c - lam``).
    linear : float
        Where the lowest eigenvalue itself, extrapolated linearly, reaches zero: exact at a
        bifurcation, late at a limit point. ``[estimate, linear]`` brackets the critical
        load factor in both cases.
    load_factors, lowest : (k,) float
        The last states' load factors and the lowest eigenvalues of their free tangents
        (force / length).
    """

    estimate: float
    linear: float
    load_factors: np.ndarray
    lowest: np.ndarray


@threads_for_sparse
def critical_ahead(
    model: Any, fixed: np.ndarray, X: np.ndarray, lam: np.ndarray, states: int = 3
) -> CriticalAhead:
    """The critical point a path runs into past its last state, from the lowest eigenvalue
    of the free tangent at its last ``states`` states (shift-invert Lanczos at 0).

    For a path whose increments fail at a critical point: every state recorded is stable,
    none lies past it, and :func:`critical_between` has no bracket. The lowest eigenvalues
    must be positive and fall monotonically over those states, and the extrapolated zero must
    lie within the larger of the last two load-factor increments ahead of the last state.

    Parameters
    ----------
    model : the bar-and-hinge model; fixed : (n_nodes, 3) bool, the supports
    X : (n_states, n_nodes, 3) float, the path's states; lam : (n_states,) their load factors

    Raises
    ------
    BucklingError
        If there are fewer than ``states`` states (at least 2), a tangent is not positive
        definite, the eigenvalues do not fall, or their zero lies farther ahead.
    """
    import scipy.linalg
    import scipy.sparse.linalg as sla

    lam = np.asarray(lam, float)
    k = min(int(states), len(lam))
    if k < 2:
        raise BucklingError("critical_ahead: needs at least two states of the path")
    n = model.n_nodes
    free = np.flatnonzero(~np.asarray(fixed, bool).ravel())
    lowest = []
    for Xs in np.asarray(X, float)[-k:]:
        K = sp.csc_matrix(model.tangent(Xs.reshape(n, 3))[free][:, free])
        if len(free) <= DENSE_PENCIL:
            mu = scipy.linalg.eigvalsh(K.toarray(), subset_by_index=[0, 0])
        else:  # the eigenvalue nearest 0: the lowest while the tangent is positive definite
            mu = sla.eigsh(K, k=1, sigma=0.0, which="LM", return_eigenvectors=False)
        lowest.append(float(mu[0]))
    mu = np.asarray(lowest)
    lam_k = lam[-k:]
    if not (np.all(mu > 0.0) and np.all(np.diff(mu) < 0.0)):
        raise BucklingError(
            "critical_ahead: the lowest tangent eigenvalues of the last states "
            f"({', '.join(f'{v:.4g}' for v in mu)}) are not positive and falling"
        )
    dlam = lam_k[-1] - lam_k[-2]
    if dlam == 0.0:
        raise BucklingError("critical_ahead: the last two states have the same load factor")
    linear = float(lam_k[-1] + mu[-1] * dlam / (mu[-2] - mu[-1]))
    estimate = float(lam_k[-1] + mu[-1] ** 2 * dlam / (mu[-2] ** 2 - mu[-1] ** 2))
    reach = float(np.max(np.abs(np.diff(lam[-3:]))))
    if abs(linear - lam_k[-1]) > reach:
        raise BucklingError(
            f"critical_ahead: the lowest tangent eigenvalue ({mu[-1]:.4g} at load factor "
            f"{lam_k[-1]:.6g}) reaches zero at {linear:.6g}, farther ahead than the last "
            f"increments ({reach:.3g})"
        )
    return CriticalAhead(estimate, linear, lam_k.copy(), mu)


def _hinge_dofs(model: Any) -> np.ndarray:
    H = model.hinges
    return (3 * H[:, :, None] + np.arange(3)).reshape(len(H), 12)


def _rho_grad(model: Any, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return hinge_angle_gradient(X, model.hinges)
