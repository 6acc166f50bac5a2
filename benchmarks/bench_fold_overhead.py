"""Whole-process wall time of ``barhinge fold`` on the default scene against its solve.

Usage: python benchmarks/bench_fold_overhead.py [--repeat 7] [--pictures none] [--vs DIR]

Runs ``barhinge fold --out TMP`` in fresh processes (start-up, imports, the scene, the solve
and every file of the run included), reads the solve's own wall time from ``summary.json``
(``wall_time_s``: the solver's clock around the steps) and prints the medians and the median
of the per-run ratio total / solve. The target of issue 20 is a ratio of at most 3.

``--vs DIR`` alternates the runs with runs of another checkout (``PYTHONPATH=DIR``), so
both see the same machine load, and prints both.

The processes may write bytecode (``PYTHONDONTWRITEBYTECODE`` is dropped; the warm-up run
compiles it), as an installed package has it: ``pip install`` compiles every module.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CMD = "import sys; from barhinge.cli import main; sys.argv[0] = 'barhinge'; sys.exit(main())"


def one_run(folder: Path, pictures: str, pythonpath: str | None = None) -> tuple[float, float]:
    """(total wall s, solve wall s) of one ``barhinge fold`` process."""
    out = folder / "out"
    args = [sys.executable, "-c", CMD, "fold", "--out", str(out), "--overwrite"]
    args += ["--pictures", pictures]
    t = time.perf_counter()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
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
    args = ap.parse_args()
    here = str(Path(__file__).resolve().parents[1])
    checkouts = {"this checkout": here} | ({"--vs " + args.vs: args.vs} if args.vs else {})
    runs: dict[str, list[tuple[float, float]]] = {k: [] for k in checkouts}
    with tempfile.TemporaryDirectory() as tmp:
        for path in checkouts.values():
            one_run(Path(tmp), args.pictures, path)  # warm-up: compiled bytecode, page cache
        for _ in range(args.repeat):
            for name, path in checkouts.items():
                runs[name].append(one_run(Path(tmp), args.pictures, path))
    print(
        f"barhinge fold (default scene, --pictures {args.pictures}), {args.repeat} runs, "
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}"
    )
    for name, rs in runs.items():
        total = [t for t, _ in rs]
        solve = [s for _, s in rs]
        ratio = [t / s for t, s in rs]
        print(f"{name}:")
        print(f"  total wall s   median {statistics.median(total):.2f} (min {min(total):.2f})")
        print(f"  solve wall s   median {statistics.median(solve):.2f} (min {min(solve):.2f})")
        print(f"  total / solve  median {statistics.median(ratio):.2f} (min {min(ratio):.2f}, "
              f"max {max(ratio):.2f})")  # fmt: skip


if __name__ == "__main__":
    main()
