"""Model-build time of the bending rules on an n x n-cell Miura-ori (the default ``"plate"``
rule does one Morley solve per distinct face shape; ``"filipov"`` and ``"kirchhoff"`` are
closed forms).

Prints the median wall time of ``BarHingeModel.from_pattern`` per rule and scheme, the
ratio to ``"filipov"`` and the number of Morley solves:

    python benchmarks/bench_plate_calibration.py            # 100 x 100 cells
    python benchmarks/bench_plate_calibration.py --n 50 --fold 40 --repeat 5
    python benchmarks/bench_plate_calibration.py --publish  # into docs/calibration.md
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import barhinge as bh
import barhinge.model.model as model_mod
from barhinge.model.model import BarHingeModel

RULES = ("filipov", "kirchhoff", "plate")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--fold", type=float, default=0.0, help="facet angle (deg)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--publish", action="store_true", help="write into docs/calibration.md")
    args = ap.parse_args()
    cp = bh.families.miura(args.n, args.n, a=1.0, b=1.0, alpha=60.0, fold=args.fold)
    mat = bh.Material(E=1e6, nu=0.3, t=0.01)
    solves = [0]
    orig = model_mod.plate_corner_stiffness

    def counting(*a, **kw):
        solves[0] += 1
        return orig(*a, **kw)

    model_mod.plate_corner_stiffness = counting
    lines = [
        f"Miura {args.n} x {args.n} cells, {len(cp.faces)} faces, facet angle {args.fold:g} deg; "
        f"median of {args.repeat} builds.",
        "",
        "| scheme | rule | median build (s) | / filipov | Morley solves per build |",
        "|---|---|---|---|---|",
    ]
    print("\n".join(lines), flush=True)
    for scheme in ("N5B8", "N4B5"):
        base = None
        for rule in RULES:
            ts = []
            solves[0] = 0
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                BarHingeModel.from_pattern(cp, scheme, mat, bend_calibration=rule)
                ts.append(time.perf_counter() - t0)
            med = float(np.median(ts))
            base = med if base is None else base
            lines.append(
                f"| {scheme} | {rule} | {med:.2f} | {med / base:.2f} | {solves[0] // args.repeat} |"
            )
            print(lines[-1], flush=True)
    if args.publish:
        from barhinge._publish import generated_stamp, write_between

        doc = Path(__file__).resolve().parents[1] / "docs" / "calibration.md"
        body = "\n".join([generated_stamp("python benchmarks/bench_plate_calibration.py --publish"),
                          "", *lines])  # fmt: skip
        write_between(doc, "<!-- bench_plate_calibration:start -->",
                      "<!-- bench_plate_calibration:end -->", body)  # fmt: skip


if __name__ == "__main__":
    main()
