"""Six tessellations driven by actuators on control curves and surfaces, on one model.

For each pattern (three Miura-ori variations, a Russo-style optical-illusion pleat, Yoshimura
and Ron Resch) a section line across the middle of the flat sheet (along +x) crosses the
creases at points P; every ``spacing``-th crossing is an actuator, driven to

    rho_i = s_i * 30 deg + Phi_i,    s_i = +1 valley, -1 mountain,

with ``Phi_i`` the turning angle that puts the actuator points on a control curve (circle,
parabola or spline) of apex curvature ``kappa = kappa_L / L`` (``L`` = sheet width along the
section). A control surface (two section lines, along x and y, with curvatures ``kappa_L / L``
and ``ky_L / L_y``) asks for synclastic or anticlastic forms.

Every cell is folded by the energy-minimising rigid limit (``bh.rigid_fold`` with the
bar-and-hinge model's fold stiffnesses; incompatible targets met in least squares, the misfit
recorded), and a subset also by the bar-and-hinge model at several stiffness ratios (bars and
panel bending ``r`` times the default) to show how it approaches the rigid limit. A second
part compares actuators chosen by the DOF analysis (``bh.dof``) with section-line placement
at the same count (form error against a reference rigid form).

Run ``python studies/transformations/run.py --help``. A rerun skips finished runs.
``--publish`` writes the tables, figures and numbers of docs/transformations.md (full mode) or
the published quick numbers docs/transformations-quick.json (with ``--quick``), which
tests/studies/test_studies_transformations.py recomputes.
"""

from __future__ import annotations

import argparse
import datetime
import json
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
from transform import COMPLIANT_K, PATTERNS, make_pattern  # noqa: E402

DOC = ROOT / "docs" / "transformations.md"
#: log-log slope of the distance to the rigid limit against the stiffness ratio at or below
#: which a compliant cell counts as converging to it (``1/r`` is -1)
CONVERGING_SLOPE = -0.5
QUICK_JSON = ROOT / "docs" / "transformations-quick.json"
FULL_JSON = ROOT / "docs" / "transformations.json"


# ------------------------------------------------------------------------------ the runs
# inverse design runs: target principal curvatures (k1 L, k2 L) or a target surface; a
# saddle, a dome, an arch, targets a developable pattern cannot take, and the forward-
# difference runs beside the exact-sensitivity ones (speed-up)
def _d(pattern, k1=None, k2=None, **kw) -> dict:
    return {"kind": "design", "pattern": pattern, "target_k1L": k1, "target_k2L": k2, **kw}


DESIGNS_QUICK = [
    _d("yoshimura", 0.2, -3.0),
    _d("miura_arc", 0.0, -0.6),
    _d("miura", -0.5, -0.5),
    _d("yoshimura", 0.2, -2.0, control="surface"),
]
DESIGNS = [
    _d("yoshimura", 0.5, -4.0),
    _d("yoshimura", 0.5, -4.0, jac="fd"),
    _d("resch", -0.5, -1.5),
    _d("resch", -0.5, -1.5, jac="fd"),
    _d("resch", surface="cap", kx_L=-1.2, ky_L=0.0),
    _d("yoshimura", surface="paraboloid", kx_L=2.0, ky_L=1.0),
    _d("miura_arc", 0.0, -0.6),
    _d("miura_arc", -0.5, -0.5),
    _d("miura", -0.5, -0.5),
    _d("russo_pleat", 0.3, -0.3),
    # control parameters (base fold, control-surface curvatures) as the design variables
    _d("yoshimura", 0.5, -3.0, control="surface"),
    _d("yoshimura", 0.5, -3.0, control="surface", jac="fd"),
    _d("resch", -0.5, -1.5, control="surface"),
    _d("miura_arc", 0.0, -0.6, control="surface"),
    _d("miura", -0.5, -0.5, control="surface"),
]


