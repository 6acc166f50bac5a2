"""Stiffness of a state: tangent, effective stiffness under a load case, and soft modes.

All matrices are the model's tangent ``K = d^2E/dX^2`` (n_dof x n_dof, xyz interleaved per
node) at a state X; supports are a boolean ``fixed`` array (n_nodes, 3) removing DOFs.

* :func:`effective_stiffness`: one linear solve ``K_ff u_f = f_f`` at the state; the load's
  resultant magnitude divided by a characteristic deflection (along the resultant's direction:
  the largest nodal one, or the mean over chosen nodes), with the deflected shape.
* :func:`stiffness_modes`: the lowest eigenpairs of ``K_ff`` by shift-invert Lanczos
  (``scipy.sparse.linalg.eigsh``, shift slightly below zero so rigid-body or mechanism modes do
  not make the shifted matrix singular). A mode is **soft** when it (almost) does not stretch
  the bars: the linearised bar energy ``sum EA/L0 (e . dv)^2`` (``e`` the unit bar direction,
  ``dv`` the relative mode velocity of its ends) is below ``soft_tol`` of the mode's energy
  ``v^T K v`` - rigid-body motions and the infinitesimal mechanisms of the bar framework, which
  only the folds and panel-bending hinges resist.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.errors import ConfigError
from barhinge.linalg.backends import (
    SingularMatrixError,
    factorize_symmetric,
    get_backend,
    refined_solve,
)
from barhinge.linalg.heap import release_free_heap
from barhinge.linalg.symmetric import UpperSymmetric
from barhinge.linalg.threads import sparse_solves

__all__ = [
    "EffectiveStiffness",
    "Modes",
    "effective_stiffness",
    "free_dofs",
    "linear_response",
    "make_room_for_factor",
    "stiffness_modes",
    "tangent_stiffness",
]


def tangent_stiffness(model: Any, X: np.ndarray | None = None) -> sp.csr_matrix:
    """(n_dof, n_dof) CSR tangent stiffness of ``model`` at ``X`` (default ``model.X0``)."""
    X = model.X0 if X is None else np.asarray(X, float)
    return sp.csr_matrix(model.tangent(X))


#: a model whose assembler holds more than this (bytes) drops it before a linear analysis
#: factorises (:func:`make_room_for_factor`): a refined roof of 591 747 DOFs held 0.3 GB of
#: maps (0.9 GB of resident memory with what the heap kept), against 2.9 GB for its factor
RELEASE_ASSEMBLER_ABOVE = 2**28


def make_room_for_factor(model: Any) -> None:
    """Free what a linear analysis no longer needs before it factorises: the model's
    assembler when it holds more than :data:`RELEASE_ASSEMBLER_ABOVE` bytes (rebuilt by the
    next evaluation, 5.5 s at 591 747 DOFs) and the heap's free pages
    (:func:`barhinge.linalg.heap.release_free_heap`)."""
    asm = getattr(model, "__dict__", {}).get("assembler")
    if asm is not None and asm.nbytes > RELEASE_ASSEMBLER_ABOVE:
        model.release_assembler()
    release_free_heap()


def free_dofs(fixed: np.ndarray | None, n_nodes: int) -> np.ndarray:
    """(n_free,) int: DOF ids (3 node + axis) not fixed by ``fixed`` (n_nodes, 3) bool."""
    if fixed is None:
        return np.arange(3 * n_nodes)
    F = np.asarray(fixed, bool)
    if F.shape != (n_nodes, 3):
        raise ConfigError(f"fixed must have shape ({n_nodes}, 3), got {F.shape}")
    return np.flatnonzero(~F.ravel())


@dataclasses.dataclass(frozen=True)
class EffectiveStiffness:
    """Linear response of a state to a load case.

    Attributes
    ----------
    stiffness : float
        ``|resultant load| / deflection`` (force / length).
    deflection : float
        Characteristic deflection along ``direction`` (length).
    direction : (3,) float
        Unit direction of the load resultant.
    U : (n_nodes, 3) float
        Deflected shape (linear displacements; zero at fixed DOFs).
    reactions : (n_nodes, 3) float
        Support reactions ``K u - f`` at fixed DOFs (zero elsewhere); they balance the load.
    compliance : float
        ``f . u`` (twice the linear strain energy).
    """

    stiffness: float
    deflection: float
    direction: np.ndarray
    U: np.ndarray
    reactions: np.ndarray
    compliance: float


def linear_response(
    model: Any,
    loads: np.ndarray,
    fixed: np.ndarray,
    X: np.ndarray | None = None,
    *,
    K: sp.spmatrix | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Linear displacements and reactions of a supported state: ``K_ff u_f = f_f``.

    Parameters
    ----------
    loads : (n_nodes, 3) float
    fixed : (n_nodes, 3) bool
    X : (n_nodes, 3) float, optional (default ``model.X0``)

    Returns
    -------
    U : (n_nodes, 3) float
        Displacements (zero at fixed DOFs).
    R : (n_nodes, 3) float
        Reactions ``K u - f`` at fixed DOFs (zero elsewhere).

    Raises
    ------
    ConfigError
        If the supports leave a mechanism (singular constrained tangent) or the tangent is
        too ill-conditioned to solve (relative residual above 1e-4 after iterative
        refinement with residuals in extended precision, :func:`refined_solve`).
    """
    n = model.n_nodes
    f = np.asarray(loads, float)
    if f.shape != (n, 3):
        raise ConfigError(f"loads must have shape ({n}, 3), got {f.shape}")
    free = free_dofs(fixed, n)
    K = tangent_stiffness(model, X) if K is None else sp.csr_matrix(K)
    held = np.setdiff1d(np.arange(3 * n), free)
    K_held = K[held]  # the reactions' rows: the rest of K is not kept beside the factor
    # the supported stiffness as its upper triangle: the array PARDISO reads, and all the
    # refinement's residuals need (the full matrix beside it: 1.9 GB at 2.4 M DOFs)
    Kff = UpperSymmetric.from_full(K[free][:, free])
    del K
    make_room_for_factor(model)
    try:
        # the solver's symmetric factorisation (PARDISO where installed, else SuperLU in
        # symmetric mode): a general LU of this symmetric matrix fills in several times more
        ff = f.ravel()[free]
        with sparse_solves():
            lu = factorize_symmetric(get_backend("auto"), Kff)
            uf, rel = refined_solve(lu, Kff, ff)  # rel: |ff - Kff uf| / |ff|, extended
    except SingularMatrixError as exc:  # exactly singular
        raise ConfigError(
            "the supports leave a mechanism: the constrained tangent is singular "
            f"({len(free)} free DOFs)"
        ) from exc
    if not np.all(np.isfinite(uf)) or not rel <= 1e-4:
        raise ConfigError(
            "the constrained tangent is (nearly) singular: the supports leave a mechanism, "
            "or the mesh is too fine to solve in double precision (relative residual "
            f"{rel:.1e} after iterative refinement)"
        )
    u = np.zeros(3 * n)
    u[free] = uf
    R = np.zeros(3 * n)
    R[held] = K_held @ u - f.ravel()[held]
    return u.reshape(n, 3), R.reshape(n, 3)


