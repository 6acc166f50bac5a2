"""Imperfect roofs: every roof that carries the design load on its refined nonlinear path,
checked again with an initial geometric imperfection in its first buckling mode.

The refined ranking (docs/roofs.md, *Refined: every roof until its stiffness settles*) marks
most of the roofs that carry the design load as *imperfection-sensitive*: their linear
buckling factor is below 1 while the perfect path passes the bifurcation without taking it.
Real roofs are never perfect. This study seeds each of those roofs with its first linear
buckling mode (the mode of the refined model under the design load: uniform load plus
self-weight), on the sign that the load pushes
(:func:`barhinge.analysis.imperfection.imperfect`), at two amplitudes (``AMPLITUDES``):

* ``b/200``, the equivalent geometric imperfection of a plate panel of EN 1993-1-5:2006,
  Annex C, C.5 (``min(a, b) / 200``, ``a, b`` the panel's sides; here ``b`` is the median over
  the roof's facets of each facet's shortest side): a local imperfection;
* ``span/300``, the bow imperfection ``e0 / L = 1/300`` of EN 1993-1-1:2005, Table 5.1
  (buckling curve a, elastic analysis) over the roof's span: a global one, here in the shape
  of the first mode.

The imperfect roof is then followed by the same arc length as the perfect one
(:func:`roofs.nonlinear_check`, stopped at the first loss of stability) on the same refined
panels (m = ``LEVEL``).

With ``--sensitivity``, one roof per family (the carried roof of lowest first buckling
factor) is also seeded in its buckling modes 2 .. 4 at both amplitudes and in its first mode
at the larger bows span/150 and span/75 (``SENSITIVITY_MODES``, ``SENSITIVITY_AMPLITUDES``;
EN 1993-1-6:2007, 8.7.2: the most unfavourable shape and amplitude), written between the
``roofs-imperfect-sensitivity`` markers and to docs/roofs_imperfect_sensitivity.csv.

Run: ``python studies/roofs/imperfection.py [--quick] [--publish] [--sensitivity]
[--cache=FILE] [--only=FAMILY,...]``. Each roof is written to the cache as soon as it is
checked (default ``imperfection_cache.json`` beside this script), so an interrupted run
resumes. ``--publish`` writes the section of docs/roofs.md between the ``roofs-imperfect``
markers and docs/roofs_imperfect.csv. ``--quick``: two roofs at m = 2 (a smoke run, nothing
published).
"""

from __future__ import annotations

import argparse
import csv
import functools
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.analysis.imperfection import panel_side

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import roofs  # noqa: E402

DOC = HERE.parents[1] / "docs" / "roofs.md"
CSV_PERFECT = HERE.parents[1] / "docs" / "roofs_refined_nonlinear.csv"
CSV_OUT = HERE.parents[1] / "docs" / "roofs_imperfect.csv"
START, END = "<!-- roofs-imperfect:start -->", "<!-- roofs-imperfect:end -->"

#: sub-panels per panel side of the checked models: the refined ranking's verdict level
LEVEL = 8
#: the plate rule and membrane of the refined study (studies/roofs/refine.py)
RULE = "coupled"
#: the imperfection amplitudes: name -> (fraction, of what: "panel" side b or "span")
AMPLITUDES: dict[str, tuple[float, str]] = {
    "b/200": (1.0 / 200.0, "panel"),  # EN 1993-1-5, Annex C, C.5
    "span/300": (1.0 / 300.0, "span"),  # EN 1993-1-1, Table 5.1, curve a, elastic
}
#: the sensitivity study (``--sensitivity``): the higher buckling modes seeded at the code
#: amplitudes, and larger multiples of the global bow on the first mode (EN 1993-1-6:2007,
#: 8.7.2 asks for the most unfavourable imperfection shape and amplitude)
SENSITIVITY_MODES = (2, 3, 4)
SENSITIVITY_AMPLITUDES: dict[str, tuple[float, str]] = {
    "span/150": (1.0 / 150.0, "span"),
    "span/75": (1.0 / 75.0, "span"),
}
#: a higher mode counts as more harmful than the first when its deflection at the design load
#: exceeds the first mode's by more than this fraction of the perfect roof's (or it loses
#: stability where the first does not, or earlier)
SENSITIVITY_MARGIN = 0.01
SENS_CSV = HERE.parents[1] / "docs" / "roofs_imperfect_sensitivity.csv"
SENS_START = "<!-- roofs-imperfect-sensitivity:start -->"
SENS_END = "<!-- roofs-imperfect-sensitivity:end -->"
#: first arc-length increment of every check (1 / STEPS of the design load), and of the
#: second look at a roof that loses stability (a coarse increment can jump past the first
#: critical point; the finer path's estimate is the one reported)
STEPS, FINE_STEPS = 10, 40
#: families that are baselines, not roofs (left out of the counts)
BASELINES = ("flat",)


