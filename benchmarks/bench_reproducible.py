"""Run-to-run reproducibility of a solve, and what MKL_CBWR changes.

Usage: python benchmarks/bench_reproducible.py [--n 20] [--material compliant]
       [--modes default AUTO COMPATIBLE]

Solves the Miura n x n fold from flat (``bench_solver.miura_scene``, 50 steps) twice in fresh
processes for each MKL_CBWR setting ("default" = barhinge's own, which sets AUTO unless the
environment sets it; "unset" = MKL's own choice, which barhinge no longer makes) and prints
the largest difference between the two runs' states, their factorisation counts and wall
times.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

WORK = """
import json, sys, time
import numpy as np
sys.path.insert(0, {bench!r})
import barhinge as bh
from bench_solver import miura_scene
sc = miura_scene({n}, 0.0, 50, material={material!r})
t0 = time.perf_counter()
p = bh.solve(sc)
np.save({out!r}, p.X)
print(json.dumps({{"fact": p.meta["timing"]["n_factorizations"],
                   "wall": time.perf_counter() - t0}}))
"""


def run(mode: str, n: int, material: str, out: Path) -> dict:
    env = dict(os.environ)
    env.pop("MKL_CBWR", None)
    if mode not in ("default", "unset"):
        env["MKL_CBWR"] = mode
    code = WORK.format(bench=str(Path(__file__).parent), n=n, material=material, out=str(out))
    if mode == "unset":  # bypass barhinge's setdefault: MKL picks its own code paths
        code = "import os; os.environ['MKL_CBWR'] = ''\n" + code
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if res.returncode:
        raise SystemExit(res.stderr.strip().splitlines()[-1])
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--material", default="compliant", choices=["compliant", "quasi-rigid"])
    ap.add_argument("--modes", nargs="+", default=["default", "unset", "COMPATIBLE"])
    a = ap.parse_args()
    print(f"Miura {a.n}x{a.n} {a.material}, two fresh runs per setting")
    print(f"{'MKL_CBWR':<12}{'max |X1 - X2|':>16}{'factorisations':>18}{'wall s':>16}")
    with tempfile.TemporaryDirectory() as tmp:
        for mode in a.modes:
            recs, X = [], []
            for k in range(2):
                out = Path(tmp) / f"{mode}_{k}.npy"
                recs.append(run(mode, a.n, a.material, out))
                X.append(np.load(out))
            diff = float(np.abs(X[0] - X[1]).max()) if X[0].shape == X[1].shape else np.inf
            facts = " / ".join(str(r["fact"]) for r in recs)
            walls = " / ".join(f"{r['wall']:.1f}" for r in recs)
            print(f"{mode:<12}{diff:>16.3g}{facts:>18}{walls:>16}", flush=True)


if __name__ == "__main__":
    main()
