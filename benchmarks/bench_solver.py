"""Solver benchmarks: scaling of the Newton iteration, a 20 x 20 fold, the peer problem.

Run:  python benchmarks/bench_solver.py [--quick] [--sizes 10 20 40 70 100] [--peer 12 20 40]
      [--linear-solver auto|superlu|pardiso|cholmod] [--skip scaling fold20 peer]

Tables (medians where repeated):

1. Miura sheets n x n cells folded by actuators (the creases of the middle straight crease
   line, driven from facet angle 5 deg towards 60 deg; quasi-rigid stiffness set, see
   ``_stiffness_model``): DOF, actuators, time per Newton iteration in the steady state
   (steps 2 onwards: the first step carries the one-time ordering and analysis), the shares
   of assembly (model + actuator terms), factorisation and the bordered solves over the whole
   run, iterations per step, and the ratio of the time per iteration to one bare
   factorisation of the same matrix (numeric refactorisation; and from scratch).
2. 20 x 20 cells folded from flat to 60 deg in 50 steps: wall time, for the quasi-rigid
   and the compliant stiffness sets.
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

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.linalg.backends import get_backend
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene
from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms
from barhinge.solver.context import auto_augmentation


def _stiffness_model(cp, material: str) -> BarHingeModel:
    """``"quasi-rigid"``: the issue's peer stiffness set (bars EA = 1e5, fold 0.1 and
    bending 1e4 per unit hinge length: panels 1e5 x stiffer in bending than the folds, the
    regime of rigid-origami comparisons). ``"compliant"``: a 0.01-thick sheet with E = 1e6
    and fold stiffness 1e-3 (panel bending D ~ 0.09, only ~100 x the folds: floppy panels,
    a harder nonlinear problem), with the F17 panel bending the benchmark was defined with
    (``bend_calibration="filipov"``; under the softer plate default this sheet, driven by one
    crease line, leaves the Miura mode: the solver reports it and stops)."""
    if material == "quasi-rigid":
        probe = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5)
        h = probe.hinges[probe.hinge_kind == "bend"]
        length = np.linalg.norm(probe.X0[h[:, 1]] - probe.X0[h[:, 0]], axis=1)
        return BarHingeModel.from_pattern(
            cp, "N5B8", fold_stiffness=0.1, bar_EA=1e5, bend_k=1e4 * length
        )
    if material == "compliant":
        return BarHingeModel.from_pattern(
            cp,
            "N5B8",
            Material(E=1e6, nu=0.3, t=0.01),
            fold_stiffness=1e-3,
            bend_calibration="filipov",
        )
    raise ValueError(f"material {material!r}; expected 'quasi-rigid' or 'compliant'")


def miura_scene(
    n: int,
    theta0: float,
    steps: int,
    theta1: float = 60.0,
    material: str = "quasi-rigid",
    linear_solver: str = "auto",
) -> Scene:
    cp0 = bh.families.miura(n, n, alpha=60.0, fold=theta0)
    cp1 = bh.families.miura(n, n, alpha=60.0, fold=theta1)
    edges = miura_line_creases(bh.families.miura(n, n, alpha=60.0))
    model = _stiffness_model(cp0, material)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    return Scene(
        model,
        actuators=acts,
        steps=steps,
        name=f"miura{n}",
        options={"linear_solver": linear_solver},
    )


def bare_factorisation(
    scene: Scene, X: np.ndarray, mu: np.ndarray, backend: str, repeat: int = 5
) -> tuple[float, float]:
    """Median times of one factorisation of the matrix the solver factorises at ``X``
    (the bordered matrix for PARDISO, ``K_ff + p G^T G`` for the Schur-complement
    backends): (numeric refactorisation by a backend that has seen the pattern, as in the
    solver; a first factorisation by a fresh backend, ordering and analysis included)."""
    model = scene.model
    K = model.evaluate(X).K
    free = ~scene.fixed.ravel()
    T = actuator_terms(model, X, scene.actuator_hinges())
    # the solver's own augmentation ("auto": mean diagonal on the actuator DOFs over the
    # mean |grad rho|^2) and multipliers: the very matrix of its last iteration
    p, _ = auto_augmentation(K, T)
    b = get_backend(backend)
    sysm = BorderedSystem(b, free, T.dofs, Timer())
    sysm.set_operator(K, T, mu, p)  # factorises once (warm-up)
    saddle = getattr(b, "saddle_point", False)
    A = sysm._kkt_matrix(upper=True) if saddle else sysm.A
    kw = {"upper": True} if saddle else {}
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        b.factorize(A, **kw)
        ts.append(time.perf_counter() - t0)
    full = []  # a first factorisation by a fresh backend: ordering + analysis + numeric
    for _ in range(max(1, repeat // 2)):
        fresh = get_backend(backend)
        t0 = time.perf_counter()
        fresh.factorize(A, **kw)
        full.append(time.perf_counter() - t0)
    return statistics.median(ts), statistics.median(full)


def table_scaling(sizes: list[int], steps: int, linear_solver: str) -> None:
    print(f"\n## Miura n x n folded by actuators (5 -> 60 deg over {steps} of 50 steps)")
    cols = (
        "n",
        "DOF",
        "act",
        "iters/step",
        "s/iter",
        "assembly",
        "factor",
        "solves",
        "refactor s",
        "full factor s",
        "iter/refactor",
        "iter/full",
    )
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for n in sizes:
        # the first `steps` of a 50-step schedule: the per-iteration cost does not depend on
        # how far the sheet is folded
        sc = miura_scene(n, 5.0, 50, linear_solver=linear_solver)
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
        # steady state: steps 2.. (step 1 carries the one-time ordering and symbolic
        # analysis, the initial evaluation and the tangent predictor); from step 2 on each
        # Newton correction is one factorisation (extrapolating predictor, no reuse)
        its = path.iterations[2:].sum()
        per_iter = (path.wall_time[-1] - path.wall_time[1]) / its if its else wall / nf
        mu = -path.actuator_moments[-1]  # multipliers of the last state
        refac, full = bare_factorisation(sc, path.X[-1], mu, path.meta["linear_solver"])
        row = (
            n,
            sc.model.n_dof,
            sc.actuators.n,
            f"{nf / steps:.1f}",
            f"{per_iter:.3f}",
            f"{tm['assembly'] / wall:.0%}",
            f"{tm['factorize'] / wall:.0%}",
            f"{tm['solve'] / wall:.0%}",
            f"{refac:.3f}",
            f"{full:.3f}",
            f"{per_iter / refac:.2f}",
            f"{per_iter / full:.2f}",
        )
        print("| " + " | ".join(str(v) for v in row) + " |", flush=True)


def table_fold20(repeat: int, linear_solver: str) -> None:
    print("\n## 20 x 20 cells, flat -> 60 deg in 50 steps")
    cols = ("material", "DOF", "wall s (median)", "runs", "iterations", "factorisations")
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for material in ("quasi-rigid", "compliant"):
        ts = []
        for _ in range(repeat if material == "quasi-rigid" else 1):
            sc = miura_scene(20, 0.0, 50, material=material, linear_solver=linear_solver)
            t0 = time.perf_counter()
            path = bh.solve(sc)
            ts.append(time.perf_counter() - t0)
        row = (
            material,
            sc.model.n_dof,
            f"{statistics.median(ts):.2f}",
            ", ".join(f"{t:.2f}" for t in ts),
            int(path.iterations.sum()),
            path.meta["timing"]["n_factorizations"],
        )
        print("| " + " | ".join(str(v) for v in row) + " |", flush=True)


def peer_scene(n: int, steps: int = 50) -> Scene:
    cp = bh.families.miura(n, n, a=2.0, b=2.0, alpha=60.0, fold=15.0)
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


def table_peer(ns: list[int], repeat: int, linear_solver: str) -> None:
    print("\n## Peer problem (displacement control, 50 steps)")
    cols = ("n", "DOF", "wall s (median)", "iterations", "energy", "external work", "rel diff")
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for n in ns:
        ts = []
        for _ in range(repeat if n <= 12 else 1):
            sc = peer_scene(n).with_(options={"linear_solver": linear_solver})
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
    ap.add_argument("--steps", type=int, default=3, help="steps timed per size in table 1")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--skip", nargs="*", default=[], choices=["scaling", "fold20", "peer"])
    ap.add_argument("--linear-solver", default="auto", help="auto, superlu, pardiso, cholmod")
    a = ap.parse_args()
    if a.quick:
        a.sizes, a.peer, a.repeat = [10, 20], [12], 1
    ls = a.linear_solver
    print(f"barhinge {bh.__version__}; linear solver: {get_backend(ls).name}")
    if "scaling" not in a.skip:
        table_scaling(a.sizes, a.steps, ls)
    if "fold20" not in a.skip:
        table_fold20(a.repeat, ls)
    if "peer" not in a.skip:
        table_peer(a.peer, a.repeat, ls)


if __name__ == "__main__":
    main()
