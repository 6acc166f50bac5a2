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
directions). It is solved through one factorisation of ``A`` and the small dense Schur
complement ``S = G A^-1 G^T`` (n_act x n_act).
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge.solve.linear import LinearBackend, SingularMatrixError

__all__ = ["ActuatorTerms", "BorderedSystem", "Timer", "actuator_terms", "hinge_derivatives"]


@dataclasses.dataclass
class Timer:
    """Seconds spent in each phase of the solve (for benchmarks)."""

    assembly: float = 0.0
    factorize: float = 0.0
    solve: float = 0.0
    other: float = 0.0
    n_factorizations: int = 0
    n_iterations: int = 0

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


def hinge_derivatives(model: Any, X: np.ndarray, hinge_ids: np.ndarray):
    """(rho, grad, hess) of the given hinges: (na,), (na, 12), (na, 12, 12)."""
    if hasattr(model, "hinge_angle_derivatives"):
        return model.hinge_angle_derivatives(X, hinge_ids)
    from barhinge.kernels.geometry import hinge_angle_derivatives

    return hinge_angle_derivatives(X, np.asarray(model.hinges)[hinge_ids])


@dataclasses.dataclass
class ActuatorTerms:
    """Actuator constraint quantities at one state.

    rho : (n_act,) current angles; G : (n_act, n_dof) csr; grad/hess : per-hinge blocks;
    dofs : (n_act, 12) global DOF index of each block column.
    """

    rho: np.ndarray
    G: sp.csr_matrix
    grad: np.ndarray
    hess: np.ndarray
    dofs: np.ndarray


def actuator_terms(model: Any, X: np.ndarray, hinge_ids: np.ndarray) -> ActuatorTerms:
    """Angles, constraint Jacobian and Hessians of the actuator hinges at ``X``."""
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
    rho, grad, hess = hinge_derivatives(model, X, hinge_ids)
    nodes = np.asarray(model.hinges)[hinge_ids]  # (na, 4)
    dofs = (3 * nodes[:, :, None] + np.arange(3)[None, None, :]).reshape(na, 12)
    rows = np.repeat(np.arange(na), 12)
    G = sp.csr_matrix((grad.ravel(), (rows, dofs.ravel())), shape=(na, n_dof))
    return ActuatorTerms(rho, G, grad, hess, dofs)


