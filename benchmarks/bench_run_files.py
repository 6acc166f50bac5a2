"""The result files of a run against its solve, on a Miura sheet folded from flat.

Usage: python benchmarks/bench_run_files.py [--size 40] [--steps 50] [--repeat 3]

Solves the n x n Miura fold of ``bench_solver.miura_scene`` (flat to 60 deg, quasi-rigid)
once, then times what ``barhinge fold`` writes after the solve, part by part (medians of
``--repeat`` rounds, wall seconds): the fields of every state (``path_state_data``), the
XDMF pair, the per-state VTU files (``write_state_vtus``: several at a time), the FOLD
frames, the final-state analysis (stiffness modes, curvature), and the whole
``write_run`` (``--pictures none``, viewer included) against the solve.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from bench_solver import miura_scene  # noqa: E402

from barhinge.analysis.final_state import final_state_results  # noqa: E402
from barhinge.fields import path_state_data, write_state_vtus, write_xdmf  # noqa: E402
from barhinge.output.run import write_run  # noqa: E402
from barhinge.pattern.fold import write_fold_path  # noqa: E402
from barhinge.results import FoldPath  # noqa: E402
from barhinge.scene import Scene  # noqa: E402
from barhinge.solver.newton import solve  # noqa: E402


def one_round(path: FoldPath, scene: Scene, out: Path) -> dict[str, float]:
    """Wall seconds of each part of the run's files, written into ``out``."""
    model, cp = scene.model, scene.model.pattern
    t: dict[str, float] = {}
    t0 = time.perf_counter()
    states = path_state_data(path, model=model, pattern=cp)
    t["fields of every state"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_xdmf(out / "p.xdmf", path, states=states)
    t["XDMF pair"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_state_vtus([out / f"p_{i:04d}.vtu" for i in range(path.n_states)], states)
    t["VTU per state"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_fold_path(cp, path, out / "p.fold")
    t["FOLD frames"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    final_state_results(path, model, pattern=cp)
    t["final-state analysis"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_run(path, scene, out / "run", pictures="none", viewer=True)
    t["write_run (all of it)"] = time.perf_counter() - t0
    return t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=40)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    scene = miura_scene(a.size, 0.0, a.steps)
    t0 = time.perf_counter()
    path = solve(scene)
    t_solve = time.perf_counter() - t0
    rounds = []
    for _ in range(a.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            rounds.append(one_round(path, scene, Path(tmp)))
    print(f"Miura {a.size} x {a.size}, {scene.model.X0.size} DOF, {path.n_states - 1} steps")
    print(f"solve: {t_solve:.2f} s")
    print(f"{'part':<24} {'median s':>9} {'/ solve':>8}")
    for name in rounds[0]:
        med = statistics.median(r[name] for r in rounds)
        print(f"{name:<24} {med:9.3f} {med / t_solve:8.3f}")


if __name__ == "__main__":
    main()
