"""The summary of a run (``summary.json``) and the lines ``barhinge fold`` prints from it.

One summary for every kind of run: the run's status and totals (:func:`run_summary`, from
the path alone) and, under ``results``, the final state's analysis
(:func:`barhinge.analysis.final_state.final_state_results`: curvature, strains, stiffness).
docs/outputs.md lists the fields and their units.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from barhinge.analysis.final_state import energy_split
from barhinge.results import FoldPath

if TYPE_CHECKING:
    from barhinge.solver.state import IterationStatus

__all__ = [
    "energy_share_text",
    "flat_start_text",
    "run_summary",
    "slowest_steps",
    "stop_reason",
    "summary_rows",
]


def stop_reason(path: FoldPath) -> str | None:
    """Why a path stopped early: None (it converged), ``"interrupted"`` (Ctrl-C) or
    ``"not converged"``."""
    if path.converged:
        return None
    return str(path.meta.get("stopped") or "not converged")


#: steps named in a summary's ``slowest_steps``
SLOWEST_STEPS = 3


def slowest_steps(wall_time: np.ndarray, k: int = SLOWEST_STEPS) -> list[dict[str, float]]:
    """The ``k`` longest steps of a solve from its per-state wall clock ``wall_time`` (s since
    the solve started; state 0 first): each ``{"step": i, "wall_s": t, "share": t / total}``,
    the longest first, where step ``i`` ends at state ``i``; ``share`` is of the whole
    solve's time to its last state. Empty without a step or a finite clock."""
    wall = np.asarray(wall_time, float)
    if len(wall) < 2 or not np.all(np.isfinite(wall)) or wall[-1] <= 0.0:
        return []
    dt = np.diff(wall)
    order = np.argsort(-dt, kind="stable")[:k]
    return [
        {"step": int(i + 1), "wall_s": float(dt[i]), "share": float(dt[i] / wall[-1])}
        for i in order
    ]


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def run_summary(path: FoldPath, scene: Any = None) -> dict[str, Any]:
    """Status and totals of a run, from its path alone (JSON-serialisable; NaN -> None).

    ``model`` is ``"rigid"`` for a path of rigid kinematics, else ``"bar-hinge"``; the
    energies of a rigid path are None.
    """
    last = path.n_states - 1
    acts = path.actuator_edges
    # FoldPath fills every per-state array in __post_init__ (NaN where unknown)
    wall, iters, lam = (np.asarray(a) for a in (path.wall_time, path.iterations, path.load_factor))
    e_bars, e_bend, e_fold, work, moments = (
        np.asarray(a)
        for a in (
            path.energy_bars,
            path.energy_bend,
            path.energy_fold,
            path.external_work,
            path.actuator_moments,
        )
    )
    out: dict[str, Any] = {
        "scene": path.meta.get("scene", getattr(scene, "name", "")),
        "model": "rigid" if path.kind == "rigid" else "bar-hinge",
        "control": path.meta.get("control", "rigid kinematics" if path.kind == "rigid" else None),
        "converged": bool(path.converged),
        "reason": stop_reason(path),
        "message": path.message,
        "n_states": int(path.n_states),
        "n_nodes": int(path.X.shape[1]),
        "n_dof": path.meta.get("n_dof"),
        "linear_solver": path.meta.get("linear_solver"),
        "wall_time_s": _finite(wall[last]) if path.n_states else 0.0,
        # where the solve spent its time: the longest steps (leaving a flat start, often)
        "slowest_steps": slowest_steps(wall),
        "newton_iterations": int(np.sum(iters)),
        "load_factor": float(lam[last]),
        "max_abs_fold_deg": float(np.abs(path.fold_angles_deg[last]).max(initial=0.0)),
        "energy": {
            "bars": _finite(e_bars[last]),
            "bend": _finite(e_bend[last]),
            "fold": _finite(e_fold[last]),
            "total": _finite(e_bars[last] + e_bend[last] + e_fold[last]),
            "external_work": _finite(work[last]),
        },
        "actuators": {
            "edges": acts.tolist(),
            "angle_deg": path.fold_angles_deg[last][acts].tolist() if len(acts) else [],
            "moment": [_finite(m) for m in moments[last].tolist()],
            # compliant actuators (springs to their targets) and their stretch, deg
            "compliant": bool(path.meta.get("compliant_actuators", False)),
            "misfit_deg": (
                _finite(path.meta["actuator_misfit_deg"][last])
                if path.meta.get("actuator_misfit_deg")
                else None
            ),
        },
        "timing": path.meta.get("timing", {}),
        # step control per step: Newton iterations, increments, failed increments,
        # factorisations (bar-and-hinge runs; docs/solver-performance.md)
        "newton": path.meta.get("newton"),
        # stability events (limit points, bifurcations, negative-stiffness branches) and
        # the work balance; see docs/solver.md
        "events": [str(e) for e in path.meta.get("events", [])],
        "work_balance": path.meta.get("work_balance"),
        "reaction_sum": (
            path.reactions[last].sum(axis=0).tolist() if path.reactions is not None else None
        ),
        "closure_residual": path.meta.get("max_closure"),
        # barhinge fold --accuracy: the model chosen and its estimated error
        "model_choice": path.meta.get("model_choice"),
        # [imperfection]: the buckling mode the model is stress-free in, and its amplitude
        "imperfection": path.meta.get("imperfection"),
    }
    return out


