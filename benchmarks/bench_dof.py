"""Wall time of ``bh.dof`` (rank by the inertia of JᵀJ − τ²I, null space, local DOF,
actuators, and the folded state nearby) against crease count.

Usage: python benchmarks/bench_dof.py [--sizes 10 20 35 50 70] [--repeat 3] [--no-files]

Generated Miura sheets (n x n unit cells of bh.patterns.miura) and the two box-pleated FOLD
files of Origami Simulator kept with the tests. Printed per pattern: crease variables, DOF at
the flat state and at the folded state nearby (with the gap ratio of the rank cut), the median
wall time; then the slope of log(time) against log(creases) over the Miura sheets. Each
Miura DOF is checked against the known value (flat 4n - 2, folded 1).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import barhinge as bh
from barhinge.pattern.io import read

FILES = Path(__file__).resolve().parents[1] / "tests/data/crease-patterns/origami-simulator"


def timed(cp, repeat: int) -> tuple[float, bh.DofReport]:
    times, rep = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        rep = bh.dof(cp)
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), rep


def row(name: str, cp, repeat: int) -> tuple[int, float]:
    t, rep = timed(cp, repeat)
    m = rep.mechanism
    print(
        f"| {name} | {rep.n_variables} | {rep.global_dof} | {m.global_dof} | "
        f"{m.gap_ratio:.1e} ({'certain' if m.certain else 'UNCERTAIN'}) | {m.method} | {t:.2f} |",
        flush=True,
    )
    return rep, t


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[10, 20, 35, 50, 70])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-files", action="store_true")
    a = ap.parse_args()
    print("| pattern | creases | DOF flat | DOF folded | gap ratio (folded) | method | median s |")
    print("|---|---|---|---|---|---|---|")
    xs, ts = [], []
    for n in a.sizes:
        rep, t = row(f"Miura {n} x {n}", bh.patterns.miura(n, n), a.repeat)
        assert rep.global_dof == 4 * n - 2 and rep.mechanism.global_dof == 1, "Miura DOF wrong"
        xs.append(rep.n_variables)
        ts.append(t)
    if not a.no_files:
        for f in ("BoxPleatPyramid.fold", "BoxPleatInOutWave.fold"):
            row(f, read(FILES / f), a.repeat)
    if len(xs) > 1:
        slope = np.polyfit(np.log(xs), np.log(ts), 1)[0]
        print(f"\ntime ~ creases^{slope:.2f} over the Miura sheets")


if __name__ == "__main__":
    main()
