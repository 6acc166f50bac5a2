"""Leaving a flat (singular) start: the rigid-fold predictor of the bar-and-hinge solver.

At the flat state every folding mode of a tessellation is a zero-stiffness direction to
first order (the bars stretch only to second order), so the tangent predictor of an actuated
scene sees none of them: it bends the panels next to the actuators, and Newton converges to
whatever equilibrium lies nearest, often one with creases folded against their assignment and
crumpled panels. The flat state is a bifurcation point; the branch must be chosen.

The rule (docs/solver.md, "Leaving the flat state"): the first increment is predicted by
the rigid fold of the pattern to the increment's actuator targets, computed by
:func:`barhinge.kinematics.rigid_fold` with the model's own fold-spring stiffnesses, i.e. the
limit of the bar-and-hinge model as bars and panels become rigid, on the branch whose creases
fold with the signs of the pattern's target fold angles or M/V assignment. Where panels cannot
stay rigid (a pattern that is not rigidly foldable) the panels' diagonals may fold with the
model's bending stiffness. The predicted vertices are placed on the supports by the rigid
motion that best fits them; centre nodes (N5B8) follow as the mean of their face's corners
(exact for a rigid panel). Newton then corrects the prediction into the bar-and-hinge
equilibrium of that branch.
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge._protocols import SolverModel
from barhinge.actuators import Actuators
from barhinge.errors import BarhingeError, ConvergenceError
from barhinge.kinematics.path import RigidOptions, actuator_conflict, rigid_fold
from barhinge.linalg.extrapolation import lagrange
from barhinge.model.triangulate import quad_centres, triangulate
from barhinge.pattern.crease import CreasePattern
from barhinge.results import FoldPath

__all__ = [
    "GUIDE_HEAD",
    "RigidGuide",
    "conflicting_actuators",
    "creases_against_assignment",
    "fold_weights",
    "is_flat",
    "rigid_guide",
]

log = logging.getLogger(__name__)

#: a model whose fold hinges all lie within this of 0 rad starts flat
FLAT_START_TOL = 1e-6
#: requested steps of the rigid fold that :meth:`RigidGuide.at` interpolates through (cubic)
STENCIL = 4
#: requested steps the guide folds where the actuators leave no free motion (only the first
#: increment is predicted from it then): the states of the cubic over the first step
GUIDE_HEAD = STENCIL - 1


def is_flat(model: SolverModel) -> bool:
    """True when every fold hinge of ``model`` is flat in its reference state."""
    rest = np.asarray(model.rest_angle)[np.asarray(model.hinge_kind) == "fold"]
    return bool(rest.size) and float(np.max(np.abs(rest))) < FLAT_START_TOL


def fold_weights(model: SolverModel) -> tuple[np.ndarray, float]:
    """(n_edges,) fold-spring stiffness per pattern edge (1 where no fold hinge) and the
    median bending-hinge stiffness (for triangulated panels)."""
    kind = np.asarray(model.hinge_kind)
    k = np.asarray(model.hinge_k, float)
    edge = np.asarray(model.hinge_edge)
    w = np.ones(model.pattern.n_edges)
    f = kind == "fold"
    w[edge[f]] = np.maximum(k[f], 1e-300)
    kb = float(np.median(k[~f])) if (~f).any() else 1e4 * float(np.median(k[f]))
    return w, kb


def _node_coordinates(model: SolverModel, V: np.ndarray) -> np.ndarray:
    """(n_nodes, 3) model nodes from pattern vertices ``V``: centre nodes placed as
    :func:`~barhinge.model.triangulate.triangulate` places them (quads: where the diagonals
    cross; larger polygons: the corners' mean). ``V`` may hold many states,
    (n_states, n_vertices, 3)."""
    V = np.asarray(V, dtype=float)
    cp = model.pattern
    if int(model.n_nodes) == cp.n_vertices:
        return V.copy()
    centre_face = triangulate(cp, model.scheme).centre_face
    corners = [cp.faces[f] for f in centre_face]
    sizes = np.fromiter((len(c) for c in corners), dtype=np.int64, count=len(corners))
    quad = sizes == 4
    cols = np.fromiter((i for c in corners for i in c), dtype=np.int64, count=int(sizes.sum()))
    rows = np.repeat(np.arange(len(corners)), sizes)
    mean = sp.csr_matrix((1.0 / sizes[rows], (rows, cols)), shape=(len(corners), cp.n_vertices))
    C = np.stack([mean @ v for v in V]) if V.ndim == 3 else mean @ V
    if quad.any():
        Q = np.array([corners[i] for i in np.flatnonzero(quad)], dtype=np.int64)
        C[..., quad, :] = quad_centres(V[..., Q, :])
    return np.concatenate([V, C], axis=-2)


def _fit_supports(X: np.ndarray, fixed: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Rigid motion of ``X`` (n, 3) that best puts its fixed components (boolean (n, 3)) on
    ``target`` (n, 3) in least squares: Gauss-Newton on a rotation vector and a
    translation."""
    rows = np.argwhere(fixed)
    if len(rows) == 0:
        return X
    nodes = np.unique(rows[:, 0])
    c = X[nodes].mean(axis=0)
    Y = X - c
    R = np.eye(3)
    t = target[nodes].mean(axis=0) if len(nodes) else np.zeros(3)
    for _ in range(20):
        P = Y[rows[:, 0]] @ R.T + t  # current positions of the fixed nodes
        res = P[np.arange(len(rows)), rows[:, 1]] - target[rows[:, 0], rows[:, 1]]
        # d(R y)/d(omega) = -[R y]x ; d/dt = I
        Ry = Y[rows[:, 0]] @ R.T
        e = np.eye(3)[rows[:, 1]]
        Jm = np.hstack([np.cross(Ry, e), e])  # e . (omega x Ry) = omega . (Ry x e)
        step, *_ = np.linalg.lstsq(Jm, -res, rcond=None)
        w, dt = step[:3], step[3:]
        th = float(np.linalg.norm(w))
        if th > 0:
            k = w / th
            K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
            R = (np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K) @ R
        t = t + dt
        if np.max(np.abs(step)) < 1e-14:
            break
    return Y @ R.T + t


@dataclasses.dataclass(frozen=True)
class RigidGuide:
    """The rigid fold of a scene's whole actuator schedule, as node coordinates.

    Attributes
    ----------
    X : (n_states, n_nodes, 3) float
        Rigid-fold node coordinates at the requested steps that the rigid path reached
        (state 0 = the flat start), each placed on the supports.
    record : dict
        What was chosen: ``predictor`` ("rigid panels" or "triangulated panels"),
        ``branch`` ("M/V assignment" or "target fold angles"), ``mirrored``,
        ``sign_conflicts`` (pattern edges against the branch signs), ``free_dof`` (motions
        the actuators leave, resolved by the fold-spring energy), ``least_squares`` (the
        actuator targets conflict and were met in least squares), ``events``, ``steps``
        and ``t_max`` (path parameter the rigid fold reached).
    """

    X: np.ndarray
    record: dict[str, Any]

    @property
    def t_max(self) -> float:
        """Path parameter of the last state the rigid path reached (1 = the whole path)."""
        return self.record["t_max"]

    def at(self, t: float) -> np.ndarray:
        """(n_nodes, 3) rigid-fold coordinates at path parameter ``t`` in [0, t_max]: the
        cubic through the four requested steps nearest ``t`` (exact at the steps).

        Off a flat sheet the in-plane coordinates change like the square of the fold
        angle, so a straight line between two steps shortens the panels: on a 40 x 40
        Miura, halfway through the first step, by a bar strain of 8e-5 (against 1.5e-7
        for the cubic), which the stiff bars turn into a large residual for the
        increments that a failed first step is cut back to."""
        steps = self.record["steps"]
        s = t * steps
        last = len(self.X) - 1
        i = min(max(int(np.floor(s)), 0), last)
        lo = max(0, min(i - 1, last - STENCIL + 1))
        pts = [(k / steps, self.X[k]) for k in range(lo, min(lo + STENCIL, last + 1))]
        return lagrange(pts, t)


def rigid_guide(
    model: SolverModel,
    actuators: Actuators,
    steps: int,
    fixed: np.ndarray,
    fixed_target: np.ndarray,
    head: int | None = None,
) -> RigidGuide | None:
    """Rigid fold of the actuator schedule with the model's fold springs: the limit of the
    bar-and-hinge model as bars and panels become rigid, on the branch of the M/V
    assignment (see the module docstring).

    Parameters
    ----------
    model : BarHingeModel, flat in its reference state.
    actuators : Actuators, the scene's (its schedule over ``steps`` requested steps).
    steps : int, requested steps of the scene.
    fixed : (n_nodes, 3) bool, supported or prescribed components.
    fixed_target : (n_nodes, 3) float, their positions (at the start).
    head : int, optional
        Fold only the first ``head`` requested steps, unless the actuators leave free
        motions (then the whole schedule): the solver predicts only its first increment
        from the guide where they leave none (``GUIDE_HEAD`` steps serve the cubic of
        :meth:`RigidGuide.at` over that increment and its cut-backs). Default: the whole
        schedule.

    Returns
    -------
    RigidGuide over the part of the schedule the rigid fold reached (at least one step), or
    None when no rigid fold (with rigid or with triangulated panels) leaves the flat start;
    the reason is logged.
    """
    cp = model.pattern
    w, kb = fold_weights(model)
    opt = RigidOptions(check_rank=False)
    why = []
    for triangulated in (False, True):
        try:
            path = _rigid_schedule(cp, actuators, steps, head, opt, triangulated, w, kb)
        except ConvergenceError as exc:
            path = exc.last_state
            if path is None or path.n_states < 2:
                why.append(f"{'triangulated' if triangulated else 'rigid'} panels: {exc}")
                continue
        except BarhingeError as exc:
            why.append(f"{'triangulated' if triangulated else 'rigid'} panels: {exc}")
            continue
        fx, ft = np.asarray(fixed, bool), np.asarray(fixed_target, float)
        X = np.stack([_fit_supports(Xs, fx, ft) for Xs in _node_coordinates(model, path.X)])
        meta = path.meta
        record = {
            "predictor": "triangulated panels" if triangulated else "rigid panels",
            "branch": meta.get("branch"),
            "mirrored": bool(meta.get("mirrored", False)),
            "sign_conflicts": list(meta.get("sign_conflicts", [])),
            "free_dof": meta.get("free_dof"),
            "events": list(meta.get("events", [])),
            "least_squares": bool(max(meta.get("actuator_misfit_deg", [0.0])) > 1e-9),
            "steps": int(steps),
            "t_max": (path.n_states - 1) / steps,
        }
        return RigidGuide(X=X, record=record)
    log.warning(
        "no rigid fold predicts the first increment off the flat start (%s)", "; ".join(why)
    )
    return None


def _rigid_schedule(
    cp: CreasePattern,
    actuators: Actuators,
    steps: int,
    head: int | None,
    opt: RigidOptions,
    triangulated: bool,
    fold_stiffness: np.ndarray,
    diagonal_stiffness: float,
) -> FoldPath:
    """The rigid fold of the first ``head`` of the ``steps`` requested steps (the same
    states as the whole schedule's: each step starts from the last), and of the whole
    schedule where those leave free motions to the fold springs (or ``head`` is None or
    not shorter)."""

    def fold(act: Actuators, n: int) -> FoldPath:
        return rigid_fold(
            cp,
            act,
            steps=n,
            options=opt,
            triangulated=triangulated,
            fold_stiffness=fold_stiffness,
            diagonal_stiffness=diagonal_stiffness,
        )

    if head is None or head >= steps:
        return fold(actuators, steps)
    first = Actuators(
        edges=actuators.edges,
        table_deg=actuators.schedule(steps)[1 : head + 1],
        stiffness=actuators.stiffness,
    )
    path = fold(first, head)  # a failure inside the head is the whole schedule's too
    if path.meta.get("free_dof"):
        return fold(actuators, steps)
    return path


def creases_against_assignment(
    model: SolverModel, fold_deg: np.ndarray, mirrored: bool = False, min_deg: float = 1.0
) -> list[int]:
    """Pattern edges assigned M or V whose fold angle ``fold_deg`` (n_edges,) degrees has the
    other sign by more than ``min_deg`` (signs flipped as a whole when ``mirrored``)."""
    asg = np.asarray(model.pattern.assignment)
    want = np.where(asg == "V", 1.0, np.where(asg == "M", -1.0, 0.0))
    if mirrored:
        want = -want
    f = np.asarray(fold_deg, float)
    return np.flatnonzero(want * f < -min_deg).tolist()


def conflicting_actuators(model: Any, actuators: Actuators | None, steps: int) -> str | None:
    """Before solving a scene that starts folded: do its actuators conflict? The rank of the
    rigid-folding constraints with the actuators added at the model's reference state
    (:func:`barhinge.kinematics.path.actuator_conflict`). None when they do not, or for a
    flat start (the rigid predictor checks those); else a one-line reason naming the
    dependent actuators (the panels must bend to meet their targets)."""
    if actuators is None or actuators.n < 2 or is_flat(model):
        return None
    try:
        return actuator_conflict(model.pattern, actuators, steps)
    except (BarhingeError, RuntimeError, np.linalg.LinAlgError) as exc:
        log.debug("actuator conflict check skipped: %s", exc)
        return None
