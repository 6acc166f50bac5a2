"""Stability map: where each solution method fails, and why.

Scenarios (method x situation), each run with bounded step caps so nothing can hang:

* snap-through of the von Mises truss (limit point in load): load control, displacement
  control of the apex, arc length (MGDCM);
* snap-back (the same truss pulled through a soft spring, so the controlled displacement has
  a turning point): displacement control of the spring's end, arc length;
* the flat state, where several folding branches meet: rigid kinematics and the bar-and-hinge
  solver leaving the flat state of a degree-4 vertex whose M/V assignment asks for the
  *other* branch; the same with an explicit branch choice (target fold angles for the rigid
  path, a small imperfection along the branch for the bar-and-hinge model); the DOF of a flat
  Miura sheet (infinitesimal vs finite);
* large steps (a near-rigid Miura cell folded to 150 deg in one step, with and without
  cut-backs);
* very soft (k = 0) and very stiff folds (folds stiffer than the panels);
* near-flat-folded states (rigid path to 179.99 deg and past the lock; bar-and-hinge to
  178 deg with the penetration law).

Every scenario ends as ``converged``, ``failed`` (a ConvergenceError, with the solver's
message and the study's diagnosis of the cause) or ``bifurcation`` (a branch different from
the one asked for, or a DOF that jumps, reported explicitly). Checks guard against silent
wrong answers: limit loads against the closed form, branches against the assignment.

Run: ``python studies/stability/run.py [--quick]``: full mode writes results/stability.csv,
docs/img/stability_map.png and the table in docs/stability.md. Importing the module runs the
quick mode and leaves the records in ``RECORDS``.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import barhinge as bh
from barhinge.errors import ConvergenceError
from barhinge.verify import (
    degree4_pattern,
    rigid_link_strut,
    von_mises_limit_load,
    von_mises_model,
)

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
MAIN = __name__ == "__main__"
if MAIN:  # a mistyped option or --help must not start the full run
    from barhinge._study_args import check_study_argv

    check_study_argv(__doc__, flags=("--quick",), valued=())
QUICK = not MAIN or "--quick" in sys.argv

MAT = bh.Material(E=1.0e6, nu=0.3, t=0.01)
#: the von Mises truss of barhinge.verify: half span 1, rise 0.3, EA 1000
H_VM = 0.3
P_MAX = von_mises_limit_load()


@dataclasses.dataclass
class Outcome:
    status: str  # "converged" | "failed" | "bifurcation"
    cause: str  # named cause (diagnosis) or what was checked
    message: str = ""  # the library's own message (error text or report)
    error_type: str = ""
    detail: str = ""
    value: float = math.nan  # a checked number (e.g. peak load / closed form)


@dataclasses.dataclass(frozen=True)
class Scenario:
    id: str
    method: str
    situation: str
    expected: str
    fn: Callable[[], Outcome]
    quick: bool = False


# ------------------------------------------------------------------------- diagnosis
def diagnose(exc: ConvergenceError, scene: bh.Scene) -> str:
    """Name the cause of a ConvergenceError from its message and the last converged state.

    Rules: the solver's own words (limit point, lock, singular); else the tangent of the free
    DOFs at the last converged state: more zero-stiffness modes than actuators means an
    unrestrained mechanism; under displacement control a controlled-DOF stiffness that fell
    to zero or below means a snap-back; a failure of the first increment means a step too
    large for Newton.
    """
    msg = str(exc)
    if "limit point" in msg:
        return "limit point: load control cannot pass a load maximum"
    if "locked" in msg:
        return "lock: a crease reaches +-180 deg (panels meet)"
    if "singular" in msg:
        return "singular tangent: bifurcation or unrestrained mechanism"
    if "step cap" in msg:
        return "step cap: the arc-length path did not reach load factor 1 (max_arc_steps)"
    path = exc.last_state
    X = path.X[-1] if path is not None else scene.model.X0
    free = ~scene.fixed.ravel()
    n_act = scene.actuators.n if scene.actuators is not None else 0
    n_zero = 0
    if free.sum() <= 3000:  # dense eigenvalues: small models only
        K = scene.model.tangent(X).toarray()
        w = np.linalg.eigvalsh(K[np.ix_(free, free)])
        n_zero = int(np.sum(np.abs(w) <= 1e-9 * np.abs(w).max()))
    if n_zero > n_act:
        return f"mechanism: {n_zero} zero-stiffness modes for {n_act} actuator(s)"
    if scene.control == "displacement" and path is not None and path.n_states >= 3:
        k = _controlled_stiffness(path, scene)
        if k[-1] < 0.3 * k.max():
            return (
                f"snap-back: the stiffness at the prescribed DOF fell from {k.max():.3g} to "
                f"{k[-1]:.3g} (turning point in displacement)"
            )
    if exc.step <= 1 and scene.options.max_cutbacks == 0:
        return "step too large: Newton diverges from the first predictor, no cut-backs allowed"
    return "no convergence (cause not identified)"


def _controlled_stiffness(path, scene) -> np.ndarray:
    """Secant stiffness dF/du at the prescribed DOFs between consecutive states."""
    P = np.isfinite(scene.prescribed)
    u = (path.X - path.X[:1])[:, P].sum(axis=1)
    F = path.reactions[:, P].sum(axis=1)
    return np.diff(F) / np.diff(u)


def _solve(scene: bh.Scene) -> tuple[object | None, Outcome | None]:
    try:
        return bh.solve(scene), None
    except ConvergenceError as exc:
        return None, Outcome("failed", diagnose(exc, scene), str(exc), "ConvergenceError")


# --------------------------------------------------------------------- snap-through
def _vm_load_scene(control: str, factor: float = 1.5) -> bh.Scene:
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -factor * P_MAX
    opts = {"max_arc_steps": 200} if control == "arc_length" else {}
    return bh.Scene(model, supports=S, loads=P, control=control, steps=20, options=opts)


def snap_load() -> Outcome:
    _, out = _solve(_vm_load_scene("load"))
    return out or Outcome("converged", "passed a limit point under load control (unexpected)")


def _events(path) -> str:
    """The solver's stability events of a path, for the table."""
    return "; ".join(path.meta.get("events", [])) or "no events"


