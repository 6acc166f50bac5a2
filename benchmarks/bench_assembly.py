"""Assembly speed of the bar-and-hinge model on an n x n-cell Miura-ori (N5B8 by default).

Prints a table of median wall and CPU times per call, for each count of worker threads
(``BARHINGE_THREADS``: the element kernels' passes run side by side on them), and the ratio
of one thread to the others:

    python benchmarks/bench_assembly.py            # 100 x 100 cells, N5B8, 1 and all cores
    python benchmarks/bench_assembly.py --n 50 --scheme N4B5 --repeat 7 --workers 1 2 4
    python benchmarks/bench_assembly.py --membrane cst   # coupled triangles
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np

import barhinge as bh
from barhinge.linalg.threads import ENV, cores
from barhinge.model.model import MEMBRANES, BarHingeModel


def timed(fn, repeat: int) -> tuple[float, float]:
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)), float(np.median(cpu))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="cells per side")
    ap.add_argument("--scheme", default="N5B8", choices=["N4B5", "N5B8"])
    ap.add_argument("--fold", type=float, default=30.0, help="Miura facet angle theta, deg")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--membrane", default="fit", choices=MEMBRANES, help="bar_calibration")
    ap.add_argument(
        "--workers", type=int, nargs="*", default=None, help="worker thread counts (1 and cores)"
    )
    args = ap.parse_args()
    workers = args.workers or sorted({1, cores()})

    t0 = time.perf_counter()
    cp = bh.families.miura(args.n, args.n, fold=args.fold)
    t_pattern = time.perf_counter() - t0
    t0 = time.perf_counter()
    model = BarHingeModel.from_pattern(cp, scheme=args.scheme, bar_calibration=args.membrane)
    t_model = time.perf_counter() - t0
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    t0, c0 = time.perf_counter(), time.process_time()
    asm = model.assembler
    t_asm, c_asm = time.perf_counter() - t0, time.process_time() - c0
    rss_asm = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0
    X = model.X0 + 1e-3 * np.random.default_rng(0).normal(size=model.X0.shape)

    calls = [
        ("energy only", lambda: model.energy(X)),
        ("force (tangent=False)", lambda: model.evaluate(X, tangent=False)),
        ("force + tangent", lambda: model.evaluate(X, tangent=True)),
    ]
    print(
        f"Miura {args.n}x{args.n} cells, {args.scheme}, {args.membrane}: {model.n_nodes} nodes, "
        f"{model.n_dof} dof, {model.n_bars} bars, {model.n_hinges} hinges, "
        f"tangent nnz {asm.nnz}"
    )
    print(
        f"one-off: pattern {t_pattern:.2f} s, model {t_model:.2f} s, "
        f"scatter maps {t_asm:.2f} s (cpu {c_asm:.2f} s)"
    )
    k_bytes = asm.nnz * (8 + asm.indices.itemsize)
    print(
        f"scatter maps: {asm.nbytes / 1e6:.0f} MB kept, peak process growth while building "
        f"{rss_asm / 1e3:.0f} MB; one tangent (CSR) {k_bytes / 1e6:.0f} MB "
        f"(maps kept / tangent {asm.nbytes / k_bytes:.1f}x, peak / tangent "
        f"{rss_asm * 1e3 / k_bytes:.1f}x)"
    )
    before = os.environ.get(ENV)
    walls: dict[int, list[float]] = {}
    try:
        for w in workers:
            os.environ[ENV] = str(w)
            print(f"\n{w} worker thread(s), per call (median of {args.repeat}): wall s, cpu s")
            walls[w] = []
            for name, fn in calls:
                wall, cpu = timed(fn, args.repeat)
                walls[w].append(wall)
                print(f"{name:<28}{wall:>10.3f}{cpu:>10.3f}")
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before
    if 1 in walls:
        for w in (w for w in workers if w != 1):
            ratios = ", ".join(
                f"{name} {one / many:.2f}x"
                for (name, _), one, many in zip(calls, walls[1], walls[w], strict=True)
            )
            print(f"1 worker thread / {w}: {ratios}")


if __name__ == "__main__":
    main()
