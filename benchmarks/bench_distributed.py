"""The bordered tangent of a Miura fold factorised by a distributed direct solver (MUMPS
through PETSc, on MPI ranks) beside PARDISO, and what that says about a 10 M DOF sheet.

Usage: python benchmarks/bench_distributed.py [--sizes 20 40 70 100] [--ranks 1 2]
       [--mpi-python /usr/bin/python3] [--publish]

For each Miura n x n sheet of ``bench_solver.miura_scene`` (N5B8, quasi-rigid set, actuators
on the middle crease line) the matrix barhinge's solver factorises, the bordered tangent
``[K G^T; G 0]`` of the sheet folded to 60 deg (its rigid fold, with the solver's own
augmentation), is written to a temporary file and factorised

* by PARDISO in this process (barhinge's backend, its thread policy): first factorisation
  (ordering included), numeric refactorisation (median of three), factor memory;
* by MUMPS (PETSc's ``cholesky`` with ``mat_solver_type mumps``: LDL^T of the symmetric
  indefinite matrix) on P MPI ranks of one thread each, for every P of ``--ranks``
  (``benchmarks/distributed_solve.py`` under ``mpiexec``): the same figures, the factor
  memory of the largest rank and of all ranks (MUMPS's INFOG(21), INFOG(22)), and its
  negative pivots, which must equal PARDISO's (the inertia the stability checks read).

The MPI side needs a Python with petsc4py and mpi4py built against a PETSc with MUMPS; on
Debian: ``apt-get install python3-petsc4py python3-mpi4py python3-scipy openmpi-bin``
(``--mpi-python`` names that interpreter; ``PETSC_DIR`` is set to Debian's PETSc when unset).

The last paragraph extrapolates the distributed factorisation of a 10 M DOF sheet from the
two largest sizes (factor memory and refactorisation time against DOF, log-log slopes).
``--publish`` writes the table and that paragraph into docs/solver-performance.md (between
the ``bench_distributed`` markers).
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: the sheet of the extrapolation paragraph
TEN_MILLION = 10_000_000
#: Debian's PETSc (the petsc4py .pth file looks for it under PETSC_DIR)
DEBIAN_PETSC = "/usr/lib/petscdir/petsc*/x86_64-linux-gnu-real"


def bordered_matrix(n: int):
    """(upper triangle of the bordered tangent of the sheet folded to 60 deg, DOF of the
    sheet). The state is the rigid fold (panels undeformed, fold springs loaded), the
    augmentation the solver's own ("auto"), the multipliers zero."""
    from bench_solver import _stiffness_model, miura_scene

    import barhinge as bh
    from barhinge.linalg.backends import get_backend
    from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms
    from barhinge.solver.context import auto_augmentation

    sc = miura_scene(n, 0.0, 50)
    model = sc.model
    folded = _stiffness_model(bh.families.miura(n, n, alpha=60.0, fold=60.0), "quasi-rigid")
    X = np.asarray(folded.X0, float)
    if X.shape != np.shape(model.X0):
        raise SystemExit(f"n = {n}: the folded sheet's nodes do not match the flat sheet's")
    ev = model.evaluate(X, tangent=True)
    terms = actuator_terms(model, X, sc.actuator_hinges())
    p, _ = auto_augmentation(ev.K, terms)
    sysm = BorderedSystem(get_backend("pardiso"), ~sc.fixed.ravel(), terms.dofs, Timer())
    sysm.set_operator(ev.K, terms, np.zeros(len(terms.dofs)), p, factorize=True)
    return sysm._kkt_matrix(upper=True).copy(), int(model.n_dof)


