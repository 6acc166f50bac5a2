"""Every roof of the comparison refined until its stiffness changes by less than 2 %.

For each roof of ``roofs.FAMILIES`` (every fold state of the comparison table) the
bar-and-hinge model with every panel cut into ``m x m`` sub-panels
(:func:`roofs.subdivided_roof`, the ``coupled`` plate rule, which converges to the Kirchhoff
plate: docs/calibration.md, *Refined panels*) at m = 1, 2, 4, ...:

* the linear stiffness ``k = Q_t^2 / (f . u)`` under the uniform load (as in the comparison
  table) and ``k / width`` (width = plan area / span), with the equilibrium residual of the
  solve (``|sum of reactions + loads| / |loads|``);
* the first linear buckling factor under the design load (uniform load plus self-weight,
  :func:`barhinge.analysis.buckling.linear_buckling`).

A roof is *refined* at the first level whose stiffness differs from the previous level's by
less than ``TOL`` in the sequence's asymptotic range (the change of the same sign as the one
before and smaller, :func:`roofs.settled`: a sequence that turns can pass through a small
change by chance). Refinement stops there, or before a level whose model would exceed
``DOF_BUDGET`` DOFs (counted without building it, :func:`roofs.refinement_dofs`);
a roof stopped by the budget is reported as not refined, with the Richardson limit of its
last three levels and that extrapolation's correction as its uncertainty
(:func:`barhinge.analysis.accuracy.richardson`).

Every roof also gets the nonlinear check on refined panels (``NONLINEAR_LEVELS``, m = 4
and 8: arc length under the design load to load factor 1, stopped at the first limit point or
the first loss of stability, :func:`roofs.nonlinear_check`), beside the comparison table's
one-facet check (docs/roofs.csv, which ``run.py`` writes). The ranking written with the table
uses the refined stiffness and buckling factor and the finest nonlinear check.

Run: ``python studies/roofs/refine.py [--quick] [--publish] [--cache=FILE]
[--only=FAMILY,...] [--no-second-look] [--grading=P]`` (``--grading``: the sub-panels of
parallelogram panels whose creases meet at an angle crowded towards their corners, ``p >= 1``,
default 2,
as the shell reference's facet meshes, :func:`grading_of`; ``--only``
computes those families' roofs into the cache and publishes nothing: two such runs with their
own caches use two cores;
``--no-second-look`` runs no check again from the finer increment). Every level
is written to the cache as soon as it is computed (default ``refine_cache.json`` beside this
file, not versioned), so an interrupted run resumes where it stopped and ``--publish``
re-derives the page from it. Importing the module runs the quick mode (two roofs, up to
16 000 DOFs, nothing written); results at module level: ``RESULTS``.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import roofs  # noqa: E402

MAIN = __name__ == "__main__"
if MAIN:  # a mistyped option or --help must not start the full run
    from barhinge._study_args import check_study_argv

    check_study_argv(
        __doc__,
        flags=("--quick", "--publish", "--no-second-look"),
        valued=("--cache", "--only", "--grading"),
    )
QUICK = not MAIN or "--quick" in sys.argv
PUBLISH = MAIN and "--publish" in sys.argv and not QUICK
ROOT = HERE.parents[1]
DOC = ROOT / "docs" / "roofs.md"
CSV_MAIN = ROOT / "docs" / "roofs.csv"
CSV_OUT = ROOT / "docs" / "roofs_refined.csv"
CSV_NONLINEAR = ROOT / "docs" / "roofs_refined_nonlinear.csv"
#: the imperfect roofs' checks (written by studies/roofs/imperfection.py from CSV_NONLINEAR)
CSV_IMPERFECT = ROOT / "docs" / "roofs_imperfect.csv"
START, END = "<!-- roofs-refined:start -->", "<!-- roofs-refined:end -->"

#: refined when the stiffness changes by less than this between two levels (relative)
TOL = roofs.REFINE_TOL
#: the bending rule of the refinement
RULE = "coupled"
#: its membrane (``bar_calibration``): cached levels of another membrane are recomputed
MEMBRANE = roofs.BENDING_RULES[RULE].get("bar_calibration", "fit")
#: sub-panels crowded towards the panels' corners (``--grading=P``, default 2, the published
#: study; 1: equal sub-panels;
#: :func:`barhinge.pattern.subdivide.subdivided`), on roofs of parallelogram panels whose
#: creases meet at an angle (the others are cut equally, :func:`grading_of`); cached levels
#: of another grading are
#: recomputed
GRADING = float(next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--grading=")), 2))


def grading_of(cp) -> float:
    """The grading of a roof's sub-panels in this study (:func:`roofs.grading_of` with
    ``GRADING``): the linear levels, the nonlinear checks and the imperfect roofs of
    imperfection.py cut the panels alike."""
    return roofs.grading_of(cp, GRADING)


crease_corners = roofs.crease_corners


#: no level above this many DOFs is run
DOF_BUDGET = 16_000 if QUICK else roofs.REFINE_STUDY_DOF_BUDGET
#: sub-panels per panel side, tried in order
LEVELS = (1, 2, 4, 8, 16, 32, 64, 128)
#: the nonlinear check (:func:`roofs.nonlinear_check`, arc length to the design load or the
#: first limit point) on the refined panels: at these levels, the last one reported and the
#: change from the one before as its refinement error
NONLINEAR_LEVELS = (2, 4) if QUICK else (4, 8)
#: first arc-length increment of every nonlinear check (1 / NONLINEAR_STEPS of the design
#: load), and of the second look at a check that loses stability (a coarse increment can step
#: from a stable state past the first critical point; the finer path is the one reported,
#: with the coarse path's critical load factor beside it)
NONLINEAR_STEPS, FINE_STEPS = 10, 40
#: ``--no-second-look``: publish the cached checks as they are (no check is run again)
SECOND_LOOK = "--no-second-look" not in sys.argv
#: the shell reference of every roof (:func:`roofs.shell_reference`, facet meshes graded
#: towards the corners): these levels, then further until its Richardson estimate settles or
#: the next level would exceed ``SHELL_DOF_BUDGET`` DOFs
SHELL_LEVELS = (2, 3, 4) if QUICK else roofs.SHELL_LEVELS
SHELL_DOF_BUDGET = 60_000 if QUICK else roofs.SHELL_DOF_BUDGET
#: a shell reference counts when it is settled to within this (relative uncertainty)
SHELL_TOL = 0.05

if QUICK:
    ROOFS: list[tuple[str, float]] = [("pleats", 90.0), ("yoshimura", 20.0)]
else:
    ROOFS = [(f, float(s)) for f, spec in roofs.FAMILIES.items() for s in spec["states"]]
_only = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--only=")), None)
if _only:  # ``--only=FAMILY,...``: those families (to split a run; nothing is published)
    ROOFS = [(f, s) for f, s in ROOFS if f in _only.split(",")]
    PUBLISH = False

_cache_arg = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--cache=")), None)
#: where the levels are kept (the quick mode keeps them in memory unless ``--cache`` is given)
CACHE: Path | None = (
    Path(_cache_arg) if _cache_arg else None if QUICK else HERE / "refine_cache.json"
)


def level(cp, sv: np.ndarray, se: np.ndarray, m: int) -> dict[str, Any]:
    """One refinement level of a roof: stiffness, buckling factor, DOFs, wall time."""
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.analysis.stiffness import linear_response
    from barhinge.errors import BarhingeError
    from barhinge.scene import self_weight

    t0 = time.perf_counter()
    model, S, residual = roofs.subdivided_roof(cp, sv, se, m, RULE, grading=grading_of(cp))
    Fq = roofs.plan_load(model, roofs.Q)
    U, R = linear_response(model, Fq, S)
    Qt = float(-Fq[:, 2].sum())
    eq = float(np.linalg.norm(R.sum(0) + Fq.sum(0)) / np.linalg.norm(Fq.sum(0)))
    t1 = time.perf_counter()
    P = Fq + self_weight(model, roofs.DENSITY * roofs.MATERIAL["t"], g=(0.0, 0.0, -roofs.G))
    try:
        lam, why = float(linear_buckling(model, P, S, n_modes=1).factors[0]), ""
    except BarhingeError as exc:
        lam, why = float("nan"), str(exc).splitlines()[0]
    return {
        "m": m,
        "membrane": MEMBRANE,
        "grading": grading_of(cp),
        "n_dof": 3 * model.n_nodes,
        "stiffness": Qt**2 / float(np.sum(Fq * U)),
        "plan_area": Qt / roofs.Q,
        "equilibrium_error": eq,
        "buckling_factor": lam,
        "buckling_error": why,
        "patch_residual": residual,
        "time_linear_s": t1 - t0,
        "time_s": time.perf_counter() - t0,
    }


def nonlinear_level(
    cp,
    sv: np.ndarray,
    se: np.ndarray,
    m: int,
    keep_path: bool = False,
    steps: int = NONLINEAR_STEPS,
) -> dict[str, Any]:
    """The nonlinear check of a roof with every panel cut into ``m x m`` sub-panels (graded
    as the linear levels, :func:`grading_of`), under
    the design load (uniform load plus self-weight): :func:`roofs.nonlinear_check`, stopped
    at the first loss of stability, first increment ``1 / steps`` of the load (recorded as
    ``first_increment``); beside it ``deflection_linear``, the largest deflection of the
    linear response to the same load (m)."""
    from barhinge.analysis.stiffness import linear_response
    from barhinge.errors import BarhingeError
    from barhinge.scene import self_weight

    t0 = time.perf_counter()
    model, S, _ = roofs.subdivided_roof(cp, sv, se, m, RULE, grading=grading_of(cp))
    P = roofs.plan_load(model, roofs.Q)
    P = P + self_weight(model, roofs.DENSITY * roofs.MATERIAL["t"], g=(0.0, 0.0, -roofs.G))
    U, _ = linear_response(model, P, S)
    row: dict[str, Any] = {"m": m, "membrane": MEMBRANE, "grading": grading_of(cp),
                           "n_dof": 3 * model.n_nodes,
                           "deflection_linear": float(np.max(-U[:, 2])),
                           "first_increment": 1.0 / steps}  # fmt: skip
    try:
        row |= roofs.nonlinear_check(
            model, S, P, steps=steps, stop_at_instability=True, keep_path=keep_path
        )
        row["error"] = ""
    except BarhingeError as exc:  # stated in the table, the other roofs still run
        row |= {"limit_load_factor": None, "instability_load_factor": None, "events": [],
                "instability_bracket": None, "instability_estimate": None,
                "load_factor_reached": float("nan"), "deflection_nonlinear": float("nan"),
                "error": str(exc).splitlines()[0]}  # fmt: skip
    row["events"] = [str(e) for e in row["events"]]
    row["time_s"] = time.perf_counter() - t0
    return row


def needs_second_look(row: dict) -> bool:
    """Whether a nonlinear check lost stability, or failed, on a first increment coarser
    than ``1 / FINE_STEPS`` (checks cached before ``first_increment`` was recorded used
    ``1 / NONLINEAR_STEPS``)."""
    if not SECOND_LOOK or (not row.get("error") and critical(row) is None):
        return False
    return float(row.get("first_increment", 1.0 / NONLINEAR_STEPS)) > 1.0 / FINE_STEPS


def nonlinear(fam: str, state: float, done: list[dict], save=lambda rows: None) -> list[dict]:
    """The nonlinear checks of one roof at ``NONLINEAR_LEVELS``: ``done`` (cached) extended,
    ``save`` called after every new check. A check that loses stability or fails is run
    again from the first increment ``1 / FINE_STEPS``; that one is kept, with the coarse
    one's critical load factor as ``coarse_critical`` (or its failure as ``coarse_error``)."""
    cp, flat_xy, _ = roofs.folded(fam, state)
    rows = [
        r
        for r in done
        if r.get("membrane") == MEMBRANE
        and r.get("grading", 1.0) == grading_of(cp)
        and r["m"] in NONLINEAR_LEVELS
        and "instability_bracket" in r
    ]
    missing = [m for m in NONLINEAR_LEVELS if m not in {r["m"] for r in rows}]
    if not missing and not any(needs_second_look(r) for r in rows):
        return rows  # all cached
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
    for m in NONLINEAR_LEVELS:
        r = next((x for x in rows if x["m"] == m), None)
        if r is None:
            r = nonlinear_level(cp, sv, se, m)
        elif not needs_second_look(r):
            continue
        if needs_second_look(r):
            why = f"failed ({r['error']})" if r.get("error") else f"unstable at {critical(r):.3f}"
            print(f"  {fam} {state:g} nonlinear m = {m}: {why}, again with increment "
                  f"1/{FINE_STEPS}", flush=True)  # fmt: skip
            fine = nonlinear_level(cp, sv, se, m, steps=FINE_STEPS)
            if r.get("error"):
                fine["coarse_error"] = r["error"]
            else:
                fine["coarse_critical"] = critical(r)
            fine["time_s"] += r["time_s"]
            r = fine
        rows = sorted([x for x in rows if x["m"] != m] + [r], key=lambda x: x["m"])
        save(rows)
        print(f"  {fam} {state:g} nonlinear m = {m}: {r['n_dof']} DOF, unstable at "
              f"{r['instability_load_factor']}, reached {r['load_factor_reached']:.3f}, "
              f"{r['time_s']:.1f} s {r['error']}", flush=True)  # fmt: skip
    return rows