def perfect_rows(path: Path = CSV_PERFECT) -> dict[tuple[str, float], dict[str, str]]:
    """The refined study's nonlinear checks at m = ``LEVEL``, by roof."""
    with path.open() as fh:
        return {
            (r["family"], float(r["state"])): r for r in csv.DictReader(fh) if int(r["m"]) == LEVEL
        }


def carries(row: dict[str, str]) -> bool:
    """Whether the perfect path reached the design load stable (no loss of stability)."""
    return row["stop"] == "load_factor" and not row["critical_load_factor"] and not row["error"]


def amplitude(name: str, cp) -> float:
    """The imperfection amplitude ``name`` (a key of ``AMPLITUDES``) of a roof, m."""
    fraction, of = {**AMPLITUDES, **SENSITIVITY_AMPLITUDES}[name]
    return fraction * (panel_side(cp) if of == "panel" else roofs.SPAN)


def check(
    family: str, state: float, m: int, name: str, steps: int = STEPS, mode: int = 1
) -> dict[str, Any]:
    """The roof's nonlinear check at ``m x m`` sub-panels per panel with the imperfection
    ``name`` (a key of ``AMPLITUDES`` or ``SENSITIVITY_AMPLITUDES``) in the shape of buckling
    mode ``mode`` (1 = lowest), first arc-length increment ``1 / steps``."""
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.analysis.imperfection import imperfect
    from barhinge.errors import BarhingeError
    from barhinge.scene import self_weight

    t0 = time.perf_counter()
    cp, flat_xy, _ = roofs.folded(family, state)
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[family]["axis"])
    grading = roofs.grading_of(cp)  # the refined study's sub-panels
    model, S, _ = roofs.subdivided_roof(cp, sv, se, m, RULE, grading=grading)
    P = roofs.plan_load(model, roofs.Q)
    P = P + self_weight(model, roofs.DENSITY * roofs.MATERIAL["t"], g=(0.0, 0.0, -roofs.G))
    w0 = amplitude(name, cp)
    row: dict[str, Any] = {"family": family, "state": state, "m": m, "n_dof": 3 * model.n_nodes,
                           "imperfection": name, "panel_side": panel_side(cp),
                           "amplitude": w0, "mode": mode, "grading": grading}  # fmt: skip
    try:
        buck = linear_buckling(model, P, S, n_modes=mode)
        if len(buck.factors) < mode:
            raise BarhingeError(f"only {len(buck.factors)} positive buckling factors")
        row["buckling_factor"] = float(buck.factors[mode - 1])
        seeded = imperfect(model, buck.modes[mode - 1], w0, loads=P)
        row |= roofs.nonlinear_check(seeded, S, P, steps=steps, stop_at_instability=True)
        row["first_increment"] = 1.0 / steps
        row["error"] = ""
    except BarhingeError as exc:  # stated in the table, the other roofs still run
        row |= {"buckling_factor": float("nan"), "instability_load_factor": None,
                "instability_estimate": None, "instability_bracket": None,
                "limit_load_factor": None, "load_factor_reached": float("nan"),
                "deflection_nonlinear": float("nan"), "stop": "", "events": [],
                "error": str(exc).splitlines()[0]}  # fmt: skip
    row["events"] = [str(e) for e in row["events"]]
    row["time_s"] = time.perf_counter() - t0
    return row


def critical(row: dict[str, Any]) -> float | None:
    """The load factor at which the imperfect path loses stability: the load maximum at a
    limit point, else the interpolated estimate (else the first unstable state's), or None
    when it carries the design load."""
    if row.get("limit_load_factor") is not None:
        return float(row["limit_load_factor"])
    if row.get("instability_estimate") is not None:
        return float(row["instability_estimate"])
    if row.get("instability_load_factor") is not None:
        return float(row["instability_load_factor"])
    return None


