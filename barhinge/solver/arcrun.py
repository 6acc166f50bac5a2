"""The arc-length run (MGDCM; Leon et al. 2011): increments until a stop criterion is met,
the landing on a load-factor or displacement stop, the step cap. The Newton loops are in
:mod:`barhinge.solver.arc`; the driver (:class:`ArcDriver`) supplies the states, records
and the load-control increment of the landing."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from barhinge.errors import ConvergenceError
from barhinge.linalg.backends import SingularMatrixError
from barhinge.results import FoldPath
from barhinge.solver.arc import arc_increment, displacement_stop, land_displacement, stop_text
from barhinge.solver.bordered import BorderedSystem
from barhinge.solver.context import SolveContext
from barhinge.solver.convergence import Convergence
from barhinge.solver.stability import InertiaMonitor
from barhinge.solver.state import Evaluation, IncrementFailed, State, StepRecord
from barhinge.solver.work import WorkIntegrator
from barhinge.solver_options import SolverOptions

if TYPE_CHECKING:
    from barhinge.scene import Scene

__all__ = ["ArcDriver", "run_arc_length"]

#: progress callback: (requested steps done, total steps, load factor)
Progress = Callable[[int, int, float], None]


class ArcDriver(Protocol):
    """What the arc-length run needs of the Newton driver."""

    scene: Scene
    opts: SolverOptions
    ctx: SolveContext
    conv: Convergence
    inertia: InertiaMonitor
    work: WorkIntegrator
    system: BorderedSystem
    records: list[StepRecord]

    def initial(self) -> tuple[State, Evaluation]: ...
    def increment(
        self, st: State, t1: float, lam1: float
    ) -> tuple[State, Evaluation, list[float]]: ...
    def record(
        self,
        st: State,
        e: Evaluation,
        iters: int,
        res: list[float],
        counts: tuple[int | None, int | None] = (None, None),
    ) -> None: ...
    def path(self, converged: bool = True, message: str = "") -> FoldPath: ...
    def fail(self, step: int, lam: float, why: str, res: list[float]) -> ConvergenceError: ...


def run_arc_length(d: ArcDriver, progress: Progress | None) -> FoldPath:
    """MGDCM arc length (Leon et al. 2011): states at every increment until a stop
    criterion is met (``options.arc_stop_*``; by default the load factor 1). The
    increment that passes a load-factor or displacement stop is replaced by a correction
    onto exactly that value (from the state before it, else back from the state past
    it); a limit-point stop ends at the first state past the last limit point counted, an
    instability stop at the first state whose tangent has more negative eigenvalues than
    the starting state's. With either of those stops an increment whose correctors moved
    farther than its predictor is refused and cut back (it may have jumped the point
    sought).
    Raises ConvergenceError when an increment fails after its cut-backs, when the step
    cap comes first, or when a landing fails: a path that did not reach its stop is
    never returned as converged."""
    o, ctx = d.opts, d.ctx
    arc_s = 0.0  # chord length along the path (work integration)
    steps = d.scene.steps
    max_steps = o.max_arc_steps or 10 * steps
    dl0 = o.arc_length_increment or 1.0 / steps
    lam_stop = o.arc_stop_lambda()
    disp = displacement_stop(ctx)
    st, e = d.initial()
    d.record(st, e, 0, [])
    e_new = e
    first_tan: np.ndarray | None = None
    prev_tan: np.ndarray | None = None
    sign = 1.0
    n = 0
    limit_points = 0
    prev_dlam = 0.0
    cap = o.arc_max_load_increment
    shorter = 1.0  # arc length kept shorter after an increment climbed past ``cap``
    stop: dict[str, Any] | None = None
    # a path that stops at its first limit point or loss of stability must not jump one
    watch = o.arc_stop_instability or o.arc_stop_limit_points is not None
    while stop is None and n < max_steps:
        n += 1
        # the tangent at the converged state: its inertia for the record, and the
        # factorisation of this increment's first attempt
        e = ctx.evaluate(st)
        try:
            ctx.factorize(e, st)
            factored = True
            held = d.system.held_negative_eigenvalues() if ctx.n_act else None
            d.records[-1].neg = d.system.tangent_negative_eigenvalues()
            d.records[-1].neg_held = held
        except SingularMatrixError:
            factored = False  # the attempt raises its own failure
        if o.arc_stop_instability and _lost_stability(d.records[0].neg, d.records[-1].neg):
            stop = {"criterion": "instability", "value": float(st.lam)}
            break
        scale = dl0 * shorter
        last: IncrementFailed | None = None
        for cut in range(o.max_cutbacks + 1):
            ctx.begin_increment(n, steps, st.lam, scale / dl0, cut)
            try:
                new, e_new, res, tan, sgn = arc_increment(
                    ctx, d.conv, st, e, scale, first_tan, prev_tan, sign, factored, watch
                )
            except IncrementFailed as f:
                factored = False
                scale /= 2
                last = f
                continue
            climb = abs(new.lam - st.lam)
            if cap is None or climb <= cap * (1.0 + 1e-9):
                break
            # climbed past the cap: redo it shorter (and keep that length)
            factored = False
            scale *= 0.9 * cap / climb
            last = IncrementFailed(
                f"the load factor climbs {climb:.3g} in one increment, more than "
                f"arc_max_load_increment = {cap:g}",
                res,
            )
        else:
            assert last is not None
            raise d.fail(n, st.lam, last.why, last.residuals)
        if cap is not None:
            shorter = scale / dl0
            if abs(new.lam - st.lam) < 0.5 * cap:
                shorter = min(1.0, 1.5 * shorter)
        if first_tan is None:
            first_tan = tan
        prev_tan, sign = tan, sgn
        dlam = new.lam - st.lam
        if prev_dlam * dlam < 0.0:
            limit_points += 1  # the load factor turned between the last two increments
        prev_dlam = dlam if dlam != 0.0 else prev_dlam
        new, e_new, res, stop = _arc_stop(d, st, new, e_new, res, lam_stop, disp)
        if stop is None and o.arc_stop_limit_points is not None:
            if limit_points >= o.arc_stop_limit_points:
                stop = {"criterion": "limit_points", "value": limit_points}
        arc_s += float(np.linalg.norm(new.x - st.x))
        d.work.add(d.records[0], new, e_new, arc_s)
        st = new
        d.record(st, e_new, len(res) + 1, res)
        if progress is not None:
            progress(min(max(int(st.lam * steps), 0), steps), steps, st.lam)
    if stop is None or stop["criterion"] != "instability":  # else known, exact, at this state
        counts = d.inertia.tangent_inertia(st, e_new if n else e, exact=True)
        d.records[-1].neg, d.records[-1].neg_held = counts
    if stop is None:
        msg = (
            f"arc length stopped at its step cap (max_arc_steps = {max_steps}) at load "
            f"factor {st.lam:.6g} {stop_text(ctx, lam_stop, disp)}"
        )
        raise ConvergenceError(
            msg, step=n, load_factor=st.lam, residuals=[],
            last_state=d.path(converged=False, message=msg),
        )  # fmt: skip
    path = d.path()
    path.meta["arc_stop"] = stop
    return path


def _lost_stability(start: int | None, now: int | None) -> bool:
    """Whether a state with ``now`` negative eigenvalues of its tangent has lost stability
    against the starting state's ``start`` (unknown counts: no)."""
    return start is not None and now is not None and now > start


