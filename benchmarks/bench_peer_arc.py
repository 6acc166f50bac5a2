"""The peer problem under arc length, stopped at the peer's end shortening.

Run:  python benchmarks/bench_peer_arc.py [--sizes 40 70] [--steps 50] [--increment 0.5]
      [--publish]

The peer problem of issue 5 (``bench_solver.peer_scene``: Miura n x n, N5B8, EA = 1e5,
fold 0.1, bending 1e4 per unit hinge length, one boundary row held) with the pushed row
*loaded* instead of displaced: a reference load of 1 per node of that row in -y, followed
by MGDCM arc length until node 0 of the loaded row has moved by the peer's shortening,
``-0.8148 n`` in y (``options.arc_stop_displacement``, landed on exactly). The first
load-factor increment is ``--increment`` (``options.arc_length_increment``, default 0.5):
the default ``1 / steps`` shrinks with the softening sheet to thousands of increments.

Printed per size: DOF, increments, Newton iterations, factorisations, wall and CPU time,
the stop reached, the load factor at the end and its largest value on the way, the limit
points passed (turns of the load factor), and the work balance (external work against
stored energy). ``--publish`` writes the table into docs/solver-performance.md (between
the ``bench_peer_arc`` markers).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import barhinge as bh
from barhinge._publish import generated_stamp, write_between
from barhinge.scene import Scene

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_solver import peer_scene  # noqa: E402

COLS = (
    "n",
    "DOF",
    "increments",
    "iterations",
    "factorisations",
    "wall s",
    "CPU s",
    "stop",
    "shortening",
    "load factor at stop",
    "max load factor",
    "limit points",
    "work / energy - 1",
)


def peer_arc_scene(n: int, steps: int, increment: float = 0.5) -> tuple[Scene, int, float]:
    """The peer scene with the pushed row loaded (1 per node, -y) and the displacement stop;
    returns the scene, the stop node and the shortening asked for (length)."""
    sc = peer_scene(n, steps)
    U = sc.prescribed
    row = np.flatnonzero(np.isfinite(U[:, 1]))  # the row the peer problem pushes
    P = np.zeros_like(sc.model.X0)
    P[row, 1] = -1.0
    S = sc.supports.copy()
    node, u = int(row[0]), -0.8148 * n
    options = {
        "arc_stop_displacement": {"node": node, "axis": "y", "value": u},
        "arc_length_increment": increment,
    }
    arc = Scene(sc.model, supports=S, loads=P, control="arc_length", steps=steps,
                options=options, name=f"peer{n}-arc")  # fmt: skip
    return arc, node, u


def run(n: int, steps: int, increment: float) -> tuple:
    sc, node, u = peer_arc_scene(n, steps, increment)
    c0, t0 = time.process_time(), time.perf_counter()
    path = bh.solve(sc)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    lam = np.asarray(path.load_factor)
    d = np.diff(lam)
    d = d[d != 0]
    turns = int(np.count_nonzero(np.sign(d[1:]) != np.sign(d[:-1])))
    short = float(path.X[-1][node, 1] - path.X[0][node, 1])
    wb = path.meta["work_balance"]
    stop = path.meta["arc_stop"]["criterion"]
    return (
        n,
        sc.model.n_dof,
        path.n_states - 1,
        int(path.meta["newton"]["total_iterations"]),
        int(path.meta["timing"]["n_factorizations"]),
        f"{wall:.1f}",
        f"{cpu:.1f}",
        stop,
        f"{short:.4f} (asked {u:.4f})",
        f"{lam[-1]:.4g}",
        f"{lam.max():.4g}",
        turns,
        f"{wb['work'] / wb['energy'] - 1:.1e}",
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="*", default=[40, 70])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument(
        "--increment", type=float, default=0.5, help="options.arc_length_increment (load factor)"
    )
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    a = ap.parse_args()
    lines = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    print("\n".join(lines), flush=True)
    for n in a.sizes:
        try:
            row = run(n, a.steps, a.increment)
        except bh.ConvergenceError as exc:
            row = (n, "failed: " + str(exc).replace("|", "/"))
        lines.append("| " + " | ".join(str(v) for v in row) + " |")
        print(lines[-1], flush=True)
    if a.publish:
        cmd = "python benchmarks/bench_peer_arc.py --publish"
        if a.sizes != [40, 70]:
            cmd += " --sizes " + " ".join(map(str, a.sizes))
        doc = Path(__file__).resolve().parents[1] / "docs" / "solver-performance.md"
        body = "\n".join([generated_stamp(cmd), "", *lines])
        write_between(doc, "<!-- bench_peer_arc:start -->", "<!-- bench_peer_arc:end -->", body)


if __name__ == "__main__":
    main()