@functools.cache
def _grading(fam: str, state: float) -> float:
    """The sub-panel grading of a roof (:func:`roofs.grading_of`)."""
    return roofs.grading_of(roofs.folded(fam, state)[0])


def _key(fam: str, state: float, m: int, name: str, mode: int = 1) -> str:
    return f"{fam}/{state:g}/m{m}/{name}" + (f"/mode{mode}" if mode != 1 else "")


def run(
    roof_list: list[tuple[str, float]],
    m: int,
    cache: Path | None,
    tasks: list[tuple[str, int]] | None = None,
) -> list[dict]:
    """Check every roof at every (amplitude, mode) of ``tasks`` (default: every amplitude of
    ``AMPLITUDES`` on mode 1); cached checks are read back, the cache is written after each
    check. A check that loses stability or fails is run again from the first increment
    ``1 / FINE_STEPS``; that one is kept, with the coarse one's critical load factor as
    ``coarse_critical`` (or its failure as ``coarse_error``)."""
    store: dict[str, dict] = (
        json.loads(cache.read_text()) if cache is not None and cache.exists() else {}
    )
    rows = []
    tasks = [(name, 1) for name in AMPLITUDES] if tasks is None else tasks
    todo = [(fam, state, name, mode) for name, mode in tasks for fam, state in roof_list]
    for k, (fam, state, name, mode) in enumerate(todo, 1):
        key = _key(fam, state, m, name, mode)
        if key in store and store[key].get("grading", 1.0) != _grading(fam, state):
            del store[key]  # cut into other sub-panels than the refined study's: again
        if key not in store:
            print(f"[{k}/{len(todo)}] {fam} {state:g} (m = {m}, w0 = {name}, mode {mode})",
                  file=sys.stderr, flush=True)  # fmt: skip
            store[key] = check(fam, state, m, name, mode=mode)
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))
        coarse = store[key]
        coarse_increment = coarse.get("first_increment", 1.0 / STEPS)
        second_look = coarse["error"] or critical(coarse) is not None
        if second_look and coarse_increment > 1.0 / FINE_STEPS:
            why = "fails" if coarse["error"] else "loses stability"
            print(f"  {fam} {state:g} {why}: again with increment 1/{FINE_STEPS}",
                  file=sys.stderr, flush=True)  # fmt: skip
            fine = check(fam, state, m, name, steps=FINE_STEPS, mode=mode)
            if coarse["error"]:
                fine["coarse_error"] = coarse["error"]
            else:
                fine["coarse_critical"] = critical(coarse)
            store[key] = fine
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))
        rows.append({"mode": 1, **store[key]})  # checks cached before modes were recorded
    return rows


def _num(v: Any, fmt: str = ".3f") -> str:
    return "–" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, fmt)


def _coarse_note(row: dict[str, Any]) -> str:
    """What the first, coarser path of a check that was run again found ("" if none)."""
    if row.get("coarse_error"):
        return f" (increment 1/{STEPS}: failed)"
    coarse = row.get("coarse_critical")
    if coarse is None:
        return ""
    return f" (increment 1/{STEPS}: " + (
        f"loses stability at {coarse:.3f})" if critical(row) is None else f"{coarse:.3f})"
    )


def _lost(row: dict[str, Any], c: float) -> str:
    """Where a check loses stability, marked where it is extrapolated past the path's last
    state (``stop`` ``"critical_ahead"``: the increments failed just before it)."""
    ahead = row.get("stop") == "critical_ahead"
    return f"loses stability at {c:.3f}" + (" (extrapolated, ‡)" if ahead else "")


def _ahead_note(rows: list[dict]) -> list[str]:
    """The footnote of the ‡ mark, where a row carries it."""
    if not any(r.get("stop") == "critical_ahead" and not r["error"] for r in rows):
        return []
    return [
        "",
        "‡ The path's increments fail just before this critical point: every state"
        " reached is stable, and the lowest eigenvalue of the tangent falls to zero within"
        " the last increments ahead of the last one. The load factor given is where its"
        " square, extrapolated linearly, vanishes (exact at a limit point, slightly early at"
        " a bifurcation; `barhinge.analysis.buckling.critical_ahead`).",
    ]


def verdict(row: dict[str, Any]) -> str:
    if row["error"]:
        return f"failed: {row['error']}"
    c = critical(row)
    text = "carries the design load" if c is None else _lost(row, c)
    return text + _coarse_note(row)


