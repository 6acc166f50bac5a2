"""Whole-process wall time of ``barhinge fold`` on the default scene against its solve.

Usage: python benchmarks/bench_fold_overhead.py [--repeat 7] [--pictures none] [--vs DIR]
                                                [--cache both|warm|cold] [--publish]

Runs ``barhinge fold --out TMP`` in fresh processes (start-up, imports, the scene, the solve
and every file of the run included), reads the solve's own wall time from ``summary.json``
(``wall_time_s``: the solver's clock around the steps) and prints the medians and the median
of the per-run ratio total / solve (the target: at most 3). ``--publish`` writes the table
into docs/solver-performance.md (*The main job end to end*).

The calibration's answers are kept between processes (``BARHINGE_CACHE_DIR``,
docs/calibration.md). ``--cache warm`` times runs that find them (every run after the first
on a machine, the warm-up filling a cache folder of this benchmark's own); ``--cache cold``
gives every run an empty cache folder (the first run on a machine); ``both`` (the default)
prints both.

``--vs DIR`` alternates the runs with runs of another checkout (``PYTHONPATH=DIR``), so
both see the same machine load, and prints both.

The processes may write bytecode (``PYTHONDONTWRITEBYTECODE`` is dropped; the warm-up run
compiles it), as an installed package has it: ``pip install`` compiles every module.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CMD = "import sys; from barhinge.cli import main; sys.argv[0] = 'barhinge'; sys.exit(main())"


def one_run(
    folder: Path, pictures: str, pythonpath: str | None = None, cache: Path | None = None
) -> tuple[float, float]:
    """(total wall s, solve wall s) of one ``barhinge fold`` process (its calibration cache
    in the folder ``cache``)."""
    out = folder / "out"
    args = [sys.executable, "-c", CMD, "fold", "--out", str(out), "--overwrite"]
    args += ["--pictures", pictures]
    t = time.perf_counter()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    env.pop("BARHINGE_CACHE", None)
    if cache is not None:
        env["BARHINGE_CACHE_DIR"] = str(cache)
    proc = subprocess.run(args, capture_output=True, text=True, env=env)
    total = time.perf_counter() - t
    if proc.returncode:
        raise SystemExit(proc.stderr.strip().splitlines()[-1])
    solve = json.loads((out / "summary.json").read_text())["wall_time_s"]
    return total, float(solve)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--pictures", default="none", choices=("none", "png", "all"))
    ap.add_argument("--vs", default=None, help="another checkout to alternate with")
    ap.add_argument("--cache", default="both", choices=("both", "warm", "cold"))
    ap.add_argument("--publish", action="store_true", help="write the table into docs/")
    args = ap.parse_args()
    if args.publish and (args.vs or args.pictures != "none" or args.cache != "both"):
        ap.error("--publish times this checkout with the defaults: drop --vs, --pictures, --cache")
    here = str(Path(__file__).resolve().parents[1])
    checkouts = {"this checkout": here} | ({"--vs " + args.vs: args.vs} if args.vs else {})
    modes = ("warm", "cold") if args.cache == "both" else (args.cache,)
    runs: dict[tuple[str, str], list[tuple[float, float]]] = {
        (name, mode): [] for name in checkouts for mode in modes
    }
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        warm = {name: folder / f"warm-{j}" for j, name in enumerate(checkouts)}
        for name, path in checkouts.items():  # warm-up: bytecode, page cache, warm cache
            one_run(folder, args.pictures, path, warm[name])
        for i in range(args.repeat):
            for name, path in checkouts.items():
                for mode in modes:
                    cache = warm[name] if mode == "warm" else folder / f"cold-{i}"
                    runs[name, mode].append(one_run(folder, args.pictures, path, cache))
                    if mode == "cold":
                        shutil.rmtree(cache, ignore_errors=True)
    head = (
        f"barhinge fold (default scene, --pictures {args.pictures}), {args.repeat} runs, "
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}"
    )
    print(head)
    print("\n".join(table(runs)))
    if args.publish:
        from barhinge._publish import generated_stamp, write_between

        cmd = "python benchmarks/bench_fold_overhead.py --publish"
        if args.repeat != 7:
            cmd += f" --repeat {args.repeat}"
        body = [generated_stamp(cmd), "", *table(runs), "", head + "."]
        doc = Path(here) / "docs" / "solver-performance.md"
        write_between(doc, "<!-- fold_overhead:start -->", "<!-- fold_overhead:end -->",
                      "\n".join(body))  # fmt: skip
        print(f"wrote {doc}")


def table(runs: dict[tuple[str, str], list[tuple[float, float]]]) -> list[str]:
    """Markdown rows: per checkout and cache, the medians of the whole process, the solve,
    the time around the solve and the ratio."""
    rows = [
        "| run | calibration cache | total wall s, median (min) | solve wall s, median (min) "
        "| around the solve s, median | total / solve, median (min - max) |",
        "|---|---|---|---|---|---|",
    ]
    for (name, mode), rs in runs.items():  # rows: "this checkout" / "--vs DIR", warm / cold
        total = [t for t, _ in rs]
        solve = [s for _, s in rs]
        ratio = [t / s for t, s in rs]
        around = statistics.median(t - s for t, s in rs)
        rows.append(
            f"| {name} | {mode} | {statistics.median(total):.2f} ({min(total):.2f}) "
            f"| {statistics.median(solve):.2f} ({min(solve):.2f}) | {around:.2f} "
            f"| {statistics.median(ratio):.2f} ({min(ratio):.2f} - {max(ratio):.2f}) |"
        )
    return rows


if __name__ == "__main__":
    main()
