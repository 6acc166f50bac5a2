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
from barhinge.kinematics.dof import FLAT_TOL, _branch_direction, select_actuators
from barhinge.kinematics.linalg import DENSE_TOL, null_space
from barhinge.pattern.crease import CreasePattern
from barhinge.results import FoldPath
from barhinge.solve.linear import SingularMatrixError, get_backend

__all__ = ["RigidOptions", "rigid_fold", "RigidSolver"]

log = logging.getLogger(__name__)


#: crease variables from which the corrector uses the fastest backend instead of SuperLU
PARDISO_MIN_VARS = 5000


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
    """

    tol: float = 1e-13
    max_iter: int = 12
    max_cutbacks: int = 8
    lock_deg: float = 179.999
    check_actuators: bool = True
    check_rank: bool | None = None
    cg_maxiter: int = 25


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

    def __init__(self, rc: RigidConstraints, act_var: np.ndarray, options: RigidOptions) -> None:
        self.rc = rc
        self.act = np.asarray(act_var, dtype=np.int64)
        self.opt = options
        free = np.ones(rc.n_var, bool)
        free[self.act] = False
        self.free = free
        self._Dfree = sp.diags(free.astype(float))
        self._Dact = sp.diags((~free).astype(float))
        self._lu = None
        # PARDISO pays from ~5 000 crease variables on (70 x 70 Miura, 38 920: 239 -> 95 ms
        # per step; 20 x 20, 3 120: no gain); below, SuperLU's exact LU also lands nearer
        # the exact flat state when a path crosses it (a bifurcation, where the closure
        # residual is quadratic in the distance and any landing within tolerance converges)
        self._backend = get_backend("auto" if rc.n_var >= PARDISO_MIN_VARS else "superlu")
        self.iterations = 0
        self.last_guess: np.ndarray | None = None

    # ---------------------------------------------------------------- linear algebra
    def _factor(self, J: sp.csr_matrix) -> None:
        K = (J.T @ J).tocsr()
        Kf = self._Dfree @ K @ self._Dfree + self._Dact
        try:
            # symmetric positive (semi)definite; the solver's fastest backend (PARDISO where
            # installed, else SuperLU with symmetric settings), ordering reused across steps.
            # A (nearly) singular matrix ends in SuperLU's exact LU, which names it.
            self._lu = self._backend.factorize(Kf)
        except SingularMatrixError as exc:  # exactly singular: free creases not determined
            raise _Singular(str(exc)) from None

    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.where(self.free, rhs, 0.0)
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
        r, J, F = self.rc.evaluate_full(rho)
        for it in range(self.opt.max_iter + 1):
            res = float(np.max(np.abs(r), initial=0.0))
            hist.append(res)
            if not np.isfinite(res):
                return rho, hist, False
            if res <= tol:
                # |F - I| also rejects the spurious 180-degree loops where r = 0
                if len(F) == 0 or float(np.abs(F - np.eye(3)).max()) <= 100 * tol:
                    return rho, hist, True
                return rho, hist, False
            if it == self.opt.max_iter:
                break
            if len(hist) >= 3 and res > 2.0 * hist[-2]:
                return rho, hist, False  # diverging
            # forcing term: inexact Newton stays (nearly) quadratic with eta ~ |r|
            eta = float(np.clip(10.0 * res, 1e-10, 1e-2))
            if it == 0:
                # near the flat state the small singular values of J move fast: a reused
                # factorisation from the previous step is a poor preconditioner
                self._factor(J)
            step = self._solve_current(J, -(J.T @ r), eta)
            if not np.all(np.isfinite(step)):
                return rho, hist, False
            smax = np.max(np.abs(step), initial=0.0)
            if smax > 0.5:  # trust region: at most ~30 deg per iteration
                step *= 0.5 / smax
            n0 = float((r * r).sum())  # backtrack on |r|_2 (Gauss-Newton descends it)
            for _ in range(6):
                r_t, J_t, F_t = self.rc.evaluate_full(rho + step)
                if float((r_t * r_t).sum()) < n0:
                    break
                step *= 0.5
            rho, r, J, F = rho + step, r_t, J_t, F_t
            self.iterations += 1
        return rho, hist, False

    def tangent(self, rho: np.ndarray, dt: np.ndarray) -> tuple[np.ndarray, float]:
        """Tangent step for actuator increments ``dt``: (rho_pred, relative misfit of the
        linearised constraints, > 0 when the actuators over-determine the motion)."""
        r, J = self.rc.evaluate(rho)
        self._factor(J)
        da = np.zeros(self.rc.n_var)
        da[self.act] = dt
        b = J @ da
        d = self._solve(-(J.T @ b))
        misfit = float(np.linalg.norm(J @ d + b) / max(np.linalg.norm(b), 1e-300))
        return rho + d + da, misfit

    def leave_flat(self, rho: np.ndarray, t_new: np.ndarray) -> np.ndarray:
        """First state off the flat one, on the branch picked by the pattern.

        Guess: the branch direction (target fold angles, else M/V signs) scaled so that the
        actuators match ``t_new``. The flat state is a bifurcation point where several
        branches start (e.g. the two modes of a degree-4 vertex) and plain Newton may jump
        between them; Levenberg-Marquardt steps ``(J_F^T J_F + mu I) d = -J_F^T r`` keep the
        iterate near the guess and land on the branch closest to it. Returns the (possibly
        unconverged) result; the regular corrector finishes it.
        """
        d = _branch_direction(self.rc)
        dA = d[self.act]
        ok = np.abs(dA) > 1e-12
        if ok.any() and np.any(t_new != 0):
            s = float(np.median(t_new[ok] / dA[ok]))
        else:
            s = float(np.max(np.abs(t_new)) / max(np.max(np.abs(d)), 1e-300))
        x = rho + s * d
        x[self.act] = t_new
        self._lu = None
        r, J = self.rc.evaluate(x)
        f = float(r @ r)
        mu = None
        eye = sp.identity(self.rc.n_var, format="csr")
        for _ in range(200):
            if np.max(np.abs(r), initial=0.0) <= 1e-6:  # close enough: Newton finishes
                break
            K = (J.T @ J).tocsr()
            if mu is None:
                mu = 1e-3 * float(K.diagonal().max(initial=1.0))
            Kf = self._Dfree @ (K + mu * eye) @ self._Dfree + self._Dact
            step = spla.splu(Kf.tocsc(), permc_spec="MMD_AT_PLUS_A").solve(
                np.where(self.free, -(J.T @ r), 0.0)
            )
            step[~self.free] = 0.0
            r2, J2 = self.rc.evaluate(x + step)
            f2 = float(r2 @ r2)
            if f2 < f:
                x, r, J, f = x + step, r2, J2, f2
                mu *= 0.3
            else:
                mu *= 10.0
            self.iterations += 1
        return x


def _extrapolate(hist: list[tuple[float, np.ndarray]], s_new: float) -> np.ndarray | None:
    """Lagrange extrapolation of the last (up to four) converged states to the path parameter
    ``s_new``: cubic with four states (error O(h^4)), quadratic with three; None with fewer."""
    if len(hist) < 3:
        return None
    pts = hist[-4:]
    ss = [p[0] for p in pts]
    if len(set(ss)) < len(ss):
        return None
    out = np.zeros_like(pts[0][1])
    for i, (si, ri) in enumerate(pts):
        li = 1.0
        for j, sj in enumerate(ss):
            if j != i:
                li *= (s_new - sj) / (si - sj)
        out += li * ri
    return out


def _as_actuators(actuators: Actuators | Sequence[int], targets_deg) -> Actuators:
    if isinstance(actuators, Actuators):
        if targets_deg is not None:
            raise ConfigError("give targets_deg inside the Actuators object, not both")
        return actuators
    if targets_deg is None:
        raise ConfigError("targets_deg is required when actuators is a list of edge ids")
    return Actuators(edges=list(actuators), targets_deg=targets_deg)


def rigid_fold(
    cp: CreasePattern,
    actuators: Actuators | Sequence[int],
    targets_deg: Sequence[float] | float | None = None,
    steps: int = 50,
    *,
    triangulated: bool = False,
    options: RigidOptions | None = None,
) -> FoldPath:
    """Fold ``cp`` as a rigid origami by driving actuator creases.

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
    solver = RigidSolver(rc, av, opt)
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
    track: list[tuple[float, np.ndarray]] = [(0.0, rho.copy())]

    def dof_at(x: np.ndarray) -> int:
        sv = np.linalg.svd(rc.jacobian(x).toarray(), compute_uv=False)
        return rc.n_var - int(np.sum(sv > DENSE_TOL * max(sv.max(initial=0.0), 1e-300)))

    if check_rank:
        dofs.append(dof_at(rho))

    def partial(msg: str) -> FoldPath:
        return _make_path(
            rc, cp, act, sched, states, iters, hists, walls, False, msg, dofs, events, opt
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
        try:
            ok, rho_new, over = _advance(
                solver, rho, sched[s - 1], sched[s], opt, hist_all, track, check_misfit
            )
        except _Singular:
            x = solver.last_guess if solver.last_guess is not None else rho
            _check_actuators(rc, x, av, act.edges)
            msg = (
                f"step {s}: the Jacobian of the free creases is singular (a bifurcation "
                f"point or actuators that leave free motions)"
            )
            raise failure(msg, s, hist_all) from None
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
            _check_actuators(rc, rho, av, act.edges)
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
    return _make_path(rc, cp, act, sched, states, iters, hists, walls, True, "", dofs, events, opt)


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
    while pending:
        a, b, depth = pending.pop()
        s_new = track[-1][0] + float(np.linalg.norm(b - a)) if track else 0.0
        flat = np.max(np.abs(cur), initial=0.0) < FLAT_TOL
        guess = None
        if flat:
            guess = solver.leave_flat(cur, b)
        elif not check_misfit:
            guess = _extrapolate(track, s_new)
        if guess is None:
            guess, misfit = solver.tangent(cur, b - a)
            if misfit > 1e-6 and opt.check_actuators:
                raise ConfigError(
                    f"the actuators over-determine the motion and their targets are "
                    f"incompatible (linearised misfit {misfit:.1e}); drive fewer creases"
                )
            check_misfit = False
            if len(track) >= 2 and track[-1][0] > track[-2][0]:
                # Hermite: bend the tangent through the state before (error O(h^3))
                (s0, r0), (s1, r1) = track[-2], track[-1]
                h, h0 = s_new - s1, s0 - s1
                slope = (guess - r1) / h
                c = (r0 - r1 - slope * h0) / h0**2
                guess = guess + c * h * h
        guess[solver.act] = b
        solver.last_guess = guess
        new, hist, ok = solver.corrector(guess)
        hist_all.extend(hist)
        if ok and np.max(np.abs(new)) > np.pi:
            ok = False
            over = int(np.argmax(np.abs(new)))
        elif not ok:
            over = -1
        if ok:
            cur = new
            track.append((s_new, new.copy()))
            del track[:-4]
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


def _check_actuators(
    rc: RigidConstraints, rho: np.ndarray, av: np.ndarray, edges: np.ndarray
) -> None:
    """ConfigError if the actuators leave free motions at the folded state ``rho``."""
    ns = null_space(rc.jacobian(rho))
    k = ns.basis.shape[1]
    NA = ns.basis[av]
    r = int(np.linalg.matrix_rank(NA, tol=1e-8)) if NA.size else 0
    if r < k:
        sug = select_actuators(rc, ns)
        raise ConfigError(
            f"the actuators {edges.tolist()} fix only {r} of the {k} DOF at the first folded "
            f"state: {k - r} free motion(s) remain; drive e.g. edges {sug.tolist()}"
        )
    if len(av) > r:
        log.info(
            "actuators %s over-determine the motion (DOF %d): targets must stay compatible",
            edges.tolist(),
            k,
        )


def _make_path(
    rc, cp, act, sched, states, iters, hists, walls, converged, msg, dofs, events, opt
) -> FoldPath:
    R = np.asarray(states)
    n = len(R)
    X = np.stack([rc.coordinates(r) for r in R])
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
