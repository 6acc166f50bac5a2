"""Rigid folding path: drive actuator creases along a schedule, predictor-corrector on the
loop-closure manifold (Tachi 2009, "Simulation of rigid origami").

Each requested step goes from the converged fold angles ``rho`` to new actuator targets:

1. **Predictor** along the tangent of the constraint manifold: ``J_F d_F = -J_A dt`` (least
   squares through the normal equations; ``F`` = free creases, ``A`` = actuators).
2. **Corrector**: Gauss-Newton ``(J_F^T J_F) d_F = -J_F^T r`` with the actuator angles held at
   their targets, until ``max |r| <= tol`` and ``max |F - I|_max <= 100 tol``. The rows are
   redundant for most patterns (e.g. Miura), so the normal equations are used; the system
   is consistent on the manifold, so Gauss-Newton converges quadratically. One sparse LU per
   step; later iterations use it as a preconditioner for conjugate gradients on the current
   normal equations (inexact Newton) and backtrack on ``|r|_2``.
3. **Step control**: a step that does not converge is split in halves (cut-back), up to
   ``max_cutbacks`` times.

Coordinates are rebuilt from the fold angles along a spanning tree of faces
(:class:`~barhinge.kinematics.constraints.FaceTree`).

Leaving the flat state: at the flat state every crease axis lies in the plane, the Jacobian
loses one rank per vertex and the flat state is a bifurcation point (e.g. a Miura vertex can
leave it in two modes). The branch is picked from the pattern: the first guess scales the
pattern's target fold angles (``cp.fold_angles``) or, if none are given, the signs of its
mountain/valley assignment (V +1, M -1) so that the actuators match their first targets;
the corrector then lands on the rigid branch through that guess.

Diagnostics (one-line errors): actuators that are not foldable creases or that leave free
motions (``ConfigError``, checked at the first folded state through the null space of the
Jacobian), incompatible targets of an over-determined set (``ConfigError``), a crease that
reaches +-180 deg (locking) or a residual that will not close (``ConvergenceError`` carrying the
partial path). With ``check_rank`` the DOF is recomputed at every state and changes
(bifurcations, singular states) are recorded in ``path.meta["events"]``.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge.actuators import Actuators
from barhinge.errors import ConfigError, ConvergenceError
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.kinematics.dof import FLAT_TOL, _branch_direction
from barhinge.linalg.backends import (
    Factor,
    IndefiniteMatrixError,
    LinearBackend,
    PardisoBackend,
    SingularMatrixError,
    available_backends,
    get_backend,
)
from barhinge.linalg.extrapolation import EXTRAPOLATION_POINTS, extrapolate
from barhinge.linalg.nullspace import DENSE_TOL, null_space
from barhinge.linalg.threads import threads_for_sparse
from barhinge.pattern.crease import CreasePattern
from barhinge.results import FoldPath

__all__ = ["RigidOptions", "RigidSolver", "actuator_conflict", "rigid_fold"]

log = logging.getLogger(__name__)


#: crease variables from which the corrector uses the fastest backend instead of SuperLU
PARDISO_MIN_VARS = 500


@dataclasses.dataclass(frozen=True)
class RigidOptions:
    """Options of the rigid path solver.

    Attributes
    ----------
    tol : float
        Converged when ``max |r| <= tol`` (closure residual, radians-like).
    max_iter : int
        Corrector iterations per attempt.
    max_cutbacks : int
        Times a failing step may be halved.
    lock_deg : float
        A crease whose |fold angle| reaches this is locked (panels meet).
    check_actuators : bool
        Check at the first folded state that the actuators determine the motion.
    check_rank : bool or None
        Recompute the DOF (dense SVD) at every state; None = only when n_var <= 300.
    cg_maxiter : int
        Conjugate-gradient iterations allowed with a reused factorisation as preconditioner
        before the normal matrix is factorised afresh.
    energy_tol : float
        Free DOF left by the actuators are resolved by minimising the fold-spring energy on
        the constraint manifold; converged when the largest Newton correction of a fold angle
        is below this (radians).
    energy_max_iter : int
        Newton iterations of that minimisation per step.
    saddle_shift : bool
        After leaving a saddle of the energy, keep the multipliers and shift the Lagrangian
        Hessian past the negative curvature (and wherever the Newton step is not a descent
        direction) instead of restarting from the spring metric: avoids cycling between
        saddles (e.g. least-squares Ron Resch sheets); may land on another minimum.
    over_actuated : str
        Actuators whose targets no rigid fold can meet together: ``"least_squares"``
        (default) meets them in least squares (the actuators become stiff springs to their
        targets; the misfit per state is in ``path.meta["actuator_misfit_deg"]`` and an
        event names the dependent actuators) or ``"error"`` (``ConfigError``).
    """

    tol: float = 1e-13
    max_iter: int = 12
    max_cutbacks: int = 8
    lock_deg: float = 179.999
    check_actuators: bool = True
    check_rank: bool | None = None
    cg_maxiter: int = 25
    energy_tol: float = 1e-9
    energy_max_iter: int = 40
    over_actuated: str = "least_squares"
    saddle_shift: bool = False

    def __post_init__(self) -> None:
        if self.over_actuated not in ("least_squares", "error"):
            raise ConfigError(
                f"over_actuated = {self.over_actuated!r}; expected 'least_squares' or 'error'"
            )


class _Incompatible(ConfigError):
    """Over-determining actuators with incompatible targets (linearised misfit)."""


class _Singular(RuntimeError):
    """The normal matrix of the free creases is exactly singular."""


class RigidSolver:
    """Predictor-corrector on the loop-closure manifold with fixed actuator creases.

    Parameters
    ----------
    rc : RigidConstraints
    act_var : (n_act,) int
        Variable indices of the actuators.
    options : RigidOptions
    """

    def __init__(
        self,
        rc: RigidConstraints,
        act_var: np.ndarray,
        options: RigidOptions,
        weights: np.ndarray | None = None,
    ) -> None:
        self.rc = rc
        #: driven creases; ``act`` are those held at their targets (all of them, or none
        #: once incompatible targets are met in least squares: see :meth:`make_soft`)
        self.drive = np.asarray(act_var, dtype=np.int64)
        self.act = self.drive.copy()
        self.opt = options
        free = np.ones(rc.n_var, bool)
        free[self.act] = False
        self.free = free
        self.soft = False
        #: (n_act,) stiffness of compliant actuators (moment per radian), None when held
        self.actuator_k: np.ndarray | None = None
        #: compliant actuators are held for each step's prediction while that succeeds
        self.hold_compliant = True
        self.targets_now = np.zeros(len(self.drive))
        #: fold-spring stiffness of each variable (moment per radian) and its rest angle
        self.weights = np.ones(rc.n_var) if weights is None else np.asarray(weights, dtype=float)
        self.rest = rc.rho0.copy()
        #: True once the actuators are known to leave free motions (then the fold-spring
        #: energy resolves them); None until checked at the first folded state
        self.underactuated: bool | None = None
        #: creases that fold against the sign the branch rule asks for (after leave_flat)
        self.sign_conflicts: list[int] = []
        self.energy_iterations = 0
        self.energy_failed = False
        self.branch_attempts = 0
        self.mirrored = False
        #: (DOF, rank of the actuators on it) at the first folded state, once known
        self.dof_rank: tuple[int, int] | None = None
        self._lu: Factor | None = None
        #: entries of the normal matrix (or of its upper triangle) the held actuators
        #: remove, with the pattern and free set they were found for
        self._drops: dict[bool, tuple[object, object, np.ndarray | None]] = {}
        # PARDISO set for normal equations pays from a few hundred crease variables on
        # (Miura sheets, ms per step: 760 creases 2.1 -> 1.1, 3 120: 6.6 -> 2.1); below,
        # SuperLU spares a small fold the loading of MKL
        self._backend = _normal_backend(rc.n_var)
        self.iterations = 0
        #: corrector attempts stopped by a singular Jacobian at a bifurcation point
        self.singular_attempts = 0
        #: whether the last attempt rejected was a converged corrector that fell back to the
        #: flat state with released actuators pulled away from it (no equilibrium of theirs)
        self.fell_flat = False
        self.last_guess: np.ndarray | None = None

    # ---------------------------------------------------------------- linear algebra
    def _held_normal(
        self,
        J: sp.csr_matrix,
        shift: np.ndarray | float = 0.0,
        *,
        regularise: bool = False,
        upper: bool = False,
    ) -> sp.csr_matrix:
        """``D (J^T J + diag(shift)) D + (I - D)`` with ``D`` the free creases (the held
        actuators' rows and columns replaced by the identity), on the constraints' fixed
        pattern (a factorisation reuses its ordering); its upper triangle with ``upper``.
        ``regularise`` adds a tiny stiffness-weighted shift, ``1e-12`` of the largest
        diagonal entry of ``J^T J``."""
        K, diag = self.rc.normal_matrix(J, upper=upper)
        if regularise:
            w = self.weights
            scale = float(K.data[diag].max(initial=1.0)) / float(w.max(initial=1.0))
            shift = shift + 1e-12 * scale * w
        indptr, free, drop = self._drops.get(upper, (None, None, None))
        if indptr is not K.indptr or free is not self.free or drop is None:
            rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
            drop = np.flatnonzero(~(self.free[rows] & self.free[K.indices]))
            self._drops[upper] = (K.indptr, self.free, drop)
        K.data[drop] = 0.0
        K.data[diag] += np.where(self.free, shift, 1.0)
        return K

    def _factor(self, J: sp.csr_matrix) -> None:
        # where the actuators leave free motions a tiny stiffness-weighted regularisation
        # keeps the normal matrix regular (the right-hand side J^T r has no component along
        # them, so the step stays the minimum-norm Gauss-Newton step)
        regularise = self.underactuated is not False
        backend = self._backend
        try:
            # symmetric positive (semi)definite; the solver's fastest backend (PARDISO where
            # installed, else SuperLU with symmetric settings), ordering reused across steps.
            # A (nearly) singular matrix ends in SuperLU's exact LU, which names it.
            if isinstance(backend, PardisoBackend):
                # PARDISO's Cholesky reads the upper triangle: build only that. A pivot that
                # is not positive means singular to working precision: SuperLU's exact LU
                U = self._held_normal(J, regularise=regularise, upper=True)
                try:
                    self._lu = backend.factorize(U, upper=True)
                except IndefiniteMatrixError:
                    K = self._held_normal(J, regularise=regularise)
                    self._lu = get_backend("superlu").factorize(K)
            else:
                self._lu = backend.factorize(self._held_normal(J, regularise=regularise))
        except SingularMatrixError as exc:  # exactly singular: free creases not determined
            raise _Singular(str(exc)) from None

    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.where(self.free, rhs, 0.0)
        assert self._lu is not None, "factorise before solving"
        x = self._lu.solve(rhs)
        x[~self.free] = 0.0
        return x

    def _solve_current(self, J: sp.csr_matrix, rhs: np.ndarray, eta: float) -> np.ndarray:
        """Solve the normal equations of the current Jacobian ``J``: preconditioned conjugate
        gradients with the last factorisation as preconditioner, to relative accuracy ``eta``
        (inexact Newton); refactorise when CG needs more than ``opt.cg_maxiter``
        iterations."""
        if self._lu is None:
            self._factor(J)
            return self._solve(rhs)
        free = self.free
        b = np.where(free, rhs, 0.0)
        x = self._pcg(J, b, eta)
        if x is None:
            self._factor(J)
            return self._solve(rhs)
        return x

    def _pcg(self, J: sp.csr_matrix, b: np.ndarray, eta: float) -> np.ndarray | None:
        """Preconditioned CG on ``D J^T J D x = b`` (free creases), preconditioner = the
        stored factorisation; None if ``opt.cg_maxiter`` iterations do not reach ``|res| <=
        eta |b|``. Plain NumPy reductions (no BLAS calls on small vectors)."""
        free = self.free

        def dot(u: np.ndarray, v: np.ndarray) -> float:
            return float((u * v).sum())

        def A(v: np.ndarray) -> np.ndarray:
            return np.where(free, J.T @ (J @ np.where(free, v, 0.0)), 0.0)

        bnorm = np.sqrt(dot(b, b))
        if bnorm == 0.0:
            return np.zeros_like(b)
        x = np.zeros_like(b)
        r = b.copy()
        z = self._solve(r)
        p = z.copy()
        rz = dot(r, z)
        for _ in range(self.opt.cg_maxiter):
            Ap = A(p)
            pAp = dot(p, Ap)
            if not pAp > 0.0:
                return None
            alpha = rz / pAp
            x += alpha * p
            r -= alpha * Ap
            if np.sqrt(dot(r, r)) <= eta * bnorm:
                return x
            z = self._solve(r)
            rz_new = dot(r, z)
            if not (rz > 0.0 and np.isfinite(rz_new)):
                return None  # breakdown: refactorise instead
            p = z + (rz_new / rz) * p
            rz = rz_new
        return None

    def corrector(self, rho: np.ndarray) -> tuple[np.ndarray, list[float], bool]:
        """Gauss-Newton with the actuators held; returns (rho, residual history, ok).

        The normal matrix is factorised once per call (at the first iteration); later
        iterations solve with the current Jacobian by PCG preconditioned by that
        factorisation (:meth:`_solve_current`), so the iteration stays Newton-like
        (quadratic) for the price of one factorisation per step."""
        tol = self.opt.tol
        hist: list[float] = []
        rc = self.rc
        r, products = rc.closure(rho)  # the Jacobian only where an iteration follows
        for it in range(self.opt.max_iter + 1):
            res = float(np.max(np.abs(r), initial=0.0))
            hist.append(res)
            if not np.isfinite(res):
                return rho, hist, False
            if res <= tol:
                # |F - I| also rejects the spurious 180-degree loops where r = 0
                FT = products[0]
                if FT.shape[2] == 0 or float(np.abs(FT - np.eye(3)[:, :, None]).max()) <= 100 * tol:
                    return rho, hist, True
                return rho, hist, False
            if it == self.opt.max_iter:
                break
            if len(hist) >= 3 and res > 2.0 * hist[-2]:
                return rho, hist, False  # diverging
            J = rc.jacobian_of(products)
            # forcing term: inexact Newton stays (nearly) quadratic with eta ~ |r|, and
            # asks no more of the new residual than ``tol`` (the last iteration of a step,
            # from |r| ~ 1e-11, needs 1e-3, not 1e-10: one CG iteration instead of four)
            eta = float(np.clip(max(10.0 * res, 0.1 * tol / res), 1e-10, 1e-2))
            try:
                if it == 0:
                    # a factorisation from the previous step is a poor preconditioner (70 x
                    # 70 Miura, 4 deg steps: 11 CG iterations to 1e-3, 40 to 1e-6): factorise
                    self._factor(J)
                if it == 0 and self.underactuated is False:
                    step = self._solve(-(J.T @ r))  # the factor of this very matrix
                else:
                    step = self._solve_current(J, -(J.T @ r), eta)
            except _Singular:
                if self.underactuated is not False:
                    raise  # free motions the actuators leave, or not known yet
                # the actuators determine the motion, so the Jacobian is singular only at a
                # bifurcation point (a degree-4 vertex's flat state); the prediction or an
                # iterate met one: the step is cut back as if it had diverged
                self.singular_attempts += 1
                return rho, hist, False
            if not np.all(np.isfinite(step)):
                return rho, hist, False
            smax = np.max(np.abs(step), initial=0.0)
            if smax > 0.5:  # trust region: at most ~30 deg per iteration
                step *= 0.5 / smax
            n0 = float((r * r).sum())  # backtrack on |r|_2 (Gauss-Newton descends it)
            for _ in range(6):
                r_t, p_t = rc.closure(rho + step)
                if float((r_t * r_t).sum()) < n0:
                    break
                step *= 0.5
            rho, r, products = rho + step, r_t, p_t
            self.iterations += 1
        return rho, hist, False

    def tangent(self, rho: np.ndarray, dt: np.ndarray) -> tuple[np.ndarray, float]:
        """Tangent step for actuator increments ``dt``: (rho_pred, relative misfit of the
        linearised constraints, > 0 when the actuators over-determine the motion)."""
        if self.soft and not len(self.act):
            # released actuators (least squares, compliant): the energy minimisation moves
            # the state to the new targets from the last one (moving the actuators alone by
            # dt and projecting back onto the manifold can land on another branch)
            return rho.copy(), 0.0
        r, J = self.rc.evaluate(rho)
        self._factor(J)
        da = np.zeros(self.rc.n_var)
        da[self.act] = dt
        b = J @ da
        d = self._solve(-(J.T @ b))
        misfit = float(np.linalg.norm(J @ d + b)) / max(float(np.linalg.norm(b)), 1e-300)
        return rho + d + da, misfit

    def leave_flat(self, rho: np.ndarray, t_new: np.ndarray) -> np.ndarray:
        """First state off the flat one, on the branch the pattern asks for.

        The flat state is a bifurcation point where several branches start (e.g. the two
        modes of a degree-4 vertex), and the actuator targets alone do not say which one to
        take. The rule (docs/solver.md, "Leaving the flat state"): the branch whose creases
        fold with the signs of the *branch direction* ``d`` (the pattern's target fold angles
        where given, else its M/V assignment, V +1, M -1), flipped as a whole when the
        actuator targets ask for the opposite signs. Creases with ``d = 0`` may take either
        sign.

        Levenberg-Marquardt on ``|r(x)|^2 + |min(0, s_i x_i)|^2`` (closure residual and the
        sign violations ``s = sign(scale d)``) from the guess ``x = scale d`` (actuators at
        ``t_new``) lands on a state of that branch when one exists near the guess; otherwise
        the creases still folding against their signs are kept in ``sign_conflicts``.
        Returns the (possibly unconverged) result; the regular corrector finishes it.
        """
        d = _branch_direction(self.rc)
        dA = d[self.drive]
        ok = np.abs(dA) > 1e-12
        if ok.any() and np.any(t_new != 0):
            s = float(np.median(t_new[ok] / dA[ok]))
        else:
            s = float(np.max(np.abs(t_new)) / max(np.max(np.abs(d)), 1e-300))
        sgn = np.where(self.free, np.sign(s * d), 0.0)
        self.mirrored = s < 0.0
        self._lu = None
        # the guess scales every crease alike; where the branch needs very different
        # magnitudes (e.g. mode 2 of a degree-4 vertex) the least-squares landscape has
        # local minima on the sign boundary, so further guesses rescale the free creases
        # (deterministic log-uniform factors in [1/8, 8]); the first that closes wins
        rng = np.random.default_rng(0)
        best: tuple[tuple[bool, float], np.ndarray, list[int]] | None = None
        for attempt in range(8):
            scale = (
                np.ones(self.rc.n_var)
                if attempt == 0
                else 8.0 ** rng.uniform(-1.0, 1.0, self.rc.n_var)
            )
            x0 = rho + s * d * scale
            x0[self.drive] = t_new
            x, rmax, conflicts = self._branch_lm(rho, x0, sgn)
            key = (len(conflicts) > 0, rmax)
            if best is None or key < best[0]:
                best = (key, x, conflicts)
            if rmax <= 1e-6 and not conflicts:
                break
        assert best is not None  # the loop runs at least once
        _, x, self.sign_conflicts = best
        self.branch_attempts = attempt + 1
        self._flat_setup = (rho, s * d, sgn, np.asarray(t_new, dtype=float).copy())
        return x

    def other_landings(self, n: int = 4) -> list[np.ndarray]:
        """Further sign-consistent landings off the flat state of the last
        :meth:`leave_flat` (rescaled guesses, other seeds): where the actuators leave free
        motions, several folded branches match the signs and the one of least fold-spring
        energy is wanted (the caller minimises each)."""
        rho, sd, sgn, t_new = self._flat_setup
        rng = np.random.default_rng(1)
        out = []
        for _ in range(n):
            x0 = rho + sd * 8.0 ** rng.uniform(-1.0, 1.0, self.rc.n_var)
            x0[self.drive] = t_new
            x, rmax, conflicts = self._branch_lm(rho, x0, sgn)
            if rmax <= 1e-6 and not conflicts:
                out.append(x)
        return out

    def _branch_lm(
        self, rho: np.ndarray, x: np.ndarray, sgn: np.ndarray
    ) -> tuple[np.ndarray, float, list[int]]:
        """Levenberg-Marquardt on ``|r(x)|^2 + |min(0, sgn (x - rho))|^2`` from ``x`` with the
        actuators held; returns (x, max |r|, variables against their sign)."""

        def residuals(y: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix, np.ndarray]:
            r, J = self.rc.evaluate(y)
            viol = np.minimum(sgn * (y - rho), 0.0)
            return r, J, viol

        r, J, viol = residuals(x)
        f = float(r @ r + viol @ viol)
        mu = None
        self._lu = None  # the backend keeps one factorisation: the corrector's is replaced
        for _ in range(200):
            if np.max(np.abs(r), initial=0.0) <= 1e-6 and np.max(-viol, initial=0.0) <= 1e-9:
                break  # close enough: Newton finishes
            bound = (viol < 0).astype(float)
            if mu is None:
                mu = 1e-3 * float((_normal_diagonal(J) + bound).max(initial=1.0))
            Kf = self._held_normal(J, bound + mu)
            g = J.T @ r + sgn * viol
            try:
                step = self._backend.factorize(Kf).solve(np.where(self.free, -g, 0.0))
            except (SingularMatrixError, IndefiniteMatrixError):  # damping below round-off
                mu *= 10.0
                if mu > 1e12:
                    break
                continue
            step[~self.free] = 0.0
            r2, J2, v2 = residuals(x + step)
            f2 = float(r2 @ r2 + v2 @ v2)
            if f2 < f:
                x, r, J, viol, f = x + step, r2, J2, v2, f2
                mu *= 0.3
            else:
                mu *= 10.0
                if mu > 1e12:
                    break
            self.iterations += 1
        size = max(float(np.max(np.abs(x - rho), initial=0.0)), 1e-300)
        conflicts = np.flatnonzero(-viol > 1e-3 * size).tolist()
        return x, float(np.max(np.abs(r), initial=0.0)), conflicts

    def lands_flat(self, rho: np.ndarray, t: np.ndarray) -> bool:
        """Whether ``rho`` (converged, actuators at ``t``) is the flat state up to the
        corrector's landing error. With every actuator at 0 the flat state lies on every
        branch, but the closure residual is only quadratic in the distance from it, so a
        corrector may stop up to ~sqrt(tol) away: such a landing is snapped onto it."""
        if np.any(np.abs(t) > 1e-12) or np.max(np.abs(rho), initial=0.0) > 1e-3:
            return False
        flat = np.zeros_like(rho)
        return bool(float(np.max(np.abs(self.rc.residual(flat)), initial=0.0)) <= self.opt.tol)

    # ------------------------------------------------------------ free DOF: energy
    def make_soft(self) -> None:
        """Meet incompatible actuator targets in least squares from now on: the actuators
        are released and pulled to their targets by springs ``soft_weight`` =
        1e6 x the stiffest fold (the fold springs then only resolve what the targets leave
        free)."""
        self.soft = True
        self.act = np.zeros(0, dtype=np.int64)
        self.free = np.ones(self.rc.n_var, bool)
        self.underactuated = True
        self._lu = None

    def hold(self, on: bool) -> None:
        """Hold the driven creases (``on``) or release them: compliant actuators are held
        for the predictor and corrector of a step (so the step stays on its branch) and
        released for the energy minimisation."""
        self.act = self.drive.copy() if on else np.zeros(0, dtype=np.int64)
        free = np.ones(self.rc.n_var, bool)
        free[self.act] = False
        self.free = free
        self._lu = None

    @property
    def soft_weight(self) -> float | np.ndarray:
        """Stiffness of the actuator springs in least-squares mode: the compliant
        actuators' own (:attr:`actuator_k`), else 1e6 x the stiffest fold."""
        if self.actuator_k is not None:
            return self.actuator_k
        return 1e6 * float(self.weights.max(initial=1.0))

    def _springs(self) -> tuple[np.ndarray, np.ndarray]:
        """(weights, centres) of the quadratic energy ``1/2 sum w (rho - c)^2 + const``:
        the fold springs, plus the actuator springs in least-squares mode."""
        if not self.soft:
            return self.weights, self.rest
        w = self.weights.copy()
        c = self.rest.copy()
        d, ws = self.drive, self.soft_weight
        c[d] = (w[d] * c[d] + ws * self.targets_now) / (w[d] + ws)
        w[d] = w[d] + ws
        return w, c

    def energy(self, rho: np.ndarray) -> float:
        """Fold-spring energy ``1/2 sum w (rho - rho_rest)^2`` (moment x radian), plus the
        actuator springs in least-squares mode (up to a constant)."""
        w, c = self._springs()
        e = rho - c
        return 0.5 * float(w @ (e * e))

    def minimize(self, rho: np.ndarray) -> tuple[np.ndarray, bool]:
        """Minimise the fold-spring energy over the free motions at fixed actuators.

        Starting from a state ``rho`` on the constraint manifold, Newton steps on the KKT
        conditions with the exact Hessian of the Lagrangian (fold springs plus
        :meth:`RigidConstraints.multiplier_hessian`), the tangential system

            [W + H(lam)  J^T ] [d  ]   [-W (rho - rho_rest)]
            [J          -dI  ] [lam] = [ 0                 ]

        on the free creases (``d`` a tiny regularisation: redundant loop equations make the
        multipliers non-unique), then the corrector back onto the manifold and a
        backtracking line search on the energy. This is the limit of the bar-and-hinge model
        as the panels become rigid (stationary fold-spring energy subject to rigid folding).
        Returns (rho, converged).
        """
        rc, free = self.rc, self.free
        fi = np.flatnonzero(free)
        W, centre = self._springs()
        delta = 1e-13 / float(W.max(initial=1.0))
        lam = None
        escapes = 0
        # shift added to the Lagrangian Hessian where the Newton step is not a descent
        # direction (an indefinite reduced Hessian: the step would head for a saddle)
        shift, shift0 = 0.0, 1e-2 * float(self.weights.max(initial=1.0))
        e0 = self.energy(rho)
        for _ in range(self.opt.energy_max_iter):
            r, J = rc.evaluate(rho)
            g = W * (rho - centre)
            Jf = J[:, fi]
            Hf = sp.diags(W[fi])
            if lam is not None:
                Hf = Hf + rc.multiplier_hessian(rho, lam)[fi][:, fi]
                if shift > 0.0:
                    Hf = Hf + shift * sp.identity(len(fi))
            m = J.shape[0]
            K = sp.bmat([[Hf, Jf.T], [Jf, -delta * sp.identity(m)]], format="csc")
            rhs = np.concatenate([-g[fi], np.zeros(m)])
            try:
                sol = spla.splu(K, permc_spec="MMD_AT_PLUS_A").solve(rhs)
            except RuntimeError:  # exactly singular KKT matrix
                if lam is None:
                    return rho, False
                lam = None
                continue
            d = np.zeros(rc.n_var)
            d[fi] = sol[: len(fi)]
            lam_new = sol[len(fi) :]
            if not np.all(np.isfinite(sol)):
                return rho, False
            dmax = float(np.max(np.abs(d), initial=0.0))
            log.debug("minimize: |d| %.3e, newton %s, E %.6e", dmax, lam is not None, e0)
            if (
                self.opt.saddle_shift
                and lam is not None
                and dmax > self.opt.energy_tol
                and float(g[fi] @ d[fi]) >= 0.0
            ):
                # not a descent direction: the reduced Hessian is indefinite here; shift it
                # (Levenberg) instead of converging to the saddle Newton is heading for
                shift = max(4.0 * shift, shift0)
                self.energy_iterations += 1
                continue
            if dmax <= self.opt.energy_tol:
                # a stationary point; Newton on the KKT conditions also converges to saddles,
                # so leave along a direction of negative curvature when there is one
                esc = self._escape_saddle(rho, lam_new, e0) if escapes < 8 else None
                if esc is None:
                    return rho, True
                # keep the multipliers, with the Hessian shifted past the negative curvature
                # so that Newton descends away from the saddle instead of back to it
                rho, curv = esc
                e0, escapes = self.energy(rho), escapes + 1
                if self.opt.saddle_shift:
                    lam, shift = lam_new, max(shift0, -2.0 * curv)
                else:
                    lam = None
                continue
            if dmax > 0.5:
                d *= 0.5 / dmax
            # line search on the energy, each trial projected back onto the manifold
            alpha, accepted = 1.0, False
            for _ls in range(12):
                trial, _, ok = self.corrector(rho + alpha * d)
                if ok and (self.energy(trial) <= e0 + 1e-14 * max(abs(e0), 1.0) or dmax < 1e-6):
                    rho, e0, accepted = trial, self.energy(trial), True
                    break
                alpha *= 0.5
            self.energy_iterations += 1
            if accepted:
                shift = 0.0 if shift < 1e-6 * shift0 else 0.25 * shift
            if not accepted:
                if lam is None:
                    return rho, False
                lam = None  # indefinite Lagrangian Hessian: fall back to the spring metric
                continue
            lam = lam_new
        return rho, False

    def _escape_saddle(
        self, rho: np.ndarray, lam: np.ndarray, e0: float
    ) -> tuple[np.ndarray, float] | None:
        """A lower-energy state near the stationary state ``rho`` (multipliers ``lam``) along
        the most negative curvature of the Lagrangian on the tangent space of the free
        creases, with that curvature (per unit of the normalised direction), or None when
        it is positive (a minimum) or the tangent space is too large for a dense check (more
        than ``SADDLE_CHECK_MAX`` free creases)."""
        import scipy.linalg as sla

        fi = np.flatnonzero(self.free)
        if len(fi) > SADDLE_CHECK_MAX:
            return None
        W, _ = self._springs()
        J = self.rc.jacobian(rho)[:, fi].toarray()
        Z = sla.null_space(J, rcond=1e-9)
        if Z.shape[1] == 0:
            return None
        H = np.diag(W[fi]) + self.rc.multiplier_hessian(rho, lam)[fi][:, fi].toarray()
        vals, vecs = np.linalg.eigh(Z.T @ H @ Z)
        if vals[0] >= -1e-9 * float(np.abs(vals).max(initial=1.0)):
            return None
        v = np.zeros(self.rc.n_var)
        v[fi] = Z @ vecs[:, 0]
        vmax = float(np.max(np.abs(v)))
        v /= vmax
        for step in (0.1, 0.03, 0.01, 0.003, 1e-3):
            best = None
            for sgn in (1.0, -1.0):
                trial, _, ok = self.corrector(rho + sgn * step * v)
                if ok and self.energy(trial) < e0 - 1e-12 * max(abs(e0), 1e-300):
                    if best is None or self.energy(trial) < self.energy(best):
                        best = trial
            if best is not None:
                log.debug("minimize: left a saddle (curvature %.3e)", vals[0])
                return best, float(vals[0])
        return None


#: free creases up to which stationary states are checked for negative curvature (dense)
SADDLE_CHECK_MAX = 2000


def _least_energy_branch(solver: RigidSolver, first: np.ndarray) -> np.ndarray:
    """Of the energy minima reached from several sign-consistent landings off the flat state
    (``first`` among them), the one with fewest creases against the branch signs, then of
    least fold-spring energy."""
    _, _, sgn, _ = solver._flat_setup

    def key(x: np.ndarray) -> tuple[int, float]:
        size = max(float(np.max(np.abs(x), initial=0.0)), 1e-300)
        return int(np.sum(sgn * x < -1e-6 * size)), solver.energy(x)

    best, k_best = first, key(first)
    for x in solver.other_landings():
        cand, _, ok = solver.corrector(x)
        if not ok:
            continue
        cand, ok = solver.minimize(cand)
        k = key(cand)
        if ok and (k[0] < k_best[0] or (k[0] == k_best[0] and k[1] < k_best[1] * (1 - 1e-9))):
            best, k_best = cand, k
    return best


def _normal_backend(n_var: int) -> LinearBackend:
    """The corrector's backend: PARDISO's Cholesky from ``PARDISO_MIN_VARS`` crease
    variables on (where it imports; the normal matrices are positive definite off the
    bifurcation points, and :class:`IndefiniteMatrixError` names one that is not), else the
    fastest other backend; SuperLU below."""
    if n_var < PARDISO_MIN_VARS:
        return get_backend("superlu")
    if "pardiso" in available_backends():
        try:
            return PardisoBackend(definite=True)
        except Exception as exc:  # a broken optional install must not stop a fold
            log.debug("PARDISO unavailable: %s", exc)
    return get_backend("auto")


def _normal_diagonal(J: sp.csr_matrix) -> np.ndarray:
    """Diagonal of ``J^T J`` (the squared column norms of ``J``)."""
    return np.bincount(J.indices, weights=J.data * J.data, minlength=J.shape[1])


def _as_actuators(actuators: Actuators | Sequence[int], targets_deg) -> Actuators:
    if isinstance(actuators, Actuators):
        if targets_deg is not None:
            raise ConfigError("give targets_deg inside the Actuators object, not both")
        return actuators
    if targets_deg is None:
        raise ConfigError("targets_deg is required when actuators is a list of edge ids")
    return Actuators(edges=list(actuators), targets_deg=targets_deg)


@threads_for_sparse
def rigid_fold(
    cp: CreasePattern,
    actuators: Actuators | Sequence[int],
    targets_deg: Sequence[float] | float | None = None,
    steps: int = 50,
    *,
    triangulated: bool = False,
    options: RigidOptions | None = None,
    fold_stiffness: np.ndarray | float | None = None,
    diagonal_stiffness: float | None = None,
) -> FoldPath:
    """Fold ``cp`` as a rigid origami by driving actuator creases.

    Where the actuators leave free motions, they are resolved by minimising the fold-spring
    energy ``1/2 sum k_e (rho_e - rho_e0)^2`` subject to rigid folding: the limit of the
    bar-and-hinge model as panels and bars become rigid. At the flat state the path leaves
    along the branch that matches the M/V assignment (see :meth:`RigidSolver.leave_flat`).

    Parameters
    ----------
    cp : CreasePattern
        Pattern; its geometry (flat or folded) is state 0.
    actuators : Actuators or sequence of int
        Actuated pattern edge ids, or an :class:`~barhinge.actuators.Actuators` whose
        ``schedule`` gives the targets per step (starting from the current angles).
    targets_deg : float or sequence of float, optional
        Final actuator fold angles (degrees, valley > 0) with a list of edge ids; reached
        linearly in ``steps``.
    steps : int
        Number of steps (ignored for an ``Actuators`` with ``table_deg``: its rows are steps).
    triangulated : bool
        Let panels fold along diagonals (else panels stay rigid and planar).
    options : RigidOptions, optional
    fold_stiffness : float or (n_edges,) float, optional
        Fold-spring stiffness of each pattern edge (moment per radian); default: the crease
        length (a uniform stiffness per unit length, as the bar-and-hinge default). Only
        ratios matter.
    diagonal_stiffness : float, optional
        With ``triangulated``: stiffness of the panel diagonals (default 1e4 x the median
        fold stiffness: panels bend far less readily than creases fold).

    Returns
    -------
    FoldPath
        ``kind="rigid"``; ``X`` (n_states, n_vertices, 3) holds the pattern's vertices;
        ``fold_angles_deg`` (n_states, n_edges) per pattern edge; ``meta`` records the
        largest closure residual, the DOF per state when checked, and events.

    Raises
    ------
    ConfigError
        An actuator is not a foldable crease, the actuators leave free motions, or their
        targets are incompatible.
    ConvergenceError
        A crease locks at +-180 deg or the constraints cannot be closed; ``last_state`` is the
        partial path.
    """
    opt = options or RigidOptions()
    act = _as_actuators(actuators, targets_deg)
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    for e in act.edges:
        if e < 0 or e >= cp.n_edges:
            raise ConfigError(f"actuator edge {e} does not exist (0..{cp.n_edges - 1})")
    av = rc.var_of_source_edge[act.edges]
    if np.any(av < 0):
        e = int(act.edges[np.flatnonzero(av < 0)[0]])
        raise ConfigError(
            f"actuator edge {e} (assignment {cp.assignment[e]}) is not a foldable interior crease"
        )
    rho = rc.rho0.copy()
    if act.table_deg is not None:
        steps = len(act.table_deg)
    sched = np.radians(act.schedule(steps, start_deg=np.degrees(rho[av])))
    weights = _spring_weights(rc, fold_stiffness, diagonal_stiffness)
    solver = RigidSolver(rc, av, opt, weights)
    if act.compliant:
        # compliant actuators: springs to their targets from the first step (the state is
        # the least fold-plus-actuator-spring energy on the rigid-folding manifold)
        solver.actuator_k = np.asarray(act.stiffness, dtype=float)
        solver.make_soft()
    if rc.holes:
        log.warning(
            "the pattern has %d hole(s): loops of panels around holes are not constrained; "
            "the rigid path may open them",
            rc.holes,
        )
    check_rank = opt.check_rank if opt.check_rank is not None else rc.n_var <= 300

    t0 = time.perf_counter()
    states = [rho.copy()]
    iters = [0]
    hists: list[tuple[float, ...]] = [()]
    walls = [0.0]
    dofs: list[int] = []
    events: list[str] = []
    checked = False
    free_dof: int | None = None
    soft_from: tuple[int, str] | None = None
    track: list[tuple[float, np.ndarray]] = [(0.0, rho.copy())]

    def dof_at(x: np.ndarray) -> int:
        sv = np.linalg.svd(rc.jacobian(x).toarray(), compute_uv=False)
        return rc.n_var - int(np.sum(sv > DENSE_TOL * max(sv.max(initial=0.0), 1e-300)))

    if check_rank:
        dofs.append(dof_at(rho))

    def partial(msg: str) -> FoldPath:
        return _make_path(
            solver,
            cp,
            act,
            sched,
            states,
            iters,
            hists,
            walls,
            False,
            msg,
            dofs,
            events,
            free_dof,
        )

    def failure(msg: str, s: int, hist: list[float]) -> ConvergenceError:
        """The error for a failed step ``s`` (1-based), carrying the converged part."""
        return ConvergenceError(
            msg, step=s - 1, load_factor=(s - 1) / steps, residuals=hist, last_state=partial(msg)
        )

    for s in range(1, steps + 1):
        solver.iterations = 0
        hist_all: list[float] = []
        check_misfit = (
            opt.check_actuators
            and not checked
            and not (np.max(np.abs(rho), initial=0.0) < FLAT_TOL)
        )
        least_squares = opt.over_actuated == "least_squares" and len(av) >= 2
        singular_before = solver.singular_attempts
        while True:
            try:
                ok, rho_new, over = _advance(
                    solver, rho, sched[s - 1], sched[s], opt, hist_all, track, check_misfit
                )
            except _Singular:
                msg = (
                    f"step {s}: the Jacobian of the free creases is singular (a bifurcation "
                    f"point or actuators that leave free motions)"
                )
                raise failure(msg, s, hist_all) from None
            except _Incompatible as exc:
                if not least_squares:
                    why = _dependent_actuators(rc, rho, av, np.asarray(act.edges))
                    raise ConfigError(f"{exc}; {why}") from None
                ok, soft_from = False, (s, str(exc).split(";")[0])
            else:
                flat_fail = not ok and np.max(np.abs(rho), initial=0.0) < FLAT_TOL
                if not (flat_fail and least_squares and not solver.soft):
                    break
                soft_from = (s, "no rigid fold off the flat state meets the targets together")
            # incompatible targets: meet them in least squares from this step on
            solver.make_soft()
            hist_all.clear()
            del track[:-1]
            check_misfit = False
        if solver.soft and soft_from is not None and ok:
            mis = np.degrees(rho_new[av] - sched[s])
            ev = (
                f"step {soft_from[0]}: actuator targets incompatible ({soft_from[1]}); met in "
                f"least squares from here, misfit up to {np.max(np.abs(mis)):.3g} deg; "
                f"{_dependent_actuators(rc, rho_new, av, np.asarray(act.edges))}"
            )
            events.append(ev)
            log.warning(ev)
            soft_from = None
        if s == 1 and solver.mirrored and not solver.sign_conflicts:
            ev = (
                "step 1: the actuator targets ask for the mirror image of the branch "
                "direction: every crease folds with the opposite of its M/V sign"
            )
            events.append(ev)
            log.warning(ev)
        if s == 1 and solver.sign_conflicts:
            bad = sorted({int(rc.var_source_edge[v]) for v in solver.sign_conflicts} - {-1})
            ev = (
                f"step 1: no rigid branch off the flat state near the M/V assignment: creases "
                f"{bad} fold against it; choose the branch with target fold angles"
            )
            events.append(ev)
            log.warning(ev)
        if not ok and over < 0 and np.max(np.abs(rho), initial=0.0) >= FLAT_TOL:
            # would the tangent towards the target carry a crease past +-180 deg?
            try:
                pred, _ = solver.tangent(rho, sched[s] - rho[av])
                if np.all(np.isfinite(pred)) and np.max(np.abs(pred)) >= np.pi:
                    over = int(np.argmax(np.abs(pred)))
            except RuntimeError:  # singular: a limit point of the actuator
                pass
        if not ok:
            # rho_new: the furthest state reached inside the step (after cut-backs)
            worst = int(np.argmax(np.abs(rho_new))) if over < 0 else over
            e = int(rc.var_source_edge[worst])
            ang = float(np.degrees(rho_new[worst]))
            if over >= 0:
                msg = (
                    f"step {s}: locked: crease edge {e} (at {ang:.3f} deg) would pass "
                    f"+-180 deg before the actuators reach their targets (panels meet)"
                )
            elif abs(ang) > 170.0:
                msg = (
                    f"step {s}: locked: crease edge {e} is at {ang:.3f} deg, the panels meet "
                    f"before the actuator targets"
                )
            elif solver.energy_failed:
                msg = (
                    f"step {s}: the fold-spring energy over the free motions the actuators "
                    f"leave did not reach a minimum in {opt.energy_max_iter} Newton iterations "
                    f"after {opt.max_cutbacks} cut-backs; drive more creases"
                )
            elif solver.fell_flat:
                msg = (
                    f"step {s}: the corrector closed every loop only by falling back to the "
                    f"flat state, where the released actuators' springs are not in "
                    f"equilibrium, after {opt.max_cutbacks} cut-backs (targets met in least "
                    f"squares or by compliant actuators); drive fewer creases or make their "
                    f"targets agree"
                )
            elif solver.singular_attempts > singular_before:
                msg = (
                    f"step {s}: the Jacobian of the free creases is singular near the path "
                    f"after {opt.max_cutbacks} cut-backs (a bifurcation point the actuators "
                    f"cannot pass; drive other creases)"
                )
            else:
                flat = np.max(np.abs(rho), initial=0.0) < FLAT_TOL
                hint = (
                    " leaving the flat state along the M/V assignment; the actuators may "
                    "over-determine the motion or the pattern may not be rigidly foldable"
                    if flat
                    else ""
                )
                msg = (
                    f"step {s}: the loop-closure residual did not close (last "
                    f"{hist_all[-1] if hist_all else float('nan'):.2e} > {opt.tol:.0e}) after "
                    f"{opt.max_cutbacks} cut-backs{hint}"
                )
            raise failure(msg, s, hist_all)
        rho = rho_new
        if np.max(np.abs(rho)) >= np.radians(opt.lock_deg):
            worst = int(np.argmax(np.abs(rho)))
            e = int(rc.var_source_edge[worst])
            states.append(rho.copy())
            iters.append(solver.iterations)
            hists.append(tuple(hist_all))
            walls.append(time.perf_counter() - t0)
            msg = (
                f"step {s}: locked: crease edge {e} reached {np.degrees(rho[worst]):.3f} deg "
                f"(+-180 deg: the panels meet)"
            )
            raise ConvergenceError(
                msg, step=s - 1, load_factor=s / steps, residuals=hist_all, last_state=partial(msg)
            )
        if opt.check_actuators and not checked and np.max(np.abs(rho)) >= FLAT_TOL:
            k, r = solver.dof_rank or _actuator_rank(rc, rho, av)
            _log_actuators(k, r, len(av), np.asarray(act.edges))
            free_dof = k - r
            checked = True
        states.append(rho.copy())
        iters.append(solver.iterations)
        hists.append(tuple(hist_all))
        walls.append(time.perf_counter() - t0)
        if check_rank:
            dofs.append(dof_at(rho))
            if len(dofs) >= 3 and dofs[-1] != dofs[-2]:
                ev = f"step {s}: DOF changed from {dofs[-2]} to {dofs[-1]} (singular state)"
                events.append(ev)
                log.warning(ev)
    return _make_path(
        solver, cp, act, sched, states, iters, hists, walls, True, "", dofs, events, free_dof
    )


def _predict(
    solver: RigidSolver,
    cur: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    s_new: float,
    flat: bool,
    opt: RigidOptions,
    track: list[tuple[float, np.ndarray]],
    check_misfit: bool,
) -> tuple[np.ndarray, bool]:
    """The predicted state for actuators going from ``a`` to ``b`` (the branch rule off a
    flat state, extrapolation through the last states, or the tangent bent through the
    state before) and whether the misfit is still to be checked."""
    guess = None
    if flat:
        guess = solver.leave_flat(cur, b)
    elif not check_misfit:
        guess = extrapolate(track, s_new)
    if guess is None:
        guess, misfit = solver.tangent(cur, b - a)
        if misfit > 1e-6 and opt.check_actuators and not solver.soft:
            raise _Incompatible(
                f"the actuators over-determine the motion and their targets are "
                f"incompatible (linearised misfit {misfit:.1e})"
            )
        check_misfit = False
        if len(track) >= 2 and track[-1][0] > track[-2][0]:
            # Hermite: bend the tangent through the state before (error O(h^3))
            (s0, r0), (s1, r1) = track[-2], track[-1]
            h, h0 = s_new - s1, s0 - s1
            slope = (guess - r1) / h
            c = (r0 - r1 - slope * h0) / h0**2
            guess = guess + c * h * h
    return guess, check_misfit


def _advance(
    solver: RigidSolver,
    rho: np.ndarray,
    t_old: np.ndarray,
    t_new: np.ndarray,
    opt: RigidOptions,
    hist_all: list[float],
    track: list[tuple[float, np.ndarray]],
    check_misfit: bool,
) -> tuple[bool, np.ndarray, int]:
    """Go from ``rho`` (actuators at t_old) to actuators at t_new, cutting back on failure.

    ``track`` holds (path parameter, rho) of the last converged states (parameter = distance
    travelled by the actuator angles); it is extended in place. Returns (ok, rho, var) with
    ``var`` the crease whose angle passed +-180 deg in the last rejected attempt (-1 if none).
    """
    pending = [(t_old, t_new, 0)]
    cur = rho
    over = -1
    compliant = solver.actuator_k is not None
    while pending:
        a, b, depth = pending.pop()
        solver.targets_now = np.asarray(b, dtype=float).copy()
        s_new = track[-1][0] + float(np.linalg.norm(b - a)) if track else 0.0
        flat = np.max(np.abs(cur), initial=0.0) < FLAT_TOL
        # compliant actuators: predict and correct with them held (the step stays on its
        # branch), then release them; targets no rigid fold meets together cannot be held,
        # and from the first such failure on the prediction releases them too
        held = compliant and solver.hold_compliant
        for attempt in (True, False) if held else (False,):
            if compliant:
                solver.hold(attempt)
            guess, check_misfit = _predict(solver, cur, a, b, s_new, flat, opt, track, check_misfit)
            if flat or not solver.soft:
                # held actuators sit at their targets; released ones (least squares,
                # compliant) start where they were and the energy minimisation moves them
                guess[solver.drive] = b
            solver.last_guess = guess
            new, hist, ok = solver.corrector(guess)
            if compliant:
                solver.hold(False)
            hist_all.extend(hist)
            if ok or not attempt:
                break
            solver.hold_compliant = False
        if ok and np.max(np.abs(new)) > np.pi:
            ok = False
            over = int(np.argmax(np.abs(new)))
        elif not ok:
            over = -1
        if ok and solver.lands_flat(new, b):
            new = np.zeros_like(new)
        solver.fell_flat = False
        if ok and solver.soft and np.max(np.abs(new), initial=0.0) < FLAT_TOL and np.any(b):
            # released actuators pulled towards non-zero targets never rest flat: a landing
            # there (the flat state closes every loop) is a corrector artefact; cut back
            ok = False
            solver.fell_flat = True
        if ok and np.max(np.abs(new), initial=0.0) >= FLAT_TOL:
            if solver.underactuated is None:
                solver.dof_rank = _actuator_rank(solver.rc, new, solver.act)
                solver.underactuated = solver.dof_rank[0] > solver.dof_rank[1]
            if solver.underactuated:
                new, ok = solver.minimize(new)
                if not ok:
                    solver.energy_failed = True
                elif flat and solver.free.sum() <= SADDLE_CHECK_MAX:
                    new = _least_energy_branch(solver, new)
        if ok:
            cur = new
            track.append((s_new, new.copy()))
            del track[:-EXTRAPOLATION_POINTS]
            if flat:
                solver._lu = None  # factorised near the singular flat state: refresh
            continue
        if depth >= opt.max_cutbacks:
            return False, cur, over
        mid = 0.5 * (a + b)
        pending.append((mid, b, depth + 1))
        pending.append((a, mid, depth + 1))
        solver._lu = None
        del track[:-1]  # the extrapolation overshot: restart it from the last state
    return True, cur, -1


def _spring_weights(
    rc: RigidConstraints,
    fold_stiffness: np.ndarray | float | None,
    diagonal_stiffness: float | None,
) -> np.ndarray:
    """(n_var,) fold-spring stiffness of each variable: pattern creases from
    ``fold_stiffness`` (scalar or per source edge; default the crease length), panel
    diagonals ``diagonal_stiffness`` (default 1e4 x the median crease)."""
    pat = rc.pattern
    E = pat.edges[rc.crease_edge]
    length = np.linalg.norm(pat.vertices3d[E[:, 1]] - pat.vertices3d[E[:, 0]], axis=1)
    src = rc.var_source_edge
    crease = src >= 0
    w = np.zeros(rc.n_var)
    if fold_stiffness is None:
        w[crease] = length[crease]
    else:
        k = np.asarray(fold_stiffness, dtype=float)
        if k.ndim == 0:
            w[crease] = float(k)
        elif k.shape == (rc.source.n_edges,):
            w[crease] = k[src[crease]]
        else:
            raise ConfigError(
                f"fold_stiffness has shape {k.shape}; expected a scalar or "
                f"({rc.source.n_edges},) (one per pattern edge)"
            )
    if not np.all(np.isfinite(w)) or np.any(w[crease] <= 0):
        raise ConfigError("fold_stiffness must be finite and > 0 on every crease")
    if (~crease).any():
        kd = 1e4 * float(np.median(w[crease])) if diagonal_stiffness is None else diagonal_stiffness
        if not (np.isfinite(kd) and kd > 0):
            raise ConfigError(f"diagonal_stiffness = {kd}; expected a finite value > 0")
        w[~crease] = kd
    return w


def _dependent_actuators(
    rc: RigidConstraints, rho: np.ndarray, av: np.ndarray, edges: np.ndarray
) -> str:
    """Which actuators follow from the others at the folded state ``rho``: the rows of the
    null-space basis at the actuators, ordered by QR with column pivoting; the first
    ``rank`` are independent."""
    import scipy.linalg as sla

    ns = null_space(rc.jacobian(rho))  # no basis_limit: the basis is always formed
    assert ns.basis is not None
    NA = ns.basis[av]
    if NA.size == 0:
        return f"the motion has no DOF left for the actuators {edges.tolist()}"
    _, R, piv = sla.qr(NA.T, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    r = int(np.sum(d > 1e-8 * max(d.max(initial=0.0), 1e-300)))
    ind, dep = edges[piv[:r]].tolist(), edges[piv[r:]].tolist()
    return (
        f"the motion has {ns.basis.shape[1]} DOF and the actuators fix {r}: "
        f"edges {dep} follow from edges {ind} (drive fewer creases or make their targets agree)"
    )


def actuator_conflict(
    cp: CreasePattern, actuators: Actuators, steps: int, misfit_tol: float = 1e-6
) -> str | None:
    """Do the actuators conflict at the state of ``cp`` (its geometry, folded)? The rank test
    of the rigid-folding constraints with the actuators added, on the first increment
    ``dt`` of the schedule over ``steps`` steps (from the current angles): compatible when
    ``J_F d_F = -J_A dt`` has a solution (free creases ``F``, actuators ``A``; linearised at
    the state). Returns None when it has (or when ``cp`` is flat, where the constraints are
    singular and the rigid fold off the flat state decides), else a one-line reason naming
    the dependent actuators (:func:`_dependent_actuators`) and the relative misfit.
    """
    rc = RigidConstraints.from_pattern(cp)
    edges = np.asarray(actuators.edges, dtype=np.int64)
    av = rc.var_of_source_edge[edges]
    rho = rc.rho0
    if np.any(av < 0) or len(av) < 2 or np.max(np.abs(rho), initial=0.0) < FLAT_TOL:
        return None
    sched = np.radians(actuators.schedule(steps, start_deg=rc.angles_of_edges(rho)[edges]))
    dt = sched[1] - sched[0]
    if not np.any(dt != 0.0):
        return None
    solver = RigidSolver(rc, av, RigidOptions())
    try:
        _, misfit = solver.tangent(rho, dt)
    except _Singular:
        misfit = np.inf
    if misfit <= misfit_tol:
        return None
    return (
        f"the actuator targets conflict at the start state (rigid folding with the actuators "
        f"added: linearised misfit {misfit:.1e}); {_dependent_actuators(rc, rho, av, edges)}"
    )


def _actuator_rank(rc: RigidConstraints, rho: np.ndarray, av: np.ndarray) -> tuple[int, int]:
    """(DOF, rank of the actuators on it) at the folded state ``rho``: the nullity of the
    Jacobian and the rank of the actuator rows of its null-space basis; ``DOF - rank``
    motions are left free (resolved by the fold-spring energy)."""
    ns = null_space(rc.jacobian(rho))  # no basis_limit: the basis is always formed
    assert ns.basis is not None
    NA = ns.basis[av]
    r = int(np.linalg.matrix_rank(NA, tol=1e-8)) if NA.size else 0
    return ns.basis.shape[1], r


def _log_actuators(k: int, r: int, n_act: int, edges: np.ndarray) -> None:
    if r < k:
        log.info(
            "the actuators %s fix %d of the %d DOF; the other %d are resolved by minimising "
            "the fold-spring energy",
            edges.tolist(),
            r,
            k,
            k - r,
        )
    if n_act > r:
        log.info(
            "actuators %s over-determine the motion (DOF %d): targets must stay compatible",
            edges.tolist(),
            k,
        )


def _make_path(
    solver, cp, act, sched, states, iters, hists, walls, converged, msg, dofs, events, free_dof
) -> FoldPath:
    rc, opt = solver.rc, solver.opt
    R = np.asarray(states)
    n = len(R)
    # every state's coordinates in one composition of the face tree, in chunks of at most
    # ~4e6 face poses (0.3 GB of rotations)
    chunk = max(1, 4_000_000 // max(rc.pattern.n_faces, 1))
    X = np.concatenate([rc.coordinates(R[i : i + chunk]) for i in range(0, n, chunk)])
    ang = np.stack([rc.angles_of_edges(r) for r in R])
    closure = [float(rc.closure_error(r).max()) if len(rc.vertices) else 0.0 for r in R]
    meta = {
        "triangulated": rc.triangulated,
        "max_closure": max(closure),
        "closure": closure,
        "tol": opt.tol,
        "dof": dofs,
        "events": events,
        "holes": rc.holes,
        "free_dof": free_dof,
        "fold_energy": [solver.energy(r) for r in R],
        "energy_iterations": solver.energy_iterations,
        "branch": ("target fold angles" if np.any(cp.fold_angles != 0) else "M/V assignment"),
        "mirrored": bool(solver.mirrored),
        "least_squares": bool(solver.soft and solver.actuator_k is None),
        "compliant_actuators": solver.actuator_k is not None,
        "actuator_stiffness": (
            None if solver.actuator_k is None else [float(k) for k in solver.actuator_k]
        ),
        "actuator_misfit_deg": [
            float(np.max(np.abs(np.degrees(r[solver.drive]) - t), initial=0.0))
            for r, t in zip(R, np.degrees(sched[: len(R)]), strict=True)
        ],
        "sign_conflicts": sorted(
            {int(rc.var_source_edge[v]) for v in solver.sign_conflicts} - {-1}
        ),
    }
    return FoldPath(
        X=X,
        fold_angles_deg=ang,
        actuator_edges=act.edges,
        actuator_targets_deg=np.degrees(sched[:n]),
        iterations=np.asarray(iters),
        residual_norms=tuple(hists),
        wall_time=np.asarray(walls),
        converged=converged,
        message=msg,
        kind="rigid",
        meta=meta,
    )
