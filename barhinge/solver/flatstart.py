"""Leaving a flat start: the first increment (and, where the actuators leave free motions,
the following ones) predicted along the rigid fold of the schedule
(:func:`barhinge.solver.branch.rigid_guide`), and the events of the branch taken
(:class:`FlatStart`)."""

from __future__ import annotations

import logging
from typing import Any

from barhinge.solver.branch import (
    GUIDE_HEAD,
    RigidGuide,
    conflicting_actuators,
    creases_against_assignment,
    is_flat,
    rigid_guide,
)
from barhinge.solver.context import SolveContext
from barhinge.solver.state import State, StepRecord

__all__ = ["FlatStart"]

log = logging.getLogger("barhinge.solver.newton")


class FlatStart:
    """The rigid-fold predictor of a flat start and the branch events of a solve."""

    def __init__(self, ctx: SolveContext) -> None:
        self.ctx = ctx
        model, scene = ctx.model, ctx.scene
        self.active = bool(ctx.n_drive and ctx.opts.flat_start == "rigid" and is_flat(model))
        self.record: dict[str, Any] | None = None
        self._guide: RigidGuide | None = None
        # a folded start: conflicting actuators are named before solving (flat starts: by
        # the rigid predictor)
        # (compliant actuators may conflict: their springs share the misfit)
        clash = (
            None
            if self.active or ctx.k_act is not None
            else conflicting_actuators(model, scene.actuators, scene.steps)
        )
        self.start_events = [clash] if clash else []
        for ev in self.start_events:
            log.warning("%s: %s", scene.name or "solve", ev)

    def prediction(self, st: State, t1: float, lam1: float) -> State | None:
        """Rigid-fold prediction of the increment to ``t1`` (None: use the usual predictor).

        Off a flat start the first increment is always predicted by the rigid fold of the
        schedule. Where the actuators leave free motions, the increments that follow are
        predicted along it too, ``x = X_rigid(t1) + (x - X_rigid(t))``, so the model
        follows the branch of least fold-spring energy that the rigid fold chose instead of
        the first equilibrium its own extrapolation meets."""
        ctx = self.ctx
        assert ctx.scene.actuators is not None  # active: a flat start with actuators
        if self._guide is None and self.record is None:
            target = ctx.X0.ravel().copy()
            target[ctx.fixed] = ctx.fixed_coords(0.0)
            self._guide = rigid_guide(
                ctx.model,
                ctx.scene.actuators,
                ctx.scene.steps,
                ctx.fixed.reshape(-1, 3),
                target.reshape(-1, 3),
                head=GUIDE_HEAD,
            )
            self.record = (
                self._guide.record
                if self._guide is not None
                else {"predictor": "tangent (no rigid fold found)"}
            )
        g = self._guide
        if g is None or t1 > g.t_max + 1e-12:
            return None
        if st.t > 0.0 and not g.record.get("free_dof"):
            return None
        x = g.at(t1).ravel() + (st.x - g.at(st.t).ravel())
        new = State(x, st.mu.copy(), lam1, t1)
        new.x[ctx.fixed] = ctx.fixed_coords(t1)
        return new

    def events(self, records: list[StepRecord]) -> list[str]:
        """Events of the flat start: the rigid predictor's, and creases of the last state
        that fold against their M/V assignment."""
        ctx = self.ctx
        rec = self.record
        if not records or not (ctx.n_drive and is_flat(ctx.model)):
            return list(self.start_events)
        rec = rec or {}
        events = list(rec.get("events", []))
        bad = creases_against_assignment(
            ctx.model, records[-1].fold, mirrored=bool(rec.get("mirrored", False))
        )
        if bad:
            events.append(
                f"{len(bad)} crease(s) fold against their M/V assignment by more than 1 deg "
                f"(edges {bad[:10]}{' ...' if len(bad) > 10 else ''}): the panels bend "
                "instead of following the assigned mode (stiffer panels or more actuators "
                "follow it)"
            )
        return events