def imperfection_text(rec: dict[str, Any]) -> str:
    """An imperfection record (``model.meta["imperfection"]``) as one line: "buckling mode 1
    (factor 0.53), amplitude 0.0133 = span/300"."""
    text = ""
    if rec.get("mode") is not None:
        text = f"buckling mode {rec['mode']} (factor {rec['buckling_factor']:.4g}), "
    text += f"amplitude {rec['amplitude']:.4g}"
    return text + (f" = {rec['rule']}" if rec.get("rule") else "")


def _percent(x: float) -> str:
    p = 100.0 * x
    return f"{p:.1f} %" if p == 0.0 or abs(p) >= 0.1 else f"{p:.1g} %"


def energy_share_text(path: FoldPath) -> str:
    """The last state's energy split as one line ("folds 99.5 %, panel bending 0.4 %,
    bars 0.1 %"); "" when the total is zero or unknown (rigid paths)."""
    e = energy_split(path)
    parts = (("folds", "fold"), ("panel bending", "bend"), ("bars", "bars"))
    shares = [(label, e[f"energy_fraction_{k}"]) for label, k in parts]
    return ", ".join(f"{label} {_percent(x)}" for label, x in shares if x is not None)


def iterate_text(status: IterationStatus) -> str:
    """The running iterate in one line for a progress display, e.g. "increment 1/4 of a
    step, iterate 5, residual 3.2e+01, after 2 failed increments" (the increment only when
    shorter than a step, the failures of the step only when there were some)."""
    parts = []
    length = status.length
    if 0.0 < length < 1.0 - 1e-9:
        k = 1.0 / length
        parts.append(f"increment 1/{k:.0f} of a step" if abs(k - round(k)) < 1e-6 * k
                     else f"increment {length:.2g} of a step")  # fmt: skip
    parts.append("predictor" if status.iteration == 0 else f"iterate {status.iteration}")
    parts.append(f"residual {status.residual:.1e}")
    if status.failed:
        parts.append(f"after {status.failed} failed increment{'s' * (status.failed > 1)}")
    return ", ".join(parts)


def flat_start_text(path: FoldPath) -> str:
    """``meta["flat_start"]`` as one line ("rigid panels, M/V assignment"); "" without it."""
    rec = path.meta.get("flat_start")
    if not rec:
        return ""
    words = [str(rec.get("predictor", "?"))]
    if rec.get("branch"):
        words.append(str(rec["branch"]))
    if rec.get("mirrored"):
        words.append("mirrored")
    if rec.get("sign_conflicts"):
        words.append(f"{len(rec['sign_conflicts'])} crease(s) against the branch signs")
    return ", ".join(words)


