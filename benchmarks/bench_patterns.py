"""Time the pattern generators: Miura-ori sheets of growing size, flat and folded.

Usage: python benchmarks/bench_patterns.py [--repeat N]
Prints one row per size: counts and the median wall time of N builds, split into the
generator's own work (``validate=False``-equivalent: arrays only) and the full build
(CreasePattern construction + validation). Target: a 100 x 100 Miura in well under a second
for the generator part.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from barhinge.families import miura
from barhinge.families.miura import miura_fold_angles, miura_grid_coords, miura_layout


def _arrays_only(n: int, fold: float | None) -> None:
    lay = miura_layout(n, n)
    miura_grid_coords(np.ones(lay.ni - 1), np.ones(lay.nj - 1), 60.0, fold or 0.0)
    lay.edges()
    lay.quads()
    miura_fold_angles(lay, 60.0, fold or 60.0)


def _median(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    miura(2, 2)  # warm up imports
    print(f"{'pattern':24s} {'V':>7s} {'E':>7s} {'arrays s':>9s} {'full s':>8s}")
    for n in (10, 30, 100):
        for fold in (None, 40.0):
            cp = miura(n, n, fold=fold)
            t_arr = _median(lambda n=n, f=fold: _arrays_only(n, f), args.repeat)
            t_full = _median(lambda n=n, f=fold: miura(n, n, fold=f), args.repeat)
            label = f"miura {n}x{n}" + ("" if fold is None else f" fold={fold:g}")
            print(f"{label:24s} {cp.n_vertices:7d} {cp.n_edges:7d} {t_arr:9.3f} {t_full:8.3f}")


if __name__ == "__main__":
    main()
