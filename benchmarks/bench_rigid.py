"""Time per step of the rigid folding path (bh.rigid_fold) for Miura-ori sheets.

Usage: python benchmarks/bench_rigid.py [--sizes 5 10 20 35 50 70] [--steps 30] [--repeat 1]
       [--publish]   (writes the table into docs/kinematics.md, ``bench_rigid`` markers)

Each sheet (n x n unit cells of bh.families.miura, i.e. 2n x 2n quad panels) is folded from
flat to a 120 deg zig-zag fold by one actuator crease in the middle. Printed per size: number
of crease variables and interior vertices, set-up time (constraints + face tree), median and
90th percentile wall time per step (steps 2..N; step 1 leaves the flat state and also checks
the actuators), the floor of a step (one factorisation of the corrector's normal matrix at
the last state, median of three, under the same thread policy as the fold), median corrector
iterations, worst closure residual, the wall time of the whole ``bh.rigid_fold`` call
(set-up, every step and the states' coordinates, closure and energies); and the slope of
log(time per step) against log(number of creases).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import barhinge as bh
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.kinematics.path import RigidOptions, RigidSolver
from barhinge.linalg.threads import sparse_solves


def run(n: int, steps: int) -> dict:
    cp = bh.families.miura(n, n)
    lay = bh.families.miura_layout(n, n)
    zz = lay.interior_zigzag_edges
    e = int(zz[len(zz) // 2])
    sign = 1.0 if cp.assignment[e] == "V" else -1.0
    t0 = time.perf_counter()
    rc = RigidConstraints.from_pattern(cp)
    _ = rc.face_tree
    setup = time.perf_counter() - t0
    opt = RigidOptions(check_rank=False)
    t0 = time.perf_counter()
    path = bh.rigid_fold(cp, [e], [sign * 120.0], steps=steps, options=opt)
    call = time.perf_counter() - t0
    dt = np.diff(path.wall_time)
    return {
        "floor_ms": _factorisation_ms(rc, e, np.radians(path.fold_angles_deg[-1])),
        "cells": f"{n}x{n}",
        "creases": rc.n_var,
        "vertices": len(rc.vertices),
        "setup_s": setup,
        "call_s": call,
        "first_s": dt[0],
        "median_ms": 1e3 * float(np.median(dt[1:])),
        "p90_ms": 1e3 * float(np.percentile(dt[1:], 90)),
        "iters": float(np.median(path.iterations[2:])),
        "closure": path.meta["max_closure"],
    }


def _factorisation_ms(rc: RigidConstraints, edge: int, angles: np.ndarray) -> float:
    """Median wall time (ms) of one factorisation of the corrector's normal matrix at the
    fold angles ``angles`` (per source edge, radians): the least a corrector step costs."""
    rho = angles[rc.var_source_edge.clip(0)] * (rc.var_source_edge >= 0)
    solver = RigidSolver(rc, rc.var_of_source_edge[[edge]], RigidOptions())
    solver.underactuated = False
    _, J = rc.evaluate(rho)
    times = []
    with sparse_solves():
        for _ in range(4):
            t0 = time.perf_counter()
            solver._factor(J)
            times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times[1:]))  # the first one also orders the matrix


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[5, 10, 20, 35, 50, 70])
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--repeat", type=int, default=1, help="runs per size (median is kept)")
    ap.add_argument("--publish", action="store_true", help="write into docs/kinematics.md")
    args = ap.parse_args()
    rows = []
    table = [
        "| cells (quads) | creases | interior vertices | set-up s | step 1 s | median ms/step "
        "| p90 ms/step | floor: one factorisation, ms | iterations | max closure residual "
        "| whole call s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    print("\n".join(table), flush=True)
    for n in args.sizes:
        runs = [run(n, args.steps) for _ in range(args.repeat)]
        r = sorted(runs, key=lambda d: d["median_ms"])[len(runs) // 2]
        rows.append(r)
        table.append(
            f"| {n} × {n} ({2 * n} × {2 * n}) | {r['creases']} | {r['vertices']} | "
            f"{r['setup_s']:.2f} | {r['first_s']:.2f} | {r['median_ms']:.1f} | "
            f"{r['p90_ms']:.1f} | {r['floor_ms']:.1f} | {r['iters']:.0f} | {r['closure']:.0e} | "
            f"{r['call_s']:.2f} |"
        )
        print(table[-1], flush=True)
    if len(rows) >= 2:
        x = np.log([r["creases"] for r in rows])
        y = np.log([r["median_ms"] for r in rows])
        table += [
            "",
            f"Time per step grows like creases^{np.polyfit(x, y, 1)[0]:.2f} over these sizes "
            f"({args.steps} steps, median of {args.repeat} run(s) per size).",
        ]
        print(table[-1])
    if args.publish:
        from pathlib import Path

        from barhinge._publish import generated_stamp, write_between

        doc = Path(__file__).resolve().parents[1] / "docs" / "kinematics.md"
        body = "\n".join([generated_stamp("python benchmarks/bench_rigid.py --publish"), "",
                          *table])  # fmt: skip
        write_between(doc, "<!-- bench_rigid:start -->", "<!-- bench_rigid:end -->", body)


if __name__ == "__main__":
    main()
