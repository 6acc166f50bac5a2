"""One-command scaling table: Miura n x n folds, time, factorisations and memory against DOF.

Run:  python benchmarks/scaling.py [--sizes 10 20 40] [--steps 50] [--pieces 200]
      [--rows FILE [--fresh]] [--publish]

Every size runs in a fresh process (``--one n``), so that its peak resident memory
(``ru_maxrss``) is its own. A size is the fold of ``bench_solver.miura_scene`` (Miura n x n,
N5B8, quasi-rigid stiffness set, actuators on the middle crease line, flat -> 60 deg in
``--steps`` steps). Per size: DOF, model build time, fold wall and CPU time, Newton
iterations, factorisations, seconds per factorisation-iteration, peak memory (the fold's
own, taken before the floor's factorisation; ``time -v`` gives the whole process's). The exponent
``p`` of ``wall ~ DOF^p`` is the least-squares slope on log-log axes over the sizes run.

``--sizes ... 200`` folds the million-DOF sheet in full like the others (by far the longest
run: its row gives the time and memory); every size prints its steps on stderr as it goes.
``--pieces N`` measures, for a large sheet n = N, only the pieces that fit a short run:
model build, the first assembly of the tangent (with the process's peak memory after it),
and one Newton iteration's factorisation + solve at the flat state; where that sheet is not
folded in full, the whole fold is *extrapolated* (stated as such in the table) from the
measured per-iteration time times the iterations per step of the largest size run in full.

``--rows FILE`` keeps every finished size's row in the JSON file ``FILE`` as it completes,
and a later run takes the sizes already there from it (same ``--steps``) instead of folding
them again (``--fresh`` folds them again and replaces them): the 200 x 200 fold can run on
its own and the other sizes later, on a quiet machine, and one ``--publish`` writes them
together.

``--publish`` writes the tables into docs/solver-performance.md (between the ``scaling``
markers), using :func:`barhinge._publish.write_between`.

Every row records the barhinge commit it was folded at; rows kept from an earlier commit are
named under the table.

``--threads N`` fixes the thread count of MKL (PARDISO) and of barhinge's worker threads
(``BARHINGE_THREADS=N``) in each size's process, fold and floor alike (default: this
machine's cores; numpy's small dense calls keep one thread): under the default
``auto`` policy the fold would take the cores the load average leaves free when it starts,
while a bare factorisation outside the solver keeps the library's own default, and the ratio
of the two would move with the load the previous size left.

``--materials`` chooses the stiffness sets (``quasi-rigid``, ``compliant``: the sets of
``bench_solver.miura_scene``); ``--compliant-sizes`` the sizes of the compliant set (it is
slower). Per row also: Newton iterations per step, seconds per iteration, the *floor* (one
numeric refactorisation per step: ``steps`` x the median of three bare refactorisations of
the last tangent, ``bench_solver.bare_factorisation``), the fold's wall time over that floor,
the shares of factorisation, assembly and the rest in the solver's own clock, and the whole
process under ``/usr/bin/time -v`` (wall, user + system CPU, maximum resident set) where that
program exists.

A paragraph extrapolates a 10 M DOF sheet from the fitted exponents of the
measured refactorisation time and peak memory (stated as an estimate).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: the 10 M DOF sheet of the extrapolation paragraph
TEN_MILLION = 10_000_000
#: repetitions of the later assembly, refactorisation and solve of the large sheet (medians)
REPEATS = 3


def _peak_mb() -> float:
    """Peak resident memory of this process, MB (``ru_maxrss`` is in KB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _phase_peak_mb() -> float | None:
    """Peak resident memory since the last :func:`_reset_phase_peak` (``VmHWM``, MB); None
    where /proc does not give it."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def _reset_phase_peak() -> None:
    """Restart the count of :func:`_phase_peak_mb` (Linux: ``clear_refs`` 5)."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass


def one(n: int, steps: int, material: str) -> dict:
    """Fold the n x n sheet in this process; the figures of one row."""
    from bench_solver import bare_factorisation, miura_scene

    import barhinge as bh
    from barhinge.output.summary import iterate_text
    from barhinge.solver.state import IterationStatus

    t0 = time.perf_counter()
    sc = miura_scene(n, 0.0, steps, material=material)
    build = time.perf_counter() - t0
    c0, t0 = time.process_time(), time.perf_counter()

    def progress(done: int, total: int, value: float) -> None:
        # live per-step line on stderr: a long fold (the 200 x 200 sheet) shows where it is
        print(
            f"[n={n} {material}] step {done}/{total}  t={value:.3f}  "
            f"wall {time.perf_counter() - t0:.0f} s  CPU {time.process_time() - c0:.0f} s  "
            f"peak {_peak_mb():.0f} MB",
            file=sys.stderr,
            flush=True,
        )

    def iterate(status: IterationStatus) -> None:
        # the largest sheets take seconds per iterate: each one is shown as it goes
        print(
            f"[n={n} {material}] step {status.step}: {iterate_text(status)}  "
            f"wall {time.perf_counter() - t0:.0f} s",
            file=sys.stderr,
            flush=True,
        )

    path = bh.solve(sc, progress=progress, on_iteration=iterate if n >= 100 else None)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    fold_peak = _peak_mb()  # the fold's own, before the floor's factorisation adds its own
    tm = path.meta["timing"]
    its = int(path.meta["newton"]["total_iterations"])
    nf = int(tm["n_factorizations"])
    n_stab = int(path.meta["newton"]["total_inertia_factorizations"])
    mu = -np.asarray(path.actuator_moments[-1])  # multipliers of the last state
    refac, _ = bare_factorisation(sc, path.X[-1], mu, path.meta["linear_solver"], repeat=3)
    clock = tm["assembly"] + tm["factorize"] + tm["solve"] + tm["other"]
    solver_wall = max(clock, wall)
    return {
        "n": n,
        "material": material,
        "dof": int(sc.model.n_dof),
        "build": build,
        "wall": wall,
        "cpu": cpu,
        "iterations": its,
        "factorizations": nf,
        "stability_factorizations": n_stab,
        "s_per_iteration": wall / max(its, 1),
        "refactorisation": refac,
        "floor": steps * refac,
        "share_factorize": tm["factorize"] / solver_wall,
        "share_assembly": tm["assembly"] / solver_wall,
        "fold_peak_mb": fold_peak,
        "peak_mb": _peak_mb(),
        "steps": steps,
        # steps whose equilibrium no actuator holds (docs/solver.md, *Stability events*)
        "held_unstable": [
            i
            for i, c in enumerate(path.meta["negative_eigenvalues_held"])
            if c is not None and c > 0
        ],
    }


def _refactor_and_solve(sysm, K, terms, mu: np.ndarray) -> tuple[float, float]:
    """Medians of ``REPEATS`` numeric refactorisations of the bordered system ``sysm`` with
    the tangent ``K`` (its pattern analysed already) and of a bordered solve after each
    (seconds). Each factorisation releases the operator's values as the solver's do."""
    refact, solves = [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        sysm.set_operator(K, terms, mu, 1.0, factorize=True, release_values=True)
        refact.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        sysm.solve(np.ones(len(sysm.free_idx)), np.zeros(len(mu)))
        solves.append(time.perf_counter() - t0)
    return float(np.median(refact)), float(np.median(solves))


def pieces(n: int) -> dict:
    """Build, first assembly (peak memory after it), factorisations, bordered solves and the
    stability events' count of the released tangent at the flat state of the n x n sheet, in
    this process (later assemblies, refactorisations and solves: medians of ``REPEATS``)."""
    from bench_solver import miura_scene

    from barhinge.linalg.backends import get_backend
    from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms

    t0 = time.perf_counter()
    sc = miura_scene(n, 0.0, 50)
    build = time.perf_counter() - t0
    mem_build = _peak_mb()
    model = sc.model
    X = np.asarray(model.X0, float)
    t0 = time.perf_counter()
    ev = model.evaluate(X, tangent=True)
    assembly1 = time.perf_counter() - t0
    mem_assembly = _peak_mb()
    later = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        ev = model.evaluate(X, tangent=True)
        later.append(time.perf_counter() - t0)
    hinges = sc.actuator_hinges()
    terms = actuator_terms(model, X, hinges)
    free = ~sc.fixed.ravel()
    timer = Timer()
    sysm = BorderedSystem(get_backend("auto"), free, terms.dofs, timer)
    mu = np.zeros(len(hinges))
    t0 = time.perf_counter()
    sysm.set_operator(ev.K, terms, mu, 1.0, factorize=True)
    fact1 = time.perf_counter() - t0
    fact, solve = _refactor_and_solve(sysm, ev.K, terms, mu)
    peak_fact = _peak_mb()
    factor_bytes = getattr(sysm.backend, "factor_bytes", None)
    factor_mb = factor_bytes() / 2**20 if factor_bytes is not None else None
    # the stability events' counts of a state as a fold reads them after its last
    # factorisation (released: from the Schur complement PARDISO computed with it, or a
    # factorisation of the released tangent on the other routes)
    t0 = time.perf_counter()
    sysm.held_negative_eigenvalues()
    sysm.tangent_negative_eigenvalues()
    count = time.perf_counter() - t0
    schur = getattr(sysm.factor, "schur_complement", None)
    route = "schur" if schur is not None and schur() is not None else "released factor"
    peak_count = _peak_mb()
    # a Newton iteration as a fold makes it: the factorised tangent released (the solver
    # keeps only the factor), the next one assembled while the factor is held, then
    # refactorised; the peak through it alone (the process's peak through a fold's
    # iterations), where /proc gives it
    del ev  # the system released it with its last refactorisation
    _reset_phase_peak()
    ev_next = model.evaluate(X, tangent=True)
    sysm.set_operator(ev_next.K, terms, mu, 1.0, factorize=True, release_values=True)
    del ev_next
    peak_iteration = _phase_peak_mb() or _peak_mb()
    analysis_bytes = getattr(sysm.backend, "analysis_bytes", None)
    analysis_mb = analysis_bytes() / 2**20 if analysis_bytes is not None else None
    ev = model.evaluate(X, tangent=True)
    # what the Schur complement costs: the same bordered matrix refactorised augmented and
    # without it (the other routes' factorisation), after the first factor is freed
    plain_fact = plain_solve = None
    if route == "schur":
        getattr(sysm.backend, "release", lambda: None)()
        plain = BorderedSystem(get_backend("auto"), free, terms.dofs, Timer())
        plain._schur_counts = False
        plain.set_operator(ev.K, terms, mu, 1.0, factorize=True)  # with the ordering
        plain_fact, plain_solve = _refactor_and_solve(plain, ev.K, terms, mu)
    return {
        "n": n,
        "dof": int(model.n_dof),
        "build": build,
        "mem_build_mb": mem_build,
        "assembly_first": assembly1,
        "assembly": float(np.median(later)),
        "mem_assembly_mb": mem_assembly,
        "fact_first": fact1,
        "fact": fact,
        "solve": solve,
        "peak_mb": peak_fact,
        "count": count,
        "count_route": route,
        "peak_count_mb": peak_count,
        "peak_iteration_mb": peak_iteration,
        "fact_plain": plain_fact,
        "solve_plain": plain_solve,
        "n_act": len(hinges),
        "factor_mb": factor_mb,
        "analysis_mb": analysis_mb,
        "assembler_mb": model.assembler.nbytes / 2**20,
    }


def _time_v(stderr: str) -> dict:
    """Wall s, CPU s (user + system) and maximum resident set MB from ``time -v`` output."""

    def grab(label: str) -> str | None:
        m = re.search(rf"^\s*{re.escape(label)}: (.+)$", stderr, re.M)
        return m.group(1).strip() if m else None

    out: dict = {}
    user, system = grab("User time (seconds)"), grab("System time (seconds)")
    if user is not None and system is not None:
        out["process_cpu"] = float(user) + float(system)
    rss = grab("Maximum resident set size (kbytes)")
    if rss is not None:
        out["process_peak_mb"] = float(rss) / 1024.0
    wall = grab("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    if wall is not None:
        secs = 0.0
        for part in wall.split(":"):
            secs = 60.0 * secs + float(part)
        out["process_wall"] = secs
    return out


def _child(args: list[str], threads: int) -> dict:
    """Run one size in a fresh process (under ``time -v`` where it exists) with every
    library on ``threads`` threads, echoing its per-step progress lines live; its row, with
    the whole-process figures."""
    cmd = [sys.executable, __file__, *args]
    timer = shutil.which("time") or ("/usr/bin/time" if Path("/usr/bin/time").exists() else None)
    if timer is not None:
        cmd = [timer, "-v", *cmd]
    env = {**os.environ, "BARHINGE_THREADS": str(threads)}
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    assert proc.stderr is not None and proc.stdout is not None
    err = []
    for line in proc.stderr:
        err.append(line)
        if line.startswith("[n="):
            print(line, end="", file=sys.stderr, flush=True)
    out = proc.stdout.read()
    if proc.wait() != 0:
        # the child's own last words, without what ``time -v`` adds
        text = "".join(err).split("\tCommand being timed:")[0]
        own = [ln for ln in text.strip().splitlines() if not ln.startswith("Command ")]
        why = own[-1].strip() if own else "no message"
        code = proc.returncode
        signal = re.search(r"^Command terminated by signal (\d+)", text, re.M)
        if signal or code < 0:
            why = f"killed by signal {signal.group(1) if signal else -code}; {why}"
        raise RuntimeError(f"size run {' '.join(args)} failed (exit {code}): {why}")
    row = json.loads(out.strip().splitlines()[-1])
    row.update(_time_v("".join(err)) if timer is not None else {})
    return row


def _fit(rows: list[dict], key: str, xkey: str = "dof") -> float:
    """Least-squares slope of log(key) against log(xkey)."""
    x = np.log([r[xkey] for r in rows])
    return float(np.polyfit(x, np.log([r[key] for r in rows]), 1)[0])


def _fmt(r: dict, key: str, spec: str) -> str:
    return format(r[key], spec) if key in r else "–"


def fold_table(rows: list[dict], steps: int) -> list[str]:
    """Markdown rows of the full folds, both stiffness sets."""
    lines = [
        f"### Miura n x n folds, flat -> 60 deg in {steps} steps",
        "",
        _threads_line(rows),
        "",
        "| n | stiffness set | DOF | iterations / step | factorisations: all (of them for "
        "the stability events) | floor: one "
        "refactorisation per step, s | fold wall s | wall / floor | s / iteration | shares: "
        "factorisation / assembly / rest | fold CPU s | whole process: wall s / CPU s / max "
        "RSS MB | KB / DOF (the fold's peak) | steps unstable with the actuators held |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        rest = 1.0 - r["share_factorize"] - r["share_assembly"]
        lines.append(
            f"| {r['n']} | {r['material']} | {r['dof']} | {r['iterations'] / r['steps']:.2f} "
            f"| {r['factorizations']} ({_fmt(r, 'stability_factorizations', 'd')}) "
            f"| {r['floor']:.1f} | {r['wall']:.1f} "
            f"| {r['wall'] / r['floor']:.2f} | {r['s_per_iteration']:.3f} "
            f"| {r['share_factorize']:.0%} / {r['share_assembly']:.0%} / {rest:.0%} "
            f"| {r['cpu']:.1f} | {_fmt(r, 'process_wall', '.1f')} / "
            f"{_fmt(r, 'process_cpu', '.1f')} / {_fmt(r, 'process_peak_mb', '.0f')} "
            f"| {1024 * r['fold_peak_mb'] / r['dof']:.1f} "
            f"| {_steps(r.get('held_unstable'))} |"
        )
    return lines


def _threads_line(rows: list[dict]) -> str:
    """The thread count the rows ran on (``--threads``), fold and floor alike."""
    counts = sorted({str(r.get("threads", "-")) for r in rows})
    if len(counts) == 1:
        return (
            f"MKL (PARDISO) and the element kernels' worker threads ran on {counts[0]} "
            f"thread(s) (`BARHINGE_THREADS={counts[0]}`), in the fold and in its floor alike."
        )
    per = ", ".join(f"n = {r['n']} {r['material']}: {r.get('threads', '-')}" for r in rows)
    return (
        f"Threads of MKL and the worker threads (`BARHINGE_THREADS`), fold and floor alike: {per}."
    )


def source_commit() -> str:
    """The barhinge commit this script folds with (``git rev-parse --short HEAD`` of the
    package's checkout, ``+`` where it has uncommitted changes), ``unknown`` outside git."""
    import barhinge

    where = str(Path(barhinge.__file__).resolve().parent)
    try:
        head = subprocess.run(
            ["git", "-C", where, "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", where, "status", "--porcelain", "--", where],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+" if dirty else "")


def commit_lines(rows: list[dict], commit: str) -> list[str]:
    """A line naming the rows kept from another commit than ``commit`` (``--rows``)."""
    older = [r for r in rows if r.get("commit") != commit]
    if not older:
        return []
    named = "; ".join(
        f"n = {r['n']} ({r['material']}) at commit {r.get('commit', 'unknown')}" for r in older
    )
    return [
        "",
        f"Rows kept from an earlier run (`--rows`): {named}. The other rows were folded at "
        f"commit {commit}.",
    ]


def _steps(steps: list[int] | None) -> str:
    """Step numbers as runs ("1-3, 8"); "none" for an empty list, "-" when not measured."""
    if steps is None:
        return "-"
    if not steps:
        return "none"
    runs: list[list[int]] = []
    for i in steps:
        if runs and i == runs[-1][-1] + 1:
            runs[-1].append(i)
        else:
            runs.append([i])
    return ", ".join(f"{r[0]}" if len(r) == 1 else f"{r[0]}-{r[-1]}" for r in runs)


def stability_lines(rows: list[dict]) -> list[str]:
    """Where the factorisations of the largest fold of each stiffness set go: Newton's, and
    those made only to confirm a stability count at a state (docs/solver.md, *Stability
    events*)."""
    out = []
    for mat in dict.fromkeys(r["material"] for r in rows):
        r = max((r for r in rows if r["material"] == mat), key=lambda r: r["dof"])
        if "stability_factorizations" not in r:
            continue
        n_stab, nf, steps = r["stability_factorizations"], r["factorizations"], r["steps"]
        out.append(
            f"- {mat}, n = {r['n']}: {nf} factorisations, {nf - n_stab} of them Newton's "
            f"({(nf - n_stab) / steps:.2f} per step against the floor's 1) and {n_stab} made "
            "only to confirm a stability count at a state."
        )
    if not out:
        return []
    return [
        "",
        "Factorisations of the largest folds (the stability counts of a state, actuators "
        "released and held, come with Newton's last factorisation; one that changed from the "
        "previous state's is confirmed by a factorisation at the state):",
        "",
        *out,
    ]


def held_lines(rows: list[dict]) -> list[str]:
    """Which folds pass through equilibria that no actuator holds (the event ``unstable
    equilibrium with the actuators held``, docs/solver.md, *Stability events*)."""
    bad = [r for r in rows if r.get("held_unstable")]
    if not bad:
        return []
    out = [
        f"n = {r['n']} ({r['material']}): step(s) {_steps(r['held_unstable'])} of "
        f"{r['steps']} ({60.0 * r['held_unstable'][0] / r['steps']:.1f}"
        + (
            f"-{60.0 * r['held_unstable'][-1] / r['steps']:.1f} deg)"
            if len(r["held_unstable"]) > 1
            else " deg)"
        )
        for r in bad
    ]
    return [
        "",
        "Equilibria no actuator holds: at these steps the fold from flat, driven by one "
        "line of creases, converges to states whose tangent with the actuators held has "
        "negative eigenvalues (a real sheet would leave them; the fold reports the event): "
        + "; ".join(out)
        + ". The table times these folds as they run; the states are flagged, not avoided.",
    ]


def exponent_lines(rows: list[dict]) -> list[str]:
    """Fitted exponents per stiffness set (at least two sizes)."""
    out = []
    for mat in dict.fromkeys(r["material"] for r in rows):
        sub = [r for r in rows if r["material"] == mat]
        if len(sub) < 2:
            continue
        out.append(
            f"- {mat}, n = {', '.join(str(r['n']) for r in sub)}: fold wall time ~ "
            f"DOF^{_fit(sub, 'wall'):.2f}; refactorisation ~ "
            f"DOF^{_fit(sub, 'refactorisation'):.2f}; "
            f"iterations per step ~ DOF^{_fit(sub, 'iterations'):.2f}."
        )
    return ["", "Fitted exponents (least squares on log-log axes):", "", *out] if out else []


def pieces_lines(r: dict, rows: list[dict], steps: int) -> list[str]:
    """The measured pieces of the large sheet and the extrapolated full fold."""
    lines = [
        "",
        f"### n = {r['n']}: measured pieces ({r['dof']} DOF)",
        "| piece | s | peak memory after it, MB |",
        "|---|---|---|",
        f"| model build | {r['build']:.1f} | {r['mem_build_mb']:.0f} |",
        f"| first assembly (tangent) | {r['assembly_first']:.1f} | {r['mem_assembly_mb']:.0f} |",
        f"| later assembly (median of {REPEATS}) | {r['assembly']:.1f} | |",
        f"| first factorisation (with ordering) | {r['fact_first']:.1f} | |",
        f"| refactorisation (median of {REPEATS}) | {r['fact']:.1f} | {r['peak_mb']:.0f} |",
        f"| bordered solve (median of {REPEATS}) | {r['solve']:.2f} | |",
    ]
    if r.get("count") is not None:
        how = (
            "the released one from the Schur complement of the refactorisation"
            if r.get("count_route") == "schur"
            else "the released tangent factorised"
        )
        lines += [
            f"| stability counts of a state, held and released ({how}) | {r['count']:.2f} "
            f"| {r['peak_count_mb']:.0f} |",
        ]
    if r.get("peak_iteration_mb") is not None:
        lines += [
            "| the next assembly and refactorisation, the factor held meanwhile (a Newton "
            f"iteration; the peak through it) | | {r['peak_iteration_mb']:.0f} |",
        ]
    if r.get("fact_plain") is not None:
        lines += [
            "| refactorisation without the Schur complement (augmented bordered matrix, "
            f"median of {REPEATS}) | {r['fact_plain']:.1f} | |",
            f"| its bordered solve (median of {REPEATS}) | {r['solve_plain']:.2f} | |",
        ]
    iteration = r["assembly"] + r["fact"] + r["solve"]
    lines += [
        "",
        f"A Newton iteration (assembly + refactorisation + solve) takes {iteration:.1f} s, of "
        f"which the assembly is {100 * r['assembly'] / iteration:.0f} %.",
    ]
    if r.get("factor_mb"):
        lines += [
            "",
            f"Memory: the factor takes {r['factor_mb']:.0f} MB (PARDISO's own count, "
            f"iparm(17)), the assembler's index maps and pattern {r.get('assembler_mb', 0):.0f}"
            f" MB; the process's peak after the refactorisation is "
            f"{r['peak_mb'] / r['factor_mb']:.1f} times the factor.",
        ]
        if r.get("peak_iteration_mb") is not None:
            lines[-1] += (
                " Through a Newton iteration, whose assembly runs while the factor is held "
                "(the last tangent released once it is factorised), it is "
                f"{r['peak_iteration_mb'] / r['factor_mb']:.2f} times the factor."
            )
            if r.get("analysis_mb"):
                whole = r["factor_mb"] + r["analysis_mb"]
                lines[-1] += (
                    f" PARDISO keeps its ordering and symbolic analysis beside the factor "
                    f"({r['analysis_mb']:.0f} MB, iparm(16)): against all of PARDISO's "
                    f"memory ({whole:.0f} MB) that peak is {r['peak_iteration_mb'] / whole:.2f}"
                    " times."
                )
        if r.get("count_route") == "schur":
            lines[-1] += (
                " The stability counts read the Schur complement the refactorisation "
                "computed (docs/solver.md, *Stability events*): no second factor."
            )
    if r.get("fact_plain"):
        lines += [
            "",
            f"The Schur complement of the {r.get('n_act', '')} actuator multipliers makes the "
            f"refactorisation {100 * (r['fact'] / r['fact_plain'] - 1):+.0f} % and the solve "
            f"{100 * (r['solve'] / r['solve_plain'] - 1):+.0f} % against the same matrix "
            "factorised without it; without it, each state's released count would cost a "
            "factorisation of its own.",
        ]
    quasi = [q for q in rows if q["material"] == "quasi-rigid"]
    if any(q["n"] == r["n"] for q in quasi):
        lines += ["", "The full fold of this sheet is measured in the table above."]
    elif quasi:
        last = quasi[-1]
        per_it = r["assembly"] + r["fact"] + r["solve"]
        est = per_it * last["factorizations"]
        floor = steps * r["fact"]
        counts = ", ".join(str(q["factorizations"]) for q in quasi)
        lines += [
            "",
            f"Extrapolated, not measured: a full {steps}-step fold at n = {r['n']} with the "
            f"{last['factorizations']} factorisations of the n = {last['n']} fold, each costing "
            f"one assembly + refactorisation + solve as measured here ({per_it:.1f} s), would "
            f"take about {est / 60:.0f} min; its floor (one refactorisation per step) is "
            f"{floor / 60:.0f} min. The count grows with the size ({counts} factorisations "
            f"for n = {', '.join(str(q['n']) for q in quasi)}), so this is a lower estimate.",
        ]
    return lines


def ten_million_lines(
    big: dict | None, rows: list[dict], steps: int, kept: frozenset[int] = frozenset()
) -> list[str]:
    """Extrapolate refactorisation time and memory to 10 M DOF from the largest measured sizes:
    the refactorisation from the full folds and, where given, the measured pieces of a larger
    sheet; the memory from the full folds' own peaks only (a Newton iteration's pieces peak
    lower than a whole fold, which also holds its path and its stability counts).

    The refactorisation's exponent compares timings of this run only (``kept``: the sizes
    whose rows were kept from an earlier run, ``--rows``): the machine's speed moves from day
    to day, and a kept row's floor against a fresh one would move the exponent with it. The
    pieces of a sheet (measured in this run) stand in for its kept full fold."""
    quasi = [q for q in rows if q["material"] == "quasi-rigid"]
    if len(quasi) < 2:
        return []
    fresh = {q["dof"]: q["refactorisation"] for q in quasi if q["n"] not in kept}
    if big is not None:
        fresh.setdefault(big["dof"], big["fact"])
    same_run = len(fresh) >= 2
    if same_run:
        times = sorted(fresh.items())
    else:  # too few fresh timings: every row, whatever its run
        times = sorted({q["dof"]: q["refactorisation"] for q in quasi}.items())
    (d0, f0), (d1, f1) = times[-2:]  # the two largest sheets
    # memory above the libraries' own (the smallest sheet's fold) scales with the sheet
    base = min(q["fold_peak_mb"] for q in quasi)
    (e0, m0), (e1, m1) = sorted((q["dof"], q["fold_peak_mb"]) for q in quasi)[-2:]
    pf = float(np.log(f1 / f0) / np.log(d1 / d0))
    pm = float(np.log((m1 - base) / max(m0 - base, 1.0)) / np.log(e1 / e0))
    fact10 = f1 * (TEN_MILLION / d1) ** pf
    mem10 = base + (m1 - base) * (TEN_MILLION / e1) ** pm
    cells = int(round(np.sqrt(TEN_MILLION / 24.0), -1))  # N5B8 Miura: about 24 n^2 DOF
    ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**20
    # an extrapolation from two sheets is rough: "fits" only with a fifth of the memory spare
    if mem10 < 0.8 * ram:
        fits = f"That fits in this machine's {ram / 1024:.1f} GB"
    elif mem10 < ram:
        fits = (
            f"That is at the limit of this machine's {ram / 1024:.1f} GB (the estimate "
            "leaves less than a fifth of it spare)"
        )
    else:
        fits = f"That is beyond this machine's {ram / 1024:.1f} GB"
    needs = "it" if mem10 >= ram else "a larger sheet"
    return [
        "",
        "### A 10 M DOF sheet (estimate)",
        "",
        f"Extrapolated from the largest sheets measured above: the refactorisation grows like "
        f"DOF^{pf:.2f} (from {d0} to {d1} DOF, "
        f"{'both timed in this run' if same_run else 'timed in different runs'}) and a "
        f"fold's peak memory above the libraries' "
        f"{base:.0f} MB like DOF^{pm:.2f} (the full folds of {e0} and {e1} DOF). A sheet of "
        f"10 M DOF (a Miura of about "
        f"{cells} x {cells} cells) would need about {mem10 / 1024:.1f} GB and "
        f"{fact10 / 60:.0f} min per refactorisation, so {steps * fact10 / 3600:.1f} h for the "
        f"floor of a {steps}-step fold on one node of this kind. {fits}; {needs} needs "
        "a node with more memory (MKL PARDISO also factorises out of core), or a distributed "
        "direct solver (MUMPS or SuperLU_DIST through PETSc, which split the factor over MPI "
        "ranks), or an iterative solver preconditioned by domain decomposition. The points of a "
        "study are independent and already run on a Dask cluster (docs/sweeps.md); a single "
        "10 M DOF "
        "fold is the case that needs the distributed factorisation.",
    ]


#: what a kept row must hold to be published (rows of older versions of this script are
#: folded again)
ROW_KEYS = frozenset({"fold_peak_mb", "threads", "commit"})


def _row_complete(row: dict) -> bool:
    return ROW_KEYS <= set(row)


def _row_key(n: int, material: str, steps: int) -> str:
    return f"{material}:{n}:{steps}"


def _load_rows(path: str | None) -> dict:
    """The rows kept in ``path`` (``--rows``); empty when there is none yet."""
    if path is None or not Path(path).exists():
        return {}
    try:
        kept = json.loads(Path(path).read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise SystemExit(f"--rows {path}: not a rows file of this script ({exc})") from None
    if not isinstance(kept, dict):
        raise SystemExit(f"--rows {path}: not a rows file of this script")
    return kept


def _keep_row(path: str | None, kept: dict, key: str, row: dict) -> None:
    """Add ``row`` to the rows file (written whole, through a temporary file)."""
    if path is None:
        return
    kept[key] = row
    tmp = Path(f"{path}.tmp")
    tmp.write_text(json.dumps(kept, indent=1), encoding="utf-8")
    os.replace(tmp, path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[10, 20, 40, 70])
    ap.add_argument("--compliant-sizes", type=int, nargs="*", default=[10, 20, 40])
    ap.add_argument(
        "--materials",
        nargs="*",
        default=["quasi-rigid", "compliant"],
        choices=["quasi-rigid", "compliant"],
    )
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--pieces", type=int, nargs="*", default=[])
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--material", default="quasi-rigid", help=argparse.SUPPRESS)
    ap.add_argument("--one-pieces", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--rows", help="JSON file keeping every finished size's row (resumes)")
    ap.add_argument("--fresh", action="store_true", help="fold sizes kept in --rows again")
    ap.add_argument("--publish", action="store_true", help="write into docs/")
    ap.add_argument(
        "--threads",
        type=int,
        default=None,
        help="threads of MKL and the worker threads in each size's process (default: cores)",
    )
    a = ap.parse_args()
    if a.one is not None or a.one_pieces is not None:
        from barhinge.linalg.threads import policy, sparse_solves

        # the fixed count of the parent's BARHINGE_THREADS, for the fold's factorisations
        # and the floor's alike
        with sparse_solves():
            row = one(a.one, a.steps, a.material) if a.one is not None else pieces(a.one_pieces)
        row["threads"] = policy()
        print(json.dumps(row))
        return
    threads_given = a.threads
    if a.threads is None:
        from barhinge.linalg.threads import cores

        a.threads = cores()
    if a.threads < 1:
        raise SystemExit(f"--threads {a.threads}: expected a whole number >= 1")

    rows, failed = [], []
    commit = source_commit()
    kept = _load_rows(a.rows)
    kept_sizes: set[int] = set()  # quasi-rigid sizes whose rows were kept, not folded now
    for mat in a.materials:
        for n in a.sizes if mat == "quasi-rigid" else a.compliant_sizes:
            key = _row_key(n, mat, a.steps)
            if key in kept and not a.fresh and _row_complete(kept[key]):
                rows.append(kept[key])
                if mat == "quasi-rigid":
                    kept_sizes.add(n)
                print(f"n = {n}, {mat}: row kept in {a.rows}", file=sys.stderr, flush=True)
                continue
            if key in kept and not a.fresh:
                print(
                    f"n = {n}, {mat}: the row kept in {a.rows} is from an older version of "
                    "this script: folded again",
                    file=sys.stderr,
                    flush=True,
                )
            try:
                row = _child(
                    ["--one", str(n), "--steps", str(a.steps), "--material", mat], a.threads
                )
            except RuntimeError as exc:  # the other sizes still run and are published
                print(f"error: n = {n}, {mat}: {exc}", file=sys.stderr, flush=True)
                failed.append(f"n = {n}, {mat}: {exc}")
                continue
            row["commit"] = commit
            rows.append(row)
            _keep_row(a.rows, kept, key, row)
            print(fold_table(rows, a.steps)[-1], flush=True)
    lines = fold_table(rows, a.steps) + commit_lines(rows, commit)
    lines += held_lines(rows) + stability_lines(rows)
    lines += exponent_lines(rows)
    lines += [f"\n**Not completed**: {f}" for f in failed]
    for n in a.pieces:
        big = _child(["--one-pieces", str(n)], a.threads)
        lines += pieces_lines(big, rows, a.steps)
        lines += ten_million_lines(big, rows, a.steps, frozenset(kept_sizes))
    if not a.pieces:
        lines += ten_million_lines(None, rows, a.steps, frozenset(kept_sizes))
    print("\n".join(lines), flush=True)
    if a.publish:
        from barhinge._publish import generated_stamp, write_between

        cmd = "python benchmarks/scaling.py --publish"
        if a.sizes != [10, 20, 40, 70]:
            cmd += " --sizes " + " ".join(map(str, a.sizes))
        if a.materials != ["quasi-rigid", "compliant"]:
            cmd += " --materials " + " ".join(a.materials)
        elif a.compliant_sizes != [10, 20, 40]:
            cmd += " --compliant-sizes " + " ".join(map(str, a.compliant_sizes))
        if a.pieces:
            cmd += " --pieces " + " ".join(map(str, a.pieces))
        if threads_given is not None:
            cmd += f" --threads {threads_given}"
        doc = HERE.parent / "docs" / "solver-performance.md"
        body = "\n".join([generated_stamp(cmd), "", *lines])
        write_between(doc, "<!-- scaling:start -->", "<!-- scaling:end -->", body)
    if failed:
        sys.exit(f"error: {len(failed)} size(s) did not complete (see above)")


if __name__ == "__main__":
    main()
