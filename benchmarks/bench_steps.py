"""Where a fold's time goes, step by step: the flat start against the steps after it.

Run:  python benchmarks/bench_steps.py [--sizes 40 70 100] [--compliant-sizes 20] [--steps 50]
      [--split 1 5 10] [--threads N] [--publish]

Each size folds ``bench_solver.miura_scene`` (Miura n x n, N5B8, flat -> 60 deg in
``--steps`` steps, actuators on the middle crease line) with the solver's clock read after
every step. The steps are grouped at ``--split`` (default: step 1, steps 2-5, 6-10 and the
rest), and per group the table gives the wall time and its share of the fold, the
factorisations, tangent assemblies, force-only evaluations and back-substitutions, where
their seconds went, and the wall time per step in *factorisations*: the median time of the
fold's own factorisations, over the steps that made exactly one (the floor of one
factorisation per step, measured where the fold makes it). A step whose cost is 1.0 would
meet that floor. Each fold's sentence also gives the median of seven bare numeric
refactorisations of the last tangent (``bench_solver.bare_factorisation``, the unit of the
scaling table's floor, docs/solver-performance.md): on this shared machine that median
moved between 0.32 s and 0.53 s for the same 70 x 70 tangent from one run to the next,
where the fold's own median (some forty factorisations) stayed at 0.49-0.50 s.

Two more tables come from the solver's iterate log (``FoldPath.meta["iterates"]``): per
group, the corrections by kind (Newton, accelerated, chord, damped), those that raised the
residual and the failed increments; and, per fold, the flat start's hardest step (the most
factorisations among the steps before the last group) iterate by iterate.

``--threads N`` fixes the thread count of MKL and of the worker threads
(``BARHINGE_THREADS``; default this machine's cores), in the fold and in its
refactorisations alike. ``--publish`` writes the
table into docs/solver-performance.md (between the ``steps`` markers).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: bare refactorisations of the last tangent whose median is the unit of the last column (more
#: than the scaling table's three: a median of three moved by 40 % between runs at 40 x 40)
REPEATS = 7
#: the solver clock's parts, in the table's order: (Timer field, column name)
PARTS = (
    ("factorize", "factorisation"),
    ("assembly_tangent", "tangent assembly"),
    ("assembly_force", "force evaluations"),
    ("solve", "back-substitutions"),
    ("rest", "rest"),
)


def _snapshot(timer, t0: float) -> dict[str, float]:
    """The solver clock's totals now (seconds and counts), with the wall time since ``t0``."""
    d = dict(timer.as_dict())
    d["wall"] = time.perf_counter() - t0
    d["assembly_force"] = d["assembly"] - d["assembly_tangent"]
    return d


def fold_steps(n: int, steps: int, material: str) -> dict:
    """Fold the n x n sheet; the solver clock after every step and the refactorisation."""
    from bench_solver import bare_factorisation, miura_scene

    from barhinge.linalg.threads import sparse_solves
    from barhinge.solver.newton import _Driver

    sc = miura_scene(n, 0.0, steps, material=material)
    with sparse_solves():
        t0 = time.perf_counter()
        driver = _Driver(sc)
        # the clock starts before the driver is made: step 1 carries its set-up (rest)
        snaps = [{k: 0.0 for k in _snapshot(driver.ctx.timer, t0)}]

        def progress(done: int, total: int, value: float) -> None:
            snaps.append(_snapshot(driver.ctx.timer, t0))

        path = driver.run_parameter(progress)
        mu = -np.asarray(path.actuator_moments[-1])
        refac, _ = bare_factorisation(
            sc, path.X[-1], mu, path.meta["linear_solver"], repeat=REPEATS
        )
    if not path.converged or len(snaps) != steps + 1:
        raise RuntimeError(f"the {n} x {n} fold stopped short: {path.meta.get('message')}")
    one, secs = fold_factorisations(snaps)
    return {
        "fold_factorisation": one,
        "fold_factorisation_samples": secs,
        "n_fold_factorisations": len(secs),
        "n": n,
        "material": material,
        "dof": int(sc.model.n_dof),
        "snaps": snaps,
        "refactorisation": refac,
        "steps": steps,
        "iterates": path.meta["iterates"],
        "failed": path.meta["newton"]["failed"],
        "increments": path.meta["newton"]["increments"],
        "residuals": [list(h) for h in path.residual_norms[1:]],
        "factorizations": path.meta["newton"]["factorizations"],
        "size": float(np.linalg.norm(np.ptp(np.asarray(sc.model.X0), axis=0))),
    }