def settings(quick: bool) -> dict:
    """Grid and subsets of one mode."""
    pats = list(PATTERNS)
    if quick:
        return {
            "spacings": [1],
            "kappa_L": [0.0, 1.0],
            # the 1/r regime of the plate-calibrated panels starts near r = 100 for the Miura
            "ratios": [100.0, 1000.0],
            "bh_cells": [
                ("miura", 1, 0.0),
                ("miura", 1, 1.0),
                ("yoshimura", 1, 1.0),
                ("resch", 1, 1.0),
            ],
            "curve_patterns": ["miura", "resch"],
            "surface_patterns": ["miura", "resch"],
            "surfaces": [(0.0, 0.0), (1.0, 1.0), (1.0, -1.0)],
            "placement_patterns": ["miura", "yoshimura"],
            "designs": DESIGNS_QUICK,
            "steps": 6,
            # compliant actuators: the rigid limit and the bar-and-hinge model minimise the
            # same energy; the springs (100x the folds) need stiffer panels than held cells
            "compliant_cells": [("miura", 1, 1.0)],
            "compliant_ratios": [1e4, 1e5],
        }
    kl = [-1.0, 0.0, 0.5, 1.0, 1.5]
    return {
        "spacings": [1, 2, 3],
        "kappa_L": kl,
        "ratios": [10.0, 100.0, 1000.0],
        "bh_cells": [(p, 1, k) for p in pats for k in kl],
        "curve_patterns": pats,
        "surface_patterns": pats,
        "surfaces": [(0.0, 0.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)],
        "placement_patterns": pats,
        "designs": DESIGNS,
        "steps": 8,
        "compliant_cells": [(p, 1, k) for p in pats for k in (0.0, 1.0)],
        "compliant_ratios": [1e3, 1e4, 1e5],
    }


def _form(
    pattern, spacing=1, curve="circle", kappa_L=0.0, ky_L=None, model="rigid", actuator_k=None
):
    out = {
        "kind": "form",
        "pattern": pattern,
        "spacing": spacing,
        "curve": curve,
        "kappa_L": kappa_L,
        "ky_L": ky_L,
        "model": model,
    }
    if actuator_k is not None:  # compliant actuators (held ones keep their run keys)
        out["actuator_k"] = actuator_k
    return out


