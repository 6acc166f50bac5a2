"""Newton step control: iterations and factorisations per step, both stiffness sets.

Run:  python benchmarks/bench_newton.py [--sizes 10 20] [--steps 50] [--repeat 1]
      [--options '{"predictor": "secant"}'] [--publish]

``--publish`` also writes the tables into docs/solver-performance.md (between the
``bench_newton`` markers).

Miura n x n cells folded by actuators on the middle crease line from flat to 60 deg in
``--steps`` steps (``bench_solver.miura_scene``), for the quasi-rigid and the compliant
stiffness sets (``bench_solver._stiffness_model``). Per run: DOF, Newton iterations (of the
converged increments), increments that failed and were redone shorter, factorisations (all,
per step, in step 1, to confirm the tangent's inertia), the largest iteration count of a
step, wall and CPU time (medians over ``--repeat``), and per size the ratio compliant /
quasi-rigid of the Newton factorisations (all less the inertia ones, which both sets make
once per state) and of the wall time (issue 19 asks for at most 2; the two sets run in
turn, and the ratio is the median of each pair's, so that a drift of the machine's speed
does not move it). The figures come
from ``FoldPath.meta["newton"]`` and ``meta["timing"]``.

Two more tables run every size and set again with the other settings of the geodesic
acceleration of the Newton corrections (option ``acceleration``: plain, auto, always) and
of the predictor (option ``predictor``: quadratic or polynomial) and give the ratios of
Newton factorisations and wall time to the first setting.
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import barhinge as bh
from barhinge.solver_options import SolverOptions

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_solver import miura_scene  # noqa: E402

COLS = (
    "n",
    "material",
    "DOF",
    "iterations",
    "chord corr.",
    "failed incr.",
    "factorisations",
    "fact./step",
    "fact. step 1",
    "inertia fact.",
    "max iter./step",
    "wall s",
    "CPU s",
)


def run(n: int, material: str, steps: int, options: dict) -> dict:
    """One solve; the figures of one table row."""
    sc = miura_scene(n, 0.0, steps, material=material)
    if options:
        sc = sc.with_(options={**sc.options.__dict__, **options})
    c0, t0 = time.process_time(), time.perf_counter()
    path = bh.solve(sc)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    nw = path.meta["newton"]
    return {
        "dof": sc.model.n_dof,
        "iterations": nw["total_iterations"],
        "chord": nw["total_chord"],
        "failed": nw["total_failed"],
        "fact": path.meta["timing"]["n_factorizations"],
        "fact1": nw["factorizations"][0],
        "inertia": nw["total_inertia_factorizations"],
        "max_iter": max(nw["iterations"]),
        "accelerated": path.meta["timing"]["n_accelerated"],
        "wall": wall,
        "cpu": cpu,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="*", default=[10, 20])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeat", type=int, default=3, help="runs per row (wall and CPU: medians)")
    ap.add_argument("--options", default="{}", help="solver options (JSON) for every run")
    ap.add_argument(
        "--corrector-sizes",
        type=int,
        nargs="*",
        default=[],
        help="larger quasi-rigid sheets on which only the two correctors are compared",
    )
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    a = ap.parse_args()
    lines: list[str] = []

    def out(line: str = "") -> None:
        print(line, flush=True)
        lines.append(line)

    logging.disable(logging.WARNING)  # the compliant sheet's stability events
    options = json.loads(a.options)
    out(f"### Newton step control: Miura n x n, flat -> 60 deg in {a.steps} steps")
    if options:
        out(f"options: {options}")
    out("| " + " | ".join(COLS) + " |")
    out("|" + "---|" * len(COLS))
    ratios = []
    all_rows = []
    for n in a.sizes:
        rows = {}
        all_rows.append((n, rows))
        # the sets run in turn (quasi-rigid, compliant, quasi-rigid, ...): a drift of the
        # machine's speed during the runs moves both, and the wall ratio is taken pair by pair
        runs_of_set: dict[str, list[dict]] = {"quasi-rigid": [], "compliant": []}
        for _ in range(a.repeat):
            for material, runs in runs_of_set.items():
                runs.append(run(n, material, a.steps, options))
        for material, runs in runs_of_set.items():
            r = dict(runs[-1])
            r["wall"] = statistics.median(x["wall"] for x in runs)
            r["cpu"] = statistics.median(x["cpu"] for x in runs)
            rows[material] = r
            row = (
                n,
                material,
                r["dof"],
                r["iterations"],
                r["chord"],
                r["failed"],
                r["fact"],
                f"{r['fact'] / a.steps:.1f}",
                r["fact1"],
                r["inertia"],
                r["max_iter"],
                f"{r['wall']:.2f}",
                f"{r['cpu']:.2f}",
            )
            out("| " + " | ".join(str(v) for v in row) + " |")
        q, c = rows["quasi-rigid"], rows["compliant"]
        newton_q, newton_c = q["fact"] - q["inertia"], c["fact"] - c["inertia"]
        paired = zip(runs_of_set["quasi-rigid"], runs_of_set["compliant"], strict=True)
        ratios.append(
            (n, newton_c / newton_q, statistics.median(y["wall"] / x["wall"] for x, y in paired))
        )
    out()
    out(
        "| n | Newton factorisations (without the inertia ones) compliant / quasi-rigid "
        "| wall compliant / quasi-rigid (median of the runs' ratios, the sets run in turn) |"
    )
    out("|---|---|---|")
    for n, rf, rw in ratios:
        out(f"| {n} | {rf:.2f} | {rw:.2f} |")
    runs_of = {(n, m): r for n, rows in all_rows for m, r in rows.items()}
    compare(
        out, runs_of, a, options, "acceleration", (False, "auto", True),
        "Geodesic acceleration (option `acceleration`): plain Newton, accelerated where the "
        "residual rose or after a hard increment (auto, the default), every correction",
        ("plain", "auto", "always"),
    )  # fmt: skip
    compare(
        out, runs_of, a, options, "predictor", ("quadratic", "polynomial"),
        "Predictor (option `predictor`): the quadratic and the polynomial of the degree the "
        "path supports",
        ("quadratic", "polynomial"),
    )  # fmt: skip
    compare(
        out, runs_of, a, options, "corrector", ("newton", "chord"),
        "Corrector (option `corrector`): a factorisation per Newton correction, and chord "
        "corrections with the increment's factorisation while they contract (the default)",
        ("newton", "chord"),
    )  # fmt: skip
    if a.corrector_sizes:
        larger = {(n, "quasi-rigid"): None for n in a.corrector_sizes}
        compare(
            out, larger, a, options, "corrector", ("newton", "chord"),
            "Corrector on larger quasi-rigid sheets", ("newton", "chord"),
        )  # fmt: skip
    if a.publish:
        publish(lines, a)


def compare(
    out: Callable[..., None],
    runs_of: dict[tuple[int, str], dict | None],
    a: argparse.Namespace,
    options: dict,
    key: str,
    values: tuple[Any, ...],
    title: str,
    labels: tuple[str, ...],
) -> None:
    """A table of every size and set run with each of ``values`` of option ``key``:
    iterations, Newton factorisations (the inertia ones left out), failed increments, wall
    time, and the ratios of Newton factorisations and wall time of each later value to the
    first. The runs of the main table are reused for the value it ran with (None: every
    value is run)."""
    ran_with = options.get(key, getattr(SolverOptions(), key))
    names = " / ".join(labels)
    ratio_cols = [f"{lab} / {labels[0]}" for lab in labels[1:]]
    out()
    out(f"### {title}")
    out(
        f"| n | material | iterations {names} | Newton factorisations {names} | "
        f"failed incr. {names} | wall s {names} | "
        + " | ".join(f"Newton factorisations {c} | wall {c}" for c in ratio_cols)
        + " |"
    )
    out("|---|---|---|---|---|---|" + "---|---|" * len(ratio_cols))
    for (n, material), r in runs_of.items():
        row = []
        for v in values:
            if r is not None and v == ran_with and type(v) is type(ran_with):
                row.append(r)
                continue
            other = [run(n, material, a.steps, {**options, key: v}) for _ in range(a.repeat)]
            o = dict(other[-1])
            o["wall"] = statistics.median(x["wall"] for x in other)
            row.append(o)
        newton = [x["fact"] - x["inertia"] for x in row]
        cells = [
            " / ".join(str(x["iterations"]) for x in row),
            " / ".join(str(f) for f in newton),
            " / ".join(str(x["failed"]) for x in row),
            " / ".join(f"{x['wall']:.2f}" for x in row),
        ]
        for x, f in zip(row[1:], newton[1:], strict=True):
            cells += [f"{f / newton[0]:.2f}", f"{x['wall'] / row[0]['wall']:.2f}"]
        out(f"| {n} | {material} | " + " | ".join(cells) + " |")


def publish(lines: list[str], a: argparse.Namespace) -> None:
    """Replace the text between the markers in docs/solver-performance.md."""
    doc = Path(__file__).resolve().parents[1] / "docs" / "solver-performance.md"
    text = doc.read_text()
    start, end = "<!-- bench_newton:start -->", "<!-- bench_newton:end -->"
    cmd = "python benchmarks/bench_newton.py --publish"
    if a.corrector_sizes:
        cmd += " --corrector-sizes " + " ".join(str(n) for n in a.corrector_sizes)
    if a.options != "{}":
        cmd += f" --options '{a.options}'"
    body = "\n".join([start, f"Written by `{cmd}` (this machine).", "", *lines, end])
    if start in text and end in text:
        head, rest = text.split(start, 1)
        text = head + body + rest.split(end, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + body + "\n"
    doc.write_text(text)


if __name__ == "__main__":
    main()
