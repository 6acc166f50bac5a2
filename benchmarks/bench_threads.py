"""The thread policy against the libraries' defaults: rigid folding steps and DOF analysis.

Usage: python benchmarks/bench_threads.py [--n 35] [--repeat 5]

Runs the same work in fresh processes with ``BARHINGE_THREADS=off`` (the BLAS libraries'
own thread counts) and ``auto`` (barhinge's policy: one BLAS thread for small dense calls,
MKL matched to the free cores), alternating, and prints the medians, the ratio and the load
average seen. The policy matters most on a shared, busy machine; on an idle one the two
should be close.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

WORK = """
import json, time, numpy as np, barhinge as bh
from barhinge.kinematics.path import RigidOptions
n = {n}
cp = bh.families.miura(n, n)
zz = bh.families.miura_layout(n, n).interior_zigzag_edges
e = int(zz[len(zz) // 2]); sign = 1.0 if cp.assignment[e] == "V" else -1.0
bh.dof(bh.families.miura(2, 2))  # warm-up (imports, MKL load)
p = bh.rigid_fold(cp, [e], [sign * 120.0], steps=12, options=RigidOptions(check_rank=False))
step_ms = 1e3 * float(np.median(np.diff(p.wall_time)[1:]))
t0 = time.perf_counter(); bh.dof(cp); dof_s = time.perf_counter() - t0
print(json.dumps({{"step_ms": step_ms, "dof_s": dof_s}}))
"""


def run(policy: str, n: int) -> dict[str, float]:
    env = {**os.environ, "BARHINGE_THREADS": policy}
    out = subprocess.run(
        [sys.executable, "-c", WORK.format(n=n)], env=env, capture_output=True, text=True
    )
    if out.returncode:
        raise SystemExit(out.stderr.strip().splitlines()[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=35, help="Miura cells per side")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    res: dict[str, list[dict[str, float]]] = {"off": [], "auto": []}
    loads = []
    for _ in range(args.repeat):
        for policy in res:
            res[policy].append(run(policy, args.n))
            loads.append(os.getloadavg()[0])
    print(
        f"Miura {args.n}x{args.n}, {os.cpu_count()} cores, load average "
        f"{min(loads):.1f}-{max(loads):.1f}; medians of {args.repeat} fresh processes"
    )
    print(f"{'':<28}{'off (library default)':>22}{'auto (barhinge)':>18}{'off/auto':>10}")
    for key, label in (("step_ms", "rigid fold, ms per step"), ("dof_s", "bh.dof, s")):
        off = statistics.median(r[key] for r in res["off"])
        auto = statistics.median(r[key] for r in res["auto"])
        print(f"{label:<28}{off:>22.3g}{auto:>18.3g}{off / auto:>10.2f}")


if __name__ == "__main__":
    main()
