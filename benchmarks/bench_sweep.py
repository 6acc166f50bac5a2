"""Sweep overheads: serial vs a local Dask cluster (2 worker processes), batch sizes.

Run: ``/work/venv/bin/python benchmarks/bench_sweep.py [--repeat 3]``. The point function
sleeps (no CPU), so the numbers are the sweep machinery's cost. Columns (medians over the
repeats): wall time of the whole sweep; ``first s`` = time to the first record (for "local":
cluster start-up plus one batch); ``s/point`` = steady-state interval between records,
``(t_last - t_first) / (n - 1)``, to compare with the ideal ``t_point / workers``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from barhinge.sweep import Study, run_study

HERE = Path(__file__).resolve().parent


def nap(i: int, t: float) -> dict:
    """A point that takes ``t`` seconds without using the CPU."""
    time.sleep(t)
    return {"i": i}


def one(n: int, t: float, mode: str, batch: int) -> tuple[float, float, float]:
    study = Study(
        function="bench_sweep:nap",
        grid={"i": list(range(n))},
        fixed={"t": t},
        batch_size=batch,
        paths=(str(HERE),),
    )
    stamps: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run_study(
            study,
            out=Path(tmp),
            mode=mode,
            workers=2,
            on_record=lambda rec, rep: stamps.append(time.perf_counter()),
        )
        wall = time.perf_counter() - t0
    return wall, stamps[0] - t0, (stamps[-1] - stamps[0]) / (n - 1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cases = [
        (40, 0.0, "serial", 1),
        (40, 0.0, "local", 1),
        (40, 0.0, "local", 10),
        (20, 0.05, "serial", 1),
        (20, 0.05, "local", 1),
        (20, 0.05, "local", 5),
        (10, 0.3, "serial", 1),
        (10, 0.3, "local", 1),
    ]
    head = ("points", "t_point s", "mode", "batch", "wall s", "first s", "s/point", "ideal")
    print("{:>6} {:>9} {:>7} {:>5} {:>7} {:>7} {:>8} {:>7}".format(*head))
    for n, t, mode, batch in cases:
        runs = [one(n, t, mode, batch) for _ in range(args.repeat)]
        wall, first, per = (statistics.median(r[k] for r in runs) for k in range(3))
        ideal = t if mode == "serial" else t / 2
        print(
            f"{n:>6} {t:>9.2f} {mode:>7} {batch:>5} {wall:>7.2f} {first:>7.2f} "
            f"{per:>8.4f} {ideal:>7.3f}"
        )


if __name__ == "__main__":
    main()
