"""One-command scaling table: Miura n x n folds, time, factorisations and memory against DOF.

Run:  python benchmarks/scaling.py [--sizes 10 20 40] [--steps 50] [--pieces 200]
      [--publish]

Every size runs in a fresh process (``--one n``), so that its peak resident memory
(``ru_maxrss``) is its own. A size is the fold of ``bench_solver.miura_scene`` (Miura n x n,
N5B8, quasi-rigid stiffness set, actuators on the middle crease line, flat -> 60 deg in
``--steps`` steps). Per size: DOF, model build time, fold wall and CPU time, Newton
iterations, factorisations, seconds per factorisation-iteration, peak memory. The exponent
``p`` of ``wall ~ DOF^p`` is the least-squares slope on log-log axes over the sizes run.

``--pieces N`` measures, for the large sheet n = N, only the pieces that fit a short run:
model build, the first assembly of the tangent (with the process's peak memory after it),
and one Newton iteration's factorisation + solve at the flat state; the whole fold is then
*extrapolated* (stated as such in the table) from the measured per-iteration time times
the iterations per step of the largest size run in full.

``--publish`` writes the tables into docs/solver-performance.md (between the ``scaling``
markers), using :func:`barhinge._publish.write_between`.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def _peak_mb() -> float:
    """Peak resident memory of this process, MB (``ru_maxrss`` is in KB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def one(n: int, steps: int) -> dict:
    """Fold the n x n sheet in this process; the figures of one row."""
    from bench_solver import miura_scene

    import barhinge as bh

    t0 = time.perf_counter()
    sc = miura_scene(n, 0.0, steps)
    build = time.perf_counter() - t0
    c0, t0 = time.process_time(), time.perf_counter()
    path = bh.solve(sc)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    tm = path.meta["timing"]
    its = int(path.meta["newton"]["total_iterations"])
    return {
        "n": n,
        "dof": int(sc.model.n_dof),
        "build": build,
        "wall": wall,
        "cpu": cpu,
        "iterations": its,
        "factorizations": int(tm["n_factorizations"]),
        "s_per_fact": wall / max(int(tm["n_factorizations"]), 1),
        "peak_mb": _peak_mb(),
        "steps": steps,
    }


def pieces(n: int) -> dict:
    """Build, first assembly (peak memory after it) and one factorisation + bordered solve
    at the flat state of the n x n sheet, in this process."""
    from bench_solver import miura_scene

    from barhinge.linalg.backends import get_backend
    from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms

    t0 = time.perf_counter()
    sc = miura_scene(n, 0.0, 50)
    build = time.perf_counter() - t0
    mem_build = _peak_mb()
    model = sc.model
    X = np.asarray(model.X0, float)
    t0 = time.perf_counter()
    ev = model.evaluate(X, tangent=True)
    assembly1 = time.perf_counter() - t0
    mem_assembly = _peak_mb()
    t0 = time.perf_counter()
    ev = model.evaluate(X, tangent=True)
    assembly2 = time.perf_counter() - t0
    hinges = sc.actuator_hinges()
    terms = actuator_terms(model, X, hinges)
    free = ~sc.fixed.ravel()
    timer = Timer()
    sysm = BorderedSystem(get_backend("auto"), free, terms.dofs, timer)
    mu = np.zeros(len(hinges))
    t0 = time.perf_counter()
    sysm.set_operator(ev.K, terms, mu, 1.0, factorize=True)
    fact1 = time.perf_counter() - t0
    t0 = time.perf_counter()
    sysm.set_operator(ev.K, terms, mu, 1.0, factorize=True)
    fact2 = time.perf_counter() - t0
    t0 = time.perf_counter()
    sysm.solve(np.ones(int(free.sum())), np.zeros(len(hinges)))
    solve = time.perf_counter() - t0
    return {
        "n": n,
        "dof": int(model.n_dof),
        "build": build,
        "mem_build_mb": mem_build,
        "assembly_first": assembly1,
        "assembly": assembly2,
        "mem_assembly_mb": mem_assembly,
        "fact_first": fact1,
        "fact": fact2,
        "solve": solve,
        "peak_mb": _peak_mb(),
    }


def _child(args: list[str]) -> dict:
    out = subprocess.run(
        [sys.executable, __file__, *args], capture_output=True, text=True, check=True
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="*", default=[10, 20, 40])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--pieces", type=int, nargs="*", default=[])
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--one-pieces", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    a = ap.parse_args()
    if a.one is not None:
        print(json.dumps(one(a.one, a.steps)))
        return
    if a.one_pieces is not None:
        print(json.dumps(pieces(a.one_pieces)))
        return

    lines = [
        f"### Miura n x n folds, flat -> 60 deg in {a.steps} steps (quasi-rigid set)",
        "| n | DOF | build s | fold wall s | fold CPU s | iterations | factorisations "
        "| fold wall s / factorisation | peak memory MB | KB / DOF |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    print("\n".join(lines), flush=True)
    rows = []
    for n in a.sizes:
        r = _child(["--one", str(n), "--steps", str(a.steps)])
        rows.append(r)
        lines.append(
            f"| {n} | {r['dof']} | {r['build']:.2f} | {r['wall']:.2f} | {r['cpu']:.2f} | "
            f"{r['iterations']} | {r['factorizations']} | {r['s_per_fact']:.3f} | "
            f"{r['peak_mb']:.0f} | {1024 * r['peak_mb'] / r['dof']:.1f} |"
        )
        print(lines[-1], flush=True)
    p = None
    if len(rows) >= 2:
        dof = np.log([r["dof"] for r in rows])
        p = float(np.polyfit(dof, np.log([r["wall"] for r in rows]), 1)[0])
        pf = float(np.polyfit(dof, np.log([r["s_per_fact"] for r in rows]), 1)[0])
        lines += [
            "",
            f"Fitted exponents over n = {', '.join(str(r['n']) for r in rows)}: "
            f"fold wall time ~ DOF^{p:.2f}; wall time per factorisation ~ DOF^{pf:.2f}.",
        ]
        print(lines[-1], flush=True)
    for n in a.pieces:
        r = _child(["--one-pieces", str(n)])
        last = rows[-1] if rows else None
        lines += [
            "",
            f"### n = {n}: measured pieces ({r['dof']} DOF)",
            "| piece | s | peak memory after it, MB |",
            "|---|---|---|",
            f"| model build | {r['build']:.1f} | {r['mem_build_mb']:.0f} |",
            f"| first assembly (tangent) | {r['assembly_first']:.1f} | "
            f"{r['mem_assembly_mb']:.0f} |",
            f"| later assembly | {r['assembly']:.1f} | |",
            f"| first factorisation (with ordering) | {r['fact_first']:.1f} | |",
            f"| refactorisation | {r['fact']:.1f} | {r['peak_mb']:.0f} |",
            f"| bordered solve | {r['solve']:.2f} | |",
        ]
        if last is not None:
            per_it = r["assembly"] + r["fact"] + r["solve"]
            est = per_it * last["factorizations"]
            counts = ", ".join(str(q["factorizations"]) for q in rows)
            lines += [
                "",
                f"Extrapolated, not measured: a full {a.steps}-step fold at n = {n} with the "
                f"{last['factorizations']} factorisations of the n = {last['n']} fold, each "
                f"costing one assembly + refactorisation + solve as measured here "
                f"({per_it:.1f} s), would take about {est / 60:.0f} min. The count grows with "
                f"the size ({counts} factorisations for n = "
                f"{', '.join(str(q['n']) for q in rows)}), so this is a lower estimate.",
            ]
        print("\n".join(lines[-10:]), flush=True)
    if a.publish:
        from barhinge._publish import generated_stamp, write_between

        cmd = "python benchmarks/scaling.py --publish"
        if a.sizes != [10, 20, 40]:
            cmd += " --sizes " + " ".join(map(str, a.sizes))
        if a.pieces:
            cmd += " --pieces " + " ".join(map(str, a.pieces))
        doc = HERE.parent / "docs" / "solver-performance.md"
        body = "\n".join([generated_stamp(cmd), "", *lines])
        write_between(doc, "<!-- scaling:start -->", "<!-- scaling:end -->", body)


if __name__ == "__main__":
    main()