def _by_roof(rows: list[dict]) -> dict[tuple[str, float], dict[str, dict]]:
    out: dict[tuple[str, float], dict[str, dict]] = {}
    for r in rows:
        out.setdefault((r["family"], float(r["state"])), {})[r["imperfection"]] = r
    return out


def table(rows: list[dict], perfect: dict[tuple[str, float], dict[str, str]]) -> str:
    names = list(AMPLITUDES)
    head = (
        "| roof | state | b (m) | linear buckling factor | perfect: deflection at 1 (mm) |"
        + "".join(f" {n}: w0 (mm) | {n}: result | {n}: deflection at end (mm) |" for n in names)
    )
    lines = [head, "|" + "---|" * (5 + 3 * len(names))]
    for (fam, state), by in _by_roof(rows).items():
        p = perfect[(fam, state)]
        first = by[names[0]]
        label = f"{fam} (baseline)" if fam in BASELINES else fam
        cells = [
            label,
            f"{state:g}",
            f"{first['panel_side']:.3f}",
            _num(first["buckling_factor"]),
            f"{1e3 * float(p['deflection_nonlinear']):.1f}",
        ]
        for n in names:
            r = by[n]
            cells += [f"{1e3 * r['amplitude']:.1f}", verdict(r),
                      _num(1e3 * r["deflection_nonlinear"], ".1f")]  # fmt: skip
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summary(rows: list[dict], perfect: dict[tuple[str, float], dict[str, str]]) -> str:
    parts = []
    for name in AMPLITUDES:
        mine = [r for r in rows if r["imperfection"] == name and r["family"] not in BASELINES]
        ok = [r for r in mine if not r["error"]]
        lost = [r for r in ok if critical(r) is not None]
        kept = [r for r in ok if critical(r) is None]
        failed = [r for r in mine if r["error"]]
        grow = [_growth(r, perfect) for r in kept]
        text = (
            f"- **w0 = {name}**: of the {len(mine)} roofs, {len(kept)} still carry the design"
            f" load and {len(lost)} {'loses' if len(lost) == 1 else 'lose'} stability below it"
            + (
                " ("
                + ", ".join(f"{r['family']} {r['state']:g} at {critical(r):.3f}" for r in lost)
                + ")"
                if lost
                else ""
            )
            + "."
        )
        if grow:
            text += (
                f" Where the imperfect roof carries the load, its largest deflection there is"
                f" {min(grow):.2f}–{max(grow):.2f} times the perfect roof's (median"
                f" {float(np.median(grow)):.2f})."
            )
        if failed:
            text += (
                " The solver did not complete "
                + ", ".join(f"{r['family']} {r['state']:g}" for r in failed)
                + " (named in the table)."
            )
        parts.append(text)
    return "\n".join(parts)


def section(rows: list[dict], perfect: dict[tuple[str, float], dict[str, str]]) -> str:
    from barhinge._publish import generated_stamp

    n_roofs = len({(r["family"], r["state"]) for r in rows if r["family"] not in BASELINES})
    return "\n".join(
        [
            START,
            "",
            generated_stamp("python studies/roofs/imperfection.py --publish"),
            "",
            f"Data: [roofs_imperfect.csv](roofs_imperfect.csv). The {n_roofs} roofs that carry"
            f" the design load on the refined path at m = {LEVEL} (table above; the flat sheet"
            " beside them as a baseline), each seeded with its first linear buckling mode under"
            " the design load, on the side the load pushes, at two amplitudes w0: b/200, the"
            " equivalent imperfection of a plate panel (EN 1993-1-5, Annex C, C.5; b = the"
            " median of the facets' shortest sides), and span/300, a global bow"
            " (EN 1993-1-1, Table 5.1, curve a, elastic analysis; here in the shape of the"
            " first mode). The imperfect roof is stress-free in its imperfect shape and"
            " followed by the same arc length to the design load or the first loss of"
            f" stability (first increment 1/{STEPS} of the load; a roof that loses stability"
            f" or whose path fails is followed again from 1/{FINE_STEPS}, since a coarse"
            " increment can pass the first critical point, and that path's result is given,"
            " the coarse one beside it); deflections are measured from the imperfect shape.",
            "",
            summary(rows, perfect),
            "",
            table(rows, perfect),
            *_ahead_note(rows),
            "",
            END,
        ]
    )