def pardiso_figures(U) -> dict:
    """PARDISO on the upper triangle ``U``: first factorisation, refactorisation (median of
    three), factor memory (MB) and negative pivots, under the solver's thread policy."""
    import scipy.sparse as sp

    from barhinge.linalg.backends import PardisoBackend
    from barhinge.linalg.threads import sparse_solves

    with sparse_solves():
        b = PardisoBackend()
        t0 = time.perf_counter()
        f = b.factorize(U, upper=True)
        first = time.perf_counter() - t0
        neg = f.negative_pivots()
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            f = b.factorize(U, upper=True)
            times.append(time.perf_counter() - t0)
        mb = b.factor_bytes() / 2**20
        rhs = np.random.default_rng(0).uniform(-1.0, 1.0, U.shape[0])
        x = f.solve(rhs)
    A = U + sp.triu(U, k=1).T
    return {
        "residual": float(np.linalg.norm(A @ x - rhs) / np.linalg.norm(rhs)),
        "first_s": first,
        "refactor_s": statistics.median(times),
        "factor_mb": mb,
        "negative_pivots": neg,
    }


def mpi_env() -> dict:
    """The environment of the MPI ranks: one thread each, Debian's PETSc where unset."""
    env = dict(os.environ)
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if "PETSC_DIR" not in env:
        found = sorted(glob.glob(DEBIAN_PETSC))
        if found:
            env["PETSC_DIR"] = found[-1]
    return env


def mumps_figures(path: str, ranks: int, python: str) -> dict:
    """Run the worker on ``ranks`` MPI ranks; its JSON line."""
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        raise SystemExit("mpiexec not found: install an MPI (Debian: openmpi-bin)")
    cmd = [mpiexec, "-n", str(ranks), "--oversubscribe"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    cmd += [python, str(HERE / "distributed_solve.py"), path, "mumps"]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env())
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
        raise SystemExit(f"MUMPS on {ranks} rank(s) failed (exit {proc.returncode}): {last}")
    return json.loads(lines[-1])


def check_mpi_python(python: str) -> None:
    """Stop with one line when ``python`` lacks petsc4py, mpi4py or PETSc's MUMPS."""
    code = (
        "import petsc4py, sys; petsc4py.init(sys.argv[:1]); from petsc4py import PETSc; "
        "import mpi4py, scipy; sys.exit(0 if PETSc.Sys.hasExternalPackage('mumps') else 3)"
    )
    try:
        rc = subprocess.run([python, "-c", code], capture_output=True, env=mpi_env()).returncode
    except FileNotFoundError:
        rc = 1
    if rc == 3:
        raise SystemExit(f"{python}: PETSc is built without MUMPS")
    if rc != 0:
        raise SystemExit(
            f"{python} cannot import petsc4py, mpi4py and scipy; on Debian: apt-get install "
            "python3-petsc4py python3-mpi4py python3-scipy openmpi-bin (or --mpi-python)"
        )


def run(sizes: list[int], ranks: list[int], python: str) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            U, dof = bordered_matrix(n)
            path = os.path.join(tmp, f"miura{n}.npz")
            np.savez(path, indptr=U.indptr, indices=U.indices, data=U.data, shape=U.shape)
            row = {"n": n, "dof": dof, "rows": U.shape[0], "pardiso": pardiso_figures(U)}
            del U
            row["mumps"] = {p: mumps_figures(path, p, python) for p in ranks}
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)
    return rows


