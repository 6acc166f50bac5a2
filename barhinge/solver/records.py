"""From converged states to the :class:`~barhinge.results.FoldPath`: the record of one
state (:func:`make_record`), the step-control summary (:func:`newton_summary`) and the
path with its metadata (:func:`build_path`)."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Sequence
from typing import Any

import numpy as np

from barhinge.results import FoldPath
from barhinge.solver.context import SolveContext
from barhinge.solver.stability import held_stability_events, stability_events
from barhinge.solver.state import Evaluation, State, StepRecord, StepStats
from barhinge.solver.work import work_balance

__all__ = ["build_path", "make_record", "newton_summary"]

log = logging.getLogger("barhinge.solver.newton")


def make_record(
    ctx: SolveContext,
    st: State,
    e: Evaluation,
    iters: int,
    res: list[float],
    wall: float,
    work: float,
    neg: int | None = None,
    neg_held: int | None = None,
) -> StepRecord:
    """The record of the converged state ``st`` (``wall``: seconds since the start,
    ``work``: external work so far, ``neg``: negative eigenvalues of its free-DOF tangent,
    ``neg_held``: the same with the held actuators held; None if unknown)."""
    X = st.x.reshape(-1, 3)
    ev = e.ev
    R = np.zeros(ctx.n_dof)
    R[ctx.fixed] = e.r[ctx.fixed]  # f_int + G^T mu - lam P at supports
    moments = -e.mu_act
    return StepRecord(
        X=X.copy(),
        fold=np.asarray(ctx.model.crease_fold_angles_deg(X), float),
        targets=np.degrees(ctx.targets(st.t)),
        moments=moments.copy(),
        rho=e.terms.rho.copy(),
        eb=float(ev.energy_bars),
        ebend=float(ev.energy_bend),
        efold=float(ev.energy_fold),
        R=R.reshape(-1, 3),
        lam=st.lam,
        iters=iters,
        res=tuple(res),
        wall=wall,
        work=work,
        neg=neg,
        neg_held=neg_held,
    )


def newton_summary(
    records: Sequence[StepRecord], step_stats: Sequence[StepStats]
) -> dict[str, Any]:
    """Step control per recorded step (``FoldPath.meta["newton"]``): lists over the
    states 1.. of Newton iterations (converged increments only), increments, failed
    increments (redone shorter), factorisations (all) and those made to confirm the
    tangent's inertia at the state; totals alongside. Under arc length every state is
    one increment and only the iterations are listed."""
    if not step_stats:
        its = [int(r.iters) for r in records[1:]]
        return {"iterations": its, "total_iterations": int(sum(its))}
    keys = [f.name for f in dataclasses.fields(StepStats)]
    out: dict[str, Any] = {k: [getattr(d, k) for d in step_stats] for k in keys}
    for k in keys:
        out[f"total_{k}"] = int(sum(out[k]))
    return out


def build_path(
    ctx: SolveContext,
    records: Sequence[StepRecord],
    step_stats: Sequence[StepStats],
    flat_start: dict[str, Any] | None,
    branch_events: list[str],
    converged: bool = True,
    message: str = "",
) -> FoldPath:
    """The FoldPath of the recorded states, with its metadata and events (logged)."""
    scene = ctx.scene
    rec = records
    acts = scene.actuators
    edges = np.asarray(acts.edges) if acts is not None else np.zeros(0, np.int64)
    meta: dict[str, Any] = {
        "scene": scene.name,
        "control": scene.control,
        "steps": scene.steps,
        "scheme": str(getattr(ctx.model, "scheme", "")),
        "n_dof": int(ctx.n_dof),
        "n_free": int(ctx.free.sum()),
        "linear_solver": ctx.backend.name,
        "auto_restrained": bool(scene.auto_restrained),
        "timing": ctx.timer.as_dict(),
        "flat_start": flat_start,
        "branch_events": branch_events,
        "newton": newton_summary(records, step_stats),
        # every iterate of every increment, failed ones included (barhinge.solver.trace)
        "iterates": ctx.log.columns(),
    }
    imperfection = getattr(ctx.model, "meta", {}).get("imperfection")
    if imperfection is not None:  # the model is stress-free in a buckling-mode shape
        meta["imperfection"] = imperfection
    meta["negative_eigenvalues"] = [r.neg for r in rec]
    # the same with the held actuators held (None without held actuators)
    meta["negative_eigenvalues_held"] = [r.neg_held for r in rec]
    # distance of the actuators from their targets per state, deg (solver tolerance for
    # held actuators; the springs' stretch for compliant ones)
    meta["compliant_actuators"] = ctx.k_act is not None
    meta["actuator_misfit_deg"] = [
        float(np.max(np.abs((np.degrees(r.rho) - r.targets + 180.0) % 360.0 - 180.0), initial=0.0))
        for r in rec
    ]
    events = (
        meta["branch_events"]
        + stability_events(rec, scene.control)
        + held_stability_events(rec, scene.control)
    )
    meta["work_balance"], unbalanced = work_balance(rec, ctx.floor, ctx.size)
    if unbalanced:
        events.append(unbalanced)
    for ev in events:
        log.warning("%s: %s", scene.name or "solve", ev)
    meta["events"] = events
    n = len(rec)
    return FoldPath(
        X=np.stack([r.X for r in rec]),
        fold_angles_deg=np.stack([r.fold for r in rec]),
        actuator_edges=edges,
        actuator_targets_deg=np.stack([r.targets for r in rec]).reshape(n, -1),
        actuator_moments=np.stack([r.moments for r in rec]).reshape(n, -1),
        energy_bars=np.array([r.eb for r in rec]),
        energy_bend=np.array([r.ebend for r in rec]),
        energy_fold=np.array([r.efold for r in rec]),
        reactions=np.stack([r.R for r in rec]),
        load_factor=np.array([r.lam for r in rec]),
        iterations=np.array([r.iters for r in rec]),
        residual_norms=tuple(r.res for r in rec),
        wall_time=np.array([r.wall for r in rec]),
        external_work=np.array([r.work for r in rec]),
        converged=converged,
        message=message,
        kind="bar-hinge",
        meta=meta,
    )