def fold_factorisations(snaps: list[dict[str, float]]) -> tuple[float, list[float]]:
    """The fold's own factorisation time: (the median, s; the samples), from the clock read
    after each step. The samples are the factorisation seconds of every step that made
    exactly one; a short fold with no such step takes each step's seconds per factorisation
    instead."""
    pairs = [
        (b["factorize"] - a["factorize"], b["n_factorizations"] - a["n_factorizations"])
        for a, b in zip(snaps, snaps[1:], strict=False)
    ]
    secs = [t for t, n in pairs if n == 1] or [t / n for t, n in pairs if n > 0]
    if not secs:
        raise RuntimeError("the fold made no factorisation")
    return float(np.median(secs)), secs


def groups(steps: int, split: list[int]) -> list[tuple[int, int]]:
    """Step ranges (first, last), 1-based and inclusive, cut after each step of ``split``."""
    cuts = sorted({s for s in split if 0 < s < steps}) + [steps]
    out, first = [], 1
    for c in cuts:
        out.append((first, c))
        first = c + 1
    return out


def _range(a: int, b: int) -> str:
    return str(a) if a == b else f"{a}-{b}"


def group_row(run: dict, a: int, b: int) -> dict:
    """The clock of steps a..b of one fold (differences of its snapshots)."""
    s0, s1 = run["snaps"][a - 1], run["snaps"][b]
    d = {k: s1[k] - s0[k] for k in s1}
    d["rest"] = d["wall"] - d["factorize"] - d["assembly"] - d["solve"]
    d["n_steps"] = b - a + 1
    d["share"] = d["wall"] / run["snaps"][-1]["wall"]
    d["per_step_refac"] = d["wall"] / d["n_steps"] / run["fold_factorisation"]
    return d


def table(runs: list[dict], split: list[int]) -> list[str]:
    head = (
        "| n | stiffness set | steps | wall s (share of the fold) | factorisations | "
        "tangent assemblies | force evaluations | back-substitutions | "
        "seconds: " + " / ".join(name for _, name in PARTS) + " | "
        "a step, in the fold's factorisations |"
    )
    lines = [head, "|" + "---|" * 10]
    for run in runs:
        for a, b in groups(run["steps"], split):
            d = group_row(run, a, b)
            secs = " / ".join(f"{d[k]:.2f}" for k, _ in PARTS)
            lines.append(
                f"| {run['n']} | {run['material']} | {_range(a, b)} | "
                f"{d['wall']:.1f} ({100 * d['share']:.0f} %) | {int(d['n_factorizations'])} | "
                f"{int(d['n_tangent'])} | {int(d['n_force_only'])} | {int(d['n_solves'])} | "
                f"{secs} | {d['per_step_refac']:.2f} |"
            )
    return lines


#: the kinds of correction of the iterate log counted per group (the predictor is not one)
CORRECTIONS = ("newton", "accelerated", "chord", "damped")


def correction_counts(run: dict, a: int, b: int) -> dict[str, int]:
    """Corrections of steps a..b by kind (the solver's iterate log), those that raised the
    residual above the iterate before them (in the same increment), and the failed
    increments."""
    log = run["iterates"]
    step, inc, kind = (np.asarray(log[k]) for k in ("step", "increment", "kind"))
    res = np.asarray(log["residual"], float)
    sel = (step >= a) & (step <= b)
    out = {k: int(np.sum(sel & (kind == k))) for k in CORRECTIONS}
    same = np.r_[False, inc[1:] == inc[:-1]]  # an iterate after one of its own increment
    rose = same & np.r_[False, res[1:] > res[:-1]]
    out["rose"] = int(np.sum(sel & rose))
    out["failed"] = int(sum(run["failed"][a - 1 : b]))
    return out


def correction_table(runs: list[dict], split: list[int]) -> list[str]:
    """Per group of steps: the corrections by kind, those that raised the residual and the
    failed increments (from the iterate log, ``iterations.csv`` of ``barhinge fold``)."""
    head = (
        "| n | stiffness set | steps | corrections: " + " / ".join(CORRECTIONS) + " | "
        "corrections that raised the residual | failed increments |"
    )
    lines = [head, "|" + "---|" * 6]
    for run in runs:
        for a, b in groups(run["steps"], split):
            c = correction_counts(run, a, b)
            kinds = " / ".join(str(c[k]) for k in CORRECTIONS)
            lines.append(
                f"| {run['n']} | {run['material']} | {_range(a, b)} | {kinds} | "
                f"{c['rose']} | {c['failed']} |"
            )
    return lines


def hardest_step(run: dict, last: int) -> int:
    """The step of 1..last with the most factorisations (the first of equals)."""
    f = run["factorizations"][:last]
    return int(np.argmax(f)) + 1


