"""Worker of ``bench_distributed.py``: factorise one symmetric matrix with a distributed
direct solver (MUMPS or SuperLU_DIST through PETSc) on the MPI ranks it is started on.

Run by ``bench_distributed.py`` as
``mpiexec -n P python3 distributed_solve.py MATRIX.npz SOLVER`` with a Python that has
petsc4py and mpi4py (Debian: ``apt-get install python3-petsc4py python3-mpi4py
python3-scipy openmpi-bin``). ``MATRIX.npz`` holds the upper triangle of the matrix in CSR
(``indptr``, ``indices``, ``data``, ``shape``; what PARDISO factorises in barhinge's solver).
Every rank reads the file and keeps its block of rows. Rank 0 prints one JSON line: the
first factorisation (ordering, analysis and numeric), the median of three numeric
refactorisations, one solve, the solve's relative residual, the negative pivots (MUMPS,
LDL^T: the inertia barhinge's stability checks read), the factor memory (MUMPS: largest
per rank and total, MB) and the fill-reducing ordering MUMPS chose (its own choice: Debian's
MUMPS is built without METIS and SCOTCH).

This file runs outside barhinge's environment (no barhinge import).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np
import petsc4py

petsc4py.init(sys.argv[:1])
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

#: MUMPS's orderings by their INFOG(7) code
ORDERINGS = {0: "AMD", 1: "user", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD"}


def load_rows(path: str, rstart: int, rend: int):
    """(indptr, indices, data) of rows ``rstart:rend`` of the full symmetric matrix whose
    upper triangle is stored in ``path``."""
    import scipy.sparse as sp

    z = np.load(path)
    n = int(z["shape"][0])
    U = sp.csr_matrix((z["data"], z["indices"], z["indptr"]), shape=(n, n))
    lower = sp.triu(U, k=1, format="csr").T.tocsr()
    A = (U + lower).tocsr()[rstart:rend]
    A.sort_indices()
    return A.indptr.astype(PETSc.IntType), A.indices.astype(PETSc.IntType), A.data


def main() -> None:
    path, solver = sys.argv[1], sys.argv[2]
    comm = PETSc.COMM_WORLD
    rank, size = comm.getRank(), comm.getSize()
    n = int(np.load(path)["shape"][0])
    rows = PETSc.Vec().createMPI(n, comm=comm)
    rstart, rend = rows.getOwnershipRange()
    indptr, indices, data = load_rows(path, rstart, rend)
    A = PETSc.Mat().createAIJ(((rend - rstart, n), (rend - rstart, n)), comm=comm)
    A.setPreallocationCSR((indptr, indices, data))
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    A.assemble()

    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    # Cholesky on a symmetric (not SPD) matrix: MUMPS's LDL^T (SYM = 2);
    # SuperLU_DIST has no symmetric mode, so it takes LU
    pc.setType("cholesky" if solver == "mumps" else "lu")
    pc.setFactorSolverType(solver)
    ksp.setFromOptions()  # MUMPS picks its ordering (INFOG(7) reports which)

    b = A.createVecLeft()
    b.setRandom()
    x = A.createVecRight()

    def timed(fn) -> float:
        MPI.COMM_WORLD.Barrier()
        t0 = time.perf_counter()
        fn()
        MPI.COMM_WORLD.Barrier()
        return time.perf_counter() - t0

    first = timed(ksp.setUp)
    refac = []
    for k in range(3):
        A.scale(1.0 + 1e-12 * (k + 1))  # new values, same pattern: numeric only
        ksp.setOperators(A)
        refac.append(timed(ksp.setUp))
    solve = timed(lambda: ksp.solve(b, x))
    r = b.duplicate()
    A.mult(x, r)
    r.axpy(-1.0, b)
    out = {
        "ranks": size,
        "solver": solver,
        "n": n,
        "first_s": first,
        "refactor_s": float(np.median(refac)),
        "solve_s": solve,
        "residual": r.norm() / b.norm(),
    }
    if solver == "mumps":
        F = pc.getFactorMatrix()
        out["negative_pivots"] = int(F.getMumpsInfog(12))
        out["factor_mb_max_rank"] = float(F.getMumpsInfog(21))
        out["factor_mb_total"] = float(F.getMumpsInfog(22))
        out["factor_entries"] = int(F.getMumpsInfog(29))
        code = int(F.getMumpsInfog(7))
        out["ordering"] = ORDERINGS.get(code, str(code))
    if rank == 0:
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
