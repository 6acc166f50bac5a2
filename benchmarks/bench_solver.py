"""Solver benchmarks: scaling of the Newton iteration, a 20 x 20 fold, the peer problem.

Run:  python benchmarks/bench_solver.py [--quick] [--sizes 10 20 40 70 100] [--peer 12 20 40]

Tables (medians where repeated):

1. Miura sheets n x n cells folded by actuators (the creases of the middle straight crease
   line, driven from facet angle 5 deg towards 60 deg): DOF, actuators, time per Newton
   iteration, the shares of assembly (model + actuator terms), factorisation and the bordered
   (Schur) solves, iterations per step, and the ratio of the time per iteration to one bare
   factorisation of the same matrix.
2. 20 x 20 cells folded from flat to 60 deg in 50 steps: wall time.
3. The peer problem of issue 5: Miura n x n, gamma 60 deg, a = b = 2, initial facet angle
   15 deg, N5B8, EA = 1e5, fold 0.1 and bending 1e4 per unit hinge length; one boundary row
   fixed in the push direction, one node fixed across, the low nodes of both rows fixed in z;
   the other row pushed by 0.8148 n in 50 displacement steps. Wall time and the balance
   external work = stored energy.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import scipy.sparse as sp

import barhinge as bh
from barhinge.model.calibrate import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene, miura_line_creases
from barhinge.solve.controls import actuator_terms
from barhinge.solve.linear import get_backend


def miura_scene(n: int, theta0: float, steps: int, theta1: float = 60.0) -> Scene:
    cp0 = bh.patterns.miura(n, n, alpha=60.0, fold=theta0)
    cp1 = bh.patterns.miura(n, n, alpha=60.0, fold=theta1)
    edges = miura_line_creases(bh.patterns.miura(n, n, alpha=60.0))
    model = BarHingeModel.from_pattern(
        cp0, "N5B8", Material(E=1e6, nu=0.3, t=0.01), fold_stiffness=1e-3
    )
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    return Scene(model, actuators=acts, steps=steps, name=f"miura{n}")


def bare_factorisation(scene: Scene, X: np.ndarray, backend: str, repeat: int = 3) -> float:
    """Median time of one factorisation of the free-DOF tangent K_ff + p G^T G by the given
    backend (a fresh backend each time: ordering / symbolic analysis included)."""
    model = scene.model
    K = model.evaluate(X).K
    free = ~scene.fixed.ravel()
    T = actuator_terms(model, X, scene.actuator_hinges())
    G = T.G[:, free]
    A = K[free][:, free]
    p = float(np.mean(np.abs(A.diagonal()))) / float(np.mean(np.sum(T.grad**2, axis=1)))
    A = sp.csc_matrix(A + p * (G.T @ G))
    ts = []
    for _ in range(repeat):
        b = get_backend(backend)
        t0 = time.perf_counter()
        b.factorize(A)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def table_scaling(sizes: list[int], steps: int) -> None:
    print(f"\n## Miura n x n folded by actuators (5 -> 60 deg over {steps} of 50 steps)")
    cols = (
        "n",
        "DOF",
        "act",
        "iters/step",
        "s/iter",
        "assembly",
        "factor",
        "schur",
        "bare factor s",
        "iter/factor",
    )
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for n in sizes:
        # the first `steps` of a 50-step schedule: the per-iteration cost does not depend on
        # how far the sheet is folded
        sc = miura_scene(n, 5.0, 50)
        table = sc.actuators.schedule(
            50, np.degrees(sc.model.hinge_angles(sc.model.X0)[sc.actuator_hinges()])
        )[1 : steps + 1]
        sc = sc.with_(
            actuators=bh.Actuators(edges=sc.actuators.edges, table_deg=table), steps=steps
        )
        t0 = time.perf_counter()
        path = bh.solve(sc)
        wall = time.perf_counter() - t0
        tm = path.meta["timing"]
        nf = tm["n_factorizations"]
        per_iter = wall / nf
        lu = bare_factorisation(sc, path.X[-1], path.meta["linear_solver"])
        row = (
            n,
            sc.model.n_dof,
            sc.actuators.n,
            f"{nf / steps:.1f}",
            f"{per_iter:.3f}",
            f"{tm['assembly'] / wall:.0%}",
            f"{tm['factorize'] / wall:.0%}",
            f"{tm['solve'] / wall:.0%}",
            f"{lu:.3f}",
            f"{per_iter / lu:.2f}",
        )
        print("| " + " | ".join(str(v) for v in row) + " |", flush=True)


def table_fold20(repeat: int) -> None:
    print("\n## 20 x 20 cells, flat -> 60 deg in 50 steps")
    ts, its = [], []
    for _ in range(repeat):
        sc = miura_scene(20, 0.0, 50)
        t0 = time.perf_counter()
        path = bh.solve(sc)
        ts.append(time.perf_counter() - t0)
        its.append(int(path.iterations.sum()))
    print(
        f"DOF {sc.model.n_dof}, wall time median {statistics.median(ts):.2f} s "
        f"(runs: {', '.join(f'{t:.2f}' for t in ts)}), Newton iterations {its[0]}"
    )


def peer_scene(n: int, steps: int = 50) -> Scene:
    cp = bh.patterns.miura(n, n, a=2.0, b=2.0, alpha=60.0, fold=15.0)
    probe = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5)
    is_bend = probe.hinge_kind == "bend"
    h = probe.hinges[is_bend]
    length = np.linalg.norm(probe.X0[h[:, 1]] - probe.X0[h[:, 0]], axis=1)
    model = BarHingeModel.from_pattern(
        cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5, bend_k=1e4 * length, strain="engineering"
    )
    ni, nj = 2 * n + 1, 2 * n + 1
    vid = lambda i, j: j * ni + i  # noqa: E731
    first = np.array([vid(i, 0) for i in range(ni)])  # straight boundary row y = min
    last = np.array([vid(i, nj - 1) for i in range(ni)])  # straight boundary row y = max
    X = model.X0
    zlow = X[:, 2].min() + 1e-9
    S = np.zeros((model.n_nodes, 3), bool)
    S[first, 1] = True  # fixed in the push direction
    S[first[0], 0] = True  # one node fixed across
    S[first[X[first, 2] <= zlow], 2] = True
    U = np.full((model.n_nodes, 3), np.nan)
    U[last, 1] = -0.8148 * n
    low_last = last[X[last, 2] <= zlow]
    S[low_last, 2] = True
    return Scene(model, supports=S, prescribed=U, steps=steps, name=f"peer{n}")


def table_peer(ns: list[int], repeat: int) -> None:
    print("\n## Peer problem (displacement control, 50 steps)")
    cols = ("n", "DOF", "wall s (median)", "iterations", "energy", "external work", "rel diff")
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for n in ns:
        ts = []
        for _ in range(repeat if n <= 12 else 1):
            sc = peer_scene(n)
            t0 = time.perf_counter()
            try:
                path = bh.solve(sc)
            except bh.ConvergenceError as exc:
                print(f"| {n} | {sc.model.n_dof} | failed: {exc} |")
                break
            ts.append(time.perf_counter() - t0)
        else:
            E, W = path.energy[-1], path.external_work[-1]
            row = (
                n,
                sc.model.n_dof,
                f"{statistics.median(ts):.2f}",
                int(path.iterations.sum()),
                f"{E:.6g}",
                f"{W:.6g}",
                f"{abs(W / E - 1):.2e}",
            )
            print("| " + " | ".join(str(v) for v in row) + " |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    ap.add_argument("--sizes", type=int, nargs="*", default=[10, 20, 40, 70, 100])
    ap.add_argument("--peer", type=int, nargs="*", default=[12, 20, 40])
    ap.add_argument("--steps", type=int, default=2, help="steps timed per size in table 1")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--skip", nargs="*", default=[], choices=["scaling", "fold20", "peer"])
    a = ap.parse_args()
    if a.quick:
        a.sizes, a.peer, a.repeat = [10, 20], [12], 1
    print(f"barhinge {bh.__version__}; linear solver: {get_backend('auto').name}")
    if "scaling" not in a.skip:
        table_scaling(a.sizes, a.steps)
    if "fold20" not in a.skip:
        table_fold20(a.repeat)
    if "peer" not in a.skip:
        table_peer(a.peer, a.repeat)


if __name__ == "__main__":
    main()
