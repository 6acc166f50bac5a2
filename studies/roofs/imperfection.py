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

Run: ``python studies/roofs/imperfection.py [--quick] [--publish] [--cache=FILE]
[--only=FAMILY,...]``. Each roof is written to the cache as soon as it is checked (default
``imperfection_cache.json`` beside this script), so an interrupted run resumes. ``--publish``
writes the section of docs/roofs.md between the ``roofs-imperfect`` markers and
docs/roofs_imperfect.csv. ``--quick``: two roofs at m = 2 (a smoke run, nothing published).
"""

from __future__ import annotations

import argparse
import csv
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
    fraction, of = AMPLITUDES[name]
    return fraction * (panel_side(cp) if of == "panel" else roofs.SPAN)


def check(family: str, state: float, m: int, name: str, steps: int = STEPS) -> dict[str, Any]:
    """The roof's nonlinear check at ``m x m`` sub-panels per panel with the imperfection
    ``name`` (a key of ``AMPLITUDES``), first arc-length increment ``1 / steps``."""
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.analysis.imperfection import imperfect
    from barhinge.errors import BarhingeError
    from barhinge.scene import self_weight

    t0 = time.perf_counter()
    cp, flat_xy, _ = roofs.folded(family, state)
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[family]["axis"])
    model, S, _ = roofs.subdivided_roof(cp, sv, se, m, RULE)
    P = roofs.plan_load(model, roofs.Q)
    P = P + self_weight(model, roofs.DENSITY * roofs.MATERIAL["t"], g=(0.0, 0.0, -roofs.G))
    w0 = amplitude(name, cp)
    row: dict[str, Any] = {"family": family, "state": state, "m": m, "n_dof": 3 * model.n_nodes,
                           "imperfection": name, "panel_side": panel_side(cp),
                           "amplitude": w0}  # fmt: skip
    try:
        buck = linear_buckling(model, P, S, n_modes=1)
        row["buckling_factor"] = float(buck.factors[0])
        seeded = imperfect(model, buck.modes[0], w0, loads=P)
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


def run(roof_list: list[tuple[str, float]], m: int, cache: Path | None) -> list[dict]:
    """Check every roof at every amplitude (cached ones are read back), writing the cache
    after each check."""
    store: dict[str, dict] = (
        json.loads(cache.read_text()) if cache is not None and cache.exists() else {}
    )
    rows = []
    todo = [(fam, state, name) for name in AMPLITUDES for fam, state in roof_list]
    for k, (fam, state, name) in enumerate(todo, 1):
        key = f"{fam}/{state:g}/m{m}/{name}"
        if key not in store:
            print(f"[{k}/{len(todo)}] {fam} {state:g} (m = {m}, w0 = {name})", file=sys.stderr,
                  flush=True)  # fmt: skip
            store[key] = check(fam, state, m, name)
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))
        coarse = store[key]
        coarse_increment = coarse.get("first_increment", 1.0 / STEPS)
        if critical(coarse) is not None and coarse_increment > 1.0 / FINE_STEPS:
            print(f"  {fam} {state:g} loses stability: again with increment 1/{FINE_STEPS}",
                  file=sys.stderr, flush=True)  # fmt: skip
            fine = check(fam, state, m, name, steps=FINE_STEPS)
            fine["coarse_critical"] = critical(coarse)
            store[key] = fine
            if cache is not None:
                cache.write_text(json.dumps(store, indent=0))
        rows.append(store[key])
    return rows


def _num(v: Any, fmt: str = ".3f") -> str:
    return "–" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, fmt)


def verdict(row: dict[str, Any]) -> str:
    if row["error"]:
        return f"failed: {row['error']}"
    c = critical(row)
    if c is None:
        coarse = row.get("coarse_critical")
        return "carries the design load" + (
            f" (increment 1/{STEPS}: loses stability at {coarse:.3f})" if coarse else ""
        )
    text = f"loses stability at {c:.3f}"
    if row.get("coarse_critical") is not None:
        text += f" (increment 1/{STEPS}: {row['coarse_critical']:.3f})"
    return text


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
        grow = [
            r["deflection_nonlinear"]
            / float(perfect[(r["family"], float(r["state"]))]["deflection_nonlinear"])
            for r in kept
        ]
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
            f" is followed again from 1/{FINE_STEPS}, since a coarse increment can pass the"
            " first critical point, and that path's result is given, the coarse one"
            " beside it); deflections are measured from the imperfect shape.",
            "",
            summary(rows, perfect),
            "",
            table(rows, perfect),
            "",
            END,
        ]
    )


def write_csv(rows: list[dict], path: Path = CSV_OUT) -> None:
    cols = ["family", "state", "imperfection", "m", "n_dof", "panel_side", "amplitude",
            "buckling_factor",
            "stop", "critical_load_factor", "coarse_critical", "first_increment",
            "load_factor_reached", "deflection_nonlinear",
            "states", "iterations", "time_s", "error"]  # fmt: skip
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


if __name__ == "__main__":
    main()
