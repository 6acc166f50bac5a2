"""What every control of the Newton driver evaluates: the actuator schedule and prescribed
displacements along the path parameter, the residual and tangent at a state, and the
factorisation of the bordered system (:class:`SolveContext`)."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import scipy.sparse as sp

from barhinge._protocols import SolverModel
from barhinge.linalg.backends import SingularMatrixError, get_backend
from barhinge.linalg.indices import pattern_positions
from barhinge.solver.bordered import ActuatorTerms, BorderedSystem, Timer, actuator_terms
from barhinge.solver.diagnose import check_finite_tangent
from barhinge.solver.state import Evaluation, IncrementFailed, IterationStatus, State
from barhinge.solver.trace import IterateLog
from barhinge.solver_options import SolverOptions

if TYPE_CHECKING:
    from barhinge.scene import Scene

__all__ = ["SolveContext"]


class SolveContext:
    """The discretised problem of a scene: fixed and free DOFs, loads, actuator schedule,
    the bordered system and the scales of the convergence test.

    ``force_floor`` (force) and ``penalty`` are set at the first evaluation unless the
    options give them; ``c_scale`` (force / rad) weighs the actuator rows against the force
    rows."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.model: SolverModel = scene.model
        model = self.model
        opts = scene.options
        assert isinstance(opts, SolverOptions)  # Scene.__post_init__ normalises it
        self.opts: SolverOptions = opts
        self.X0 = np.asarray(model.X0, float)
        self.n_dof = self.X0.size
        assert scene.fixed is not None and scene.loads is not None  # set by Scene.__post_init__
        self.fixed: np.ndarray = scene.fixed.ravel()
        self.free: np.ndarray = ~self.fixed
        self.P: np.ndarray = scene.loads.ravel()
        #: follower pressure (load at the current geometry), None without
        self.follower = scene.follower
        assert scene.prescribed is not None
        pres = scene.prescribed.ravel()
        self.u_pres = np.where(np.isfinite(pres), pres, 0.0)
        self.hinges = scene.actuator_hinges()
        acts = scene.actuators
        #: (n_drive,) stiffness of compliant actuators (springs in the residual and tangent,
        #: force x length / rad), None for held actuators (constraint rows)
        self.k_act: np.ndarray | None = (
            np.asarray(acts.stiffness, float) if acts is not None and acts.compliant else None
        )
        #: driven creases, held or compliant
        self.n_drive = len(self.hinges)
        #: constraint rows of the bordered system: the held actuators
        self.n_act = 0 if self.k_act is not None else self.n_drive
        self.schedule = np.radians(scene.actuator_schedule_deg())  # (steps+1, n_act)
        self.timer = Timer()
        ext = np.ptp(self.X0, axis=0)
        self.size = float(np.linalg.norm(ext)) or 1.0
        self.force_floor: float | None = self.opts.force_floor
        self.penalty: float | None = None
        # positions of the free diagonal in the values of K's pattern (the arrays held)
        self._diag_pos = np.zeros(0, np.int64)
        self._diag_arrays: tuple[Any, Any] = (None, None)
        self.c_scale = 1.0
        #: told of every iterate (:meth:`iterate`); None: nobody listens
        self.on_iteration: Callable[[IterationStatus], None] | None = None
        # (step, steps, value, length, failed) of the current increment, its iterates so far
        self._increment: tuple[int, int, float, float, int] = (0, 0, 0.0, 1.0, 0)
        self._n_iterate = 0
        #: every iterate of the solve (``FoldPath.meta["iterates"]``)
        self.log = IterateLog()

    def make_system(self) -> BorderedSystem:
        """The bordered system of this problem (after the scene checks)."""
        self.backend = get_backend(self.opts.linear_solver)
        terms0 = actuator_terms(self.model, self.X0, self.hinges, hessians=False)
        self.system = BorderedSystem(
            self.backend,
            self.free,
            terms0.dofs,
            self.timer,
            reuse=self.opts.reuses_factorization(self.scene.control),
            krylov_max=self.opts.krylov_max,
        )
        return self.system

    @property
    def floor(self) -> float:
        """The force floor of the convergence test (after the first evaluation), force."""
        assert self.force_floor is not None
        return self.force_floor

    # ------------------------------------------------------------ schedules
    def targets(self, t: float) -> np.ndarray:
        """Actuator target angles (rad) at path parameter t (linear between rows)."""
        if not self.n_drive:
            return np.zeros(0)
        s = t * self.scene.steps
        i = min(int(np.floor(s)), self.scene.steps - 1)
        f = s - i
        return (1 - f) * self.schedule[i] + f * self.schedule[i + 1]

    def fixed_coords(self, t: float) -> np.ndarray:
        """Coordinates of the fixed DOFs at path parameter t, length."""
        return self.X0.ravel()[self.fixed] + t * self.u_pres[self.fixed]

    # ------------------------------------------------------------ live progress
    def begin_increment(
        self, step: int, steps: int, value: float, length: float, failed: int
    ) -> None:
        """An increment starts: requested ``step`` of ``steps``, aiming at the path
        parameter ``value``, ``length`` a whole step's (see :class:`IterationStatus`), after
        ``failed`` failed increments of the step."""
        self._increment = (step, steps, value, length, failed)
        self._n_iterate = 0
        self.log.begin_increment()

    def begin_landing(self, value: float) -> None:
        """A correction onto an arc-length stop starts (a load-factor or displacement stop
        passed): a new increment of the current one's step, aiming at ``value`` (load
        factor)."""
        step, steps, _, length, failed = self._increment
        self.begin_increment(step, steps, value, length, failed)

    def iterate(
        self,
        residual: float,
        value: float | None = None,
        correction: float = float("nan"),
        kind: str = "newton",
    ) -> None:
        """Count one iterate of the current increment, whose free force residual norm is
        ``residual`` (``value``: its path parameter or load factor, if not the increment's
        aim; ``correction``: the norm of the free displacement change that made it, length;
        ``kind``: what made it, :data:`barhinge.solver.trace.ITERATE_KINDS`), log it and
        tell ``on_iteration``."""
        self.timer.n_iterations += 1
        step, steps, aim, length, failed = self._increment
        v = aim if value is None else float(value)
        n_fact = self.timer.n_factorizations
        self.log.add(step, self._n_iterate, v, length, residual, correction, kind, n_fact)
        if self.on_iteration is not None:
            status = IterationStatus(
                step, steps, v, length, self._n_iterate, residual, failed, correction, kind
            )
            self.on_iteration(status)
        self._n_iterate += 1

    # ------------------------------------------------------------ evaluation
    def evaluate(self, st: State, tangent: bool = True) -> Evaluation:
        """Residual, constraints and (unless ``tangent`` is False) the tangent at ``st``."""
        t0 = time.perf_counter()
        X = st.x.reshape(-1, 3)
        tangent = tangent or self.force_floor is None or self.penalty is None
        ev = self.model.evaluate(X, tangent=tangent)
        self.timer.n_force_only += not tangent
        # a residual alone needs no actuator Hessians (factorize adds them when needed)
        terms = actuator_terms(self.model, X, self.hinges, hessians=tangent)
        P = self.P
        if self.follower is not None:
            P = P + self.follower.force(self.model, X)
            if ev.K is not None and st.lam != 0.0:
                # the symmetric part of the load stiffness (exact residual, symmetric tangent)
                Kl = self.follower.stiffness(self.model, X)
                K = (ev.K - (0.5 * st.lam) * (Kl + Kl.T)).tocsr()
                ev = dataclasses.replace(cast(Any, ev), K=K)  # the model's frozen dataclass
        dt = time.perf_counter() - t0
        self.timer.assembly += dt
        if tangent:
            self.timer.n_tangent += 1
            self.timer.assembly_tangent += dt
        r = np.asarray(ev.force, float).ravel() - st.lam * P
        mu_act = st.mu
        if self.k_act is not None:  # compliant: spring moments k (rho - target)
            mu_act = self.k_act * _wrap(terms.rho - self.targets(st.t))
        if self.n_drive:
            r = r + terms.G.T @ mu_act
        c = _wrap(terms.rho - self.targets(st.t)) if self.n_act else np.zeros(0)
        if self.force_floor is None:
            d = np.abs(ev.K.diagonal())
            self.force_floor = 1e-12 * float(d.max() if d.size else 1.0) * self.size
        if self.penalty is None:
            self.penalty = self._auto_penalty(ev.K, terms)
        return Evaluation(ev, terms, r, c, mu_act, P)

    def _auto_penalty(self, K: Any, terms: ActuatorTerms) -> float:
        a = self.opts.augmentation
        self.c_scale = 1.0
        if not self.n_act:
            return 0.0
        penalty, self.c_scale = auto_augmentation(K, terms)
        if a != "auto":
            return float(a)
        return penalty

    def factorize(
        self,
        e: Evaluation,
        st: State,
        reuse: bool = False,
        keep_operator: bool = False,
        shift: float = 0.0,
    ) -> None:
        """Make the tangent at ``st`` the operator of the bordered system and factorise it
        (``reuse``: unless the system keeps an earlier factorisation as GMRES
        preconditioner). Unless ``keep_operator`` is set, the operator's values and ``e``'s
        tangent are released where the factor alone serves every later solve (the next
        tangent is then assembled without this one beside it). An ``e`` without its
        tangent (evaluated without it, or released) has it assembled first. ``shift``
        (force / length, >= 0) is added to the free DOFs' diagonal of the operator (damped
        Newton); ``e``'s tangent itself is left unshifted."""
        self.system.row_scale = self.c_scale
        if e.ev.K is None or e.terms.hess is None:
            # evaluated without the tangent, or released by an earlier factorisation
            fresh = self.evaluate(st)
            e.ev, e.terms = fresh.ev, fresh.terms
        check_finite_tangent(e.ev.K)  # NaN / inf never reach the factorisation
        springs = None
        if self.k_act is not None:
            springs = (e.mu_act, self.k_act)
        self.system.set_operator(
            self._shifted(e.ev.K, shift) if shift else e.ev.K,
            e.terms,
            st.mu,
            self.penalty or 0.0,
            factorize=not reuse,
            springs=springs,
            release_values=not keep_operator,
        )
        if not self.system.holds_values and dataclasses.is_dataclass(e.ev):
            # only the factor solves from here: K is not held beside the next tangent (242 MB
            # at the 1 M DOFs of a 200 x 200 Miura); a later need assembles it again
            e.ev = dataclasses.replace(cast(Any, e.ev), K=None)

    def factorize_or_fail(
        self,
        e: Evaluation,
        st: State,
        res: list[float],
        reuse: bool = False,
        keep_operator: bool = False,
        shift: float = 0.0,
    ) -> None:
        """:meth:`factorize`; a singular tangent fails the increment."""
        try:
            self.factorize(e, st, reuse, keep_operator=keep_operator, shift=shift)
        except SingularMatrixError as exc:
            raise IncrementFailed(f"singular tangent ({exc})", res) from None

    def _shifted(self, K: Any, shift: float) -> sp.csr_matrix:
        """``K + shift I_free``: a copy of K's values on K's own pattern arrays (the
        bordered system's scatter maps stay valid)."""
        K.sort_indices()
        if self._diag_arrays[0] is not K.indptr or self._diag_arrays[1] is not K.indices:
            idx = np.flatnonzero(self.free)
            pos = pattern_positions(K.indptr, K.indices, idx, idx)
            if np.any(pos < 0):
                raise AssertionError("the tangent's pattern lacks diagonal entries")
            # the arrays are held, so a new pattern is never mistaken for them
            self._diag_pos, self._diag_arrays = pos, (K.indptr, K.indices)
        shifted = sp.csr_matrix(K.shape, dtype=K.dtype)
        shifted.indices, shifted.indptr = K.indices, K.indptr  # not views: the same arrays
        shifted.data = K.data.copy()
        shifted.data[self._diag_pos] += shift
        shifted.has_sorted_indices = True
        return shifted


def auto_augmentation(K: Any, terms: ActuatorTerms) -> tuple[float, float]:
    """The solver's ``augmentation = "auto"`` for the tangent ``K`` and the actuators
    ``terms``: (penalty ``p`` of ``K + p G^T G``, the mean stiffness on the actuators' DOFs
    over the mean ``|grad rho|^2``, in force x length; the row scale of the actuator
    constraints, that stiffness over the root of that mean)."""
    dd = np.abs(K.diagonal())[terms.dofs.ravel()]
    kd = float(np.mean(dd)) if dd.size and np.mean(dd) > 0 else 1.0
    g2 = float(np.mean(np.sum(terms.grad**2, axis=1)))
    if g2 > 0:
        return kd / g2, kd / np.sqrt(g2)
    return kd, kd


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles (rad) wrapped into [-pi, pi)."""
    return (a + np.pi) % (2 * np.pi) - np.pi