def effective_stiffness(
    model: Any,
    loads: np.ndarray,
    fixed: np.ndarray,
    X: np.ndarray | None = None,
    *,
    at: np.ndarray | None = None,
    K: sp.spmatrix | None = None,
) -> EffectiveStiffness:
    """Effective stiffness of a supported state under a load case (linear, at state X).

    Parameters
    ----------
    model : BarHingeModel
    loads : (n_nodes, 3) float
        Nodal loads (e.g. :func:`barhinge.scene.self_weight`, a distributed or a point load).
    fixed : (n_nodes, 3) bool
        Supported DOFs.
    X : (n_nodes, 3) float, optional
        State (default ``model.X0``).
    at : (m,) int, optional
        Nodes whose mean displacement along the load direction is the deflection (e.g. the
        mid-span nodes). Default: the largest nodal displacement along it.
    K : sparse (n_dof, n_dof), optional
        Tangent to use (default: assembled at X).
    """
    U, R = linear_response(model, loads, fixed, X, K=K)
    f = np.asarray(loads, float)
    u = U.ravel()
    total = f.sum(0)
    mag = float(np.linalg.norm(total))
    if mag == 0:
        raise ConfigError("the load case has a zero resultant; give a load with a direction")
    d = total / mag
    proj = U @ d
    if at is None:
        defl = float(proj[np.argmax(np.abs(proj))])
    else:
        defl = float(proj[np.asarray(at, np.int64)].mean())
    return EffectiveStiffness(
        stiffness=mag / defl if defl != 0 else float("inf"),
        deflection=defl,
        direction=d,
        U=U,
        reactions=R,
        compliance=float(f.ravel() @ u),
    )