def snap_arc() -> Outcome:
    path, out = _solve(_vm_load_scene("arc_length"))
    if out:
        return out
    lam = path.load_factor
    peak = float(lam[: int(np.argmax(np.diff(lam) < 0)) + 1].max()) * 1.5
    return Outcome(
        "converged",
        f"passed the limit point; peak {peak:.4f} P_max (closed form 1)",
        detail=f"{path.n_states} states; {_events(path)}",
        value=peak,
    )


def snap_arc_cap() -> Outcome:
    """Arc length with too few increments for the whole path: must not report success."""
    _, out = _solve(_vm_load_scene("arc_length").with_(options={"max_arc_steps": 20}))
    return out or Outcome("converged", "reached load factor 1 within 20 arc steps")


def roof_arc() -> Outcome:
    """The Yoshimura roof of data/scenes at 30 times its weight: load control stops at a
    limit point near 0.70 (not in the table: see snap-load); arc length passes it and a
    bifurcation on the falling branch, and records both."""
    base = bh.load_scene(ROOT / "data" / "scenes" / "yoshimura_roof.toml")
    scene = base.with_(loads=30 * base.loads, control="arc_length", steps=10,
                       options={"max_arc_steps": 80})  # fmt: skip
    path, out = _solve(scene)
    if out:
        return out
    ev = path.meta["events"]
    ok = any(e.startswith("limit point") for e in ev) and path.load_factor[-1] == 1.0
    return Outcome(
        "converged" if ok else "failed",
        f"through the snap-through to load factor 1; {len(ev)} events recorded",
        detail=f"{path.n_states} states; {_events(path)}",
    )


