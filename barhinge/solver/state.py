"""The states of the Newton driver: a converged or trial state (:class:`State`), everything
evaluated at it (:class:`Evaluation`), the failure of one increment
(:class:`IncrementFailed`), the record of a converged state kept for the
:class:`~barhinge.results.FoldPath` (:class:`StepRecord`, :class:`StepStats`), and what a
live display is told of every iterate (:class:`IterationStatus`)."""

from __future__ import annotations

import dataclasses

import numpy as np

from barhinge._protocols import ModelEvaluation
from barhinge.solver.bordered import ActuatorTerms

__all__ = [
    "Evaluation",
    "IncrementFailed",
    "IterationStatus",
    "State",
    "StepRecord",
    "StepStats",
]


@dataclasses.dataclass
class State:
    """One state of the path."""

    x: np.ndarray  # (n_dof,) coordinates, flattened, length
    mu: np.ndarray  # (n_act,) Lagrange multipliers (= -actuator moments), force x length
    lam: float  # load factor
    t: float  # path parameter


@dataclasses.dataclass
class Evaluation:
    """Everything computed at one iterate."""

    ev: ModelEvaluation
    terms: ActuatorTerms
    r: np.ndarray  # (n_dof,) f_int - lam P + G^T mu (all DOFs), force
    c: np.ndarray  # (n_act,) rho - target, rad (held actuators; empty for compliant ones)
    #: (n_drive,) actuator multipliers, force x length: ``mu`` of held actuators, the
    #: spring moment ``k (rho - target)`` of compliant ones (the actuator moment is minus it)
    mu_act: np.ndarray
    #: (n_dof,) reference load at this iterate, force (the fixed loads plus any follower
    #: pressure at the current geometry)
    P: np.ndarray


class IncrementFailed(Exception):
    """One increment did not converge: ``why`` names the cause, ``residuals`` the force
    residual norms met on the way."""

    def __init__(self, why: str, residuals: list[float]) -> None:
        super().__init__(why)
        self.why = why
        self.residuals = residuals


@dataclasses.dataclass
class StepRecord:
    """A converged state as the FoldPath stores it."""

    X: np.ndarray  # (n_nodes, 3) coordinates, length
    fold: np.ndarray  # (n_edges,) fold angles, deg
    targets: np.ndarray  # (n_act,) actuator targets, deg
    moments: np.ndarray  # (n_act,) actuator moments, force x length
    rho: np.ndarray  # (n_act,) actuator hinge angles, rad
    eb: float  # bar energy
    ebend: float  # panel bending energy
    efold: float  # fold-spring energy
    R: np.ndarray  # (n_nodes, 3) reactions, force
    lam: float  # load factor
    iters: int  # Newton iterations of the step
    res: tuple[float, ...]  # force residual norms of the step
    wall: float  # seconds since the start of the solve
    work: float  # external work up to this state
    neg: int | None  # negative eigenvalues of the free-DOF tangent (None: unknown)
    #: the same with the held actuators held (None: unknown or no held actuators)
    neg_held: int | None = None


@dataclasses.dataclass
class StepStats:
    """Step control of one requested step (parameter controls)."""

    iterations: int  # Newton corrections of the converged increments
    increments: int  # converged increments
    failed: int  # failed increments (redone shorter)
    factorizations: int  # all factorisations
    inertia_factorizations: int  # those made to confirm the inertia at the state
    chord: int = 0  # chord corrections kept (options.corrector = "chord")


@dataclasses.dataclass(frozen=True)
class IterationStatus:
    """One iterate of a running solve, as ``bh.solve(..., on_iteration=...)`` reports it
    (a live display of a long step: at a million DOFs an iterate takes seconds).

    Attributes
    ----------
    step : int
        Requested step being solved (1-based; arc length: the increment's number).
    steps : int
        Requested steps of the scene.
    value : float
        Path parameter of the iterate (the load factor under load control and arc length).
    length : float
        The increment's length over a whole step's (parameter control: 1, or 1/2, 1/4, ...
        after cut-backs; arc length: over the first increment's arc length).
    iteration : int
        The iterate within its increment: 0 for the predictor, then one per correction.
    residual : float
        Norm of the force residual on the free DOFs at the iterate (force).
    failed : int
        Increments of this step that failed so far (each redone shorter, or once at the
        same length from the tangent predictor).
    correction : float
        Norm of the free displacement change that made the iterate (from the last
        converged state for the predictor), length; NaN where not known.
    kind : str
        What made the iterate (:data:`barhinge.solver.trace.ITERATE_KINDS`): "predictor",
        "newton", "accelerated", "chord" or "damped".
    """

    step: int
    steps: int
    value: float
    length: float
    iteration: int
    residual: float
    failed: int
    correction: float = float("nan")
    kind: str = "newton"