def placement_counts(pattern: str, quick: bool) -> list[int]:
    import barhinge as bh

    n = len(bh.dof(make_pattern(pattern, quick)).mechanism.actuators)
    return sorted({1, max(1, n // 2), n})


def runs(quick: bool) -> list[dict]:
    """Every run of one mode (each a point of the sweep)."""
    s = settings(quick)
    pts = [
        _form(p, sp, "circle", k) for p in PATTERNS for sp in s["spacings"] for k in s["kappa_L"]
    ]
    pts += [_form(p, sp, "circle", k, model=r) for p, sp, k in s["bh_cells"] for r in s["ratios"]]
    for p, sp, k in s["compliant_cells"]:
        for m in ["rigid", *s["compliant_ratios"]]:
            pts.append(_form(p, sp, "circle", k, model=m, actuator_k=COMPLIANT_K))
    for p in s["curve_patterns"]:
        for c in ("parabola", "spline"):
            pts.append(_form(p, 1, c, 1.0))
            if not quick:
                pts.append(_form(p, 1, c, 1.0, model=100.0))
    for p in s["surface_patterns"]:
        for kx, ky in s["surfaces"]:
            pts.append(_form(p, 1, "parabola", kx, ky))
            if not quick:
                pts.append(_form(p, 1, "parabola", kx, ky, model=100.0))
    for p in s["placement_patterns"]:
        for n in placement_counts(p, quick):
            for pl in ("dof", "section"):
                pts.append({"kind": "placement", "pattern": p, "count": n, "placement": pl})
    pts += [dict(d) for d in s["designs"]]
    return pts


def run(quick: bool, out: Path, serial: bool, workers: int | None, retry_failed: bool):
    from barhinge.sweep import Study, read_records, run_study

    study = Study(
        function="cells:cell",
        points=tuple(runs(quick)),
        fixed={"quick": quick, "steps": settings(quick)["steps"]},
        name="transformations-quick" if quick else "transformations",
        batch_size=1,
        paths=(str(HERE),),
    )
    report = run_study(
        study,
        out=out,
        mode="serial" if serial else "local",
        workers=workers,
        retry_failed=retry_failed,
    )
    return report, read_records(out)


# ------------------------------------------------------------------------------ results
def key(prm: dict) -> tuple:
    """Hashable id of a run from its parameters (without quick/steps)."""
    return tuple((k, prm[k]) for k in sorted(prm) if k not in ("quick", "steps"))


def index(records: dict) -> dict:
    return {key(r["params"]): r for r in records.values()}


def get(ix: dict, **prm) -> dict | None:
    """The result of one run (None if it failed or is missing)."""
    full = prm if prm.get("kind") in ("placement", "design") else _form(**prm)
    rec = ix.get(key(full))
    return rec["result"] if rec and rec["status"] == "ok" else None


def slope(ratios: list[float], errors: list[float]) -> float:
    """Log-log slope of the distance to the rigid limit against the stiffness ratio."""
    e = np.asarray(errors, float)
    if len(e) < 2 or np.any(~np.isfinite(e)) or np.any(e <= 0):
        return float("nan")
    return float(np.polyfit(np.log(ratios), np.log(e), 1)[0])


def convergence(ix: dict, s: dict, compliant: bool = False) -> list[dict]:
    """Per bar-and-hinge cell: distance of the fold angles and of K L^2 to the rigid limit
    (held actuators, or with ``compliant`` the compliant cells)."""
    rows = []
    cells, ratios = (
        (s["compliant_cells"], s["compliant_ratios"]) if compliant else (s["bh_cells"], s["ratios"])
    )
    kw = {"actuator_k": COMPLIANT_K} if compliant else {}
    for p, sp, k in cells:
        rig = get(ix, pattern=p, spacing=sp, kappa_L=k, **kw)
        bhs = [get(ix, pattern=p, spacing=sp, kappa_L=k, model=r, **kw) for r in ratios]
        if rig is None or any(b is None for b in bhs):
            rows.append({"pattern": p, "spacing": sp, "kappa_L": k, "ok": False})
            continue
        d = [float(np.max(np.abs(np.asarray(b["rho_deg"]) - rig["rho_deg"]))) for b in bhs]
        rows.append(
            {
                "pattern": p,
                "spacing": sp,
                "kappa_L": k,
                "ok": True,
                "misfit_deg": rig["actuator_misfit_deg"],
                "KL2_rigid": rig["KL2"],
                "KL2_bh": [b["KL2"] for b in bhs],
                "misfit_bh": [b["actuator_misfit_deg"] for b in bhs],
                "drho_deg": d,
                "slope": slope(ratios, d),
            }
        )
    return rows


def placement_rows(ix: dict, s: dict, quick: bool) -> list[dict]:
    rows = []
    for p in s["placement_patterns"]:
        counts = placement_counts(p, quick)
        row = {"pattern": p, "n_dof": counts[-1], "counts": counts}
        for pl in ("dof", "section"):
            res = [get(ix, kind="placement", pattern=p, count=n, placement=pl) for n in counts]
            row[pl] = [None if r is None else r["form_error_deg"] for r in res]
            fixed = [
                n
                for n, r in zip(counts, res, strict=True)
                if r is not None and r["form_error_deg"] < 1e-3
            ]
            row[f"{pl}_needed"] = fixed[0] if fixed else None
            row[f"{pl}_KL2"] = [None if r is None else r["KL2"] for r in res]
        ref = get(ix, kind="placement", pattern=p, count=counts[-1], placement="dof")
        row["KL2_reference"] = None if ref is None else ref["KL2_reference"]
        rows.append(row)
    return rows


def headline(records: dict, quick: bool) -> dict:
    """The numbers a test recomputes: per run key, the main scalars."""
    out = {}
    for rec in records.values():
        if rec["status"] != "ok":
            continue
        prm = {k: v for k, v in rec["params"].items() if k not in ("quick", "steps")}
        r = rec["result"]
        keep = (
            "KL2",
            "actuator_misfit_deg",
            "form_error_deg",
            "model_label",
            "relative_error",
            "reached",
            "achieved",
            "variables",
        )
        out[json.dumps(prm, sort_keys=True)] = {k: r[k] for k in keep if k in r}
    return out


# ------------------------------------------------------------------------------ tables
def _f(v, fmt=".3g") -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    if isinstance(v, float) and abs(v) < 5e-10:
        return "0"
    return format(v, fmt).replace("-", "−")


def table_rigid(ix: dict, s: dict) -> str:
    """K L^2 of the rigid limit and the actuator misfit, per pattern x spacing x kappa L."""
    head = "| pattern | spacing | " + " | ".join(f"κL = {_f(k, 'g')}" for k in s["kappa_L"]) + " |"
    lines = [head, "|---|---|" + "---|" * len(s["kappa_L"])]
    for p in PATTERNS:
        for sp in s["spacings"]:
            cells = []
            for k in s["kappa_L"]:
                r = get(ix, pattern=p, spacing=sp, kappa_L=k)
                if r is None:
                    cells.append("failed")
                    continue
                m = r["actuator_misfit_deg"]
                cells.append(_f(r["KL2"]) + ("" if m < 1e-6 else f" ({_f(m, '.2g')}°)"))
            lines.append(f"| {p} | {sp} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def table_convergence(rows: list[dict], s: dict, compliant: bool = False) -> str:
    rs = s["compliant_ratios"] if compliant else s["ratios"]
    head = (
        "| pattern | κL | misfit (deg) | K L² rigid | "
        + " | ".join(f"K L² r = {r:g}" for r in rs)
        + " | "
        + " | ".join(f"max Δρ r = {r:g}" for r in rs)
        + " | slope |"
    )
    lines = [head, "|---|---|---|---|" + "---|" * (2 * len(rs) + 1)]
    for row in rows:
        if not row["ok"]:
            lines.append(
                f"| {row['pattern']} | {_f(row['kappa_L'], 'g')} | failed |"
                + " |" * (2 * len(rs) + 2)
            )
            continue
        lines.append(
            f"| {row['pattern']} | {_f(row['kappa_L'], 'g')} | {_f(row['misfit_deg'], '.2g')} | "
            f"{_f(row['KL2_rigid'])} | "
            + " | ".join(_f(v) for v in row["KL2_bh"])
            + " | "
            + " | ".join(_f(v, ".2g") for v in row["drho_deg"])
            + f" | {_f(row['slope'], '.2f')} |"
        )
    return "\n".join(lines)


def table_curves(ix: dict, s: dict) -> str:
    lines = ["| pattern | model | circle | parabola | spline |", "|---|---|---|---|---|"]
    for p in s["curve_patterns"]:
        for model in ("rigid", 100.0):
            res = [
                get(ix, pattern=p, curve=c, kappa_L=1.0, model=model)
                for c in ("circle", "parabola", "spline")
            ]
            if all(r is None for r in res):
                continue
            name = "rigid limit" if model == "rigid" else f"bar-and-hinge r = {model:g}"
            cells = [
                "–"
                if r is None
                else _f(r["KL2"])
                + (
                    ""
                    if r["actuator_misfit_deg"] < 1e-6
                    else f" ({_f(r['actuator_misfit_deg'], '.2g')}°)"
                )
                for r in res
            ]
            lines.append(f"| {p} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def table_surfaces(ix: dict, s: dict) -> str:
    sf = s["surfaces"]
    head = (
        "| pattern | model | "
        + " | ".join(f"κxL, κyL = {_f(a, 'g')}, {_f(b, 'g')}" for a, b in sf)
        + " |"
    )
    lines = [head, "|---|---|" + "---|" * len(sf)]
    for p in s["surface_patterns"]:
        for model in ("rigid", 100.0):
            res = [
                get(ix, pattern=p, curve="parabola", kappa_L=a, ky_L=b, model=model) for a, b in sf
            ]
            if all(r is None for r in res):
                continue
            name = "rigid limit" if model == "rigid" else f"bar-and-hinge r = {model:g}"
            cells = [
                "–" if r is None else f"{_f(r['KL2'])} ({_f(r['actuator_misfit_deg'], '.2g')}°)"
                for r in res
            ]
            lines.append(f"| {p} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def table_placement(rows: list[dict]) -> str:
    lines = [
        "| pattern | DOF (actuators of bh.dof) | counts | form error, bh.dof placement (deg) "
        "| form error, section lines (deg) | needed: bh.dof | needed: section |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['pattern']} | {r['n_dof']} | {', '.join(map(str, r['counts']))} | "
            + ", ".join(_f(v, ".2g") for v in r["dof"])
            + " | "
            + ", ".join(_f(v, ".2g") for v in r["section"])
            + " | "
            + f"{r['dof_needed'] or 'not reached'} | {r['section_needed'] or 'not reached'} |"
        )
    return "\n".join(lines)


def table_design(ix: dict, s: dict) -> str:
    lines = [
        "| pattern | vertices | control | actuators | target | target k1 L, k2 L | "
        "achieved k1 L, k2 L | error | reached | derivatives | rigid folds | seconds | why not |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for d in s["designs"]:
        r = get(ix, **d)
        what = (
            f"{d['surface']} κxL = {_f(d['kx_L'], 'g')}, κyL = {_f(d['ky_L'], 'g')}"
            if d.get("surface")
            else "curvatures"
        )
        if r is None:
            lines.append(f"| {d['pattern']} | | | | {what} | | failed | | | | | | |")
            continue
        a, t = r["achieved"], r["target"]
        v = r.get("variables")
        control = (
            "angles of the bh.dof actuators"
            if v is None
            else f"surface: β = {v['beta_deg']:.3g}°, κxL = {_f(v['kx_L'])}, κyL = {_f(v['ky_L'])}"
        )
        lines.append(
            f"| {d['pattern']} | {r['n_vertices']} | {control} | {r['n_actuators']} | {what} | "
            f"{_f(t[0], '.4g')}, {_f(t[1], '.4g')} | {_f(a[0], '.4g')}, {_f(a[1], '.4g')} | "
            f"{_f(100 * r['relative_error'], '.2g')} % | {'yes' if r['reached'] else 'no'} | "
            f"{'exact' if r['jac'] == 'exact' else 'forward differences'} | "
            f"{r['evaluations']} | {r['seconds']:.1f} | {r['reason'] or ''} |"
        )
    return "\n".join(lines)


def design_speedups(ix: dict, s: dict) -> str:
    """Wall-time ratio forward differences / exact sensitivities per design run pair."""
    out = []
    for d in s["designs"]:
        if d.get("jac") != "fd":
            continue
        ex = {k: v for k, v in d.items() if k != "jac"}
        a, b = get(ix, **ex), get(ix, **d)
        if a is not None and b is not None:
            out.append(
                f"* {d['pattern']}: {b['seconds']:.1f} s ({b['evaluations']} rigid folds) with "
                f"forward differences, {a['seconds']:.1f} s ({a['evaluations']}) with exact "
                f"sensitivities: {b['seconds'] / a['seconds']:.1f}× faster"
            )
    return "\n".join(out) or "none"


def table_signs(ix: dict, records: dict) -> str:
    """Range of K L^2 per pattern over every form run, by model."""
    lines = [
        "| pattern | model | runs | K L² min | K L² max | any K > 0 |",
        "|---|---|---|---|---|---|",
    ]
    for p in PATTERNS:
        for m in ("rigid", "bar-hinge"):
            for compliant in (False, True):
                ks = form_KL2(records, p, m, compliant)
                if not ks:
                    continue
                pos = max(ks) > 1e-3
                name = ("rigid limit" if m == "rigid" else "bar-and-hinge") + (
                    ", compliant actuators" if compliant else ""
                )
                lines.append(
                    f"| {p} | {name} | {len(ks)} | {_f(min(ks))} | {_f(max(ks))} | "
                    f"{'yes' if pos else 'no'} |"
                )
    return "\n".join(lines)


def form_KL2(records: dict, pattern: str, model: str, compliant: bool) -> list[float]:
    """K L^2 of every finished form run of ``pattern`` by ``model`` ("rigid" or
    "bar-hinge"), with held or compliant actuators."""
    return [
        r["result"]["KL2"]
        for r in records.values()
        if r["params"]["kind"] == "form"
        and r["params"]["pattern"] == pattern
        and r["status"] == "ok"
        and r["result"]["model"] == model
        and (r["params"].get("actuator_k") is not None) == compliant
    ]


# ------------------------------------------------------------------------------ findings
MIURA_FAMILY = ("miura", "miura_arc", "miura_nonuniform", "russo_pleat")


def _range(v: list[float], fmt: str = ".2g") -> str:
    v = [x for x in v if x is not None and np.isfinite(x)]
    if not v:
        return "–"
    lo, hi = min(v), max(v)
    return _f(lo, fmt) if _f(lo, fmt) == _f(hi, fmt) else f"{_f(lo, fmt)} to {_f(hi, fmt)}"


def findings(ix: dict, s: dict, records: dict, conv: list, comp: list, place: list) -> str:
    """The findings of the study, every number computed from the records."""
    out = []
    rig = [
        get(ix, pattern=p, spacing=sp, kappa_L=k)
        for p in MIURA_FAMILY
        for sp in s["spacings"]
        for k in s["kappa_L"]
    ]
    rig = [r for r in rig if r is not None]
    mis = [r["actuator_misfit_deg"] for r in rig if r["actuator_misfit_deg"] > 1e-6]
    kmax = max((abs(r["KL2"]) for r in rig), default=float("nan"))
    out.append(
        "**The Miura family cannot be steered by a curve with rigid panels.** The Miura-ori, "
        "the arc and non-uniform Miura-ori and the Russo pleat have one rigid DOF, so two or "
        "more actuators with different targets over-determine them. The rigid limit meets "
        f"curved targets only in least squares ({len(mis)} of {len(rig)} cells, misfit "
        f"{_range(mis)}°) and stays globally developable (|K L²| ≤ {_f(kmax, '.1g')})."
    )
    held_in = [r for r in conv if r["ok"] and r["misfit_deg"] > 1e-6]
    held_ok = [r for r in conv if r["ok"] and r["misfit_deg"] <= 1e-6]
    bh_miura = form_KL2(records, "miura", "bar-hinge", False)
    out.append(
        "**Held actuators: the bar-and-hinge model reaches incompatible targets only by "
        "straining.** Where the rigid limit has a misfit, the distance of the bar-and-hinge "
        "model to it tends to that misfit instead of to zero (log-log slopes "
        f"{_range([r['slope'] for r in held_in])} against the stiffness ratio, {len(held_in)} "
        "cells): stiffer panels raise the actuator moments, they do not make the form rigid. "
        "Where the targets are compatible the distance falls with r (slopes "
        f"{_range([r['slope'] for r in held_ok])} over {len(held_ok)} cells, −1 being `1/r`; "
        f"distances at r = {s['ratios'][-1]:g}: {_range([r['drho_deg'][-1] for r in held_ok])}°)."
        + (
            f" Every held bar-and-hinge Miura-ori run has `K < 0` (largest K L² "
            f"{_f(max(bh_miura), '.2g')}), the sign of Schenk & Guest's saddle."
            if bh_miura and max(bh_miura) < 0
            else ""
        )
    )
    c_ok = [r for r in comp if r["ok"]]
    # a cell converges when its distance to the rigid limit falls at least like r^-1/2
    c_conv = [r for r in c_ok if r["slope"] <= CONVERGING_SLOPE]
    c_other = [r for r in c_ok if not r["slope"] <= CONVERGING_SLOPE]
    c_in = [r for r in c_conv if r["misfit_deg"] > 1e-6]
    last = [r["drho_deg"][-1] for r in c_conv]
    fam_last = [
        abs(r["KL2_bh"][-1]) for r in c_conv if r["pattern"] in MIURA_FAMILY and r["kappa_L"] != 0
    ]
    where = (
        f"every cell that finished ({len(c_ok)} of {len(comp)}"
        if len(c_conv) == len(c_ok)
        else f"{len(c_conv)} of the {len(c_ok)} cells that finished (of {len(comp)}"
    )
    out.append(
        "**Compliant actuators make both models answer the same question.** With the actuators "
        f"springs of {COMPLIANT_K:g} × the stiffest fold in both models, the bar-and-hinge model "
        f"converges to the rigid limit in {where}; the springs stretch "
        f"{_range([r['misfit_deg'] for r in c_in])}° in the rigid limit): slopes "
        f"{_range([r['slope'] for r in c_conv])}, largest fold-angle distance "
        f"{_range(last)}° at r = {s['compliant_ratios'][-1]:g}."
        + (
            " The saddles of the held Miura family under curved targets vanish with it: "
            f"|K L²| ≤ {_f(max(fam_last), '.2g')} at that ratio. They came from the strained "
            "panels, not from the control."
            if fam_last
            else ""
        )
        + (
            f" In {len(c_other)} cell(s) ("
            + ", ".join(f"{r['pattern']} κL = {r['kappa_L']:g}" for r in c_other)
            + ") the two models settle in different equilibria: the distance stays at "
            f"{_range([r['drho_deg'][-1] for r in c_other])}° whatever the stiffness ratio "
            f"(slopes {_range([r['slope'] for r in c_other])}); the sheet is multistable there "
            "and each solver's path meets another energy minimum."
            if c_other
            else ""
        )
    )
    signs = []
    for p in PATTERNS:
        ks = [k for m in ("rigid", "bar-hinge") for c in (False, True)
              for k in form_KL2(records, p, m, c)]  # fmt: skip
        if ks:
            signs.append((p, max(ks), min(ks)))
    never = [p for p, hi, _ in signs if hi <= 1e-3]
    both = [f"{p} (K L² up to {_f(hi, '.2g')})" for p, hi, lo in signs if hi > 1e-3 and lo < -1e-3]
    out.append(
        "**Which sign of K a sheet can take is the pattern's, not the curve's.** "
        + (
            f"No run of {', '.join(never)} has K L² > 10⁻³, rigid or strained, held or compliant. "
            if never
            else ""
        )  # fmt: skip
        + (f"Both signs: {', '.join(both)}. " if both else "")
        + "Circle, parabola and spline of the same apex curvature give similar forms (table "
        "above): what matters is whether the targets are compatible."
    )
    multi = [r for r in place if r["n_dof"] > 1]
    if multi:

        def needs(r: dict, key: str) -> str:
            n = r[f"{key}_needed"]
            return f"fix it with {n}" if n else f"do not fix it with {r['counts'][-1]}"

        parts = [
            f"{r['pattern']} ({r['n_dof']} DOF): the bh.dof actuators {needs(r, 'dof')}, "
            f"section-line creases {needs(r, 'section')} (form error at "
            f"{r['counts'][-1]}: {_f(r['section'][-1], '.2g')}°)"
            for r in multi
        ]
        out.append(
            "**Actuators from the DOF analysis fix the form; section lines need not.** "
            + "; ".join(parts)
            + ". For the one-DOF patterns any one actuator fixes the form."
        )
    des = [(d, get(ix, **d)) for d in s["designs"] if d.get("jac") != "fd"]
    done = [(d, r) for d, r in des if r is not None]

    def name(d: dict) -> str:
        what = (
            f"{d['surface']} surface" if d.get("surface")
            else f"k1 L, k2 L = {_f(d['target_k1L'], 'g')}, {_f(d['target_k2L'], 'g')}"
        )  # fmt: skip
        return f"{d['pattern']} ({what}, control: {d.get('control', 'actuators')})"

    hit = [name(d) for d, r in done if r["reached"]]
    miss = [f"{name(d)}: {r['reason']}" for d, r in done if not r["reached"]]
    out.append(
        f"**Design from a target.** {len(hit)} of {len(des)} designs reach their target within "
        f"5 %: {', '.join(hit) or 'none'}. "
        + ("Not reached, with the reason: " + "; ".join(miss) + "." if miss else "")
    )
    lo_col = [get(ix, pattern=p, spacing=1, kappa_L=-1.0) for p in MIURA_FAMILY]
    hi_col = [get(ix, pattern=p, spacing=1, kappa_L=1.0) for p in MIURA_FAMILY]
    if -1.0 in s["kappa_L"] and 1.0 in s["kappa_L"]:
        a = [r["actuator_misfit_deg"] for r in lo_col if r is not None]
        b = [r["actuator_misfit_deg"] for r in hi_col if r is not None]
        if a and b and max(a) > 2.0 * max(b):
            tail = (
                ": the continuation from the flat state lands on another rigid mode there (a "
                "partly unfolded sheet, visible in the forms figure), a local minimum of the "
                "misfit, not the best rigid fit."
            )
        else:
            tail = ": curves bent either way are fitted about equally well."
        out.append(
            f"**The κL = −1 column of the Miura family** has least-squares misfits of "
            f"{_range(a)}° against {_range(b)}° at κL = +1" + tail
        )
    n_failed = sum(r["status"] != "ok" for r in records.values())
    out.append(
        f"**Failures**: {n_failed} of {len(records)} runs; each is listed above with its "
        "reason, and no run falls back to another model silently."
    )
    return "\n".join(f"{i}. {t}" for i, t in enumerate(out, 1))


# ------------------------------------------------------------------------------ figures
def figure_convergence(
    rows: list[dict], ratios: list[float], path: Path, stamp: str, title: str, solid: bool = False
) -> None:
    """Distance to the rigid limit against the stiffness ratio per cell (dotted: the rigid
    limit misses the targets, unless ``solid``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5), layout="constrained")
    colour = {p: f"C{i}" for i, p in enumerate(PATTERNS)}
    seen = set()
    for row in rows:
        if row["ok"]:
            ls = "-" if solid or row["misfit_deg"] < 1e-6 else ":"
            p = row["pattern"]
            ax.loglog(ratios, np.maximum(row["drho_deg"], 1e-12), "o" + ls, ms=3,
                      color=colour[p], label=None if p in seen else p)  # fmt: skip
            seen.add(p)
    r = np.asarray(ratios)
    ax.loglog(r, 10 * r[0] / r, "k--", lw=0.8, label="slope −1")
    ax.set(
        xlabel="stiffness ratio r (bars and panels / default)",
        ylabel="max |ρ_bh − ρ_rigid| over creases (deg)",
        title=title,
    )
    ax.title.set_fontsize(8)
    ax.legend(fontsize=6, ncol=2)
    fig.text(0.99, 0.005, stamp, ha="right", fontsize=6, color="0.4")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_forms(ix: dict, s: dict, quick: bool, path: Path, stamp: str) -> None:
    """Rigid-limit forms: rows patterns, columns kappa L (spacing 1)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    kl = s["kappa_L"]
    fig = plt.figure(figsize=(2.2 * len(kl), 2.0 * len(PATTERNS)), layout="constrained")
    for i, p in enumerate(PATTERNS):
        cp = make_pattern(p, quick)
        for j, k in enumerate(kl):
            ax = fig.add_subplot(len(PATTERNS), len(kl), i * len(kl) + j + 1, projection="3d")
            ax.set_axis_off()
            r = get(ix, pattern=p, spacing=1, kappa_L=k)
            if r is None:
                ax.set_title(f"{p} κL={k:g}: failed", fontsize=7)
                continue
            X = np.asarray(r["X"])
            ax.add_collection3d(
                Poly3DCollection(
                    [X[list(f)] for f in cp.faces],
                    facecolor="#9ec5e8",
                    edgecolor="k",
                    linewidths=0.2,
                )
            )
            lo, hi = X.min(0), X.max(0)
            c, h = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo))
            ax.set(xlim=(c[0] - h, c[0] + h), ylim=(c[1] - h, c[1] + h), zlim=(c[2] - h, c[2] + h))
            ax.view_init(elev=25, azim=-60)
            ax.set_title(
                f"{p} κL={k:g}\nKL²={_f(r['KL2'], '.2g')}, misfit {r['actuator_misfit_deg']:.2g}°",
                fontsize=6,
            )
    fig.suptitle(f"Rigid-limit forms (spacing 1) — {stamp}", fontsize=8)
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------ docs
def replace_block(text: str, name: str, content: str) -> str:
    """Replace the text between ``<!-- BEGIN name -->`` and ``<!-- END name -->``."""
    pat = re.compile(rf"(<!-- BEGIN {name} -->\n).*?(<!-- END {name} -->)", re.S)
    if not pat.search(text):
        raise KeyError(f"docs/transformations.md has no block {name!r}")
    return pat.sub(lambda m: m.group(1) + content.rstrip() + "\n" + m.group(2), text)


def _describe(prm: dict) -> str:
    """``pattern kind, key = value, ...`` of a run (for the list of failed runs)."""
    skip = ("pattern", "kind", "quick", "steps")
    rest = ", ".join(f"{k} = {v}" for k, v in prm.items() if k not in skip and v is not None)
    return f"{prm['pattern']} ({prm['kind']}): {rest}"


def stamp_text() -> str:
    import barhinge

    return f"barhinge {barhinge.__version__}, {datetime.date.today().isoformat()}"


def publish(records: dict, quick: bool) -> None:
    s = settings(quick)
    ix = index(records)
    stamp = stamp_text()
    data = {"stamp": stamp, "quick": quick, "runs": headline(records, quick)}
    if quick:
        QUICK_JSON.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
        return
    FULL_JSON.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    conv = convergence(ix, s)
    comp = convergence(ix, s, compliant=True)
    img = ROOT / "docs" / "img"
    figure_convergence(
        conv,
        s["ratios"],
        img / "transformations_convergence.png",
        stamp,
        "held actuators: bar-and-hinge → rigid limit (solid: compatible targets; dotted: "
        "least squares)",
    )
    figure_convergence(
        comp,
        s["compliant_ratios"],
        img / "transformations_compliant.png",
        stamp,
        f"compliant actuators ({COMPLIANT_K:g} × stiffest fold): bar-and-hinge → rigid limit",
        solid=True,
    )
    figure_forms(ix, s, quick, img / "transformations_forms.png", stamp)
    n_failed = sum(r["status"] != "ok" for r in records.values())
    text = DOC.read_text()
    blocks = {
        "stamp": f"*Tables and figures below: written by `python studies/transformations/run.py "
        f"--publish` ({stamp}; {len(records)} runs, {n_failed} failed).*",
        "rigid": table_rigid(ix, s),
        "convergence": table_convergence(conv, s),
        "compliant": table_convergence(comp, s, compliant=True),
        "curves": table_curves(ix, s),
        "surfaces": table_surfaces(ix, s),
        "placement": table_placement(placement_rows(ix, s, quick)),
        "signs": table_signs(ix, records),
        "design": table_design(ix, s),
        "speedup": design_speedups(ix, s),
        "findings": findings(ix, s, records, conv, comp, placement_rows(ix, s, quick)),
        "failed": "\n".join(
            f"* {_describe(r['params'])}: {r['error']['type']}: "
            f"{r['error']['message'].splitlines()[0][:160]}"
            for r in records.values()
            if r["status"] != "ok"
        )
        or "none",
    }
    for name, content in blocks.items():
        text = replace_block(text, name, content)
    DOC.write_text(text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python studies/transformations/run.py",
        description="Six tessellations under control curves and surfaces: rigid limit and "
        "bar-and-hinge model per cell, actuator placement from the DOF analysis. A rerun "
        "skips finished runs.",
    )
    ap.add_argument("--quick", action="store_true", help="small sheets, few cells (what CI checks)")
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="result folder (default studies/transformations/results[-quick])",
    )
    ap.add_argument("--serial", action="store_true", help="run in this process (no Dask)")
    ap.add_argument("--workers", type=int, default=None, help="local Dask workers")
    ap.add_argument("--retry-failed", action="store_true", help="rerun the failed runs")
    ap.add_argument(
        "--publish",
        action="store_true",
        help="write docs/transformations.md tables and figures (full) or "
        "docs/transformations-quick.json (--quick)",
    )
    a = ap.parse_args(argv)
    out = a.out or HERE / ("results-quick" if a.quick else "results")
    report, records = run(a.quick, out, a.serial or a.quick, a.workers, a.retry_failed)
    s = settings(a.quick)
    ix = index(records)
    print(
        table_rigid(ix, s),
        "",
        table_convergence(convergence(ix, s), s),
        "",
        table_placement(placement_rows(ix, s, a.quick)),
        "",
        table_signs(ix, records),
        "",
        table_design(ix, s),
        sep="\n",
    )
    failed = [r for r in records.values() if r["status"] != "ok"]
    print(f"{report.total} runs ({report.skipped} from before), {len(failed)} failed -> {out}")
    for r in failed:
        print(f"  failed: {r['params']}: {r['error']['type']}: {r['error']['message'][:150]}")
    if a.publish:
        publish(records, a.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