# ------------------------------------------------------------------------ snap-back
def spring_truss(ks: float):
    """The von Mises truss pulled down through a spring (node 3 below the apex, stiffness
    ``ks``); snap-back when ``ks < EA h^2 / L0^3`` (= 79 here). Node 4 only closes a face."""
    from barhinge.pattern.crease import CreasePattern

    h = H_VM
    cp = CreasePattern(
        vertices=[[-1, 0, 0], [1, 0, 0], [0, 0, h], [0, 0, -h], [0, 1, 0]],
        edges=[[0, 1], [1, 2], [2, 0], [2, 3], [3, 4], [4, 2]],
        assignment=list("BBBBBB"),
        faces=[[0, 1, 2], [2, 3, 4]],
    )
    m0 = bh.BarHingeModel.from_pattern(cp, scheme="N4B5", bar_EA=1000.0)
    bars = np.sort(np.asarray(m0.bars), axis=1).tolist()
    EA = np.full(len(bars), 1000.0)
    EA[bars.index([2, 3])] = ks * 2 * h
    EA[bars.index([3, 4])] = EA[bars.index([2, 4])] = 1e-9
    model = m0.with_(bar_EA=EA)
    S = np.zeros((5, 3), bool)
    S[[0, 1, 4]] = True
    S[[2, 3], :2] = True
    return model, S


def snap_disp() -> Outcome:
    """Displacement control through a stiff spring (k = 1e4: practically the apex itself)."""
    model, S = spring_truss(1e4)
    Pres = np.full((5, 3), np.nan)
    Pres[3, 2] = -2 * H_VM
    scene = bh.Scene(model, supports=S, prescribed=Pres, control="displacement", steps=20)
    path, out = _solve(scene)
    if out:
        return out
    peak = float(np.max(path.reactions[:, 3, 2] * -1.0)) / P_MAX
    ok = abs(peak - 1) < 0.02
    return Outcome(
        "converged" if ok else "failed",
        f"through the snap-through; peak reaction {peak:.4f} P_max (closed form 1, 20 steps)",
        value=peak,
    )


def snapback_disp(ks: float = 20.0) -> Outcome:
    model, S = spring_truss(ks)
    Pres = np.full((5, 3), np.nan)
    Pres[3, 2] = -1.0
    scene = bh.Scene(model, supports=S, prescribed=Pres, control="displacement", steps=20)
    path, out = _solve(scene)
    if out:
        return out
    z = path.X[:, 2, 2]
    jump = float(np.max(np.abs(np.diff(z))))
    if jump > 0.1:
        return Outcome("failed", f"silent jump of the apex by {jump:.3f} in one step (wrong)")
    return Outcome("converged", f"no snap-back (spring stiffness {ks})")


def snapback_arc() -> Outcome:
    model, S = spring_truss(20.0)
    P = np.zeros((5, 3))
    P[3, 2] = -1.2 * P_MAX
    scene = bh.Scene(
        model, supports=S, loads=P, control="arc_length", steps=20, options={"max_arc_steps": 400}
    )
    path, out = _solve(scene)
    if out:
        return out
    u = path.X[:, 3, 2] - path.X[0, 3, 2]
    back = bool(np.any(np.diff(u) > 1e-9))
    return Outcome(
        "converged",
        "followed the snap-back (controlled displacement reverses)"
        if back
        else "converged without a displacement reversal",
        detail=f"{path.n_states} states; {_events(path)}",
    )


# ----------------------------------------------------------------------- flat state
def _branch_check(fold_deg: np.ndarray, cp) -> list[int]:
    """Creases whose fold sign contradicts their M/V assignment."""
    A = cp.assignment
    bad = ((A == "M") & (fold_deg > 1e-6)) | ((A == "V") & (fold_deg < -1e-6))
    return np.flatnonzero(bad).tolist()


def _mmvm():
    cp = degree4_pattern()
    return cp.replaced(assignment=np.array(list("MMVMBBBB")))


def _mode2_targets(rho1: float = -20.0) -> list[float]:
    a, b = math.radians(70.0), math.radians(50.0)
    q = math.sin((a + b) / 2) / math.sin((a - b) / 2)
    r2 = math.degrees(2 * math.atan(q * math.tan(math.radians(rho1) / 2)))
    return [rho1, r2, -rho1, r2, 0, 0, 0, 0]


def flat_rigid_assignment() -> Outcome:
    cp = _mmvm()
    path = bh.rigid_fold(cp, [0], targets_deg=[-40.0], steps=6)
    bad = _branch_check(path.fold_angles_deg[-1], cp)
    if bad:
        return Outcome(
            "bifurcation",
            "flat state: landed on a branch other than the assigned one",
            f"creases {bad} fold against their assignment; give target fold angles to choose",
        )
    return Outcome("converged", "M/V assignment selects its mode (mode 2) off the flat state")