def change(rows: list[dict]) -> float:
    """Relative change of the stiffness between the last two levels (NaN for one level)."""
    if len(rows) < 2:
        return float("nan")
    return rows[-1]["stiffness"] / rows[-2]["stiffness"] - 1.0


def refine(fam: str, state: float, done: list[dict], save=lambda rows: None) -> list[dict]:
    """The levels of one roof: ``done`` (cached) extended until the stiffness changes by less
    than ``TOL`` or the next level would exceed ``DOF_BUDGET``; ``save`` is called after every
    new level. Cached levels of another membrane than ``MEMBRANE`` or another grading than
    :func:`grading_of` the roof are not used."""
    cp, flat_xy, _ = roofs.folded(fam, state)
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
    rows = [
        r
        for r in done
        if r.get("membrane", "fit") == MEMBRANE and r.get("grading", 1.0) == grading_of(cp)
    ]
    rows = rows if len(rows) == len(done) else []
    for m in LEVELS[len(rows) :]:
        if roofs.settled([r["stiffness"] for r in rows], TOL):
            break
        if roofs.refinement_dofs(cp, m) > DOF_BUDGET:
            break
        rows.append(level(cp, sv, se, m))
        save(rows)
        r = rows[-1]
        print(f"  {fam} {state:g} m = {m}: {r['n_dof']} DOF, k = {r['stiffness'] / 1e3:.1f} "
              f"kN/m, change {100 * change(rows):+.2f} %, buckling {r['buckling_factor']:.3f}, "
              f"{r['time_s']:.1f} s", flush=True)  # fmt: skip
    return rows


