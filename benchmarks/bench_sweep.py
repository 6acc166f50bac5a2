"""Sweep overheads: serial vs a local Dask cluster (2 worker processes), batch sizes.

Run: ``python benchmarks/bench_sweep.py [--repeat 3] [--publish]`` (``--publish`` writes
the table into docs/sweeps.md between the ``bench_sweep`` markers). The point function
sleeps (no CPU), so the numbers are the sweep machinery's cost. Columns (medians over the
repeats): wall time of the whole sweep; ``first s`` = time to the first record (for "local":
cluster start-up plus one batch); ``s/point`` = steady-state interval between records,
``(t_last - t_first) / (n - 1)``, to compare with the ideal ``t_point / workers``.
"""

from __future__ import annotations

import argparse
import os
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
    ap.add_argument("--publish", action="store_true", help="write the table into docs/sweeps.md")
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
    rows = [
        "| points × duration | mode | batch | wall s | first record s | s between records "
        "| ideal |",
        "|---|---|---|---|---|---|---|",
    ]
    for n, t, mode, batch in cases:
        runs = [one(n, t, mode, batch) for _ in range(args.repeat)]
        wall, first, per = (statistics.median(r[k] for r in runs) for k in range(3))
        ideal = t if mode == "serial" else t / 2
        label = "local (2 workers)" if mode == "local" else mode
        rows.append(
            f"| {n} × {t:g} s | {label} | {batch} | {wall:.2f} | {first:.2f} | {per:.4f} "
            f"| {ideal:.3f} |"
        )
        print(rows[-1], flush=True)
    if args.publish:
        from barhinge._publish import generated_stamp, write_between

        load = os.getloadavg()[0]
        body = "\n".join(
            [
                generated_stamp("python benchmarks/bench_sweep.py --publish"),
                "",
                f"{os.cpu_count()} cores, load average {load:.1f} at the start; points that "
                f"sleep, medians of {args.repeat}.",
                "",
                *rows,
            ]
        )
        write_between(HERE.parent / "docs" / "sweeps.md", "<!-- bench_sweep:start -->",
                      "<!-- bench_sweep:end -->", body)  # fmt: skip


if __name__ == "__main__":
    main()
