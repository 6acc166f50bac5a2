"""Wall time of ``bh.dof`` against crease count, whole and stage by stage: the rank (inertia
of JᵀJ − τ²I and null space), local and region DOF (batched SVDs), the actuator choice
(pivoted QR) and the search for a folded state nearby.

Usage: python benchmarks/bench_dof.py [--sizes 10 20 35 50 70] [--repeat 3] [--no-files]
       [--families miura yoshimura eggbox] [--max-yoshimura 70]
       [--yoshimura-sizes 10 20 40 115] [--publish]

``--publish`` writes the table and the fitted exponents into docs/kinematics.md between the
``dof-scale:start`` / ``dof-scale:end`` markers.

Generated sheets (n x n unit cells of ``bh.families.miura``, ``yoshimura`` and ``eggbox``)
and the two box-pleated FOLD files of Origami Simulator kept with the tests. Printed per
pattern: crease variables, DOF at the flat state and at the folded state nearby (with the
gap ratio of the rank cut), the median wall time and its split over the stages (both
states together); then per family the slope of log(time) against log(creases), whole and
per stage, and the fitted time at 10 000 creases. Each Miura DOF is checked against the
known value (flat 4n - 2, folded 1), each folded Yoshimura's (triangular panels) against
Tachi's count (no redundant constraint at a generic folded state).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

import barhinge as bh
from barhinge._publish import write_between
from barhinge.pattern.io import read

ROOT = Path(__file__).resolve().parents[1]
FILES = ROOT / "tests/data/crease-patterns/origami-simulator"
DOC = ROOT / "docs" / "kinematics.md"
START, END = "<!-- dof-scale:start -->", "<!-- dof-scale:end -->"
LINES: list[str] = []


def emit(line: str = "") -> None:
    print(line, flush=True)
    LINES.append(line)


STAGES = ("rank", "local", "actuators", "folded")


def _stage(name: str) -> str | None:
    if name.startswith("rank"):
        return "rank"
    if name.startswith("local"):
        return "local"
    if name == "actuators":
        return "actuators"
    if name.startswith("folded"):
        return "folded"
    return None


def timed(cp, repeat: int) -> tuple[float, dict[str, float], bh.DofReport]:
    """Median wall time of ``bh.dof(cp)``, median time per stage, the report."""
    times, per, rep = [], defaultdict(list), None
    for _ in range(repeat):
        marks: list[tuple[str, float]] = []
        t0 = time.perf_counter()
        rep = bh.dof(cp, progress=lambda s, d, n, m=marks: m.append((s, time.perf_counter())))
        times.append(time.perf_counter() - t0)
        acc = dict.fromkeys(STAGES, 0.0)
        for (s, t), (_, t_next) in zip(marks[:-1], marks[1:], strict=True):
            k = _stage(s)
            if k is not None:
                acc[k] += t_next - t
        for k, v in acc.items():
            per[k].append(v)
    return float(np.median(times)), {k: float(np.median(v)) for k, v in per.items()}, rep


def row(name: str, cp, repeat: int) -> tuple[bh.DofReport, float, dict[str, float]]:
    t, per, rep = timed(cp, repeat)
    m = rep.mechanism
    split = " | ".join(f"{per[k]:.2f}" for k in STAGES)
    folded = str(m.global_dof) if rep.folded is not None or not rep.flat else "none found"
    emit(
        f"| {name} | {rep.n_variables} | {rep.global_dof} | {folded} | "
        f"{m.gap_ratio:.1e} ({'certain' if m.certain else 'UNCERTAIN'}) | {m.method} | "
        f"{t:.2f} | {split} |"
    )
    return rep, t, per


FAMILY = {
    "miura": lambda n: bh.families.miura(n, n),
    "yoshimura": lambda n: bh.families.FAMILIES["yoshimura"](nx=n, ny=n),
    "eggbox": lambda n: bh.families.FAMILIES["eggbox"](nx=n, ny=n),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[10, 20, 35, 50, 70])
    ap.add_argument("--families", nargs="+", default=["miura"], choices=sorted(FAMILY))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-files", action="store_true")
    ap.add_argument(
        "--max-yoshimura", type=int, default=70, help="largest Yoshimura n (cells per side)"
    )
    ap.add_argument("--yoshimura-sizes", type=int, nargs="+", help="Yoshimura n (default: --sizes)")
    ap.add_argument("--publish", action="store_true", help="rewrite docs/kinematics.md")
    a = ap.parse_args()
    emit(
        "| pattern | creases | DOF flat | DOF folded | gap ratio (folded) | method | median s | "
        + " | ".join(f"{k} s" for k in STAGES)
        + " |"
    )
    emit("|---" * (7 + len(STAGES)) + "|")
    fits = {}
    for fam in a.families:
        xs, ts, ps = [], [], defaultdict(list)
        sizes = a.yoshimura_sizes if fam == "yoshimura" and a.yoshimura_sizes else a.sizes
        for n in sizes:
            if fam == "yoshimura" and n > a.max_yoshimura:
                continue  # flat Yoshimura: a first-order null space of ~creases / 3
            rep, t, per = row(f"{fam} {n} x {n}", FAMILY[fam](n), a.repeat)
            if fam == "miura":
                assert rep.global_dof == 4 * n - 2 and rep.mechanism.global_dof == 1, "Miura DOF"
            if fam == "yoshimura":
                m = rep.mechanism
                assert m is not rep and m.global_dof == m.counted_dof, "Yoshimura DOF"
            xs.append(rep.n_variables)
            ts.append(t)
            for k in STAGES:
                ps[k].append(max(per[k], 1e-4))
        fits[fam] = (xs, ts, ps)
    if not a.no_files:
        for f in ("BoxPleatPyramid.fold", "BoxPleatInOutWave.fold"):
            row(f, read(FILES / f), a.repeat)
    emit()
    for fam, (xs, ts, ps) in fits.items():
        if len(xs) > 1:
            slope = lambda y, x=xs: np.polyfit(np.log(x), np.log(y), 1)[0]  # noqa: E731
            parts = ", ".join(f"{k} ^{slope(ps[k]):.2f}" for k in STAGES)
            c = np.polyfit(np.log(xs), np.log(ts), 1)
            at = float(np.exp(np.polyval(c, np.log(1e4))))
            emit(
                f"* {fam}: time ~ creases^{c[0]:.2f} ({parts}); at 10 000 creases (fit): {at:.1f} s"
            )
    if a.publish:
        cmd = "python benchmarks/bench_dof.py " + " ".join(sys.argv[1:])
        write_between(DOC, START, END, "\n".join([f"`{cmd}`:", "", *LINES]))
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