def shell_reference(fam: str, state: float) -> list[dict]:
    """The graded shell levels of one roof at this run's ``SHELL_LEVELS`` and
    ``SHELL_DOF_BUDGET`` (:func:`roofs.shell_reference`)."""
    return roofs.shell_reference(fam, state, SHELL_LEVELS, SHELL_DOF_BUDGET)


def summary(
    fam: str,
    state: float,
    rows: list[dict],
    shell: list[dict] | None = None,
    nonlinear_rows: list[dict] | None = None,
) -> dict[str, Any]:
    """A roof's refinement: the level it was refined to (or the budget), stiffness per width
    there, the Richardson limit and its uncertainty, the buckling factors, and against the
    ``shell`` levels (when given) the shell reference and the gap of the limit to it, and the
    nonlinear checks (``nonlinear_rows``, by level) with the finest one's verdict."""
    from barhinge.analysis.accuracy import richardson

    k = [r["stiffness"] for r in rows]
    dk = change(rows)
    refined = roofs.settled(k, TOL)
    limit, rate, corr = richardson(k)
    width = rows[-1]["plan_area"] / roofs.SPAN
    cp = roofs.folded(fam, state)[0]  # formed once (resch, waterbomb relax to their state)
    ref, unc = float("nan"), math.inf
    if shell:
        ref, _, c = richardson([s_["stiffness"] for s_ in shell])
        unc = abs(c / ref) if math.isfinite(c) else math.inf
    return {
        "family": fam,
        "state": state,
        "rows": rows,
        "refined": refined,
        "m": rows[-1]["m"],
        "n_dof": rows[-1]["n_dof"],
        # the DOFs of the level after the last (the one the budget refused, if not refined)
        "next_dof": roofs.refinement_dofs(cp, 2 * rows[-1]["m"]),
        "change": dk,
        "stiffness": k[-1],
        "stiffness_per_width": k[-1] / width,
        "coarse_per_width": k[0] / width,
        "limit_per_width": limit / width,
        "limit_uncertainty": corr / limit if math.isfinite(corr) else math.inf,
        "rate": rate,
        "buckling_factor": rows[-1]["buckling_factor"],
        "buckling_change": (
            rows[-1]["buckling_factor"] / rows[-2]["buckling_factor"] - 1.0
            if len(rows) >= 2
            else float("nan")
        ),
        "coarse_buckling_factor": rows[0]["buckling_factor"],
        "equilibrium_error": max(r["equilibrium_error"] for r in rows),
        "patch_residual": max(r["patch_residual"] for r in rows),
        "time_s": sum(r["time_s"] for r in rows),
        "membrane_error": roofs.cell_membrane_error(cp, MEMBRANE),
        "bar_membrane_error": roofs.cell_membrane_error(cp, "fit"),
        "shell": shell or [],
        "shell_reference_per_width": ref / width,
        "shell_uncertainty": unc,
        "shell_gap": limit / ref - 1.0 if math.isfinite(limit) else k[-1] / ref - 1.0,
        "nonlinear": nonlinear_rows or [],
    }


def _key(fam: str, state: float) -> str:
    return f"{fam}|{state:g}"


def run(roof_list: list[tuple[str, float]], cache: Path | None) -> list[dict]:
    store: dict[str, list[dict]] = (
        json.loads(cache.read_text()) if cache is not None and cache.exists() else {}
    )
    out = []
    for fam, state in roof_list:
        key = _key(fam, state)

        def save(rows: list[dict], key: str = key) -> None:
            store[key] = rows
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))

        rows = refine(fam, state, store.get(key, []), save)
        skey = "shell|" + key
        if skey not in store:
            store[skey] = shell_reference(fam, state)
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))
        nkey = "nonlinear|" + key

        def save_nl(rows: list[dict], nkey: str = nkey) -> None:
            store[nkey] = rows
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))

        nl = nonlinear(fam, state, store.get(nkey, []), save_nl)
        out.append(summary(fam, state, rows, store[skey], nl))
    return out


def main_table() -> dict[str, dict[str, str]]:
    """The comparison table's rows (docs/roofs.csv, one facet per panel), by roof."""
    if not CSV_MAIN.exists():
        return {}
    with CSV_MAIN.open() as fh:
        return {_key(r["family"], float(r["state"])): r for r in csv.DictReader(fh)}


def _f(x: float, spec: str = ".1f") -> str:
    return "—" if x is None or not math.isfinite(x) else format(x, spec)


def _pct(x: float) -> str:
    return "—" if not math.isfinite(x) else f"{100 * x:+.1f} %"


def _limit(r: dict) -> str:
    if not math.isfinite(r["limit_uncertainty"]):
        return "not settled"
    return f"{r['limit_per_width'] / 1e3:.1f} ± {100 * r['limit_uncertainty']:.1f} %"


def _shell(r: dict) -> str:
    ref = r["shell_reference_per_width"] / 1e3
    if not math.isfinite(ref):
        return "—"
    unc = r["shell_uncertainty"]
    return f"{ref:.1f} ± {100 * unc:.1f} %" if math.isfinite(unc) else f"{ref:.1f} (not settled)"