def flat_rigid_branch() -> Outcome:
    cp = _mmvm().replaced(fold_angles=_mode2_targets())
    path = bh.rigid_fold(cp, [0], targets_deg=[-40.0], steps=6)
    bad = _branch_check(path.fold_angles_deg[-1], cp)
    if bad:
        return Outcome("bifurcation", "explicit branch choice ignored", f"creases {bad}")
    return Outcome("converged", "explicit branch choice (target fold angles): assigned branch")


def flat_dof() -> Outcome:
    rep = bh.dof(bh.families.miura(3, 3))
    fold = rep.folded.global_dof if rep.folded is not None else rep.global_dof
    if rep.global_dof != fold:
        return Outcome(
            "bifurcation",
            "flat state is a bifurcation point (reported by bh.dof)",
            f"{rep.global_dof} infinitesimal DOF at the flat state, {fold} at a folded state",
        )
    return Outcome("converged", "no DOF change at the flat state")


def seeded_pattern(cp, actuator: int, seed_deg: float, branch_deg=None):
    """Branch selection by imperfection: the pattern moved rigidly ``seed_deg`` off the flat
    state along the branch given by ``branch_deg`` (target fold angles; default the
    pattern's own), to be used as the stress-free reference of a bar-and-hinge model."""
    cpb = cp if branch_deg is None else cp.replaced(fold_angles=branch_deg)
    path = bh.rigid_fold(cpb, [actuator], targets_deg=[seed_deg], steps=2)
    return cpb.replaced(vertices=path.X[-1])


def flat_barhinge(seed: bool) -> Outcome:
    cp = _mmvm()
    if seed:
        cp = seeded_pattern(cp, 0, -2.0, _mode2_targets())
    model = bh.BarHingeModel.from_pattern(cp, scheme="N4B5", material=MAT, stiffness_ratio=1e3)
    scene = bh.Scene(model, actuators=bh.Actuators(edges=[0], targets_deg=[-40.0]), steps=8)
    path, out = _solve(scene)
    if out:
        return out
    bad = _branch_check(path.fold_angles_deg[-1], cp)
    if bad:
        return Outcome(
            "bifurcation",
            "flat state: the solver's branch contradicts the M/V assignment",
            f"creases {bad} fold against their assignment; seed an imperfection to choose",
        )
    if seed:
        return Outcome(
            "converged",
            "imperfection (2 deg along mode 2) selects the assigned branch",
            detail=_events(path),
        )
    return Outcome(
        "converged",
        "rigid-fold predictor leaves the flat state on the assigned branch (mode 2)",
        detail=_events(path),
    )


def flat_barhinge_soft() -> Outcome:
    """A 6 x 6 Miura sheet whose panels are only 100 x the default stiffness, driven by one
    crease from flat: the panels bend rather than fold the far creases, which then fold
    against their assignment; the run must say so."""
    cp = bh.families.miura(6, 6, alpha=60.0)
    z = int(bh.families.miura_layout(6, 6).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=1e2)
    acts = bh.Actuators(edges=[z], targets_deg=[0.5 * cp.fold_angles[z]])
    path, out = _solve(bh.Scene(model, actuators=acts, steps=6))
    if out:
        return out
    events = path.meta.get("branch_events", [])
    bad = _branch_check(path.fold_angles_deg[-1], cp)
    if events:
        return Outcome(
            "bifurcation", "soft panels bend: creases fold against the assignment", events[0]
        )
    if bad:
        return Outcome("failed", "creases against the assignment were not reported", str(bad))
    return Outcome("converged", "the whole sheet followed the assignment")


# ---------------------------------------------------------------------- large steps
def _miura_cell_scene(target: float, steps: int, cutbacks: int = 8, **model_kw) -> bh.Scene:
    # starts folded (10 deg): from the flat state the rigid-fold predictor would place the
    # first increment exactly, and this scenario is about Newton's own reach
    cp = bh.families.miura(1, 1, alpha=60.0, fold=10.0)
    kw = {"stiffness_ratio": 1e3, **model_kw}
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, **kw)
    return bh.Scene(
        model,
        actuators=bh.Actuators(edges=[7], targets_deg=[target]),
        steps=steps,
        options={"max_cutbacks": cutbacks},
    )


