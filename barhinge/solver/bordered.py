"""Building blocks of the controls: actuator constraints, the bordered Newton system and the
MGDCM arc-length rules.

Actuator (fold-angle) control
-----------------------------
Actuator ``a`` is the fold hinge of a crease; its constraint is
``c_a(X) = rho_a(X) - rho_a,target(t) = 0``. With Lagrange multipliers ``mu`` the
equilibrium equations on the free DOFs are

    r(X, mu) = f_int(X) - lambda P + G^T mu = 0,      G = d rho_a / d X   (n_act, n_dof)

and Newton's step solves the bordered (saddle-point) system

    [ K_t   G^T ] [dx ]     [ r ]
    [ G     0   ] [dmu] = - [ c ],     K_t = K + sum_a mu_a d^2 rho_a / dX^2 .

The multiplier is minus the actuator moment: an actuator exerting the moment ``m_a``
(positive when it drives the crease towards valley, i.e. increasing rho) adds the nodal
forces ``m_a grad rho_a``; so ``m_a = -mu_a``. For one linear fold spring,
``m = k L (rho - rho_rest)``.

K alone may be singular (a crease pattern is a mechanism when its folds are free, and only
the constraint rows remove that mechanism). The system is therefore factorised in the
augmented-Lagrangian form ``A = K_t + p G^T G`` with the right-hand side
``-(r + p G^T c)``: adding ``p G^T`` times the second block row to the first gives an
*equivalent* system, so the solution is exactly the one of the bordered system, and ``A`` is
nonsingular whenever the bordered system is (for a large enough ``p`` on the constrained
directions). Backends that factorise symmetric indefinite matrices (PARDISO) factorise the
whole bordered matrix ``[A G^T; G 0]`` once; the others factorise ``A`` and form the small
dense Schur complement ``S = G A^-1 G^T`` (n_act x n_act). Optionally a factorisation is
reused as the preconditioner of GMRES on later tangents (:class:`BorderedSystem`).
"""

from __future__ import annotations

import dataclasses
import logging
import time
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge._protocols import SolverModel
from barhinge.kernels.geometry import hinge_angle_gradient_t
from barhinge.linalg.backends import LinearBackend, SingularMatrixError
from barhinge.linalg.indices import gather_into, index_dtype, pattern_positions
from barhinge.linalg.inertia import InertiaCounter

__all__ = ["ActuatorTerms", "BorderedSystem", "Timer", "actuator_terms", "hinge_derivatives"]

log = logging.getLogger("barhinge.solver.bordered")


@dataclasses.dataclass
class Timer:
    """Seconds spent in each phase of the solve (for benchmarks)."""

    assembly: float = 0.0
    factorize: float = 0.0
    solve: float = 0.0
    other: float = 0.0
    n_factorizations: int = 0
    n_iterations: int = 0
    n_krylov: int = 0
    n_force_only: int = 0  # evaluations without the tangent (convergence expected)
    n_accelerated: int = 0  # Newton corrections taken with their geodesic acceleration
    n_chord: int = 0  # chord corrections kept (solved with the increment's factorisation)
    n_chord_rejected: int = 0  # chord corrections tried and discarded for a Newton one
    n_tangent: int = 0  # evaluations with the tangent (force and tangent assembled)
    assembly_tangent: float = 0.0  # their seconds (part of ``assembly``)
    n_solves: int = 0  # back-substitutions with a factorisation (GMRES solves: n_krylov)

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


def hinge_derivatives(model: SolverModel, X: np.ndarray, hinge_ids: np.ndarray):
    """(rho, grad, hess) of the given hinges: (na,), (na, 12), (na, 12, 12)."""
    if hasattr(model, "hinge_angle_derivatives"):
        return model.hinge_angle_derivatives(X, hinge_ids)
    from barhinge.kernels.geometry import hinge_angle_derivatives

    return hinge_angle_derivatives(X, np.asarray(model.hinges)[hinge_ids])


@dataclasses.dataclass
class ActuatorTerms:
    """Actuator constraint quantities at one state.

    rho : (n_act,) current angles; G : (n_act, n_dof) csr; grad/hess : per-hinge blocks
    (``hess`` None where only the residual was asked for: ``actuator_terms(...,
    hessians=False)``); dofs : (n_act, 12) global DOF index of each block column.
    """

    rho: np.ndarray
    G: sp.csr_matrix
    grad: np.ndarray
    hess: np.ndarray | None
    dofs: np.ndarray


def actuator_terms(
    model: SolverModel, X: np.ndarray, hinge_ids: np.ndarray, hessians: bool = True
) -> ActuatorTerms:
    """Angles, constraint Jacobian and (``hessians``) Hessians of the actuator hinges at
    ``X``. A residual needs no Hessian: without them the angles and gradients come from
    the gradient kernel alone (the 12 actuators of the default scene: 0.25 ms against
    0.8 ms with the Hessians)."""
    n_dof = 3 * len(X)
    na = len(hinge_ids)
    if na == 0:
        z = np.zeros(0)
        return ActuatorTerms(
            z,
            sp.csr_matrix((0, n_dof)),
            z.reshape(0, 12),
            z.reshape(0, 12, 12),
            np.zeros((0, 12), np.int64),
        )
    nodes = np.asarray(model.hinges)[hinge_ids]  # (na, 4)
    hess: np.ndarray | None = None
    if hessians or hasattr(model, "hinge_angle_derivatives"):  # a model's own derivatives
        rho, grad, hess = hinge_derivatives(model, X, hinge_ids)
    else:
        rho, grad_t = hinge_angle_gradient_t(np.asarray(X, float), nodes)
        grad = np.ascontiguousarray(grad_t.T)
    dofs = (3 * nodes[:, :, None] + np.arange(3)[None, None, :]).reshape(na, 12)
    rows = np.repeat(np.arange(na), 12)
    G = sp.csr_matrix((grad.ravel(), (rows, dofs.ravel())), shape=(na, n_dof))
    return ActuatorTerms(rho, G, grad, hess, dofs)


