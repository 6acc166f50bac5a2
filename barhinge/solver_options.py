"""Solver options (tolerances, step control, linear backend): plain data that a
:class:`~barhinge.scene.Scene` carries and :func:`barhinge.solve` reads, so it sits below both."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from barhinge import _check
from barhinge.errors import ConfigError

__all__ = ["SolverOptions"]

#: linear solvers (see barhinge.linalg.backends)
LINEAR_SOLVERS = ("auto", "superlu", "cholmod", "pardiso")
#: upper bound of the iteration-count options (a typo such as 1e9 would never stop)
MAX_ITERATIONS = 100_000
#: upper bound of ``max_arc_steps``
MAX_ARC_STEPS = 10_000_000


@dataclasses.dataclass(frozen=True)
class SolverOptions:
    """Options of :func:`barhinge.solve`.

    Attributes
    ----------
    tol_force : float
        Relative force tolerance: ``|R_free| <= tol_force * F_ref`` where ``F_ref`` is the
        largest of the applied loads, the support reactions, the actuator forces ``G^T mu``
        and ``force_floor``.
    tol_disp : float
        Relative displacement tolerance: ``|dx| <= tol_disp * size`` (``size`` = the model's
        bounding-box diagonal) on the last correction. Where the force and actuator tests
        pass and the last correction is larger, it is met by the next correction (one
        back-substitution of the residual with the last factorisation) instead.
    tol_angle : float
        Absolute tolerance on the actuator constraints ``|rho_a - rho_target|`` (radians).
    force_floor : float or None
        Absolute force scale below which residuals count as zero (default: ``1e-12`` times the
        largest diagonal entry of the first tangent times ``size``).
    max_iter : int
        Newton iterations per increment before the increment is cut back.
    max_cutbacks : int
        How many times an increment may be halved (the smallest increment is
        ``2**-max_cutbacks`` of a requested step); beyond that the solve raises
        :class:`~barhinge.errors.ConvergenceError`.
    grow_iters : int
        An increment that converged in at most this many iterations lets the next one double
        (never beyond the next requested step, so results land exactly on the steps).
    divergence_ratio : float
        Cut back when the residual grows by this factor over the increment's first residual.
    linear_solver : str
        ``"auto"``, ``"superlu"``, ``"cholmod"`` or ``"pardiso"`` (see ``linalg.backends``).
    augmentation : float or "auto"
        Penalty ``p`` of the augmented-Lagrangian form ``K + p G^T G`` used to factorise the
        bordered actuator system (exact: the term is compensated on the right-hand side).
        ``"auto"`` scales it to the tangent; 0 disables it.
    predictor : str
        ``"polynomial"`` (default): extrapolation of coordinates and multipliers through
        the last converged states (up to eight) of the degree they support
        (:func:`barhinge.linalg.extrapolation.extrapolate`) or the quadratic through the last
        three, whichever leaves the smaller residual (two force evaluations without the
        tangent). ``"quadratic"``: Lagrange extrapolation through the last three converged
        states. Both use the secant with two states and a tangent step for the first
        increment. ``"secant"``: through the last two. ``"tangent"``: always a linearised
        step at the last converged state. An increment whose extrapolated start fails is
        retried once with the tangent predictor before it is cut back. On a smooth path the
        polynomial start is close enough that most steps take one Newton correction
        (docs/solver-performance.md, the predictor table).
    line_search : int
        Maximum halvings of a Newton correction in the backtracking line search on
        ``|r|^2 + (s c)^2`` (0 = plain Newton, the default: on stiff-bar / soft-fold
        mechanisms full Newton steps with cut-back of the increment were measured faster).
        Arc length halves its correctors the same way, load factor included (a scaled
        corrector keeps the arc-length constraint); thin plates under load, whose full
        corrections overshoot by orders of magnitude, need it.
    acceleration : bool or "auto"
        Geodesic acceleration of Newton corrections (Transtrum & Sethna 2012,
        arXiv:1201.5885): the second directional derivative of the residual along the step
        ``v``, ``r'' = (r(x + h v) + r(x - h v) - 2 r(x)) / h^2`` (two force evaluations,
        no tangent), is solved with the step's factorisation, and the step becomes
        ``v + a / 2`` when ``2 |a| <= |v|``. Along a near-mechanism the plain step leaves
        the curved valley of the soft mode and stretches the bars (the next iterate's
        residual jumps); the corrected step follows the valley to second order.
        ``"auto"`` (default): the corrections of an increment are accelerated once its
        residual has risen from one iterate to the next (the near-mechanism's signature),
        and every correction of an increment that follows one which failed or needed more
        than ``AUTO_ACCELERATION_AFTER`` corrections; plain Newton elsewhere, so a stiff
        sheet pays nothing. ``True``: every correction; ``False``: none.
        docs/solver-performance.md, the acceleration table, measures all three. Not used
        under arc length.
    corrector : str
        ``"chord"`` (default): after an increment's first Newton correction (which always
        assembles and factorises the tangent at the predicted state), each further
        correction is first tried as a chord step: the residual is evaluated without the
        tangent and solved with the increment's factorisation (one back-substitution). The
        step is kept when it lowers ``sqrt(|r_free|^2 + (s c)^2)`` at least
        ``1 / CHORD_CONTRACTION`` times (ten) or its state passes the force and actuator
        tests; otherwise it is discarded and a full Newton
        correction (tangent assembled and factorised) is made from the same iterate. On a
        smooth path most increments then need one factorisation
        (docs/solver-performance.md, the corrector table). ``"newton"``: every correction
        assembles and factorises the tangent. Not used under arc length.
    reuse_factorization : bool
        Reuse a factorisation over Newton iterations and increments as the preconditioner
        of GMRES on the exact tangent system (a fresh factorisation when GMRES stalls or has
        cost more than one factorisation): the same converged states with fewer
        factorisations. Off by default: on the Miura benchmarks the tangent changes too much
        between iterates (bar forces of the predictor) and GMRES needs 10-30 iterations, so
        it was measured slower than factorising (docs/solver-performance.md). Worth trying
        with many small increments and a slow factorisation. Not used under arc length.
    krylov_max : int
        GMRES iterations per solve before a fresh factorisation is made instead.
    arc_length_increment : float or None
        Load-factor increment of the first arc-length (MGDCM) step; default ``1/steps``.
    arc_max_load_increment : float or None
        Largest change of the load factor in one arc-length increment. MGDCM keeps a
        generalised arc length, so on a path that stiffens (a soft start, an imperfect
        shell) one increment can climb far: an increment that climbs more is redone shorter,
        and later increments keep the shorter length until they climb less than half of it.
        The stability of the path is then sampled at least every this much load. Default
        None (no cap).
    max_arc_steps : int or None
        Cap on arc-length increments (default ``10 * steps``); a run that reaches it before
        one of its stop criteria raises :class:`~barhinge.errors.ConvergenceError`.
    arc_stop_load_factor : float or None
        Arc length stops on this load factor, landing on it exactly. Default: 1 when no other
        stop criterion is given, else no load-factor stop (the path runs through any load
        factor until another criterion is met).
    arc_stop_displacement : mapping or None
        Arc length stops when one displacement component reaches a value, landing on it
        exactly: ``{"node": i, "axis": "x" | "y" | "z", "value": u}`` (``u`` in the model's
        length unit, from the reference position). The node's component must be free.
    arc_stop_limit_points : int or None
        Arc length stops at the first state past this many limit points of the load
        factor (turning points of the load-factor path).
    arc_stop_instability : bool
        Arc length stops at the first state whose free tangent has more negative eigenvalues
        than the starting state's: the first loss of stability on the path, a bifurcation
        or a limit point passed (``FoldPath.meta["arc_stop"]["value"]`` is its load factor).
        Default False.
    stability_check : bool or None
        How the inertia of the free-DOF tangent (its number of negative eigenvalues, actuators
        released, and with held actuators also held) is found at every recorded state
        (``FoldPath.meta["negative_eigenvalues"]``, ``["negative_eigenvalues_held"]`` and the
        stability events). True: the tangent *at* the state is factorised (exact;
        one extra factorisation per state, except under arc length, whose next increment
        uses the same one). False: the count comes from the last factorisation Newton made
        in the increment (free: the tangent one iterate before convergence), confirmed by a
        factorisation at the state whenever either count differs from the previous
        state's or is unknown (e.g. with ``reuse_factorization``): no false events, but a
        change may be reported one step late. None (default): True under load and
        arc-length control, False under fold-angle and displacement control.
    flat_start : str
        How an actuated scene leaves a flat (singular) start, where the tangent predictor
        cannot see the folding mode: ``"rigid"`` (default) predicts the first increment by
        the energy-minimising rigid fold on the branch of the M/V assignment
        (:mod:`barhinge.solver.branch`); ``"tangent"`` uses the plain tangent predictor (the
        branch is then whatever Newton finds; use it with an imperfect start).
    damping : str
        How an increment off a flat start is solved when plain Newton fails it. Near flat
        the folds resist at second order in the fold angle and the bars only at fourth, so
        the rest of a large sheet is a near-mechanism whose plain Newton corrections
        overshoot by orders of magnitude (on a 200 x 200 Miura sheet they diverge), and a
        shorter increment lies farther from the rigid fold, so cutting it back does not
        help. ``"auto"`` (default): the failed first increment, and a later one that the
        tangent predictor has failed too, is redone with damped Newton corrections
        (:mod:`barhinge.solver.damping`) before it is cut back: the tangent's free diagonal
        is shifted by ``delta``, which follows the residual from one correction to the next
        (pseudo-transient continuation), a correction that raises the residual more than ten
        times is redone with a larger shift, and plain Newton takes over once the residual
        is a thousandth of the one after the first correction, or once the damped
        corrections stop gaining. ``"always"``: the first increment is damped from the start
        (skips the failed plain attempt on a sheet known to need it). ``"off"``: plain
        Newton and cut-backs only. Not used under load or arc-length control. The damped
        corrections may settle on another equilibrium than plain Newton where several lie
        near the rigid fold; the crease-sign check of the flat start names creases that
        fold against their assignment.
    """

    tol_force: float = 1e-8
    tol_disp: float = 1e-8
    tol_angle: float = 1e-10
    force_floor: float | None = None
    max_iter: int = 25
    max_cutbacks: int = 8
    grow_iters: int = 6
    divergence_ratio: float = 1e4
    linear_solver: str = "auto"
    augmentation: float | str = "auto"
    predictor: str = "polynomial"
    line_search: int = 0
    acceleration: bool | str = "auto"
    corrector: str = "chord"
    reuse_factorization: bool = False
    krylov_max: int = 30
    arc_length_increment: float | None = None
    arc_max_load_increment: float | None = None
    max_arc_steps: int | None = None
    arc_stop_load_factor: float | None = None
    arc_stop_displacement: dict[str, Any] | None = None
    arc_stop_limit_points: int | None = None
    arc_stop_instability: bool = False
    flat_start: str = "rigid"
    stability_check: bool | None = None
    damping: str = "auto"

    def __post_init__(self) -> None:
        # every field: type (bools are not numbers), finiteness and range; messages start
        # with "options.<field>" (the TOML scene prefixes "solve.")
        def num(name: str, lo: float, lo_open: bool = True) -> None:
            v = _check.number(getattr(self, name), f"options.{name}", lo, lo_open=lo_open)
            object.__setattr__(self, name, v)

        def whole(name: str, lo: int, hi: int) -> None:
            object.__setattr__(
                self, name, _check.integer(getattr(self, name), f"options.{name}", lo, hi)
            )

        for name in ("tol_force", "tol_disp", "tol_angle", "divergence_ratio"):
            num(name, 0.0)
        if self.force_floor is not None:
            num("force_floor", 0.0, lo_open=False)
        whole("max_iter", 1, MAX_ITERATIONS)
        whole("grow_iters", 1, MAX_ITERATIONS)
        whole("krylov_max", 1, MAX_ITERATIONS)
        # 2**-60 of a step is below the resolution of the path parameter
        whole("max_cutbacks", 0, 60)
        whole("line_search", 0, 60)
        _check.choice(self.linear_solver, "options.linear_solver", LINEAR_SOLVERS)
        _check.choice(
            self.predictor, "options.predictor", ("polynomial", "quadratic", "secant", "tangent")
        )
        _check.choice(self.flat_start, "options.flat_start", ("rigid", "tangent"))
        _check.choice(self.damping, "options.damping", ("auto", "always", "off"))
        _check.choice(self.corrector, "options.corrector", ("chord", "newton"))
        _check.boolean(self.reuse_factorization, "options.reuse_factorization")
        if self.acceleration != "auto":
            _check.boolean(self.acceleration, "options.acceleration")
        _check.boolean(self.arc_stop_instability, "options.arc_stop_instability")
        if self.stability_check is not None:
            _check.boolean(self.stability_check, "options.stability_check")
        if self.augmentation != "auto":
            if isinstance(self.augmentation, str):
                raise ConfigError(
                    f"options.augmentation = {self.augmentation!r}; expected 'auto' or a "
                    "number >= 0"
                )
            num("augmentation", 0.0, lo_open=False)
        if self.arc_length_increment is not None:
            num("arc_length_increment", 0.0)
        if self.arc_max_load_increment is not None:
            num("arc_max_load_increment", 0.0)
        if self.max_arc_steps is not None:
            whole("max_arc_steps", 1, MAX_ARC_STEPS)
        if self.arc_stop_load_factor is not None:
            num("arc_stop_load_factor", -math.inf)
        if self.arc_stop_limit_points is not None:
            whole("arc_stop_limit_points", 1, MAX_ARC_STEPS)
        if self.arc_stop_displacement is not None:
            object.__setattr__(
                self, "arc_stop_displacement", _displacement_stop(self.arc_stop_displacement)
            )

    def has_arc_stop(self) -> bool:
        """Whether any arc-length stop criterion other than the default is given."""
        return self.arc_stop_instability or any(
            v is not None
            for v in (
                self.arc_stop_load_factor,
                self.arc_stop_displacement,
                self.arc_stop_limit_points,
            )
        )

    def arc_stop_lambda(self) -> float | None:
        """The load factor arc length stops on (None: no load-factor stop)."""
        if self.arc_stop_load_factor is not None:
            return float(self.arc_stop_load_factor)
        if not self.has_arc_stop():
            return 1.0
        return None

    def reuses_factorization(self, control: str) -> bool:
        """Whether the solve under ``control`` reuses factorisations (see the option)."""
        return bool(self.reuse_factorization) and control != "arc_length"

    def exact_inertia(self, control: str) -> bool:
        """Whether the tangent is factorised at every recorded state under ``control``
        (see ``stability_check``)."""
        if self.stability_check is None:
            return control in ("load", "arc_length")
        return bool(self.stability_check)

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> SolverOptions:
        """Options from a mapping (TOML ``[solve.options]``); unknown keys are errors."""
        if d is not None and not isinstance(d, dict):
            raise ConfigError(f"options = {d!r}; expected a table of solver options")
        d = dict(d or {})
        names = {f.name for f in dataclasses.fields(cls)}
        for k in d:
            if k not in names:
                raise ConfigError(
                    f"options.{k} is not a solver option; expected one of "
                    f"{', '.join(sorted(names))}"
                )
        return cls(**d)


_AXES = {"x": 0, "y": 1, "z": 2}


def _displacement_stop(spec: Any) -> dict[str, Any]:
    """``{"node": int >= 0, "axis": "x"|"y"|"z", "value": finite float}`` from a mapping."""
    key = "options.arc_stop_displacement"
    if not isinstance(spec, dict):
        raise ConfigError(
            f"{key} = {_check.show(spec)}; expected a table {{node = i, axis = 'z', value = u}}"
        )
    extra = set(spec) - {"node", "axis", "value"}
    missing = {"node", "axis", "value"} - set(spec)
    if extra or missing:
        what = f"unknown key(s) {sorted(extra)}" if extra else f"missing {sorted(missing)}"
        raise ConfigError(f"{key}: {what}; expected keys node, axis, value")
    node = _check.integer(spec["node"], f"{key}.node", 0)
    axis = _check.choice(spec["axis"], f"{key}.axis", tuple(_AXES))
    value = _check.number(spec["value"], f"{key}.value")
    return {"node": node, "axis": axis, "value": value}


def displacement_stop_dof(spec: dict[str, Any]) -> int:
    """Global DOF index (xyz interleaved per node) of a validated displacement stop."""
    return 3 * int(spec["node"]) + _AXES[spec["axis"]]
