"""Time reading (parse + build + validate) of the large box-pleat FOLD files and a few SVGs.

Usage: python benchmarks/bench_read.py [--repeat N]
Prints one row per file: counts and the median / min wall time of N reads (target: < 2 s
for each box-pleat FOLD file).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from barhinge.pattern.io import read
from barhinge.pattern.validate import findings

SHARED = Path(__file__).resolve().parents[1] / "tests" / "data" / "crease-patterns"
FILES = [
    "origami-simulator/BoxPleatPyramid.fold",
    "origami-simulator/BoxPleatInOutWave.fold",
    "origami-simulator/FTpoly7.svg",
    "origami-simulator/huffmanRectangularWeave.svg",
    "origami-simulator/miura_sharpangle.svg",
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    print(f"{'file':45s} {'V':>6s} {'E':>6s} {'F':>6s} {'median s':>9s} {'min s':>8s} "
          f"{'findings s':>10s}")  # fmt: skip
    for name in FILES:
        path = SHARED / name
        if not path.is_file():
            print(f"{name:45s} (absent)")
            continue
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            cp = read(path)  # parse + CreasePattern + check()
            times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        findings(cp)
        tf = time.perf_counter() - t0
        print(
            f"{name:45s} {cp.n_vertices:6d} {cp.n_edges:6d} {cp.n_faces:6d} "
            f"{statistics.median(times):9.3f} {min(times):8.3f} {tf:10.3f}"
        )


if __name__ == "__main__":
    main()