def hardest_lines(runs: list[dict], split: list[int]) -> list[str]:
    """The flat start's hardest step of each fold, iterate by iterate."""
    out = []
    for run in runs:
        a, _ = groups(run["steps"], split)[-1]
        s = hardest_step(run, max(a - 1, 1))
        log = run["iterates"]
        rows = [i for i, st in enumerate(log["step"]) if st == s]
        out += [
            f"#### {run['material']}, n = {run['n']}: step {s}, "
            f"{run['factorizations'][s - 1]} factorisations (sheet size {run['size']:.1f})",
            "",
            "| increment | iterate | kind | correction (norm over the free DOFs) | "
            "correction / sheet size (what the displacement test bounds by tol_disp) | "
            "residual |",
            "|---|---|---|---|---|---|",
        ]
        first_inc = log["increment"][rows[0]]
        for i in rows:
            c = log["correction"][i]
            out.append(
                f"| {log['increment'][i] - first_inc + 1} | {log['iterate'][i]} | "
                f"{log['kind'][i]} | {c:.3g} | {c / run['size']:.1e} | "
                f"{log['residual'][i]:.3g} |"
            )
        moved = [log["correction"][i] for i in rows if log["kind"][i] != "predictor"]
        c = correction_counts(run, s, s)
        out += [
            "",
            f"{c['rose']} of its {len(moved)} corrections raised the residual; the longest had a "
            f"norm of {max(moved):.3g} ({max(moved) / run['size']:.1e} of the sheet size), the "
            f"shortest {min(moved):.3g}.",
            "",
        ]
    return out


def cost_lines(runs: list[dict], split: list[int]) -> list[str]:
    """One sentence per fold: what a step after the flat start costs, in the fold's
    factorisations."""
    out = []
    for run in runs:
        a, b = groups(run["steps"], split)[-1]
        d = group_row(run, a, b)
        per = run["fold_factorisation"] * d["n_steps"]
        parts = ", ".join(f"{name} {d[k] / per:.2f}" for k, name in PARTS)
        first = group_row(run, 1, a - 1) if a > 1 else None
        lead = (
            f"steps 1-{a - 1} took {100 * first['share']:.0f} % of the fold"
            if first is not None
            else "no flat-start group"
        )
        out.append(
            f"- {run['material']}, n = {run['n']} ({run['dof']} DOF; the fold's factorisation "
            f"{run['fold_factorisation']:.3f} s, median of {run['n_fold_factorisations']} steps; "
            f"a bare refactorisation of the last tangent {run['refactorisation']:.3f} s): "
            f"{lead}; a step of steps {a}-{b} costs "
            f"{d['per_step_refac']:.2f} factorisations ({parts}), with "
            f"{d['n_factorizations'] / d['n_steps']:.2f} factorisations, "
            f"{d['n_tangent'] / d['n_steps']:.2f} tangent assemblies, "
            f"{d['n_force_only'] / d['n_steps']:.2f} force evaluations and "
            f"{d['n_solves'] / d['n_steps']:.2f} back-substitutions per step."
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[40, 70, 100])
    ap.add_argument("--compliant-sizes", type=int, nargs="*", default=[20])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--split", type=int, nargs="*", default=[1, 5, 10])
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    args = ap.parse_args()
    if args.threads < 1:
        ap.error(f"--threads must be at least 1, got {args.threads}")
    os.environ["BARHINGE_THREADS"] = str(args.threads)
    runs = []
    jobs = [(n, "quasi-rigid") for n in args.sizes]
    jobs += [(n, "compliant") for n in args.compliant_sizes]
    for n, material in jobs:
        print(f"folding {n} x {n} ({material}) ...", file=sys.stderr, flush=True)
        runs.append(fold_steps(n, args.steps, material))
    title = (
        f"### Miura n x n, flat -> 60 deg in {args.steps} steps: the clock step by step "
        f"({args.threads} thread(s))"
    )
    body = [title, "", *table(runs, args.split), "", *cost_lines(runs, args.split), ""]
    body += [
        "### The corrections of each group of steps (the solver's iterate log)",
        "",
        *correction_table(runs, args.split),
        "",
        "### The flat start's hardest step, iterate by iterate",
        "",
        *hardest_lines(runs, args.split),
    ]
    while body[-1] == "":
        body.pop()
    print("\n".join(body))
    if args.publish:
        from barhinge._publish import generated_stamp, write_between

        cmd = "python benchmarks/bench_steps.py --publish"
        for flag, value, default in (
            ("--sizes", args.sizes, [40, 70, 100]),
            ("--compliant-sizes", args.compliant_sizes, [20]),
            ("--steps", [args.steps], [50]),
            ("--split", args.split, [1, 5, 10]),
        ):
            if value != default:
                cmd += f" {flag} " + " ".join(str(v) for v in value)
        doc = HERE.parent / "docs" / "solver-performance.md"
        write_between(
            doc,
            "<!-- steps:start -->",
            "<!-- steps:end -->",
            "\n".join([generated_stamp(cmd), "", *body]),
        )
        print(f"wrote {doc}", file=sys.stderr)


if __name__ == "__main__":
    main()