class _KrylovStalled(Exception):
    """GMRES used up its iterations (raised from its callback)."""


@dataclasses.dataclass
class _DirectSolver:
    """One factorisation of ``A = K_t + p G^T G`` and its Schur complement: solves the
    bordered system of the state where it was factorised exactly."""

    factor: Any
    Gf: sp.csr_matrix | None  # (n_act, n_free) or None without actuators
    Z: np.ndarray | None  # A^-1 G^T (None with a Cholesky half solve)
    S_inv: np.ndarray | None  # (G A^-1 G^T)^-1
    penalty: float

    def solve(self, rhs_x: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.Gf is None:
            dx = np.asarray(self.factor.solve(rhs_x))
            return dx, np.zeros((0,) + np.shape(rhs_x)[1:])
        # augmented first block row: rhs_x + p G^T rhs_c (compensates the p G^T G in A)
        bx = rhs_x + self.penalty * (self.Gf.T @ rhs_c)
        a0 = np.asarray(self.factor.solve(bx))
        dmu = self.S_inv @ (self.Gf @ a0 - rhs_c)
        if self.Z is not None:
            dx = a0 - self.Z @ dmu
        else:
            dx = a0 - np.asarray(self.factor.solve(self.Gf.T @ dmu))
        return dx, dmu


#: from this many actuators on, the inertia of the released tangent (Haynsworth's formula:
#: one solve per actuator with the bordered factor) is read from a factorisation of the
#: released tangent itself instead: a 40 x 40 Miura fold with 80 actuators spent 0.33 s per
#: state on the solves against 0.18 s per factorisation, and the solves grow with the
#: number of actuators
RELEASED_FACTOR_MIN_ACT = 8

#: backends with a Schur complement (PARDISO) factorise the bordered matrix unaugmented with
#: the multipliers last and read the released tangent's inertia from it (no factorisation
#: of its own, :class:`BorderedSystem`); False: the routes above
SCHUR_COUNTS = True


@dataclasses.dataclass
class _KKTSolver:
    """A factorisation of the augmented bordered matrix ``[A G^T; G 0]`` itself."""

    factor: Any
    Gf: sp.csr_matrix
    penalty: float

    def solve(self, rhs_x: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        bx = rhs_x + self.penalty * (self.Gf.T @ rhs_c)
        z = np.asarray(self.factor.solve(np.concatenate([bx, rhs_c])))
        nf = len(rhs_x)
        return z[:nf], z[nf:]


class BorderedSystem:
    """Factorise and solve the (bordered) Newton system on the free DOFs.

    Two modes:

    * direct (``reuse=False``): every :meth:`set_operator` factorises; :meth:`solve` is
      exact.
    * factorisation reuse (``reuse=True``): :meth:`set_operator` only assembles the new
      tangent; :meth:`solve` runs preconditioned GMRES (scipy) on the exact bordered system
      of the new tangent, preconditioned by the last factorisation (an exact solve of a
      nearby state's system). A new factorisation is made when GMRES does not reach its
      tolerance within ``krylov_max`` iterations (then the solve is direct), or when the
      GMRES time accumulated since the last factorisation exceeds that factorisation's
      cost (then at the next :meth:`set_operator`). Newton keeps its quadratic rate when
      the linear tolerance follows the residual (inexact Newton, Dembo, Eisenstat &
      Steihaug 1982); the driver passes that tolerance.

    Parameters
    ----------
    backend : LinearBackend
    free : (n_dof,) bool mask of the free DOFs.
    act_dofs : (n_act, 12) global DOFs of the actuator blocks (fixed for the whole solve).
    timer : Timer
    reuse : bool
        Factorisation reuse with GMRES (see above).
    krylov_max : int
        GMRES iterations before a fresh factorisation is made.
    """

    def __init__(
        self,
        backend: LinearBackend,
        free: np.ndarray,
        act_dofs: np.ndarray,
        timer: Timer,
        reuse: bool = False,
        krylov_max: int = 30,
    ) -> None:
        self.backend = backend
        self.free = np.asarray(free, bool)
        self.free_idx = np.flatnonzero(self.free)
        self.n_dof = len(self.free)
        self.act_dofs = act_dofs
        self.timer = timer
        self.reuse = reuse
        self.krylov_max = krylov_max
        self.row_scale = 1.0  # scale of the constraint rows in the GMRES norm (force/rad)
        self._key: tuple | None = None
        self._pattern_arrays: tuple = (None, None)
        self._sel: np.ndarray | None = None
        self._sub_indptr: np.ndarray | None = None
        self._sub_indices: np.ndarray | None = None
        self._blk_pos: np.ndarray | None = None  # positions of actuator blocks in K.data
        self._blk_ok = False
        self.factor: Any = None
        #: load and displacement control: an increment whose held counts change fails
        self.track_inertia = False
        #: negative eigenvalues of the last factorised tangent with the actuators held
        #: (:meth:`held_negative_eigenvalues`), and of every factorisation since the driver
        #: last emptied the list
        self.negative_pivots: int | None = None
        self.inertia_seen: list[int | None] = []
        # current operator (exact tangent of the current iterate)
        # the current operator's values: K's (no copy) and the actuator blocks added to them
        # where they are needed (the saddle-point path adds them after its gather)
        self._values: np.ndarray | None = None
        self._blocks: np.ndarray = np.zeros((0, 12, 12))
        self._full: np.ndarray | None = None  # K's values + the blocks (built on first use)
        self._kkt_blk: tuple[np.ndarray, np.ndarray] | None = None  # blocks -> KKT values
        self._A: sp.csr_matrix | None = None
        self.Gf: sp.csr_matrix | None = None
        self.penalty = 0.0
        self.direct: _DirectSolver | _KKTSolver | None = None  # last factorisation
        self.current_factored = False  # the last factorisation is of the current operator
        self._fact_cost = 0.0  # seconds of the last factorisation (incl. Schur complement)
        self._krylov_cost = 0.0  # GMRES seconds since the last factorisation
        self.last_krylov_iters = 0
        self._kkt_key: tuple | None = None
        self._kkt_gather: np.ndarray | None = None
        self._kkt_g: tuple[np.ndarray, np.ndarray] | None = None
        self._kkt_pattern: tuple | None = None
        self._kkt_data: np.ndarray | None = None  # the bordered matrix's values (reused)
        # (values of the factorised bordered operator's A, its penalty blocks) for the
        # released tangent's inertia; a backend of its own keeps that factor apart
        self._penalty_blocks: np.ndarray | None = None
        self._released: tuple[np.ndarray, np.ndarray] | None = None
        self._released_counter: InertiaCounter | None = None
        #: factorise the bordered matrix ``[K_t G^T; G 0]`` (no augmentation) with the
        #: multipliers last and the Schur complement ``-G K_t^-1 G^T`` beside the factor
        #: (backends with ``schur_complement``): the released tangent's inertia then comes
        #: with every factorisation (Haynsworth), not from one of its own. Off for the rest
        #: of the solve once K_t itself is singular (perturbed pivots), where the augmented
        #: matrix ``K_t + p G^T G`` is factorised instead.
        self._schur_counts = SCHUR_COUNTS and bool(getattr(backend, "schur_complement", False))
        self._augmentation: tuple[float, np.ndarray] | None = None  # (p, grad) asked
        #: release a bordered factor larger than ``InertiaCounter.RELEASE_ABOVE`` before the
        #: released tangent is factorised (the two are then never held together): for
        #: callers whose next solve follows a new factorisation (the increments of parameter
        #: control), not for arc length, whose next increment solves with this factor
        self.release_before_count = False

    # ---------------------------------------------------------------- structure
    def _prepare(self, K: sp.csr_matrix) -> None:
        """Scatter maps from K's CSR pattern to the free-free submatrix, built once."""
        K.sort_indices()
        if K.indices is self._pattern_arrays[0] and K.indptr is self._pattern_arrays[1]:
            return  # the assembler's own pattern arrays again (held here: ids stay unique)
        key = (K.shape, K.nnz, hash(K.indptr.tobytes()), hash(K.indices[::97].tobytes()))
        self._pattern_arrays = (K.indices, K.indptr)
        if key == self._key:
            return
        self._key = key
        self._sel = self._sub_indptr = self._sub_indices = None  # built on first use
        # positions of the actuator 12x12 blocks inside K.data (if K's pattern holds them)
        if len(self.act_dofs):
            pos = pattern_positions(K.indptr, K.indices, *_block_entries(self.act_dofs))
            self._blk_ok = bool(np.all(pos >= 0))
            self._blk_pos = pos
        else:
            self._blk_ok = True
            self._blk_pos = np.zeros(0, np.int64)

    def _submatrix_maps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(positions in K's values of the free-free entries, sorted; the free submatrix's
        ``indptr``; its ``indices``) for the pattern of the last :meth:`_prepare`, built on
        first use: the bordered factorisation needs them once (for its pattern), the free
        submatrix ``A`` and the released tangent's own factorisation at every use."""
        if self._sel is None or self._sub_indptr is None or self._sub_indices is None:
            indices, indptr = self._pattern_arrays
            n = self.n_dof
            rows = np.repeat(np.arange(n), np.diff(indptr))
            newidx = np.full(n, -1, np.int64)
            newidx[self.free_idx] = np.arange(len(self.free_idx))
            keep = self.free[rows] & self.free[indices]
            self._sel = np.flatnonzero(keep).astype(index_dtype(len(indices)))
            r, c = newidx[rows[keep]], newidx[indices[keep]]
            del rows, keep
            nf = len(self.free_idx)
            self._sub_indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=nf))])
            self._sub_indices = c.astype(np.int32)
        return self._sel, self._sub_indptr, self._sub_indices

    def _set_values(self, K: sp.csr_matrix, blocks: np.ndarray) -> None:
        """Make K's values (its CSR pattern; not copied) and the actuator blocks
        ``(n_act, 12, 12)`` the current operator's."""
        self._prepare(K)
        self._full = None
        if len(blocks) and not self._blk_ok:
            # the model's pattern does not hold the blocks: add them as a sparse matrix
            B = sp.csr_matrix((blocks.ravel(), _block_entries(self.act_dofs)), shape=K.shape)
            K = (K + B).tocsr()
            self._key = None
            self._prepare(K)
            blocks = np.zeros((0, 12, 12))
        self._values, self._blocks = K.data, blocks

    def _full_values(self) -> np.ndarray:
        """K's values plus the actuator blocks (a copy of K's values when there are
        blocks, made on first use)."""
        assert self._values is not None  # an operator was set
        if self._full is None:
            if len(self._blocks):
                assert self._blk_pos is not None  # set by _prepare
                self._full = self._values.copy()
                np.add.at(self._full, self._blk_pos, self._blocks.ravel())
            else:
                self._full = self._values
        return self._full

    @property
    def A(self) -> sp.csr_matrix | None:
        """The current free-DOF operator ``K_ff + sum mu_a H_a + p G^T G`` (built on first
        use: the saddle-point path gathers its matrix straight from K's values)."""
        if self._A is None and self._values is not None:
            nf = len(self.free_idx)
            sel, indptr, indices = self._submatrix_maps()
            self._A = sp.csr_matrix((self._full_values()[sel], indices, indptr), shape=(nf, nf))
        return self._A

    # ---------------------------------------------------------------- operator
    def set_operator(
        self,
        K: sp.csr_matrix,
        terms: ActuatorTerms,
        mu: np.ndarray,
        penalty: float,
        factorize: bool = False,
        springs: tuple[np.ndarray, np.ndarray] | None = None,
        release_values: bool = False,
    ) -> None:
        """Make ``A = K_ff + sum mu_a H_a + p G^T G`` (and G) the current operator.

        ``springs = (m, k)``: the actuators are compliant (no constraint rows); their
        springs add ``m_a H_a + k_a g_a g_a^T`` (``m = k (rho - target)``) instead.
        Factorises it in direct mode, when ``factorize`` is set, when there is no
        factorisation yet, or when the reuse policy asks for a fresh one. Raises
        SingularMatrixError when a factorisation finds A or the Schur complement singular.

        ``release_values``: after a factorisation in direct mode, forget K's values where
        nothing but the factor reads them until the next operator (:attr:`holds_values`
        says whether they were kept); a caller that drops its own reference to K then
        returns K's memory before it assembles the next tangent.
        """
        na = len(mu)
        g = terms.grad
        if terms.hess is None and len(g):
            raise ValueError("the actuator terms of an operator need their Hessians")
        if springs is not None:
            m, k = springs
            na = 0
            blocks = (
                m[:, None, None] * terms.hess + k[:, None, None] * g[:, :, None] * g[:, None, :]
            )
        elif na:
            self._augmentation = (penalty, g)
            if self._schur_counts:
                penalty = 0.0  # the Schur complement of K_t itself gives its inertia
            self._penalty_blocks = penalty * g[:, :, None] * g[:, None, :]
            blocks = mu[:, None, None] * terms.hess + self._penalty_blocks
        else:
            blocks = np.zeros((0, 12, 12))
        self._set_values(K, blocks)
        self._A = None
        self.Gf = terms.G[:, self.free_idx].tocsr() if na else None
        self.penalty = penalty
        self.current_factored = False
        stale = self._krylov_cost > self._fact_cost
        if factorize or not self.reuse or self.direct is None or stale:
            self._factorize_current()
            if release_values and not self.reuse:
                self._forget_values()

    @property
    def holds_values(self) -> bool:
        """Whether the current operator's values (K's, and what is built from them) are
        kept after its factorisation (see ``release_values`` of :meth:`set_operator`)."""
        return self._values is not None

    def _forget_values(self) -> None:
        """Drop the current operator's values (K's, the free submatrix ``A`` and the
        released tangent's) where the factor alone gives every later solve and count: the
        bordered factor with its Schur complement, or the factor of ``A`` with the Schur
        complement of the actuators. Not where the released tangent's count factorises K
        itself (the augmented bordered route), which reads them."""
        if self.direct is None or (isinstance(self.direct, _KKTSolver) and not self._schur_counts):
            return
        self._values = self._full = self._A = None
        self._released = None

    def factorize(
        self, K: sp.csr_matrix, terms: ActuatorTerms, mu: np.ndarray, penalty: float
    ) -> None:
        """Set the operator and factorise it (see :meth:`set_operator`)."""
        self.set_operator(K, terms, mu, penalty, factorize=True)

    def _kkt_matrix(self, upper: bool = False) -> sp.csr_matrix:
        """The augmented bordered matrix ``[A G^T; G 0]`` (explicit zero diagonal kept),
        or its upper triangle.

        Its pattern is built once (entries tagged with their source position in K's values
        or G's) and every later call is one gather from K's values and G's, into one values
        buffer of this system: the matrix returned is overwritten by the next call. (A
        factorisation replaces the factor of the last matrix, which then cannot solve: the
        two are never held together, 250 MB at the 1 M DOFs of a 200 x 200 Miura.)"""
        G = self.Gf
        assert G is not None and self._values is not None  # an operator with actuators
        na, nnz_k, nnz_g = G.shape[0], len(self._values), G.nnz
        key = (self._key, upper, nnz_g, hash(G.indptr.tobytes()), hash(G.indices.tobytes()))
        if key != self._kkt_key:
            nf = len(self.free_idx)
            sel, sub_indptr, sub_indices = self._submatrix_maps()
            tag_a = sp.csr_matrix((sel + 1.0, sub_indices, sub_indptr), shape=(nf, nf))
            if self._schur_counts:  # nothing else reads them on this route: freed
                del sel, sub_indptr, sub_indices
                self._sel = self._sub_indptr = self._sub_indices = None
            tag_g = sp.csr_matrix(
                (np.arange(nnz_k + 1.0, nnz_k + nnz_g + 1), G.indices, G.indptr), G.shape
            )
            tag_0 = sp.csr_matrix(
                (np.full(na, nnz_k + nnz_g + 1.0), (np.arange(na), np.arange(na))), (na, na)
            )
            tags = sp.bmat([[tag_a, tag_g.T], [tag_g, tag_0]], format="csr")
            if upper:
                tags = sp.triu(tags, format="csr")
            tags.sort_indices()
            src = tags.data.astype(np.int64) - 1
            from_k = src < nnz_k
            # one take from K's values (the few G and zero entries read position 0 and are
            # overwritten): no copy of K's values into a concatenated source
            itype = index_dtype(nnz_k)
            self._kkt_gather = np.where(from_k, src, 0).astype(itype)
            self._kkt_g = (np.flatnonzero(~from_k), src[~from_k] - nnz_k)  # G, then the zero
            self._kkt_pattern = (tags.indices, tags.indptr, tags.shape)
            self._kkt_blk = self._kkt_block_positions(tags.indptr, tags.indices, upper)
            self._kkt_key = key
        assert self._kkt_pattern is not None and self._kkt_g is not None
        assert self._kkt_gather is not None
        indices, indptr, shape = self._kkt_pattern
        if self._kkt_data is None or len(self._kkt_data) != len(indices):
            self._kkt_data = np.empty(len(indices))
        data = gather_into(self._values, self._kkt_gather, self._kkt_data)
        if len(self._blocks):  # the actuator blocks, added here: no copy of K's values
            assert self._kkt_blk is not None  # set with the pattern
            entry, at = self._kkt_blk
            np.add.at(data, at, self._blocks.ravel()[entry])
        pos, idx = self._kkt_g
        data[pos] = np.append(G.data, 0.0)[idx]
        kkt = sp.csr_matrix((data, indices, indptr), shape=shape)
        kkt.has_sorted_indices = True
        return kkt

    def _kkt_block_positions(
        self, indptr: np.ndarray, indices: np.ndarray, upper: bool
    ) -> tuple[np.ndarray, np.ndarray]:
        """(entries of the flattened actuator blocks, their positions in the bordered
        matrix's values) for the bordered pattern ``(indptr, indices)``: the entries whose
        DOFs are both free (and, for the upper triangle, whose row is not after the
        column)."""
        newidx = np.full(self.n_dof, -1, np.int64)
        newidx[self.free_idx] = np.arange(len(self.free_idx))
        rows, cols = _block_entries(self.act_dofs)
        r, c = newidx[rows], newidx[cols]
        keep = (r >= 0) & (c >= 0)
        if upper:
            keep &= r <= c
        entry = np.flatnonzero(keep)
        at = pattern_positions(indptr, indices, r[entry], c[entry])
        assert np.all(at >= 0)  # the bordered pattern holds A's, which holds the blocks
        return entry, at

    def _factorize_current(self) -> None:
        t_start = time.perf_counter()
        if self.Gf is not None and getattr(self.backend, "saddle_point", False):
            if self._factorize_kkt(t_start):
                return
            if self._schur_counts:
                # K_t itself is singular: the augmented bordered matrix from now on
                self._augment()
                t_start = time.perf_counter()
                if self._factorize_kkt(t_start):
                    return
            # perturbed pivots: the bordered matrix is (nearly) singular. Factorise A and the
            # Schur complement instead, which names the cause (redundant actuators) or, if
            # only the bordered pivoting struggled, solves exactly.
            t_start = time.perf_counter()
        self.factor = self.backend.factorize(self.A)
        self.timer.factorize += time.perf_counter() - t_start
        self.timer.n_factorizations += 1
        Z = S_inv = None
        if self.Gf is not None:
            t0 = time.perf_counter()
            half = getattr(self.factor, "half_solve", None)
            if half is not None:  # Cholesky: S = W^T W with W = L^-1 P G^T
                W = half(self.Gf.T.toarray())
                S = W.T @ W
            else:
                Z = np.asarray(self.factor.solve(self.Gf.T.toarray()))
                if Z.ndim == 1:
                    Z = Z[:, None]
                S = self.Gf @ Z
            S = 0.5 * (S + S.T)
            self.timer.solve += time.perf_counter() - t0
            try:
                S_inv = np.linalg.inv(S) if np.linalg.cond(S) <= 1e14 else None
            except np.linalg.LinAlgError:
                S_inv = None
            if S_inv is None or not np.all(np.isfinite(S_inv)):
                raise SingularMatrixError(
                    "Schur complement G A^-1 G^T is singular: "
                    "actuators are redundant or fixed by supports"
                )
        self._keep(_DirectSolver(self.factor, self.Gf, Z, S_inv, self.penalty), t_start)

    def _augment(self) -> None:
        """Stop the Schur-complement factorisations for the rest of the solve and make the
        current operator the augmented ``K_t + sum mu_a H_a + p G^T G`` asked for."""
        self._schur_counts = False
        assert self._augmentation is not None  # set with an operator with actuators
        p, g = self._augmentation
        pen = p * g[:, :, None] * g[:, None, :]
        if len(self._blocks):
            self._blocks = self._blocks + pen
        else:  # the blocks went into K's values (a pattern without them)
            self._blocks = pen
        self._penalty_blocks = pen
        self.penalty = p
        self._A = None
        self._full = None
        log.debug("bordered matrix singular without augmentation: augmented from here on")

    def held_negative_eigenvalues(self) -> int | None:
        """Negative eigenvalues of the free-DOF tangent ``K_t`` with the actuators *held*:
        of ``Z^T K_t Z``, ``Z`` a basis of the motions that keep every actuator angle
        (``G Z = 0``), from the last factorisation at no extra cost; None when the backend's
        factor gives no inertia or no factor is kept. Without actuators: ``K_t``'s count.

        For ``G`` of full row rank ``In(B) = In(Z^T K_t Z) + (n_act, n_act, 0)`` for the
        bordered matrix ``B = [K_t G^T; G 0]`` (Nocedal & Wright 2006, Numerical
        Optimization, Thm. 16.3; Gould 1985, Math. Prog. 32), so the count is
        ``neg(B) - n_act``: the saddle-point factorisation gives ``neg(B)``,
        the Schur route ``neg(A) + neg(-S)`` (``A = K_t + p G^T G``, ``S = G A^-1 G^T``,
        Haynsworth). Read it before :meth:`tangent_negative_eigenvalues`, which may release
        the bordered factor."""
        n_b = self._bordered_negative_pivots()
        if n_b is None or self.Gf is None:
            return n_b
        return n_b - self.Gf.shape[0]

    def _bordered_negative_pivots(self) -> int | None:
        """``neg(B)`` of the bordered matrix ``B = [K_t G^T; G 0]`` from the last
        factorisation (``neg(K_t)`` without actuators): the saddle-point factor's pivots, or
        on the Schur route those of ``A = K_t + p G^T G`` plus ``neg(-S) = pos(S^-1)``; None
        when the factor gives no inertia or none is kept."""
        direct = self.direct
        neg = getattr(self.factor, "negative_pivots", None)
        if neg is None or direct is None:
            return None
        n_b = neg()
        if n_b is None:
            return None
        if self.Gf is not None and isinstance(direct, _DirectSolver):
            assert direct.S_inv is not None  # kept with actuators
            S_inv = 0.5 * (direct.S_inv + direct.S_inv.T)  # (G A^-1 G^T)^-1
            n_b += int(np.sum(np.linalg.eigvalsh(S_inv) > 0))
        return int(n_b)

    def tangent_negative_eigenvalues(self) -> int | None:
        """Negative eigenvalues of the free-DOF tangent ``K_t = K_ff + sum mu_a H_a`` with the
        actuators *released* (their moments held), from the last factorisation; None when
        the backend's factor gives no inertia (SuperLU after off-diagonal pivoting).

        Without actuators the factorised matrix is ``K_t`` itself. With actuators the
        factorisation is of the bordered matrix ``B = [K_t G^T; G 0]`` (or of ``A = K_t +
        p G^T G``, whose Schur complement adds ``In(-G A^-1 G^T)``; both congruent forms
        have the inertia of B). Haynsworth's formula on ``K_t`` gives
        ``In(B) = In(K_t) + In(Y)`` with ``Y = -(G K_t^-1 G^T)^-1``, the multiplier block of
        ``B^-1``: ``n_act`` solves with the factorisation at hand (valid while K_t is
        nonsingular, i.e. away from the critical point itself). A PARDISO factorisation of
        B with the multipliers last carries ``Y^-1 = -G K_t^-1 G^T`` itself (its Schur
        complement, :attr:`_schur_counts`): then no solve at all."""
        n_b = self._bordered_negative_pivots()
        if n_b is None or self.Gf is None:
            return n_b
        direct = self.direct
        assert direct is not None  # a count came from it
        na = self.Gf.shape[0]
        schur = getattr(self.factor, "schur_complement", None)
        S = schur() if schur is not None and isinstance(direct, _KKTSolver) else None
        if S is not None:  # B's own Schur complement -G K_t^-1 G^T (no augmentation)
            return n_b - int(np.sum(np.linalg.eigvalsh(S) < 0))
        if (
            isinstance(direct, _KKTSolver)
            and na >= RELEASED_FACTOR_MIN_ACT
            and self._released is not None
        ):
            return self._released_inertia()
        _, Y = direct.solve(np.zeros((len(self.free_idx), na)), np.eye(na))
        Y = np.asarray(Y).reshape(na, na)
        return n_b - int(np.sum(np.linalg.eigvalsh(0.5 * (Y + Y.T)) < 0))

    def _keep(self, direct: _DirectSolver | _KKTSolver, t_start: float) -> None:
        """Make ``direct`` the factorisation of the current operator."""
        self.direct = direct
        self.current_factored = True
        self._fact_cost = time.perf_counter() - t_start
        self._krylov_cost = 0.0
        # the held count of every factorisation (free): load and displacement control check
        # it inside an increment, and a failed increment names it
        self.negative_pivots = self.held_negative_eigenvalues()
        self.inertia_seen.append(self.negative_pivots)

    def _factorize_kkt(self, t_start: float) -> bool:
        """One symmetric indefinite factorisation of the whole bordered matrix (backends
        with ``saddle_point``): no Schur complement, no ``n_act`` solves per iteration.
        Returns False (nothing kept) when the factorisation had to perturb pivots."""
        assert self.Gf is not None  # called with actuators only
        # saddle-point backends take the upper triangle (``upper``)
        factorize: Any = self.backend.factorize
        schur = {"schur": self.Gf.shape[0]} if self._schur_counts else {}
        # the last operator's values (kept for its released count) are not held through
        # the factorisation's own peak (242 MB at the 1 M DOFs of a 200 x 200 Miura)
        self._released = None
        self.factor = factorize(self._kkt_matrix(upper=True), upper=True, **schur)
        self.timer.factorize += time.perf_counter() - t_start
        self.timer.n_factorizations += 1
        perturbed = getattr(self.factor, "perturbed_pivots", None)
        if perturbed is not None and perturbed() > 0:
            return False
        self._keep(_KKTSolver(self.factor, self.Gf, self.penalty), t_start)
        if self._blk_ok and self._penalty_blocks is not None and self._values is not None:
            self._released = (self._values, self._blocks - self._penalty_blocks)
        return True

    def _released_inertia(self) -> int | None:
        """Negative eigenvalues of the released tangent ``K_t = A - p G^T G`` of the last
        bordered factorisation, from a factorisation of ``K_t`` itself (a backend of its
        own, so the bordered factor stays alive: Cholesky while the released tangents are
        positive definite, :class:`~barhinge.linalg.inertia.InertiaCounter`); None when its
        backend gives no inertia."""
        assert self._released is not None and self._blk_pos is not None
        sel, sub_indptr, sub_indices = self._submatrix_maps()
        if self.release_before_count:
            self._release_large_factor()
        data, blocks = self._released
        # the free submatrix of K's values (one copy), the blocks ``mu_a H_a`` added where
        # their entries are free (``_sel`` is sorted)
        vals = data[sel]
        sub = np.searchsorted(sel, self._blk_pos)
        free = sub < len(vals)
        free[free] = sel[sub[free]] == self._blk_pos[free]
        np.add.at(vals, sub[free], blocks.ravel()[free])
        nf = len(self.free_idx)
        Kt = sp.csr_matrix((vals, sub_indices, sub_indptr), (nf, nf))
        if self._released_counter is None:
            self._released_counter = InertiaCounter(self.backend)
        counter = self._released_counter
        made = counter.factorizations
        t0 = time.perf_counter()
        try:
            return counter.negative_eigenvalues(Kt)
        except SingularMatrixError:
            return None
        finally:
            self.timer.factorize += time.perf_counter() - t0
            self.timer.n_factorizations += counter.factorizations - made

    def _release_large_factor(self) -> None:
        """Free the bordered factor when it is larger than ``InertiaCounter.RELEASE_ABOVE``
        (the backend keeps its ordering and analysis); the next operator is factorised
        afresh. A no-op for a backend that cannot release its factor."""
        size = getattr(self.backend, "factor_bytes", None)
        if size is None or size() <= InertiaCounter.RELEASE_ABOVE:
            return
        self.backend.release()  # type: ignore[attr-defined]
        self.factor = None
        self.direct = None
        self.current_factored = False

    # ---------------------------------------------------------------- solve
    def solve(
        self, rhs_x: np.ndarray, rhs_c: np.ndarray, rtol: float = 1e-10
    ) -> tuple[np.ndarray, np.ndarray]:
        """Solve the exact bordered system ``[K_t G^T; G 0] [dx; dmu] = [rhs_x; rhs_c]`` of
        the current operator (free DOFs).

        rhs_x : (n_free,) or (n_free, k); rhs_c : (n_act,) or (n_act, k).
        rtol : relative tolerance of GMRES on the scaled residual (reuse mode only; the
            solve is exact up to round-off when the current operator is factorised).
        """
        t0 = time.perf_counter()
        self.last_krylov_iters = 0
        if self.direct is None:  # released (release_before_count): factorise this operator
            self._factorize_current()
        if self.current_factored:
            assert self.direct is not None  # current_factored: kept by _keep
            out = self.direct.solve(rhs_x, rhs_c)
            self.timer.solve += time.perf_counter() - t0
            self.timer.n_solves += 1
            return out
        if np.ndim(rhs_x) == 2:
            cols = [self.solve(rhs_x[:, j], rhs_c[:, j], rtol) for j in range(rhs_x.shape[1])]
            return np.stack([c[0] for c in cols], 1), np.stack([c[1] for c in cols], 1)
        kout = self._krylov(rhs_x, rhs_c, rtol)
        dt = time.perf_counter() - t0
        self.timer.solve += dt
        if kout is None:  # GMRES did not reach rtol: factorise this operator, solve directly
            self._factorize_current()
            t1 = time.perf_counter()
            assert self.direct is not None  # kept by _factorize_current
            out = self.direct.solve(rhs_x, rhs_c)
            self.timer.solve += time.perf_counter() - t1
            self.timer.n_solves += 1
        else:
            self._krylov_cost += dt
            out = kout
        return out

    def _krylov(
        self, rhs_x: np.ndarray, rhs_c: np.ndarray, rtol: float
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """GMRES on the scaled bordered system, preconditioned by the last factorisation.

        Unknowns ``(dx, w = dmu / s)``, rows ``(forces, s * constraints)`` with ``s`` =
        :attr:`row_scale`, so that every entry of the residual is a force."""
        A, G, p = self.A, self.Gf, self.penalty
        assert A is not None and self.direct is not None  # an operator and a factorisation
        nf = A.shape[0]
        s = self.row_scale
        pre = self.direct
        na = 0 if G is None else G.shape[0]

        def matvec(z: np.ndarray) -> np.ndarray:
            dx = z[:nf]
            if not na:
                return A @ dx
            assert G is not None  # na > 0
            w = z[nf:]
            gdx = G @ dx
            # K_t dx = A dx - p G^T G dx (the current operator is augmented)
            top = A @ dx - p * (G.T @ gdx) + s * (G.T @ w)
            return np.concatenate([top, s * gdx])

        def psolve(v: np.ndarray) -> np.ndarray:
            if not na:
                return np.asarray(pre.solve(v, np.zeros(0))[0])
            dx, dmu = pre.solve(v[:nf], v[nf:] / s)
            return np.concatenate([dx, dmu / s])

        n = nf + na
        op = spla.LinearOperator((n, n), matvec=matvec, dtype=float)
        M = spla.LinearOperator((n, n), matvec=psolve, dtype=float)
        b = np.concatenate([rhs_x, s * rhs_c]) if na else np.asarray(rhs_x, float)
        if not np.any(b):
            return np.zeros(nf), np.zeros(na)
        kmax = int(self.krylov_max)
        if kmax < 1:  # no iterations allowed: the caller factorises (scipy >= 1.12 raises
            return None  # UnboundLocalError for restart=0 or maxiter=0)
        count = [0]

        def cb(_r: float) -> None:
            count[0] += 1
            if count[0] > kmax:
                raise _KrylovStalled

        try:
            # restarts re-check the true residual (scipy's inner test is on the
            # preconditioned one); the callback caps the total of inner iterations.
            # Keywords as in scipy >= 1.12 (rtol, atol, restart, maxiter = restart cycles,
            # callback_type); restart and maxiter must be >= 1 (checked above).
            z, info = spla.gmres(
                op,
                b,
                rtol=rtol,
                atol=0.0,
                restart=kmax,
                maxiter=kmax,
                M=M,
                callback=cb,
                callback_type="pr_norm",
            )
        except _KrylovStalled:
            z, info = None, -1
        self.last_krylov_iters = count[0]
        self.timer.n_krylov += count[0]
        if info != 0 or z is None or not np.all(np.isfinite(z)):
            return None
        return z[:nf], s * z[nf:]


def _block_entries(act_dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, columns) of every entry of the actuators' 12 x 12 blocks ``(n_act, 12, 12)``,
    flattened in the blocks' order (``act_dofs``: (n_act, 12) global DOFs)."""
    return np.repeat(act_dofs, 12, axis=1).ravel(), np.tile(act_dofs, (1, 12)).ravel()


def gdcm_sign(prev_tangent: np.ndarray | None, tangent: np.ndarray, prev_sign: float) -> float:
    """Direction of the next MGDCM predictor (Leon et al. 2011, AMR 64(4), Sec. 'generalized
    displacement control'): the sign flips when the tangent displacement of the new step
    points against the previous one, ``sign(du_1^{i-1} . du_1^i) < 0`` (a limit point was
    passed)."""
    if prev_tangent is None:
        return prev_sign
    return prev_sign * (1.0 if float(prev_tangent @ tangent) >= 0 else -1.0)


def gdcm_scale(
    first_tangent: np.ndarray, prev_tangent: np.ndarray | None, tangent: np.ndarray
) -> float:
    """|GSP|^(1/2) with the generalized stiffness parameter
    ``GSP = (du_1^1 . du_1^1) / (du_1^{i-1} . du_1^i)`` (Yang & Shieh 1990; Leon et al. 2011,
    Eq. for the GDCM load increment ``dlambda_1^i = +-dlambda_1^1 |GSP|^(1/2)``)."""
    if prev_tangent is None:
        return 1.0
    den = abs(float(prev_tangent @ tangent))
    if den == 0.0:
        return 1.0
    return float(np.sqrt(float(first_tangent @ first_tangent) / den))