def large_step(cutbacks: int) -> Outcome:
    path, out = _solve(_miura_cell_scene(-150.0, 1, cutbacks))
    if out:
        return out
    ref = bh.solve(_miura_cell_scene(-150.0, 20))
    d = float(np.max(np.abs(path.fold_angles_deg[-1] - ref.fold_angles_deg[-1])))
    ok = d < 0.05
    return Outcome(
        "converged" if ok else "failed",
        f"one step with cut-backs; fold angles within {d:.1e} deg of a 20-step path"
        if ok
        else f"landed {d:.2f} deg away from the 20-step path (another branch)",
        detail=_events(path),
    )


# ------------------------------------------------------------------ soft/stiff folds
def soft_folds() -> Outcome:
    cp = bh.families.miura(2, 2, alpha=60.0)
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, fold_stiffness=0.0)
    scene = bh.Scene(
        model,
        actuators=bh.Actuators(
            edges=[int(np.flatnonzero(cp.assignment == "M")[0])], targets_deg=[-60.0]
        ),  # fmt: skip
        steps=6,
        options={"max_cutbacks": 3},
    )
    path, out = _solve(scene)
    if out:
        return out
    # folded, the Miura is a 1-DOF mechanism the actuator fixes: the rigid fold is the answer
    rigid = bh.rigid_fold(cp, scene.actuators, steps=6).fold_angles_deg[-1]
    d = float(np.max(np.abs(path.fold_angles_deg[-1] - rigid)))
    if d > 1e-3:
        return Outcome("failed", f"zero-stiffness folds: {d:.3g} deg from the rigid fold")
    return Outcome(
        "converged",
        f"mechanism fixed by its actuator once folded; rigid fold to {d:.1e} deg",
    )


def stiff_folds() -> Outcome:
    scene = _miura_cell_scene(-100.0, 10, stiffness_ratio=1e-4)
    path, out = _solve(scene)
    if out:
        return out
    rigid = 2 * math.degrees(math.atan(math.cos(math.radians(60)) * math.tan(math.radians(50))))
    got = float(np.max(np.abs(path.fold_angles_deg[-1][[2, 3]])))
    return Outcome(
        "converged",
        "equilibrium found; panels bend instead of folding (folds 1e4x stiffer)",
        detail=f"straight creases at {got:.2f} deg vs rigid {rigid:.2f} deg",
    )


# ---------------------------------------------------------------- near flat-folded
def rigid_near_flat(target: float) -> Outcome:
    cp = bh.families.miura(1, 1, alpha=60.0)
    try:
        path = bh.rigid_fold(cp, [7], targets_deg=[target], steps=20)
    except ConvergenceError as exc:
        return Outcome("failed", "lock: a crease reaches +-180 deg", str(exc), "ConvergenceError")
    return Outcome(
        "converged",
        f"reached {abs(path.fold_angles_deg[-1]).max():.3f} deg (lock at 179.999)",
    )


def barhinge_near_flat() -> Outcome:
    scene = _miura_cell_scene(-178.0, 20, fold_law="penetration")
    path, out = _solve(scene)
    if out:
        return out
    return Outcome(
        "converged",
        f"reached -178 deg ({int(path.iterations.sum())} Newton iterations)",
        detail=_events(path),
    )