def table(results: list[dict], coarse: dict[str, dict[str, str]]) -> str:
    lines = [
        "| family | state | refined to | DOFs | last change | k / width, refined (kN/m/m) | "
        "limit (kN/m/m) | k / width, comparison table (kN/m/m) | table / refined − 1 | "
        "buckling factor, refined | its last change | buckling factor, comparison table | "
        "membrane error of the cells (bars `fit`) | shell reference (kN/m/m) | "
        "limit / shell − 1 |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c = coarse.get(_key(r["family"], r["state"]))
        kt = float(c["stiffness_per_width"]) if c else float("nan")
        bt = float(c["buckling_factor"]) if c and c["buckling_factor"] else float("nan")
        lvl = f"m = {r['m']}" if r["refined"] else f"not reached (m = {r['m']}, budget)"
        lines.append(
            f"| {r['family']} | {r['state']:g} | {lvl} | {r['n_dof']} | {_pct(r['change'])} | "
            f"{r['stiffness_per_width'] / 1e3:.1f} | {_limit(r)} | {_f(kt / 1e3)} | "
            f"{_pct(kt / r['stiffness_per_width'] - 1.0)} | {_f(r['buckling_factor'], '.3f')} | "
            f"{_pct(r['buckling_change'])} | {_f(bt, '.3f')} | {r['membrane_error']:.3f} "
            f"({r['bar_membrane_error']:.3f}) | {_shell(r)} | {_pct(r['shell_gap'])} |"
        )
    return "\n".join(lines)


def critical(x: dict) -> float | None:
    """A nonlinear check's load factor of the first loss of stability: the load maximum
    where the path stopped past a limit point, else the interpolated estimate inside its
    bracket where there is one, else the first unstable state's; None when the path
    carries the design load."""
    if x["instability_load_factor"] is None:
        return None
    if x.get("stop") == "limit_points" and x.get("limit_load_factor") is not None:
        return float(x["limit_load_factor"])
    est = x.get("instability_estimate")
    return float(est) if est is not None else float(x["instability_load_factor"])


def nonlinear_verdict(r: dict) -> tuple[float | None, dict | None]:
    """(the load factor at which the finest nonlinear check loses stability, or None; that
    level's row, or None when no check ran or it failed)."""
    ok = [x for x in r.get("nonlinear", []) if not x.get("error")]
    if not ok:
        return None, None
    return critical(ok[-1]), ok[-1]


def nonlinear_change(r: dict) -> float:
    """Relative change of the critical load factor between the last two nonlinear levels
    (NaN unless both lose stability)."""
    ok = [critical(x) for x in r.get("nonlinear", []) if not x.get("error")]
    if len(ok) < 2 or ok[-1] is None or ok[-2] is None:
        return float("nan")
    return ok[-1] / ok[-2] - 1.0


def stable(r: dict, c: dict[str, str] | None) -> tuple[bool, str]:
    """(carries the design load, why not).

    The verdict is the nonlinear check on the refined panels (the finest of
    ``NONLINEAR_LEVELS``): the path reaches load factor 1 with no limit point and no state
    whose tangent has a negative eigenvalue. Where that check is missing or failed, the
    comparison table's one-facet path (``c``) and the refined linear buckling factor above 1
    decide, and the reason names them."""
    lam = r["buckling_factor"]
    inst, row = nonlinear_verdict(r)
    if row is not None:
        if inst is None:
            return True, ""
        return False, f"unstable at load factor {inst:.3f} on the nonlinear path (m = {row['m']})"
    why = []
    one = c.get("instability_load_factor", "") if c else ""
    if one:
        why.append(f"unstable at load factor {float(one):.3f} on the one-facet nonlinear path")
    if not math.isfinite(lam):
        why.append("no linear buckling factor")
    elif lam <= 1.0:
        why.append(f"linear buckling factor {lam:.3f}")
    return not why, "; ".join(why)


def _inst(x: dict | None) -> str:
    """A nonlinear check as a table cell: where stability is lost (the estimate and its
    bracket), or that the path carries the design load, or why the check failed."""
    if x is None:
        return "—"
    if x.get("error"):
        return "failed: " + x["error"]
    crit = critical(x)
    was = x.get("coarse_critical")
    coarse = f"1/{NONLINEAR_STEPS}: {was:.3f}" if was is not None else ""
    if x.get("coarse_error"):
        coarse = f"1/{NONLINEAR_STEPS}: failed at {_failed_at({'error': x['coarse_error']})}"
    if crit is None:
        return "stable to 1" + (f" ({coarse})" if coarse else "")
    coarse = f"; {coarse}" if coarse else ""
    if x.get("stop") == "limit_points":
        return f"{crit:.3f} (limit point{coarse})"
    b = x.get("instability_bracket")
    return f"{crit:.3f} ({b[0]:.3f}–{b[1]:.3f}{coarse})" if b else f"{crit:.3f}{coarse}"


def nonlinear_table(results: list[dict], coarse: dict[str, dict[str, str]]) -> str:
    """Every roof's nonlinear check: one facet per panel (the comparison table) and on the
    refined panels of ``NONLINEAR_LEVELS``."""
    lv = NONLINEAR_LEVELS
    lines = [
        "| family | state | one facet per panel | "
        + " | ".join(f"m = {m} (DOFs)" for m in lv)
        + " | change | load factor where the path ends | largest deflection there (mm) |"
        " linear buckling factor, refined |",
        "|---|---|---|" + "---|" * (len(lv) + 4),
    ]
    for r in results:
        c = coarse.get(_key(r["family"], r["state"]))
        one = c.get("instability_load_factor", "") if c else ""
        one_txt = "—" if c is None else f"{float(one):.3f}" if one else "stable to 1"
        by_m = {x["m"]: x for x in r.get("nonlinear", [])}
        cells = [_inst(by_m.get(m)) + (f" ({by_m[m]['n_dof']})" if m in by_m else "") for m in lv]
        last = by_m.get(lv[-1])
        end = "—" if last is None or last.get("error") else f"{last['load_factor_reached']:.3f}"
        defl = (
            "—"
            if last is None or last.get("error")
            else f"{1e3 * last['deflection_nonlinear']:.2f}"
        )
        lines.append(
            f"| {r['family']} | {r['state']:g} | {one_txt} | {' | '.join(cells)} | "
            f"{_pct(nonlinear_change(r))} | {end} | {defl} | {_f(r['buckling_factor'], '.3f')} |"
        )
    return "\n".join(lines)


#: above this worst membrane error of its cells a roof's refined figures are indicative only
MEMBRANE_TOL = 0.05
#: families that are baselines, not roofs: left out of the ranking
BASELINES = ("flat",)


def imperfect_rows(path: Path = CSV_IMPERFECT) -> dict[str, list[dict[str, str]]]:
    """The imperfect roofs' checks (one per imperfection amplitude) by roof key; empty
    before the imperfection study ran."""
    if not path.exists():
        return {}
    out: dict[str, list[dict[str, str]]] = {}
    with path.open() as fh:
        for r in csv.DictReader(fh):
            out.setdefault(_key(r["family"], float(r["state"])), []).append(r)
    return out


def imperfect_verdict(r: dict, row: dict | None, imp: dict[str, list[dict[str, str]]]) -> str:
    """What the buckling-mode imperfections do to a roof that carries the load perfect."""
    said = []
    for i in imp.get(_key(r["family"], r["state"]), []):
        if i["error"]:
            said.append(f"w0 = {i['imperfection']}: not completed")
        elif i["critical_load_factor"]:
            crit = float(i["critical_load_factor"])
            said.append(f"**w0 = {i['imperfection']}: loses stability at {crit:.3f}**")
        else:
            grow = ""
            if row is not None and row["deflection_nonlinear"]:
                ratio = float(i["deflection_nonlinear"]) / row["deflection_nonlinear"]
                grow = f" (deflection × {ratio:.2f})"
            said.append(f"w0 = {i['imperfection']}: carries it{grow}")
    return "; imperfect: " + ", ".join(said) if said else ""


def ranking(results: list[dict], coarse: dict[str, dict[str, str]]) -> str:
    roofs_only = [r for r in results if r["family"] not in BASELINES]
    order = sorted(roofs_only, key=lambda r: -r["stiffness_per_width"])
    imp = imperfect_rows()
    ok, bad = [], []
    for r in order:
        st, why = stable(r, coarse.get(_key(r["family"], r["state"])))
        label = f"{r['family']} {r['state']:g}"
        k = f"k / width {r['stiffness_per_width'] / 1e3:.1f} kN/m/m"
        k += "" if r["refined"] else f" (not refined: last change {_pct(r['change'])})"
        if r["membrane_error"] > MEMBRANE_TOL:
            k += f" (indicative: cells' membrane error {r['membrane_error']:.2f})"
        lb = f"linear buckling factor {_f(r['buckling_factor'], '.3f')}"
        if st:
            _, row = nonlinear_verdict(r)
            if row is not None and not r["buckling_factor"] > 1.0:
                lb += (
                    " (below 1: imperfection-sensitive; linear / nonlinear deflection "
                    f"{row['deflection_linear'] / row['deflection_nonlinear']:.1f})"
                )
            ok.append(f"{len(ok) + 1}. {label}: {k}, {lb}{imperfect_verdict(r, row, imp)}")
        else:
            bad.append(f"- {label}: {k}; {why}" + ("" if "linear buckling" in why else f"; {lb}"))
    return "\n".join(
        [
            "Stiffest refined roofs that carry the design load: on the nonlinear path of the"
            f" refined panels (m = {NONLINEAR_LEVELS[-1]}) the roof reaches load factor 1 with"
            " no limit point and no state whose tangent has a negative eigenvalue; the flat"
            " sheet, a baseline, is left out. This is the perfect geometry: where the linear"
            " buckling factor beside it is below 1 (given with the ratio of the linear to the"
            " nonlinear deflection at the design load), it points to a critical point near the"
            " path, so that roof is imperfection-sensitive (finding 7). *Imperfect*: the same"
            " roof with its first buckling mode as an initial imperfection w0 (section"
            " *Imperfect* below):",
            "",
            *(ok or ["(none)"]),
            "",
            "Roofs that are not stable up to the design load, by refined stiffness:",
            "",
            *(bad or ["(none)"]),
        ]
    )


def findings(results: list[dict], coarse: dict[str, dict[str, str]]) -> str:
    done = [r for r in results if r["refined"]]
    open_ = [r for r in results if not r["refined"]]
    ratio = [
        float(coarse[_key(r["family"], r["state"])]["stiffness_per_width"])
        / r["stiffness_per_width"]
        for r in results
        if _key(r["family"], r["state"]) in coarse
    ]
    by_fam: dict[str, list[dict]] = {}
    for r in open_:
        by_fam.setdefault(r["family"], []).append(r)
    eq = max(r["equilibrium_error"] for r in results)
    flips = [
        r
        for r in results
        if _key(r["family"], r["state"]) in coarse
        and stable(r, coarse[_key(r["family"], r["state"])])[0]
        != _coarse_stable(coarse[_key(r["family"], r["state"])])
    ]

    def lab(r: dict) -> str:
        return f"{r['family']} {r['state']:g}"

    return "\n".join(
        [
            "What the refinement says:",
            "",
            f"1. **{len(done)} of {len(results)} roofs are refined** (stiffness change below "
            f"{100 * TOL:g} % between the last two levels, at m = "
            + ", ".join(sorted({str(r["m"]) for r in done}, key=int))
            + f"); {len(open_)} reach the budget of {DOF_BUDGET:,} DOFs first"
            + (
                ": "
                + "; ".join(
                    f"{f} ({', '.join(format(r['state'], 'g') for r in rs)}: last change "
                    f"{_pct(min(r['change'] for r in rs))} … {_pct(max(r['change'] for r in rs))})"
                    for f, rs in by_fam.items()
                )
                if open_
                else ""
            )
            + ". For those the table gives the Richardson limit of the last three levels with its"
            " correction as the uncertainty; the panels' corners, where a folded sheet's"
            " stresses are singular, set their slow convergence (*Against a shell model*,"
            " finding 6). The budget is set by the memory of the machine the study runs on"
            " (23.5 GB)"
            + (
                f": their next level has {min(r['next_dof'] for r in open_):,} DOFs or more"
                if open_
                else ""
            )
            + "; the finest levels are solved with their residuals accumulated in"
            " extended precision (a plate's stiffness matrix is conditioned like the cell"
            " size to the power -4: in double precision the rounding of the residual alone"
            " exceeds the 1e-4 that `linear_response` accepts at the parallelogram roofs'"
            " m = 64).",
            (
                "2. **The one-facet comparison table is stiff.** Its k / width over the refined "
                f"one: {min(ratio):.2f} … {max(ratio):.2f} (median {float(np.median(ratio)):.2f});"
                " the refined figures are the ones to design with."
                if ratio
                else "2. The comparison table (docs/roofs.csv) is not there to compare with."
            ),
            "3. **Stability changes with refinement.** "
            + (
                "The nonlinear verdict on refined panels differs from the one-facet path's"
                " (the comparison table) for " + ", ".join(lab(r) for r in flips) + "."
                if flips
                else "No roof changes its nonlinear verdict against the one-facet path's."
            ),
            f"4. Every solve balances: largest equilibrium residual {eq:.1e}.",
            membrane_finding(results),
            shell_finding(results),
            nonlinear_finding(results, coarse),
        ]
    )


#: a roof that loses stability within this fraction below the design load is marginal
MARGINAL = 0.05


def _failed_at(x: dict) -> str:
    """The load factor a failed check's message names ("at load factor 0.77"), or "?"."""
    import re

    found = re.search(r"at load factor ([-+0-9.eE]+)", x.get("error", ""))
    return f"{float(found.group(1)):.3f}" if found else "?"


def carried_all(results: list[dict]) -> list[dict]:
    """The roofs whose finest nonlinear check carries the design load."""
    return [
        r
        for r in results
        if nonlinear_verdict(r)[1] is not None and nonlinear_verdict(r)[0] is None
    ]


def nonlinear_finding(results: list[dict], coarse: dict[str, dict[str, str]]) -> str:
    """The nonlinear check on refined panels against the one-facet one."""
    checked = [r for r in results if nonlinear_verdict(r)[1] is not None]
    failed = [r for r in results if r.get("nonlinear") and nonlinear_verdict(r)[1] is None]
    if not checked:
        return "7. **Nonlinear check on refined panels.** Not run."
    m = NONLINEAR_LEVELS[-1]
    lost = [r for r in checked if nonlinear_verdict(r)[0] is not None]

    def one(r: dict) -> float | None:
        c = coarse.get(_key(r["family"], r["state"]))
        v = c.get("instability_load_factor", "") if c else ""
        return float(v) if v else None

    with_one = [r for r in checked if _key(r["family"], r["state"]) in coarse]
    lost_one = [r for r in with_one if one(r) is not None]
    both = [r for r in lost if one(r) is not None]
    ratio = [nonlinear_verdict(r)[0] / one(r) for r in both]  # type: ignore[operator]
    newly = [r for r in lost if r in with_one and one(r) is None]
    regained = [r for r in lost_one if nonlinear_verdict(r)[0] is None]
    dch = [abs(nonlinear_change(r)) for r in lost if math.isfinite(nonlinear_change(r))]
    flipped_m = [
        r
        for r in carried_all(checked)
        if len(r["nonlinear"]) >= 2 and critical(r["nonlinear"][-2]) is not None
    ]

    def lab(r: dict) -> str:
        return f"{r['family']} {r['state']:g}"

    parts = [
        "7. **Nonlinear check on refined panels.** Arc length under the design load with"
        " every panel cut into m × m sub-panels, m = "
        + ", ".join(map(str, NONLINEAR_LEVELS))
        + ", stopped at load factor 1, the first limit point or the first loss of stability"
        f" (table below). At m = {m}, {len(lost)} of {len(checked)} roofs lose stability below"
        f" the design load (one facet per panel: {len(lost_one)} of {len(with_one)})."
    ]
    looked = [(r, x) for r in checked for x in r["nonlinear"] if "coarse_critical" in x]
    rescued = [(r, x) for r in results for x in r.get("nonlinear", []) if x.get("coarse_error")]
    if looked:
        turned = [(r, x) for r, x in looked if critical(x) is None]
        parts.append(
            f" Every check that lost stability from a first increment of 1/{NONLINEAR_STEPS}"
            f" was followed again from 1/{FINE_STEPS} ({len(looked)} checks), and that path's"
            " verdict is the one given: a coarse increment can step from a stable state past"
            " the first critical point."
            + (
                " With the finer increment "
                + ", ".join(
                    f"{lab(r)} at m = {x['m']} (was {x['coarse_critical']:.3f})" for r, x in turned
                )  # fmt: skip
                + " carry the design load."
                if turned
                else " No verdict changed."
            )
        )
        moved = [
            (r, x)
            for r, x in looked
            if critical(x) is not None and abs(critical(x) / x["coarse_critical"] - 1.0) > 0.05
        ]

        def listed(group: list) -> str:
            return ", ".join(
                f"{lab(r)} at m = {x['m']} ({critical(x):.3f}, was {x['coarse_critical']:.3f})"
                for r, x in group
            )

        earlier = [(r, x) for r, x in moved if critical(x) < x["coarse_critical"]]
        later = [(r, x) for r, x in moved if critical(x) > x["coarse_critical"]]
        if earlier:
            parts.append(
                " The finer path loses stability more than 5 % earlier for "
                + listed(earlier)
                + ": the coarse increment stepped past the first critical point."
            )
        if later:
            parts.append(
                " It loses stability more than 5 % later for "
                + listed(later)
                + ": there the coarse first increment converged onto an equilibrium off the"
                " path that the finer increments follow."
            )
    for r, x in rescued:
        parts.append(
            f" The check of {lab(r)} at m = {x['m']} failed from 1/{NONLINEAR_STEPS} (at load"
            f" factor {_failed_at({'error': x['coarse_error']})}) and was run again from"
            f" 1/{FINE_STEPS}: "
            + (f"failed again ({x['error']})." if x.get("error") else f"{_inst(x)}.")
        )
    if ratio:
        parts.append(
            f" Where both lose it, the refined load factor over the one-facet one is"
            f" {min(ratio):.2f} … {max(ratio):.2f} (median {float(np.median(ratio)):.2f})."
        )
    if newly:
        parts.append(" Stable on one facet, unstable refined: " + ", ".join(map(lab, newly)) + ".")
    if regained:
        parts.append(
            " Unstable on one facet, stable refined: " + ", ".join(map(lab, regained)) + "."
        )
    if dch:
        parts.append(
            f" From m = {NONLINEAR_LEVELS[-2]} to m = {m} the load factor where stability is"
            f" lost changes by {100 * float(np.median(dch)):.1f} % in the median and"
            f" {100 * max(dch):.1f} % at most, so the column m = {m} is a refinement estimate of"
            " that size, not a converged value."
        )
    if flipped_m:
        parts.append(
            " " + ", ".join(map(lab, flipped_m)) + f" lose stability at m = {NONLINEAR_LEVELS[-2]}"
            f" and not at m = {m}: for them the coarser level is outside the range where the"
            " verdict settles, and the finer level's verdict is the one given."
        )
    marginal = [r for r in lost if nonlinear_verdict(r)[0] >= 1.0 - MARGINAL]  # type: ignore[operator]
    if marginal:
        parts.append(
            " "
            + ", ".join(f"{lab(r)} ({nonlinear_verdict(r)[0]:.3f})" for r in marginal)
            + (" loses" if len(marginal) == 1 else " lose")
            + f" stability within {100 * MARGINAL:g} % of the design load: marginal, a"
            " verdict that a finer load increment or sub-panel level can turn."
        )
    carried = [r for r in checked if nonlinear_verdict(r)[0] is None]
    lba = [r for r in carried if not r["buckling_factor"] > 1.0]
    if lba:
        over = [nonlinear_verdict(r)[1] for r in lba]
        q = [x["deflection_linear"] / x["deflection_nonlinear"] for x in over]  # type: ignore[index]
        parts.append(
            f" {len(lba)} roofs that the nonlinear path carries to the design load have a linear"
            f" buckling factor below 1 ({', '.join(map(lab, lba))}); at load factor 1 their"
            f" linear response deflects {min(q):.1f} … {max(q):.1f} × the nonlinear one. The"
            " linear estimate takes the pre-buckling state as linear and its stress as"
            " proportional to the load; the nonlinear path follows the deforming roof and"
            " counts the negative eigenvalues of its tangent at every state (checked against a"
            " dense eigensolver in `tests/studies/test_studies_refine.py`). Where the two"
            " disagree, the perfect roof carries the load on its path, but the linear estimate"
            " points to a critical point nearby: an imperfect roof may not carry it, and the"
            " ranking marks these roofs imperfection-sensitive."
        )
        imp = imperfect_rows()
        seeded = [i for r in lba for i in imp.get(_key(r["family"], r["state"]), [])]
        for name in dict.fromkeys(i["imperfection"] for i in seeded):
            mine = [i for i in seeded if i["imperfection"] == name]
            lost_i = [i for i in mine if i["critical_load_factor"] and not i["error"]]
            kept_i = [i for i in mine if not i["critical_load_factor"] and not i["error"]]
            parts.append(
                f" Seeded with their first buckling mode at w0 = {name} (section *Imperfect*),"
                f" {len(kept_i)} of them still carry the design load"
                + (
                    " and "
                    + ", ".join(
                        f"{i['family']} {float(i['state']):g}"
                        f" ({float(i['critical_load_factor']):.3f})"
                        for i in lost_i
                    )
                    + (" loses" if len(lost_i) == 1 else " lose")
                    + " stability below it"
                    if lost_i
                    else ""
                )
                + "."
            )
    if failed:
        parts.append(
            " The check failed on " + ", ".join(map(lab, failed)) + " (named in the table);"
            " their verdict is the one-facet path's."
        )
    fine_failed = [
        r for r in checked if r["nonlinear"][-1].get("error") and r["nonlinear"][-1]["m"] == m
    ]
    if fine_failed:
        parts.append(
            f" At m = {m} the check failed on "
            + ", ".join(
                f"{lab(r)} (at load factor {_failed_at(r['nonlinear'][-1])})" for r in fine_failed
            )
            + " with no loss of stability before (named in the table); "
            + ("its" if len(fine_failed) == 1 else "their")
            + f" verdict is the one at m = {NONLINEAR_LEVELS[-2]}."
        )
    return "".join(parts)


def membrane_finding(results: list[dict]) -> str:
    """The bar lattice's own limit: roofs whose cells store a uniform membrane strain badly."""
    off = [r for r in results if r["membrane_error"] > MEMBRANE_TOL]
    good = [r for r in results if r["membrane_error"] <= MEMBRANE_TOL]
    if not off:
        bars = sorted(results, key=lambda r: -r["bar_membrane_error"])
        worst: dict[str, float] = {}
        for r in bars:
            worst.setdefault(r["family"], r["bar_membrane_error"])
        off_bars = {f: e for f, e in worst.items() if e > MEMBRANE_TOL}
        return (
            f"5. **Membranes.** The refined models have the `{MEMBRANE}` membrane: every "
            "roof's cells store a uniform membrane strain within "
            f"{max(r['membrane_error'] for r in results):.3f} of the plane-stress energy. "
            "With bars instead (`fit`, the bracketed values), a panel cut into cells keeps "
            "its shape's error (docs/calibration.md, Table 4), so refinement would converge "
            "to a sheet whose membrane is off by that much in its worst direction: "
            + "; ".join(f"{f} up to {e:.2f}" for f, e in off_bars.items())
            + f" (the other roofs at most "
            f"{max((e for f, e in worst.items() if f not in off_bars), default=0.0):.3f})."
        )
    fams: dict[str, list[float]] = {}
    for r in off:
        fams.setdefault(r["family"], []).append(r["membrane_error"])
    return (
        "5. **The bar lattice's own limit.** A panel cut into cells keeps its shape's membrane"
        " error under a uniform strain (docs/calibration.md, Table 4), so refinement converges"
        " to a sheet whose membrane is off by that much in its worst direction. "
        + "; ".join(f"{f}: up to {max(v):.2f}" for f, v in fams.items())
        + f" (column *membrane error of the cells*; the other roofs: at most "
        f"{max((r['membrane_error'] for r in good), default=0.0):.3f}). The refined stiffness"
        " and buckling factors of those roofs are indicative only; the ranking marks them."
    )


def shell_finding(results: list[dict]) -> str:
    """Every roof's refined limit against its shell reference (``roofs.shell_level``)."""
    have = [r for r in results if r["shell"]]
    if not have:
        return "6. **Against the shell.** No shell reference was computed."
    settled = [r for r in have if r["shell_uncertainty"] <= SHELL_TOL]
    within = [r for r in settled if abs(r["shell_gap"]) <= 0.05]
    off = sorted((r for r in settled if abs(r["shell_gap"]) > 0.05), key=lambda r: r["shell_gap"])
    open_ = [r for r in have if r["shell_uncertainty"] > SHELL_TOL]

    def lab(r: dict) -> str:
        return f"{r['family']} {r['state']:g}"

    return (
        "6. **Against the shell.** Every roof also has a shell reference (facet shell, meshes"
        f" graded {roofs.SHELL_GRADING:g} towards the corners, r = {SHELL_LEVELS[0]} …"
        f" {SHELL_LEVELS[-1]} and further until it settles, up to {SHELL_DOF_BUDGET:,} DOFs;"
        " docs/roofs.md, *Against a shell model*). "
        f"{len(settled)} of {len(have)} references settle to within {100 * SHELL_TOL:g} %; of"
        f" those roofs, {len(within)} have a refined limit within 5 % of the shell"
        + (
            "; "
            + ", ".join(f"{lab(r)} {_pct(r['shell_gap'])}" for r in off)
            + " do not"
            + (
                " (all of them stopped at the DOF budget, finding 1)"
                if all(not r["refined"] for r in off)
                else " (all of them refined to 2 %)"
                if all(r["refined"] for r in off)
                else " ("
                + ", ".join(lab(r) for r in off if r["refined"])
                + " refined to 2 %, the others stopped at the DOF budget, finding 1)"
            )
            if off
            else ""
        )
        + "."
        + (" Not settled: " + ", ".join(lab(r) for r in open_) + "." if open_ else "")
    )


def _coarse_stable(c: dict[str, str]) -> bool:
    """The one-facet nonlinear path's verdict (docs/roofs.csv): no loss of stability."""
    return not c["instability_load_factor"]


def write_csv(results: list[dict], path: Path) -> None:
    cols = ["family", "state", "m", "n_dof", "stiffness", "stiffness_per_width",
            "buckling_factor", "equilibrium_error", "time_s"]  # fmt: skip
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*cols, "refined"])
        for r in results:
            for row in r["rows"]:
                width = row["plan_area"] / roofs.SPAN
                vals = {**row, "family": r["family"], "state": r["state"],
                        "stiffness_per_width": row["stiffness"] / width}  # fmt: skip
                last = int(r["refined"] and row is r["rows"][-1])
                w.writerow([f"{vals[c]:.6g}" if isinstance(vals[c], float) else vals[c]
                            for c in cols] + [last])  # fmt: skip