class BorderedSystem:
    """Factorise and solve the (bordered) Newton system on the free DOFs.

    Parameters
    ----------
    backend : LinearBackend
    free : (n_dof,) bool mask of the free DOFs.
    act_dofs : (n_act, 12) global DOFs of the actuator blocks (fixed for the whole solve).
    timer : Timer
    """

    def __init__(
        self, backend: LinearBackend, free: np.ndarray, act_dofs: np.ndarray, timer: Timer
    ) -> None:
        self.backend = backend
        self.free = np.asarray(free, bool)
        self.free_idx = np.flatnonzero(self.free)
        self.n_dof = len(self.free)
        self.act_dofs = act_dofs
        self.timer = timer
        self._key: tuple | None = None
        self._sel: np.ndarray | None = None
        self._sub_indptr: np.ndarray | None = None
        self._sub_indices: np.ndarray | None = None
        self._blk_pos: np.ndarray | None = None  # positions of actuator blocks in K.data
        self._blk_ok = False
        self.factor = None
        self.track_inertia = False
        self.negative_pivots: int | None = None
        self.inertia_seen: list[int | None] = []
        self.Gf: sp.csr_matrix | None = None
        self.Z: np.ndarray | None = None  # A^-1 G^T (None with a Cholesky half solve)
        self.S_lu = None

    # ---------------------------------------------------------------- structure
    def _prepare(self, K: sp.csr_matrix) -> None:
        """Scatter maps from K's CSR pattern to the free-free submatrix, built once."""
        K.sort_indices()
        key = (K.shape, K.nnz, hash(K.indptr.tobytes()), hash(K.indices[::97].tobytes()))
        if key == self._key:
            return
        self._key = key
        n = self.n_dof
        rows = np.repeat(np.arange(n), np.diff(K.indptr))
        cols = K.indices
        newidx = np.full(n, -1, np.int64)
        newidx[self.free_idx] = np.arange(len(self.free_idx))
        keep = self.free[rows] & self.free[cols]
        self._sel = np.flatnonzero(keep)
        r, c = newidx[rows[keep]], newidx[cols[keep]]
        nf = len(self.free_idx)
        self._sub_indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=nf))])
        self._sub_indices = c.astype(np.int32)
        # positions of the actuator 12x12 blocks inside K.data (if K's pattern holds them)
        ad = self.act_dofs
        if len(ad):
            br = np.repeat(ad, 12, axis=1).ravel()
            bc = np.tile(ad, (1, 12)).ravel()
            pos = _csr_positions(K, br, bc)
            self._blk_ok = bool(np.all(pos >= 0))
            self._blk_pos = pos
        else:
            self._blk_ok = True
            self._blk_pos = np.zeros(0, np.int64)

    def _free_matrix(self, K: sp.csr_matrix, blocks: np.ndarray) -> sp.csr_matrix:
        """K_ff plus the actuator blocks (n_act, 12, 12) scattered on their DOFs."""
        self._prepare(K)
        if len(blocks) and not self._blk_ok:
            # the model's pattern does not hold the blocks: add them as a sparse matrix
            ad = self.act_dofs
            br = np.repeat(ad, 12, axis=1).ravel()
            bc = np.tile(ad, (1, 12)).ravel()
            B = sp.csr_matrix((blocks.ravel(), (br, bc)), shape=K.shape)
            K = (K + B).tocsr()
            self._key = None
            self._prepare(K)
            data = K.data
        elif len(blocks):
            data = K.data.copy()
            np.add.at(data, self._blk_pos, blocks.ravel())
        else:
            data = K.data
        nf = len(self.free_idx)
        return sp.csr_matrix((data[self._sel], self._sub_indices, self._sub_indptr), shape=(nf, nf))

    # ---------------------------------------------------------------- factorise
    def factorize(
        self, K: sp.csr_matrix, terms: ActuatorTerms, mu: np.ndarray, penalty: float
    ) -> None:
        """Factorise ``A = K_ff + sum mu_a H_a + p G^T G`` and the Schur complement.

        Raises SingularMatrixError when A or S is singular.
        """
        na = len(mu)
        if na:
            g = terms.grad
            blocks = mu[:, None, None] * terms.hess + penalty * g[:, :, None] * g[:, None, :]
        else:
            blocks = np.zeros((0, 12, 12))
        A = self._free_matrix(K, blocks)
        t0 = time.perf_counter()
        self.factor = self.backend.factorize(A)
        self.timer.factorize += time.perf_counter() - t0
        self.timer.n_factorizations += 1
        if self.track_inertia:
            neg = getattr(self.factor, "negative_pivots", None)
            self.negative_pivots = neg() if neg is not None else None
            self.inertia_seen.append(self.negative_pivots)
        self.penalty = penalty
        if na:
            t0 = time.perf_counter()
            self.Gf = terms.G[:, self.free_idx].tocsr()
            half = getattr(self.factor, "half_solve", None)
            if half is not None:  # Cholesky: S = W^T W with W = L^-1 P G^T
                W = half(self.Gf.T.toarray())
                S = W.T @ W
                self.Z = None
            else:
                self.Z = np.asarray(self.factor.solve(self.Gf.T.toarray()))
                if self.Z.ndim == 1:
                    self.Z = self.Z[:, None]
                S = self.Gf @ self.Z
            S = 0.5 * (S + S.T)
            self.timer.solve += time.perf_counter() - t0
            try:
                self.S_inv = np.linalg.inv(S)
            except np.linalg.LinAlgError as exc:
                raise SingularMatrixError(
                    "Schur complement G A^-1 G^T is singular: "
                    "actuators are redundant or fixed by supports"
                ) from exc
            if not np.all(np.isfinite(self.S_inv)) or np.linalg.cond(S) > 1e14:
                raise SingularMatrixError(
                    "Schur complement G A^-1 G^T is singular: "
                    "actuators are redundant or fixed by supports"
                )
        else:
            self.Gf = None

    def solve(self, rhs_x: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Solve ``[A_b G^T; G 0] [dx; dmu] = [rhs_x; rhs_c]`` (free DOFs; exact bordered
        system, the augmentation being compensated here).

        rhs_x : (n_free,) or (n_free, k); rhs_c : (n_act,) or (n_act, k).
        """
        t0 = time.perf_counter()
        if self.Gf is None:
            dx = np.asarray(self.factor.solve(rhs_x))
            self.timer.solve += time.perf_counter() - t0
            return dx, np.zeros((0,) + np.shape(rhs_x)[1:])
        # augmented first block row: rhs_x + p G^T rhs_c
        bx = rhs_x + self.penalty * (self.Gf.T @ rhs_c)
        a0 = np.asarray(self.factor.solve(bx))
        dmu = self.S_inv @ (self.Gf @ a0 - rhs_c)
        if self.Z is not None:
            dx = a0 - self.Z @ dmu
        else:
            dx = a0 - np.asarray(self.factor.solve(self.Gf.T @ dmu))
        self.timer.solve += time.perf_counter() - t0
        return dx, dmu


def _csr_positions(K: sp.csr_matrix, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Index into ``K.data`` of each (row, col) pair, -1 where the pattern has no entry.
    K must have sorted indices."""
    out = np.full(len(rows), -1, np.int64)
    start = K.indptr[rows]
    end = K.indptr[rows + 1]
    for q in range(len(rows)):  # small: 144 entries per actuator
        s, e = start[q], end[q]
        k = s + np.searchsorted(K.indices[s:e], cols[q])
        if k < e and K.indices[k] == cols[q]:
            out[q] = k
    return out


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
