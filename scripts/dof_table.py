"""Run ``barhinge dof --json`` on every crease pattern kept with the tests and on generated
patterns that stress the method; print the table and, with ``--publish``, write it into
docs/kinematics.md between the ``dof-real:start`` / ``dof-real:end`` markers.

Usage: python scripts/dof_table.py [--publish] [--timeout 60]

Also every FOLD file of the pattern catalogue (data/patterns).

Each pattern runs in its own process, as a user would run it (wall time includes Python's
start-up and the import of barhinge). Real patterns: tests/data/crease-patterns (Origami
Simulator and the FOLD specification's examples). Stress patterns (written to a temporary
folder as FOLD files): Miura 35 x 35 (9 660 creases, 4 761 interior vertices, thousands of
redundant vertex equations), Miura 30 x 30 with three panels removed (holes), a Yoshimura
sheet with every other crease unassigned (U), and the hypar with its panels triangulated.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from barhinge._publish import write_between

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "crease-patterns"
CATALOGUE = ROOT / "data" / "patterns"
DOC = ROOT / "docs" / "kinematics.md"
START, END = "<!-- dof-real:start -->", "<!-- dof-real:end -->"


def stress_patterns(folder: Path) -> list[tuple[str, list[str]]]:
    """(label, CLI arguments) of the generated stress patterns (FOLD files in ``folder``)."""
    import barhinge as bh
    from barhinge.pattern.fold import write_fold

    out = [("Miura 35 × 35 (generated)", ["miura:nx=35,ny=35"])]
    cp = bh.families.miura(30, 30)
    drop = {cp.n_faces // 4 + 7, cp.n_faces // 2 + 31, 3 * cp.n_faces // 4 + 11}
    faces = [f for i, f in enumerate(cp.faces) if i not in drop]
    asg = cp.assignment.copy()
    holed = bh.CreasePattern(
        cp.vertices, cp.edges, asg, cp.fold_angles, faces=faces, validate=False
    )
    asg[(holed.edge_faces < 0).any(1)] = "B"  # the edges around a hole are boundary
    holed = bh.CreasePattern(cp.vertices, cp.edges, asg, cp.fold_angles, faces=faces)
    write_fold(holed, folder / "miura30_3holes.fold")
    out.append(
        ("Miura 30 × 30, 3 panels removed (generated)", [str(folder / "miura30_3holes.fold")])
    )
    y = bh.families.FAMILIES["yoshimura"](nx=12, ny=12)
    asg = y.assignment.copy()
    mv = np.flatnonzero(np.isin(asg, ["M", "V"]))
    asg[mv[::2]] = "U"
    yu = bh.CreasePattern(y.vertices, y.edges, asg, np.where(asg == "U", 0.0, y.fold_angles))
    write_fold(yu, folder / "yoshimura12_half_U.fold")
    out.append(("Yoshimura 12 × 12, half the creases U (generated)",
                [str(folder / "yoshimura12_half_U.fold")]))  # fmt: skip
    hyp = DATA / "origami-simulator" / "hypar.svg"
    out.append(("hypar.svg --triangulated", [str(hyp), "--triangulated"]))
    return out


def run(args: list[str], timeout: float) -> dict:
    """One ``barhinge dof --json`` run: exit code, wall time, the JSON or the error line."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-c", "import sys; from barhinge.cli import main; main(sys.argv[1:])",
           "dof", "--json", *args]  # fmt: skip
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return {
            "rc": None,
            "s": time.perf_counter() - t0,
            "error": f"still running at {timeout:g} s",
        }
    s = time.perf_counter() - t0
    if p.returncode != 0:
        err = (p.stderr.strip().splitlines() or ["(no message)"])[-1]
        return {"rc": p.returncode, "s": s, "error": err, "lines": len(p.stderr.splitlines())}
    return {"rc": 0, "s": s, "data": json.loads(p.stdout)}


def _short(note: str) -> str:
    """The reason no folded state was found, in a few words."""
    if "collapses to the flat" in note:
        return "none: not rigidly foldable (rigid panels)"
    m = re.search(
        r"no rigidly folded state found near the flat one \(closure error ([^)]*)\)", note
    )
    if m:
        return f"none found (closure {m.group(1)})"
    if "no assignment" in note:
        return "none: no M/V assignment"
    return "none"


def cells(label: str, r: dict) -> list[str]:
    if r["rc"] != 0:
        code = "timeout" if r["rc"] is None else str(r["rc"])
        return [label, "–", "–", "–", "–", "–", code, f"{r['s']:.1f}", r["error"]]
    d = r["data"]
    st = d["state"]
    fo = d.get("folded_state")
    m = fo if fo is not None else st

    def doubt(x: dict) -> str:
        g = x["gap_ratio"]
        txt = "∞" if g is None else f"{g:.0e}"
        if not x["certain"]:
            lo, hi = x["dof_range"]
            txt += f" UNCERTAIN {lo}–{hi}"
        return txt

    holes = re.search(r"has (\d+) hole", st["note"])
    if st["flat"] and fo is None:
        folded = _short(st["note"])
    elif fo is None:
        folded = "(folded input)"
    else:
        folded = str(fo["global_dof"])
    extra = [f"{holes.group(1)} hole(s)"] if holes else []
    poly = re.search(r"(\d+) non-triangular panel", st["note"])
    if poly:
        extra.append(f"{poly.group(1)} non-triangular panels held rigid")
    if "disagrees with the M/V assignment" in (fo or {}).get("note", ""):
        extra.append("folded state against some M/V")
    return [label, str(st["n_variables"]), str(st["counted_dof"]), str(st["global_dof"]),
            folded, doubt(m), "0", f"{r['s']:.1f}", "; ".join(extra)]  # fmt: skip


def table(rows: list[list[str]]) -> str:
    head = ["pattern", "creases", "count", "DOF (this state)", "DOF (folded nearby)",
            "gap ratio", "exit", "s", "remark"]  # fmt: skip
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--publish", action="store_true", help="rewrite docs/kinematics.md")
    ap.add_argument("--timeout", type=float, default=60.0)
    a = ap.parse_args()
    files = sorted(p for p in DATA.rglob("*") if p.suffix.lower() in (".fold", ".svg"))
    cat = sorted(CATALOGUE.glob("*.fold"))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        todo = [(str(p.relative_to(DATA)), [str(p)]) for p in files]
        todo += [(f"catalogue {p.name}", [str(p)]) for p in cat]
        todo += stress_patterns(Path(tmp))
        for label, args in todo:
            r = run(args, a.timeout)
            rows.append(cells(label, r))
            print("| " + " | ".join(rows[-1]) + " |", flush=True)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    worst = max(float(r[7]) for r in rows)
    failed = sum(r[6] not in ("0", "2") for r in rows)
    text = (
        f"{table(rows)}\n\n{len(rows)} patterns; the slowest took {worst:.1f} s; "
        f"{failed} ended other than with a report (exit 0) or a one-line input error "
        f"(exit 2). Load average when the run ended: {load:.1f} on {os.cpu_count()} cores.\n"
    )
    print()
    print(text)
    if a.publish:
        write_between(DOC, START, END, text)
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