def write_nonlinear_csv(results: list[dict], path: Path) -> None:
    """One row per roof and nonlinear level: where the path stopped and why, the bracket
    and the critical load factor (:func:`critical`), deflections (m), cost."""
    cols = ["family", "state", "m", "n_dof", "stop", "critical_load_factor",
            "bracket_low", "bracket_high", "load_factor_reached", "deflection_linear",
            "deflection_nonlinear", "states", "iterations", "first_increment",
            "coarse_critical", "coarse_error", "time_s", "error"]  # fmt: skip
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in results:
            for x in r.get("nonlinear", []):
                b = x.get("instability_bracket") or [None, None]
                crit = None if x.get("error") else critical(x)
                vals = {**x, "family": r["family"], "state": r["state"],
                        "critical_load_factor": crit, "bracket_low": b[0], "bracket_high": b[1],
                        "stop": x.get("stop", ""), "states": x.get("states", ""),
                        "first_increment": x.get("first_increment", 1.0 / NONLINEAR_STEPS),
                        "iterations": x.get("iterations", "")}  # fmt: skip
                w.writerow(
                    ["" if vals.get(c) is None else f"{vals[c]:.6g}" if isinstance(vals[c], float)
                     else vals[c] for c in cols]
                )  # fmt: skip


def chart(results: list[dict], path: Path) -> None:
    """k / width and buckling factor against DOFs, one panel pair per family."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fams = [f for f in dict.fromkeys(r["family"] for r in results) if f not in BASELINES]
    fig, axes = plt.subplots(2, len(fams), figsize=(2.6 * len(fams), 5.4), squeeze=False)
    for j, fam in enumerate(fams):
        for r in (r for r in results if r["family"] == fam):
            n = [x["n_dof"] for x in r["rows"]]
            w = r["rows"][-1]["plan_area"] / roofs.SPAN
            ls = "-" if r["refined"] else "--"
            axes[0, j].loglog(n, [x["stiffness"] / w / 1e3 for x in r["rows"]], "o" + ls, ms=3,
                              label=f"{r['state']:g}")  # fmt: skip
            axes[1, j].semilogx(n, [x["buckling_factor"] for x in r["rows"]], "o" + ls, ms=3)
        axes[0, j].set_title(fam)
        axes[0, j].legend(fontsize=6, title="state", title_fontsize=6)
        axes[1, j].axhline(1.0, color="grey", lw=0.8, ls=":")
        axes[1, j].set_xlabel("DOFs")
        for ax in axes[:, j]:
            ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].set_ylabel("k / width (kN/m/m)")
    axes[1, 0].set_ylabel("linear buckling factor")
    fig.suptitle("Refinement of every roof (coupled rule, m = 1, 2, 4, …; dashed: budget reached)",
                 fontsize=9)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def section(results: list[dict]) -> str:
    coarse = main_table()
    return "\n".join(
        [
            START,
            "",
            "Written by `python studies/roofs/refine.py --publish"
            + (f" --grading={GRADING:g}" if GRADING != 2.0 else "")
            + "` (every level is kept in"
            " `studies/roofs/refine_cache.json` as it is computed, so an interrupted run"
            " resumes; data: [roofs_refined.csv](roofs_refined.csv))."
            f" Every roof of the comparison table with each panel cut into m × m sub-panels"
            f" (`{RULE}` plate rule, `{MEMBRANE}` membrane"
            + (
                f"; on roofs of parallelogram panels whose creases meet at an angle,"
                f" sub-panels graded towards the panels' corners with"
                f" p = {GRADING:g}"
                if GRADING != 1.0
                else ""
            )
            + "), m = 1, 2, 4, … until the"
            f" stiffness changes by less than {100 * TOL:g} % between two levels (a change"
            " of the same sign as the one before and smaller), or up to"
            f" {DOF_BUDGET:,} DOFs. Stiffness and width as in the comparison table (uniform"
            " load only); buckling factor under the uniform load plus self-weight;"
            " limit = Richardson over the last three levels (± its correction;"
            " *not settled* where the changes do not shrink).",
            "",
            "![refinement of every roof](img/roofs_refined.png)",
            "",
            table(results, coarse),
            "",
            ranking(results, coarse),
            "",
            findings(results, coarse),
            "",
            "Nonlinear check, one facet per panel (the comparison table) and refined (cut into"
            " the linear levels' sub-panels): the load"
            " factor at which the path loses stability (a limit point, or the first state whose"
            " tangent has a negative eigenvalue), or *stable to 1*. On the refined panels the"
            " path stops at the first unstable state; the load factor given is the load maximum"
            " at a limit point, else where the tangent, interpolated between the last stable"
            " state and that one, turns singular"
            " (`barhinge.analysis.buckling.critical_between`), with the two states' load factors"
            " in brackets. A refined check that loses stability from a first increment of"
            f" 1/{NONLINEAR_STEPS} of the design load is followed again from 1/{FINE_STEPS}; that"
            f" path is given, with the 1/{NONLINEAR_STEPS} path's value after it"
            f" (*1/{NONLINEAR_STEPS}: …*)."
            " Then the change between the refined levels, where the refined path"
            " ends and its largest deflection there (every level:"
            " [roofs_refined_nonlinear.csv](roofs_refined_nonlinear.csv)).",
            "",
            nonlinear_table(results, coarse),
            "",
            END,
        ]
    )


RESULTS = run(ROOFS, CACHE)

if MAIN:
    text = section(RESULTS)
    print(text)
    if PUBLISH:
        doc = DOC.read_text()
        if START in doc:
            a, b = doc.index(START), doc.index(END) + len(END)
            doc = doc[:a] + text + doc[b:]
        else:
            at = doc.find("## Independent check: the corrugated roof")
            head = "## Refined: every roof until its stiffness settles\n\n" + text + "\n\n"
            doc = doc[:at] + head + doc[at:] if at >= 0 else doc.rstrip("\n") + "\n\n" + head
        DOC.write_text(doc)
        chart(RESULTS, DOC.parent / "img" / "roofs_refined.png")
        write_csv(RESULTS, CSV_OUT)
        write_nonlinear_csv(RESULTS, CSV_NONLINEAR)
        print(f"wrote {DOC}, {CSV_OUT}, {CSV_NONLINEAR}")