@dataclasses.dataclass(frozen=True)
class Modes:
    """Lowest eigenpairs of the constrained tangent.

    Attributes
    ----------
    eigenvalues : (k,) float
        Ascending (force / length for translational DOFs).
    shapes : (k, n_nodes, 3) float
        Mode shapes (unit 2-norm; zero at fixed DOFs).
    bar_fraction : (k,) float
        Share of each mode's energy stored in bar stretching (0 for a mechanism).
    n_soft : int
        Modes with ``bar_fraction < soft_tol`` or a (near-)zero eigenvalue: rigid-body motions
        and mechanisms. If ``n_soft == k``, ask for more modes: there may be more.
    n_dof, n_free : int
        DOFs of the model and DOFs left free by the supports.
    """

    eigenvalues: np.ndarray
    shapes: np.ndarray
    bar_fraction: np.ndarray
    n_soft: int
    n_dof: int
    n_free: int


def _lowest_eigenpairs(Kff: sp.csc_matrix, k: int, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` eigenpairs of the symmetric ``Kff`` nearest ``sigma`` (shift-invert Lanczos,
    ``scipy.sparse.linalg.eigsh``), with ``Kff - sigma I`` factorised by the solver's own
    backend (PARDISO where installed, else SuperLU, as in the Newton solve); ``sigma`` just
    below zero keeps rigid-body and mechanism modes from making it singular. eigsh's own
    shift-invert factorises with SuperLU: 2.0 s of factorisation and 2.9 s of solves on the
    tangent of a folded 40 x 40 Miura sheet."""
    shifted = UpperSymmetric.from_full(
        (Kff - sigma * sp.identity(Kff.shape[0], format="csc")).tocsr()
    )
    with sparse_solves():
        lu = factorize_symmetric(get_backend("auto"), shifted)
        inverse = spla.LinearOperator(Kff.shape, matvec=lu.solve, dtype=float)
        return spla.eigsh(Kff, k=k, sigma=sigma, which="LM", OPinv=inverse)


def stiffness_modes(
    model: Any,
    X: np.ndarray | None = None,
    *,
    fixed: np.ndarray | None = None,
    k: int = 10,
    soft_tol: float = 1e-2,
    K: sp.spmatrix | None = None,
) -> Modes:
    """The ``k`` lowest eigenvalues and modes of the (constrained) tangent at X.

    Parameters
    ----------
    fixed : (n_nodes, 3) bool, optional
        Supported DOFs (None: unsupported; then the six rigid-body modes are among the soft).
    k : int
        Number of eigenpairs (at most n_free - 1; the dense solver is used for small models).
    soft_tol : float
        Bar-energy share below which a mode is soft.
    """
    n = model.n_nodes
    free = free_dofs(fixed, n)
    K = tangent_stiffness(model, X) if K is None else sp.csr_matrix(K)
    Kff = K[free][:, free]
    Kff = (0.5 * (Kff + Kff.T)).tocsc()
    nf = len(free)
    if not 1 <= k < nf:
        raise ConfigError(f"k = {k}; expected 1 <= k < {nf} (the number of free DOFs)")
    scale = float(np.abs(Kff.diagonal()).mean()) or 1.0
    if nf <= 600:
        w, V = np.linalg.eigh(Kff.toarray())
        w, V = w[:k], V[:, :k]
    else:
        w, V = _lowest_eigenpairs(Kff, k, sigma=-1e-6 * scale)
        order = np.argsort(w)
        w, V = w[order], V[:, order]
    shapes = np.zeros((k, 3 * n))
    shapes[:, free] = V.T
    shapes = shapes.reshape(k, n, 3)
    Xs = model.X0 if X is None else np.asarray(X, float)
    B = np.asarray(model.bars, np.int64)
    e = Xs[B[:, 1]] - Xs[B[:, 0]]
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    rate = np.einsum("bx,mbx->mb", e, shapes[:, B[:, 1]] - shapes[:, B[:, 0]])
    L0 = np.asarray(model.bar_L0)
    bar_energy = (np.asarray(model.bar_EA) / L0 * rate**2).sum(1)
    if len(getattr(model, "bar_pairs", ())):  # the CST membrane's couplings: eps^T C_off eps
        strain_rate = rate / L0
        bar_energy += np.einsum("mb,mb->m", strain_rate, (model._bar_C @ strain_rate.T).T)
    total = np.einsum("mi,im->m", shapes.reshape(k, -1), K @ shapes.reshape(k, -1).T)
    zero = np.abs(w) <= 1e-10 * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(zero, 0.0, bar_energy / np.abs(total))
    return Modes(
        eigenvalues=w,
        shapes=shapes,
        bar_fraction=frac,
        n_soft=int((frac < soft_tol).sum()),
        n_dof=3 * n,
        n_free=nf,
    )