# ---------------------------------------------------------------- driven instability
def driven_strut() -> Outcome:
    """Three rigid links on two crease springs k (l = 1, k = 2), pinned at both ends, the
    first inner crease driven and held at 0 deg while the axial load grows to 4.4: held,
    the strut buckles at ``3 k / (2 l) = 3`` (the held crease joins two links), so the
    fold-angle path converges to states no actuator can hold from the first step past it
    (step 7, load 3.08); the run must report that, not only the released count's change
    at ``2 k / l = 2``."""
    model, S, P = rigid_link_strut(3, ell=1.0, k=2.0)
    crease = next(i for i, e in enumerate(model.pattern.edges) if set(e) == {1, 5})
    acts = bh.Actuators(edges=[crease], targets_deg=[0.0])
    scene = bh.Scene(model, supports=S, loads=4.4 * P, actuators=acts, steps=10)
    path, out = _solve(scene)
    if out:
        return out
    held = [e for e in path.meta["events"] if e.startswith("unstable equilibrium")]
    if not held:
        return Outcome("failed", "the held instability was not reported", _events(path))
    first = path.meta["negative_eigenvalues_held"].index(1)
    load = 4.4 * float(path.load_factor[first])
    return Outcome(
        "bifurcation",
        f"unstable with the actuator held from load {load:.2f} (closed form: past 3)",
        held[0],
        value=load / 3.0,
    )


# --------------------------------------------------------------------------- table
SCENARIOS: list[Scenario] = [
    Scenario("snap-load", "load control", "snap-through (limit point)", "failed", snap_load, True),
    Scenario(
        "snap-disp",
        "displacement control",
        "snap-through (limit point)",
        "converged",
        snap_disp,
        True,
    ),  # fmt: skip
    Scenario("snap-arc", "arc length", "snap-through (limit point)", "converged", snap_arc, True),
    Scenario(
        "snap-arc-cap",
        "arc length",
        "snap-through, max_arc_steps = 20",
        "failed",
        snap_arc_cap,
        True,
    ),  # fmt: skip
    Scenario(
        "roof-arc",
        "arc length",
        "Yoshimura roof, 30x weight (snap-through)",
        "converged",
        roof_arc,
    ),  # fmt: skip
    Scenario("snapback-disp", "displacement control", "snap-back", "failed", snapback_disp, True),
    Scenario("snapback-arc", "arc length", "snap-back", "converged", snapback_arc),
    Scenario(
        "flat-rigid-mv",
        "rigid path",
        "flat-state bifurcation, M/V assignment",
        "converged",
        flat_rigid_assignment,
        True,
    ),  # fmt: skip
    Scenario(
        "flat-rigid-branch",
        "rigid path",
        "flat-state bifurcation, branch chosen",
        "converged",
        flat_rigid_branch,
        True,
    ),  # fmt: skip
    Scenario("flat-dof", "rigid DOF", "flat Miura 3x3", "bifurcation", flat_dof, True),
    Scenario(
        "flat-bh",
        "fold-angle control",
        "flat-state bifurcation, no imperfection",
        "converged",
        lambda: flat_barhinge(False),
    ),  # fmt: skip
    Scenario(
        "flat-bh-soft",
        "fold-angle control",
        "flat start, soft panels (6x6 Miura, 1 actuator)",
        "bifurcation",
        flat_barhinge_soft,
    ),  # fmt: skip
    Scenario(
        "flat-bh-seed",
        "fold-angle control",
        "flat-state bifurcation, 2 deg imperfection",
        "converged",
        lambda: flat_barhinge(True),
    ),  # fmt: skip
    Scenario(
        "large-step",
        "fold-angle control",
        "10 -> 150 deg in 1 step, no cut-back",
        "failed",
        lambda: large_step(0),
        True,
    ),  # fmt: skip
    Scenario(
        "large-step-cut",
        "fold-angle control",
        "10 -> 150 deg in 1 step, cut-backs",
        "converged",
        lambda: large_step(8),
    ),  # fmt: skip
    Scenario(
        "driven-strut",
        "fold-angle control",
        "driven strut loaded past the buckling load of its held structure",
        "bifurcation",
        driven_strut,
        True,
    ),  # fmt: skip
    Scenario("soft-folds", "fold-angle control", "k_fold = 0 (Miura 2x2)", "converged", soft_folds),
    Scenario(
        "stiff-folds",
        "fold-angle control",
        "folds 1e4x stiffer than panels",
        "converged",
        stiff_folds,
    ),  # fmt: skip
    Scenario(
        "rigid-179.99",
        "rigid path",
        "near flat-folded (179.99 deg)",
        "converged",
        lambda: rigid_near_flat(-179.99),
    ),  # fmt: skip
    Scenario(
        "rigid-lock",
        "rigid path",
        "past the lock (179.9995 deg)",
        "failed",
        lambda: rigid_near_flat(-179.9995),
        True,
    ),  # fmt: skip
    Scenario(
        "bh-178",
        "fold-angle control",
        "near flat-folded (178 deg, penetration law)",
        "converged",
        barhinge_near_flat,
    ),  # fmt: skip
]


