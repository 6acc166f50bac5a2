"""Assembly speed of the bar-and-hinge model on an n x n-cell Miura-ori (N5B8 by default).

Prints a table of median wall and CPU times per call:

    /work/venv/bin/python benchmarks/bench_assembly.py            # 100 x 100 cells, N5B8
    /work/venv/bin/python benchmarks/bench_assembly.py --n 50 --scheme N4B5 --repeat 7
    /work/venv/bin/python benchmarks/bench_assembly.py --membrane cst   # coupled triangles
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

import barhinge as bh
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
    args = ap.parse_args()

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

    rows = [
        ("energy only", timed(lambda: model.energy(X), args.repeat)),
        ("force (tangent=False)", timed(lambda: model.evaluate(X, tangent=False), args.repeat)),
        ("force + tangent", timed(lambda: model.evaluate(X, tangent=True), args.repeat)),
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
    print(f"{'per call (median of ' + str(args.repeat) + ')':<28}{'wall s':>10}{'cpu s':>10}")
    for name, (w, c) in rows:
        print(f"{name:<28}{w:>10.3f}{c:>10.3f}")


if __name__ == "__main__":
    main()