def table(rows: list[dict], ranks: list[int]) -> list[str]:
    head = (
        "| n | DOF | PARDISO: first / refactorisation s, factor MB | "
        + " | ".join(
            f"MUMPS {p} rank{'s' if p > 1 else ''}: first / refactorisation s, factor MB "
            "largest rank / all (ordering)"
            for p in ranks
        )
        + " | negative pivots PARDISO / MUMPS | solve residual PARDISO / MUMPS |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        pa = r["pardiso"]
        cells = [
            f"{m['first_s']:.2f} / {m['refactor_s']:.2f}, "
            f"{m['factor_mb_max_rank']:.0f} / {m['factor_mb_total']:.0f} ({m['ordering']})"
            for m in (r["mumps"][p] for p in ranks)
        ]
        negs = sorted({r["mumps"][p]["negative_pivots"] for p in ranks})
        res = max(r["mumps"][p]["residual"] for p in ranks)
        lines.append(
            f"| {r['n']} | {r['dof']} | {pa['first_s']:.2f} / {pa['refactor_s']:.2f}, "
            f"{pa['factor_mb']:.0f} | " + " | ".join(cells) + f" | {pa['negative_pivots']} / "
            f"{', '.join(map(str, negs))} | {pa['residual']:.1e} / {res:.1e} |"
        )
    return lines


def slope(x: list[float], y: list[float]) -> float:
    """Log-log slope through the two points."""
    return float(np.log(y[1] / y[0]) / np.log(x[1] / x[0]))


def ten_million(rows: list[dict], ranks: list[int]) -> list[str]:
    """The distributed factorisation of a 10 M DOF sheet, extrapolated from the two largest
    sizes with the most ranks measured."""
    if len(rows) < 2:
        return []
    p = max(ranks)
    a, b = rows[-2], rows[-1]
    d = [a["dof"], b["dof"]]
    mt = [a["mumps"][p]["factor_mb_total"], b["mumps"][p]["factor_mb_total"]]
    mr = [a["mumps"][p]["factor_mb_max_rank"], b["mumps"][p]["factor_mb_max_rank"]]
    tf = [a["mumps"][p]["refactor_s"], b["mumps"][p]["refactor_s"]]
    pm, pt = slope(d, mt), slope(d, tf)
    scale = TEN_MILLION / d[1]
    total10 = mt[1] * scale**pm
    pf = [a["pardiso"]["factor_mb"], b["pardiso"]["factor_mb"]]
    pardiso10 = pf[1] * scale ** slope(d, pf)
    orderings = sorted({b["mumps"][q]["ordering"] for q in ranks})
    one_rank = [r["mumps"][min(ranks)]["factor_mb_total"] / r["pardiso"]["factor_mb"] for r in rows]
    larger = f"{min(one_rank):.1f} to {max(one_rank):.1f} times the size of"
    share = mr[1] / mt[1]  # the largest rank's share of the factor at p ranks
    t10 = tf[1] * scale**pt
    one = b["mumps"].get(1)
    speed = f"{one['refactor_s'] / b['mumps'][p]['refactor_s']:.2f}" if one and p > 1 else None
    node_gb = 24.0
    need = int(np.ceil(total10 / 1024 / (0.5 * node_gb)))
    text = (
        f"Extrapolated from the two largest sheets ({d[0]} and {d[1]} DOF) on {p} ranks: "
        f"MUMPS's factor grows like DOF^{pm:.2f} and its refactorisation like DOF^{pt:.2f}, "
        f"so a 10 M DOF sheet's factor would take about {total10 / 1024:.0f} GB in all "
        f"(PARDISO's, extrapolated alike: {pardiso10 / 1024:.0f} GB; MUMPS orders with "
        f"{' and '.join(orderings)} here, Debian's build having neither METIS nor SCOTCH, and "
        f"its factor on one rank is {larger} PARDISO's at every size above). "
        f"Split over ranks as measured here (the largest of {p} ranks holds "
        f"{share:.0%} of it), nodes like this one (24 GB, half of it for the factor, the "
        f"rest for the model and the solver) would need about {need} of them; one "
        f"refactorisation would take about {t10 / 60:.0f} min on {p} ranks of this "
        "machine"
    )
    text += (
        f" (from 1 to {p} ranks here the refactorisation of the largest sheet ran {speed}x "
        "faster; more ranks were not measured)."
        if speed
        else "."
    )
    return ["", text]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[20, 40, 70, 100])
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--mpi-python", default="/usr/bin/python3")
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    args = ap.parse_args()
    check_mpi_python(args.mpi_python)
    rows = run(args.sizes, args.ranks, args.mpi_python)
    lines = table(rows, args.ranks) + ten_million(rows, args.ranks)
    print("\n".join(lines))
    if args.publish:
        from barhinge._publish import generated_stamp, write_between

        cmd = "python benchmarks/bench_distributed.py --publish"
        if args.sizes != [20, 40, 70, 100]:
            cmd += " --sizes " + " ".join(map(str, args.sizes))
        if args.ranks != [1, 2]:
            cmd += " --ranks " + " ".join(map(str, args.ranks))
        stamp = generated_stamp(cmd)
        path = write_between(
            HERE.parent / "docs" / "solver-performance.md",
            "<!-- bench_distributed:start -->",
            "<!-- bench_distributed:end -->",
            "\n".join([stamp, "", *lines]),
        )
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