def run_map(quick: bool = True) -> list[dict]:
    """Run the scenarios (the quick subset when ``quick``); one record per scenario."""
    out = []
    for sc in SCENARIOS:
        if quick and not sc.quick:
            continue
        t0 = time.perf_counter()
        try:
            res = sc.fn()
        except ConvergenceError as exc:  # a scenario that did not catch its own
            res = Outcome("failed", "uncaught", str(exc), "ConvergenceError")
        except Exception as exc:  # noqa: BLE001 - any other error is a finding too
            res = Outcome("error", f"{type(exc).__name__}", str(exc), type(exc).__name__)
        rec = {
            "id": sc.id,
            "method": sc.method,
            "situation": sc.situation,
            "expected": sc.expected,
            **dataclasses.asdict(res),
            "time_s": round(time.perf_counter() - t0, 3),
        }
        out.append(rec)
    return out


RECORDS = run_map(QUICK)


def markdown_table(records: list[dict]) -> str:
    rows = ["| scenario | method | situation | result | cause | library message |",
            "|---|---|---|---|---|---|"]  # fmt: skip
    for r in records:
        msg = (r["message"] or r["detail"]).replace("|", "/")
        rows.append(
            f"| {r['id']} | {r['method']} | {r['situation']} | {r['status']} | "
            f"{r['cause']} | {msg} |"
        )
    return "\n".join(rows)


if MAIN:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    res_dir = HERE / ("results-quick" if QUICK else "results")
    res_dir.mkdir(exist_ok=True)
    with (res_dir / "stability.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(RECORDS[0]))
        w.writeheader()
        w.writerows(RECORDS)
    print(markdown_table(RECORDS))
    colours = {"converged": "tab:green", "failed": "tab:red", "bifurcation": "tab:orange",
               "error": "black"}  # fmt: skip
    methods = list(dict.fromkeys(r["method"] for r in RECORDS))
    fig, ax = plt.subplots(figsize=(14, 0.42 * len(RECORDS) + 1.8))
    for y, r in enumerate(RECORDS):
        x = methods.index(r["method"])
        ax.scatter(x, y, s=160, color=colours[r["status"]], zorder=3)
        text = f"{r['situation']}: {r['cause']}"
        text = text if len(text) <= 100 else text[:99] + "..."
        ax.text(len(methods) - 0.4, y, text, va="center", fontsize=7.5)
    ax.set_yticks(range(len(RECORDS)), [r["id"] for r in RECORDS], fontsize=8)
    ax.set_xticks(range(len(methods)), methods, rotation=20, ha="right", fontsize=8)
    ax.set_xlim(-0.5, len(methods) + 7.5)
    ax.invert_yaxis()
    ax.grid(axis="x", alpha=0.3)
    for s, c in colours.items():
        if any(r["status"] == s for r in RECORDS):
            ax.scatter([], [], color=c, label=s)
    ax.legend(loc="upper center", bbox_to_anchor=(0.75, -0.04), ncol=4, fontsize=8)
    ax.set_title(
        "Stability map: where each method converges, fails (ConvergenceError) or reports a "
        "bifurcation",
        fontsize=10,
    )
    fig.tight_layout()
    img = ROOT / "docs" / "img" / "stability_map.png"
    fig.savefig(res_dir / "stability_map.png", dpi=110)
    if not QUICK:
        fig.savefig(img, dpi=110)
        doc = ROOT / "docs" / "stability.md"
        text = doc.read_text()
        a, b = "<!-- stability-table:start -->", "<!-- stability-table:end -->"
        if a in text and b in text:
            head, rest = text.split(a, 1)
            tail = rest.split(b, 1)[1]
            doc.write_text(f"{head}{a}\n{markdown_table(RECORDS)}\n{b}{tail}")
    print(f"wrote {res_dir / 'stability.csv'}")
