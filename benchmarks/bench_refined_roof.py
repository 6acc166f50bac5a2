"""Time and peak memory of the linear stiffness of a refined roof with coupled plate hinges.

Usage: python benchmarks/bench_refined_roof.py [--roof pleats 90] [--levels 4 8 16]

The roof study's bar-and-hinge model (``studies/roofs/shell_check.py``, ``bar_hinge`` with
the ``coupled`` rule: every panel cut into m x m cells, the cells' hinge angles coupled so
that they store the plate energy with the sheet's Poisson ratio) is built and solved once
per level, each in a fresh process. Printed per level: DOF, hinge couplings, wall time of
the whole level (subdivision, model, couplings, tangent, linear solve), the process's peak
resident memory and that memory per DOF, and the stiffness.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, resource, sys, time
sys.path.insert(0, {study!r})
import numpy as np
import roofs, shell_check as S
fam, state, m = {fam!r}, {state!r}, {m!r}
cp, flat_xy, _ = roofs.folded(fam, state)
sv, se = S.support_sets(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
t0 = time.perf_counter()
r = S.bar_hinge(cp, sv, se, m, "coupled")
wall = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps({{"m": m, "dof": r["n_dof"], "wall": wall, "peak_mb": peak,
                   "stiffness": r["stiffness"]}}))
"""


def level(fam: str, state: float, m: int) -> dict:
    code = CHILD.format(study=str(ROOT / "studies" / "roofs"), fam=fam, state=state, m=m)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(out.stderr.strip().splitlines()[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--roof", nargs=2, default=["pleats", "90"], metavar=("FAMILY", "STATE"))
    ap.add_argument("--levels", type=int, nargs="+", default=[4, 8, 16])
    args = ap.parse_args()
    fam, state = args.roof[0], float(args.roof[1])
    print(f"{fam} {state:g}, coupled plate hinges, one process per level")
    print("| m | DOF | wall s | peak MB | KB / DOF | stiffness |")
    print("|---|---|---|---|---|---|")
    for m in args.levels:
        r = level(fam, state, m)
        print(
            f"| {m} | {r['dof']} | {r['wall']:.1f} | {r['peak_mb']:.0f} | "
            f"{1024 * r['peak_mb'] / r['dof']:.1f} | {r['stiffness']:.6g} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