def sensitivity_roofs(rows: list[dict]) -> list[tuple[str, float]]:
    """One roof per family (baselines left out): the carried roof whose first linear
    buckling factor is lowest, the one the linear estimate calls the most sensitive."""
    best: dict[str, dict] = {}
    for r in rows:
        if r["family"] in BASELINES or r["mode"] != 1 or r["error"]:
            continue
        b = best.get(r["family"])
        if b is None or r["buckling_factor"] < b["buckling_factor"]:
            best[r["family"]] = r
    return [(r["family"], float(r["state"])) for r in best.values()]


def sensitivity_tasks() -> list[tuple[str, int]]:
    """(amplitude, mode) of the sensitivity study: modes 1 .. 4 at the code amplitudes, and
    the larger bows on mode 1."""
    modes = (1, *SENSITIVITY_MODES)
    return [(n, k) for k in modes for n in AMPLITUDES] + [(n, 1) for n in SENSITIVITY_AMPLITUDES]


def _growth(r: dict, perfect: dict[tuple[str, float], dict[str, str]]) -> float:
    """The imperfect roof's largest deflection at the design load over the perfect roof's."""
    return r["deflection_nonlinear"] / float(
        perfect[(r["family"], float(r["state"]))]["deflection_nonlinear"]
    )


def _effect(r: dict, perfect: dict[tuple[str, float], dict[str, str]]) -> str:
    """A check as a cell: where stability is lost, or the deflection at the design load over
    the perfect roof's."""
    if r["error"]:
        return "failed: " + r["error"]
    c = critical(r)
    text = _lost(r, c) if c is not None else f"× {_growth(r, perfect):.2f}"
    return text + _coarse_note(r)


def _severity(r: dict, perfect: dict[tuple[str, float], dict[str, str]]) -> float:
    """Order of harm: a loss of stability (earlier worse) before any deflection growth."""
    if r["error"]:
        return -np.inf
    c = critical(r)
    if c is not None:
        return 10.0 - c
    return _growth(r, perfect)


def sensitivity_section(rows: list[dict], perfect: dict[tuple[str, float], dict[str, str]]) -> str:
    """The sensitivity subsection: every selected roof at modes 1 .. 4 and the larger bows."""
    from barhinge._publish import generated_stamp

    by: dict[tuple[str, float], dict[tuple[str, int], dict]] = {}
    for r in rows:
        by.setdefault((r["family"], float(r["state"])), {})[(r["imperfection"], r["mode"])] = r
    modes = (1, *SENSITIVITY_MODES)
    names = list(AMPLITUDES)
    head = "| roof | state | mode | buckling factor |" + "".join(f" {n} |" for n in names)
    lines = [head, "|" + "---|" * (4 + len(names))]
    worst_mode = {}
    for (fam, state), got in by.items():
        for k in modes:
            first = got[(names[0], k)]
            cells = [fam, f"{state:g}", str(k), _num(first["buckling_factor"])]
            cells += [_effect(got[(n, k)], perfect) for n in names]
            lines.append("| " + " | ".join(cells) + " |")
        for n in names:
            worst = max(modes, key=lambda k, n=n: _severity(got[(n, k)], perfect))
            gain = _severity(got[(n, worst)], perfect) - _severity(got[(n, 1)], perfect)
            worst_mode[(fam, state, n)] = worst if gain > SENSITIVITY_MARGIN else 1
    amps = [*names, *SENSITIVITY_AMPLITUDES]
    head2 = "| roof | state |" + "".join(f" w0 = {n} |" for n in amps)
    lines2 = [head2, "|" + "---|" * (2 + len(amps))]
    for (fam, state), got in by.items():
        cells = [fam, f"{state:g}"] + [
            f"{1e3 * got[(n, 1)]['amplitude']:.1f} mm: {_effect(got[(n, 1)], perfect)}"
            for n in amps
        ]
        lines2.append("| " + " | ".join(cells) + " |")
    lost = [r for r in rows if not r["error"] and critical(r) is not None]
    bullets = []
    for (fam, state), got in by.items():
        worse = [
            f"{n}: mode {worst_mode[(fam, state, n)]}, "
            f"{_effect(got[(n, worst_mode[(fam, state, n)])], perfect)} against "
            f"{_effect(got[(n, 1)], perfect)}"
            for n in names
            if worst_mode[(fam, state, n)] != 1
        ]
        bullets.append(
            f"- {fam} {state:g}: "
            + ("; ".join(worse) if worse else "the first mode is the most harmful at both")
            + "."
        )
    summary_text = (
        "The most harmful mode at each code amplitude (the earliest loss of stability, else"
        " the largest deflection), where it is not the first (by more than"
        f" {SENSITIVITY_MARGIN:g} in the load factor of the loss of stability, or"
        f" {100 * SENSITIVITY_MARGIN:g} % of the perfect roof's deflection):\n\n"
        + "\n".join(bullets)
        + "\n\n"
        + (
            f"{len(lost)} of the {len(rows)} checks lose stability below the design load: "
            + ", ".join(
                f"{r['family']} {r['state']:g} (mode {r['mode']}, w0 = "
                f"{r['imperfection']}) at {critical(r):.3f}"
                for r in lost
            )  # fmt: skip
            + "."
            if lost
            else f"All {len(rows)} checks carry the design load."
        )
    )
    return "\n".join(
        [
            SENS_START,
            "",
            "### Sensitivity: higher buckling modes and larger imperfections",
            "",
            generated_stamp("python studies/roofs/imperfection.py --sensitivity --publish"),
            "",
            f"Data: [roofs_imperfect_sensitivity.csv](roofs_imperfect_sensitivity.csv). For"
            " each family, the carried roof with the lowest first buckling factor, seeded in"
            f" each of its first {len(modes)} buckling modes at the two code amplitudes, and in"
            " its first mode at larger global bows (EN 1993-1-6, 8.7.2 asks for the most"
            " unfavourable shape and amplitude). Same check as above; a cell gives where the"
            " imperfect roof loses stability, or its largest deflection at the design load"
            " over the perfect roof's (× …).",
            "",
            summary_text,
            "",
            "\n".join(lines),
            "",
            "First mode, growing amplitude:",
            "",
            "\n".join(lines2),
            *_ahead_note(rows),
            "",
            SENS_END,
        ]
    )