def summary_rows(summary: dict[str, Any], path: FoldPath | None = None) -> list[tuple[str, str]]:
    """(quantity, value) rows of the ``barhinge fold`` table, from a summary written by
    :func:`barhinge.output.run.write_run` (and the path, for the energy share and the flat
    start)."""
    rows: list[tuple[str, str]] = [("model", str(summary["model"]))]
    if summary["model"] != "rigid":
        rows.append(("DOF", str(summary["n_dof"])))
    rows.append(("states", str(summary["n_states"])))
    if summary["model"] != "rigid":
        rows.append(("Newton iterations", str(summary["newton_iterations"])))
        nw = summary.get("newton") or {}
        if nw.get("total_factorizations") is not None:
            steps = max(len(nw.get("factorizations") or []), 1)
            rows.append(
                (
                    "factorisations (per step; failed increments)",
                    f"{nw['total_factorizations']} ({nw['total_factorizations'] / steps:.1f}; "
                    f"{nw.get('total_failed', 0)})",
                )
            )
        if nw.get("total_chord"):
            rows.append(("chord corrections", str(nw["total_chord"])))
    if summary["wall_time_s"] is not None:
        rows.append(("wall time (s)", f"{summary['wall_time_s']:.2f}"))
    slow = summary.get("slowest_steps") or []
    if summary["model"] != "rigid" and len(slow) > 1:
        rows.append(
            (
                "slowest steps",
                ", ".join(
                    f"{d['step']}: {d['wall_s']:.2f} s ({_percent(d['share'])})" for d in slow
                ),
            )
        )
    if summary.get("linear_solver"):
        rows.append(("linear solver", str(summary["linear_solver"])))
    for k, v in summary["energy"].items():
        if v is not None:
            rows.append((f"energy {k}", f"{v:.6g}"))
    if path is not None:
        share, flat = energy_share_text(path), flat_start_text(path)
        if share:
            rows.append(("energy share", share))
        if flat:
            rows.append(("flat start", flat))
    moments = [abs(m) for m in summary["actuators"]["moment"] if m is not None]
    if moments:
        rows.append(("max |actuator moment|", f"{max(moments):.6g}"))
    mis = summary["actuators"].get("misfit_deg")
    if mis is not None and summary["actuators"].get("compliant"):
        rows.append(("compliant actuators: max |rho - target| (deg)", f"{mis:.4g}"))
    if summary.get("imperfection"):
        rows.append(("imperfection", imperfection_text(summary["imperfection"])))
    if summary.get("closure_residual") is not None:
        rows.append(("max loop-closure residual", f"{summary['closure_residual']:.2g}"))
    rows += _results_rows(summary.get("results") or {})
    return rows


def _results_rows(s: dict[str, Any]) -> list[tuple[str, str]]:
    rows: list[tuple[str, str]] = []

    def add(label: str, key: str, fmt: str = "{:.4g}") -> None:
        v = s.get(key)
        if v is not None:
            rows.append((label, fmt.format(v)))

    act = s.get("actuator_fold_deg") or []
    if len(act) > 4:
        a = np.abs(act)
        rows.append(
            (
                f"final |actuator fold| (deg), {len(act)} actuators",
                f"{a.min():.2f} .. {a.max():.2f}",
            )
        )
    elif act:
        rows.append(("final actuator fold (deg)", ", ".join(f"{v:.2f}" for v in act)))
    add("max |fold angle| (deg)", "max_abs_fold_deg", "{:.2f}")
    add("Gaussian curvature K (global form)", "K_global")
    add("mean curvature H (global form)", "H_global")
    add("max |angle defect| (deg)", "max_abs_angle_defect_deg", "{:.3g}")
    add("max |bar strain|", "max_abs_bar_strain", "{:.3g}")
    f = s.get("forces") or {}
    if f.get("max_displacement") is not None:
        rows.append(
            (
                "max displacement (node)",
                f"{f['max_displacement']:.4g} ({f['max_displacement_node']})",
            )
        )
    if f.get("reaction_total") is not None and any(f.get("reactions_by_support") or {}):
        rx, ry, rz = f["reaction_total"]
        rows.append(("reaction total (x, y, z)", f"{rx:.4g}, {ry:.4g}, {rz:.4g}"))
    if f.get("max_tension") is not None:
        rows.append(
            (
                "max bar tension / compression",
                f"{f['max_tension']:.4g} / {f['max_compression']:.4g}",
            )
        )
    b = s.get("buckling") or {}
    if b.get("factors"):
        rows.append(("linear buckling factor (state 0)", f"{b['factors'][0]:.4g}"))
    elif b.get("error"):
        rows.append(("linear buckling factor (state 0)", "none: " + b["error"].split(": ")[-1]))
    if f.get("max_crease_moment"):
        rows.append(("max |crease moment|", f"{f['max_crease_moment']:.4g}"))
    if s.get("lowest_eigenvalues"):
        rows.append(
            ("lowest tangent eigenvalue (actuators released)", f"{s['lowest_eigenvalues'][0]:.4g}")
        )
    add("soft modes (of those computed)", "n_soft_modes", "{}")
    add("effective stiffness (scene loads)", "effective_stiffness")
    return rows