def _arc_stop(
    d: ArcDriver,
    st: State,
    new: State,
    e_new: Evaluation,
    res: list[float],
    lam_stop: float | None,
    disp: tuple[int, float] | None,
) -> tuple[State, Evaluation, list[float], dict[str, Any] | None]:
    """Whether the increment ``st`` -> ``new`` passed a load-factor or displacement
    stop; if so the state landed exactly on it. Returns (state, evaluation, residuals,
    stop record or None)."""

    def crossed(a: float, b: float) -> bool:
        return a != 0.0 and (a * b < 0.0 or b == 0.0)

    candidates = []
    if lam_stop is not None and crossed(st.lam - lam_stop, new.lam - lam_stop):
        frac = (lam_stop - st.lam) / (new.lam - st.lam)
        candidates.append((frac, "load_factor"))
    if disp is not None:
        dof, target = disp
        if crossed(st.x[dof] - target, new.x[dof] - target):
            frac = (target - st.x[dof]) / (new.x[dof] - st.x[dof])
            candidates.append((frac, "displacement"))
    if not candidates:
        return new, e_new, res, None
    _, which = min(candidates)
    if which == "load_factor":
        assert lam_stop is not None
        if new.lam != lam_stop:
            new, e_new, res = _land(d, st, new, lam_stop)
        return new, e_new, res, {"criterion": "load_factor", "value": lam_stop}
    assert disp is not None
    dof, target = disp
    if new.x[dof] != target:
        try:
            new, e_new, res = land_displacement(d.ctx, d.conv, st, new, dof, target)
        except IncrementFailed as f:
            msg = (
                "arc length passed its displacement stop but the correction onto it "
                f"failed ({f.why})"
            )
            raise ConvergenceError(
                msg, step=len(d.records), load_factor=st.lam, residuals=f.residuals,
                last_state=d.path(converged=False, message=msg),
            ) from None  # fmt: skip
    u = target - float(d.ctx.X0.ravel()[dof])
    return new, e_new, res, {"criterion": "displacement", "value": u}


def _land(
    d: ArcDriver, st: State, past: State, lam: float = 1.0
) -> tuple[State, Evaluation, list[float]]:
    """Correct onto load factor exactly ``lam`` by load control: from ``st`` (before
    it), else from ``past`` (the arc-length state beyond it) back, else from ``st`` in
    load-controlled sub-steps (halved on failure, at most ``max_cutbacks`` times, doubled
    after a success; for an increment that leapt far past ``lam``, as on a sheet that
    stiffens by orders of magnitude as it deflects). Raises ConvergenceError with the path
    up to ``st`` when all fail."""
    whys = []
    for start in (st, past):
        d.ctx.begin_landing(lam)
        try:
            return d.increment(start, start.t, lam)
        except IncrementFailed as f:
            whys.append(f.why)
    cur, h = st, 0.5 * (lam - st.lam)
    res_all: list[float] = []
    halvings, whys_sub = 0, ""
    while halvings <= d.opts.max_cutbacks:
        to = lam if abs(lam - cur.lam) <= abs(h) else cur.lam + h
        d.ctx.begin_landing(to)
        try:
            cur, e, res = d.increment(cur, cur.t, to)
        except IncrementFailed as f:
            h, halvings = 0.5 * h, halvings + 1
            whys_sub = f.why
            continue
        res_all += res
        if cur.lam == lam:
            return cur, e, res_all
        h *= 2.0
    else:
        whys.append(f"in sub-steps: {whys_sub}")
    msg = (
        f"arc length passed load factor {lam:g} (from {st.lam:.6g} to {past.lam:.6g}) "
        f"but the correction onto {lam:g} failed ({whys[0]}; from the far side: {whys[1]}; "
        f"{whys[2]})"
    )
    raise ConvergenceError(
        msg, step=len(d.records), load_factor=st.lam, residuals=[],
        last_state=d.path(converged=False, message=msg),
    )  # fmt: skip