def write_csv(rows: list[dict], path: Path = CSV_OUT) -> None:
    cols = ["family", "state", "imperfection", "mode", "m", "n_dof", "panel_side", "amplitude",
            "buckling_factor",
            "stop", "critical_load_factor", "coarse_critical", "coarse_error", "first_increment",
            "load_factor_reached", "deflection_nonlinear",
            "states", "iterations", "time_s", "failure", "error"]  # fmt: skip
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in rows:
            c = critical(r)
            vals = {**r, "critical_load_factor": "" if c is None else f"{c:.6g}"}
            w.writerow(
                [
                    f"{vals.get(k):.6g}" if isinstance(vals.get(k), float) else vals.get(k, "")
                    for k in cols
                ]  # fmt: skip
            )


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two roofs at m = 2, no publish")
    ap.add_argument("--publish", action="store_true", help="rewrite the docs section and CSV")
    ap.add_argument("--cache", type=Path, default=None, help="JSON file of checked roofs")
    ap.add_argument("--only", default=None, help="comma-separated families (no publish)")
    ap.add_argument("--sensitivity", action="store_true",
                    help="also seed modes 2-4 and larger bows on one roof per family")  # fmt: skip
    a = ap.parse_args(argv)
    perfect = perfect_rows()
    roof_list = [k for k, r in perfect.items() if carries(r)]
    m = LEVEL
    if a.quick:
        roof_list, m = [("pleats", 90.0), ("waterbomb", 0.6)], 2
    if a.only:
        roof_list = [k for k in roof_list if k[0] in a.only.split(",")]
    cache = a.cache if a.cache else (None if a.quick else HERE / "imperfection_cache.json")
    rows = run(roof_list, m, cache)
    text = section(rows, perfect)
    print(text)
    if a.publish and not (a.quick or a.only):
        from barhinge._publish import write_between

        write_between(DOC, START, END, text[len(START) : -len(END)])
        write_csv(rows)
        print(f"wrote {DOC}, {CSV_OUT}")
    if a.sensitivity:
        sens = run(sensitivity_roofs(rows), m, cache, sensitivity_tasks())
        text = sensitivity_section(sens, perfect)
        print(text)
        if a.publish and not (a.quick or a.only):
            from barhinge._publish import write_between

            write_between(DOC, SENS_START, SENS_END, text[len(SENS_START) : -len(SENS_END)])
            write_csv(sens, SENS_CSV)
            print(f"wrote {DOC}, {SENS_CSV}")


if __name__ == "__main__":
    main()
