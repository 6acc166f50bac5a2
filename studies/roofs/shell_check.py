"""Bar-and-hinge roofs against an independent shell model of the same folded sheet.

For each roof (geometry, supports and load of ``roofs.py``: span 4 m, aluminium 2 mm, pinned
along the two supported edges, 1 kN/m^2 per unit plan area) the linear stiffness
``k = Q_t^2 / (f . u)`` (total load squared over the compliance) of

* the bar-and-hinge model (N5B8, the study's calibration) with every panel cut into
  ``m x m`` sub-panels by flat lines (:func:`barhinge.pattern.subdivide.subdivided`; flat
  lines get the plate-strip stiffness ``D l / s`` of ``roofs.flat_line_stiffness``), m = 1, 2,
  4, (8);
* the facet shell (:mod:`barhinge.model.shell`: CST membrane + Morley plate on each facet,
  each facet edge cut into ``2^r`` elements), with the creases given the bar-and-hinge fold
  stiffness per unit length (the same structure), r = 1, 2, 3, (4); its converged value is
  extrapolated (Richardson, with the observed rate of the three finest levels).

The bar-and-hinge error against the shell reference and its observed rate
(``polyfit`` of log error against log m) go to docs/roofs.md (``--publish``).

Run: ``python studies/roofs/shell_check.py [--quick] [--publish]``. Importing the module
runs the quick mode (one roof, coarse levels); its results stay at module level in
``RESULTS``.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import roofs  # noqa: E402

MAIN = __name__ == "__main__"
QUICK = not MAIN or "--quick" in sys.argv
PUBLISH = MAIN and "--publish" in sys.argv
ROOT = HERE.parents[1]
DOC = ROOT / "docs" / "roofs.md"
START, END = "<!-- shell_check:start -->", "<!-- shell_check:end -->"

#: bar-and-hinge variants: name -> BarHingeModel.from_pattern keywords
VARIANTS = {"plate": {}, "kirchhoff": {"bend_calibration": "kirchhoff"}}

if QUICK:
    ROOFS = [("pleats", 90.0)]
    BH_LEVELS, SHELL_LEVELS = [1, 2], [1, 2, 3]
else:
    ROOFS = [("miura60", 45.0), ("yoshimura", 20.0), ("pleats", 90.0), ("miura_arc", 60.0)]
    BH_LEVELS, SHELL_LEVELS = [1, 2, 4, 8], [1, 2, 3, 4]


def support_sets(cp, flat_xy: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """(supported vertex ids, pattern edges joining two of them): the study's supports."""
    c = flat_xy[:, axis]
    tol = 1e-6 * float(np.ptp(c))
    sv = np.flatnonzero((c <= c.min() + tol) | (c >= c.max() - tol))
    E = np.asarray(cp.edges)
    se = np.flatnonzero(np.isin(E[:, 0], sv) & np.isin(E[:, 1], sv))
    return sv, se


def crease_stiffness_per_length(model) -> float:
    """Fold-hinge stiffness per unit crease length of the M/V creases (uniform)."""
    asg = np.asarray(model.pattern.assignment)
    X = np.asarray(model.X0)
    h = model.hinges
    f = (model.hinge_kind == "fold") & (model.hinge_edge >= 0)
    f &= np.isin(asg[np.maximum(model.hinge_edge, 0)], ["M", "V"])
    ell = np.linalg.norm(X[h[f, 1]] - X[h[f, 0]], axis=1)
    k = model.hinge_k[f] / ell
    if not np.allclose(k, k[0], rtol=1e-9):
        raise ValueError("crease stiffness per length is not uniform")
    return float(k[0])


def bar_hinge(cp, sv, se, m: int, variant: str = "plate") -> dict:
    """Stiffness of the bar-and-hinge roof with m x m sub-panels (``VARIANTS[variant]``
    calibration)."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response
    from barhinge.pattern.subdivide import subdivided

    t0 = time.perf_counter()
    cpm, parent = subdivided(cp, m)
    model = bh.BarHingeModel.from_pattern(cpm, "N5B8", roofs.material(), **VARIANTS[variant])
    crease = np.isin(np.asarray(cpm.assignment), ["M", "V"])
    if "F" in set(np.asarray(cpm.assignment)):
        model = roofs.flat_line_stiffness(model, crease)
    S = np.zeros((model.n_nodes, 3), bool)
    S[np.union1d(sv, np.flatnonzero(np.isin(parent, se)))] = True
    F = roofs.plan_load(model, roofs.Q)
    U, _ = linear_response(model, F, S)
    Qt = float(-F[:, 2].sum())
    return {
        "m": m,
        "stiffness": Qt**2 / float(np.sum(F * U)),
        "n_dof": 3 * model.n_nodes,
        "time_s": time.perf_counter() - t0,
        "crease_k": crease_stiffness_per_length(model),
    }


def shell(cp, sv, se, r: int, crease_k: float) -> dict:
    """Stiffness of the facet shell roof at refinement r."""
    from barhinge.model.shell import shell_model

    t0 = time.perf_counter()
    sh = shell_model(cp, roofs.material(), r, crease_stiffness=crease_k)
    f = sh.surface_load((0.0, 0.0, -roofs.Q), per="plan")
    u = sh.solve(f, np.union1d(sh.nodes_on_edges(se), sv))
    Qt = float(-sh.translations(f)[:, 2].sum())
    return {
        "r": r,
        "stiffness": Qt**2 / float(f @ u),
        "n_dof": sh.n_dof,
        "time_s": time.perf_counter() - t0,
        "load": Qt,
    }


def navier_plate_stiffness(a: float, D: float, q: float, terms: int = 199) -> float:
    """Compliance stiffness ``Q_t^2 / (f . u) = q a^2 / mean(w)`` of a simply supported
    square plate (side a, rigidity D) under a uniform load q, from Navier's series
    (Timoshenko & Woinowsky-Krieger 1959, Sec. 30): ``mean(w) = 64 q a^4 / (pi^8 D)
    sum_(m, n odd) 1 / (m^2 n^2 (m^2 + n^2)^2)``."""
    k = np.arange(1, terms + 1, 2, dtype=float)
    M, N = np.meshgrid(k, k)
    mean_w = (
        64 * q * a**4 / (np.pi**8 * D) * float(np.sum(1.0 / (M**2 * N**2 * (M**2 + N**2) ** 2)))
    )
    return q * a * a / mean_w


def flat_plate(levels_bh: list[int], levels_shell: list[int]) -> dict:
    """The panel-subdivision rule on a flat square plate (1 m, the roofs' sheet), simply
    supported on its four edges under 1 kN/m^2: stiffness of the subdivided bar-and-hinge
    panel (each variant) and of the shell, over the Navier value."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response
    from barhinge.model.shell import shell_model
    from barhinge.pattern.crease import CreasePattern
    from barhinge.pattern.subdivide import subdivided

    mat = roofs.material()
    ref = navier_plate_stiffness(1.0, mat.bending_rigidity, roofs.Q)
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = CreasePattern(sq, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    out: dict = {"navier": ref, "bar_hinge": {}, "shell": []}
    for v, kw in VARIANTS.items():
        rows = []
        for m in levels_bh:
            cpm, parent = subdivided(cp, m)
            model = bh.BarHingeModel.from_pattern(cpm, "N5B8", mat, **kw)
            model = roofs.flat_line_stiffness(model, np.zeros(cpm.n_edges, bool))
            S = np.zeros((model.n_nodes, 3), bool)
            S[np.union1d(np.arange(4), np.flatnonzero(parent >= 0))] = True
            F = roofs.plan_load(model, roofs.Q)
            U, _ = linear_response(model, F, S)
            rows.append({"m": m, "ratio": float(F[:, 2].sum() ** 2 / np.sum(F * U)) / ref})
        out["bar_hinge"][v] = rows
    for r in levels_shell:
        sh = shell_model(cp, mat, r)
        f = sh.surface_load((0.0, 0.0, -roofs.Q))
        u = sh.solve(f, sh.nodes_on_edges(np.arange(4)))
        Qt = float(sh.translations(f)[:, 2].sum())
        out["shell"].append({"r": r, "ratio": Qt**2 / float(f @ u) / ref})
    return out


def extrapolate(k: list[float]) -> tuple[float, float, float]:
    """(reference, observed rate p in h, uncertainty) from values on levels h, h/2, h/4...:
    Richardson with ``p = log2(d1 / d2)`` of the last two differences when they shrink
    monotonically; otherwise the finest value, with the last change as its uncertainty."""
    if len(k) >= 3:
        d1, d2 = k[-2] - k[-3], k[-1] - k[-2]
        if d1 * d2 > 0 and abs(d2) < abs(d1):
            p = math.log2(d1 / d2)
            corr = d2 / (2.0**p - 1.0)
            return k[-1] + corr, p, abs(corr)
    return k[-1], float("nan"), abs(k[-1] - k[-2]) if len(k) > 1 else float("nan")


def run() -> list[dict]:
    out = []
    for fam, state in ROOFS:
        cp, flat_xy, _ = roofs.folded(fam, state)
        sv, se = support_sets(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
        bhr = {v: [bar_hinge(cp, sv, se, m, v) for m in BH_LEVELS] for v in VARIANTS}
        ck = bhr["plate"][0]["crease_k"]
        shr = [shell(cp, sv, se, r, ck) for r in SHELL_LEVELS]
        ref, p, unc = extrapolate([s["stiffness"] for s in shr])
        ms = np.array(BH_LEVELS, float)
        errors, rates = {}, {}
        for v, rows in bhr.items():
            err = np.array([b["stiffness"] / ref - 1.0 for b in rows])
            ok = np.abs(err) > 0
            errors[v] = err.tolist()
            rates[v] = float(-np.polyfit(np.log(ms[ok]), np.log(np.abs(err[ok])), 1)[0])
        out.append(
            {
                "family": fam,
                "state": state,
                "bar_hinge": bhr,
                "shell": shr,
                "shell_reference": ref,
                "shell_rate": p,
                "shell_uncertainty": unc / ref,
                "errors": errors,
                "rate": rates,
            }
        )
    return out


RESULTS = run()
PLATE = flat_plate([2, 4] if QUICK else [2, 4, 8, 16], [2, 3] if QUICK else [2, 3, 4, 5])


def table(results: list[dict]) -> str:
    lines = [
        "| roof | state | shell, finest (kN/m) | shell reference (kN/m) | shell rate | "
        "bending calibration | " + " | ".join(f"m = {m}" for m in BH_LEVELS) + " | rate |",
        "|---|---|---|---|---|---|" + "---|" * len(BH_LEVELS) + "---|",
    ]
    for r in results:
        sh = r["shell"][-1]
        p = "n/a" if math.isnan(r["shell_rate"]) else f"{r['shell_rate']:.2f}"
        for v in VARIANTS:
            errs = " | ".join(f"{100 * e:+.1f} %" for e in r["errors"][v])
            lines.append(
                f"| {r['family']} | {r['state']:g} | {sh['stiffness'] / 1e3:.1f} (r = {sh['r']}) | "
                f"{r['shell_reference'] / 1e3:.1f} ± {100 * r['shell_uncertainty']:.1f} % | {p} | "
                f"{v} | {errs} | {r['rate'][v]:.2f} |"
            )
    return "\n".join(lines)


def timing(results: list[dict]) -> str:
    lines = [
        "| roof | model | level | DOFs | stiffness (kN/m) | wall time (s) |",
        "|---|---|---|---|---|---|",
    ]
    for r in results:
        for v, rows in r["bar_hinge"].items():
            for b in rows:
                lines.append(
                    f"| {r['family']} | bar-hinge N5B8, {v} | m = {b['m']} | {b['n_dof']} | "
                    f"{b['stiffness'] / 1e3:.1f} | {b['time_s']:.2f} |"
                )
        for s in r["shell"]:
            lines.append(
                f"| {r['family']} | shell | r = {s['r']} | {s['n_dof']} | "
                f"{s['stiffness'] / 1e3:.1f} | {s['time_s']:.2f} |"
            )
    return "\n".join(lines)


def plate_table(plate: dict) -> str:
    lines = ["| model | level | stiffness / Navier |", "|---|---|---|"]
    for v, rows in plate["bar_hinge"].items():
        for b in rows:
            lines.append(f"| bar-hinge N5B8, {v} | m = {b['m']} | {b['ratio']:.3f} |")
    for s_ in plate["shell"]:
        lines.append(f"| shell | r = {s_['r']} | {s_['ratio']:.4f} |")
    return "\n".join(lines)


def section(results: list[dict]) -> str:
    ck = results[0]["bar_hinge"]["plate"][0]["crease_k"]
    return "\n".join(
        [
            START,
            "",
            "Written by `python studies/roofs/shell_check.py --publish`. Stiffness = total load"
            " squared over the compliance, linear, under 1 kN/m² (no self-weight). Creases in both"
            f" models have the fold stiffness {ck:.1f} N·m/rad per metre of crease. Error ="
            " bar-and-hinge stiffness / shell reference − 1 for m × m sub-panels per panel, with"
            " the study's bending calibration (plate) and the refinement-consistent"
            " kirchhoff one; rate = slope of log |error|"
            " against log m; shell rate = observed order in the"
            " element size of the shell's own refinement (r: 2^r elements per facet edge).",
            "",
            table(results),
            "",
            timing(results),
            "",
            "The subdivision rule itself, on a flat square plate simply supported on its four"
            " edges (closed form: Navier's series): stiffness over the Navier value.",
            "",
            plate_table(PLATE),
            "",
            END,
        ]
    )


if MAIN:
    text = section(RESULTS)
    print(text)
    if PUBLISH and not QUICK:
        doc = DOC.read_text()
        if START in doc:
            a, b = doc.index(START), doc.index(END) + len(END)
            doc = doc[:a] + text + doc[b:]
        else:
            head = "## Against a shell model\n\n" + text + "\n\n"
            at = doc.find("## Limitations and notes")
            doc = doc[:at] + head + doc[at:] if at >= 0 else doc.rstrip("\n") + "\n\n" + head
        DOC.write_text(doc)
        print(f"wrote {DOC}")
