"""Regenerate the calibration tables of docs/calibration.md (between the
``<!-- calibration-table:start -->`` and ``<!-- calibration-table:end -->`` markers).

Usage::

    python scripts/calibration_table.py            # rewrite the tables in docs/calibration.md
    python scripts/calibration_table.py --print    # print them instead

Every entry is a relative energy error ``U_bar / U_ref - 1`` of one flat panel
(:func:`barhinge.model.compare.panel_errors`): homogeneous membrane modes against the
closed-form plane-stress energy (which the scikit-fem membrane reproduces to 1e-10, the patch
test in tests/model/test_model_calibration.py), corner warping against the scikit-fem Morley
plate. ``quick=True`` computes the subset the tests recompute (nu = 0.3).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from barhinge._publish import generated_stamp, write_between
from barhinge.model.compare import panel_errors, subdivided_membrane_errors
from barhinge.model.material import Material
from barhinge.model.model import MEMBRANES

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "calibration.md"
START, END = "<!-- calibration-table:start -->", "<!-- calibration-table:end -->"

MODES = ("dilation", "uniaxial_x", "uniaxial_y", "shear")
NUS = (0.0, 0.2, 0.3, 0.45)
QUICK_NUS = (0.3,)
T = 0.01  # thickness; panels ~1 wide, so L/t ~ 100 (only the F17 bending column depends on it)


def _regular(k: int) -> np.ndarray:
    t = 2 * np.pi * np.arange(k) / k
    return np.column_stack([np.cos(t), np.sin(t)])


def _para(alpha_deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(alpha_deg)), np.sin(np.radians(alpha_deg))
    return np.array([[0, 0], [1, 0], [1 + c, s], [c, s]])


def _rect(W: float) -> np.ndarray:
    return np.array([[0, 0], [W, 0], [W, 1], [0, 1]], float)


#: name -> (polygon, schemes, outside the compact set: elongated, or a triangle far from
#: equilateral)
SHAPES: dict[str, tuple[np.ndarray, tuple[str, ...], bool]] = {
    "triangle": (_regular(3), ("N5B8",), False),
    "square": (_rect(1.0), ("N4B5", "N5B8"), False),
    "para 60°": (_para(60.0), ("N4B5", "N5B8"), False),
    "skew quad": (np.array([[0, 0], [1.2, 0], [1.0, 0.9], [0.1, 1.1]]), ("N4B5", "N5B8"), False),
    "hexagon": (_regular(6), ("N5B8",), False),
    "rect 2:1": (_rect(2.0), ("N4B5", "N5B8"), True),
    "rect 4:1": (_rect(4.0), ("N4B5", "N5B8"), True),
    # the Yoshimura's facets: a bar triangle is isotropic only when equilateral
    "right isosceles": (np.array([[0, 0], [1, 0], [0.5, 0.5]]), ("N5B8",), True),
}


#: panels cut into m x m cells (Table 4): the skew quad above and a panel of the roof study's
#: arched Miura (miura_arc 6 x 3 at 60 deg, in its own plane, rounded to 1 mm per m)
REFINED_SHAPES: dict[str, np.ndarray] = {
    "skew quad": SHAPES["skew quad"][0],
    "arched-Miura panel": np.array(
        [[0.465, -0.017], [-0.014, 0.267], [-0.420, -0.010], [-0.031, -0.241]]
    ),
}
REFINED_LEVELS = (1, 2, 4, 8)
#: the membranes of Table 4: the default bar rule and the constant-strain triangle
REFINED_RULES = ("fit", "cst")


def refined_rows() -> list[dict]:
    """Table 4: the membrane patch test of N5B8 panels cut into m x m cells (nu = 0.3;
    boundary displaced by ``eps x``, inner nodes free), per membrane rule."""
    mat = Material(E=1.0, nu=0.3, t=T)
    return [
        dict(
            shape=name,
            rule=rule,
            m=m,
            **{
                k: float(v)
                for k, v in subdivided_membrane_errors(P, mat, m, bar_calibration=rule).items()
            },
        )
        for name, P in REFINED_SHAPES.items()
        for rule in REFINED_RULES
        for m in REFINED_LEVELS
    ]


def membrane_rows(quick: bool = False) -> list[dict]:
    """One row per (shape, scheme, nu, rule): the errors of the four homogeneous modes."""
    rows = []
    for nu in QUICK_NUS if quick else NUS:
        mat = Material(E=1.0, nu=nu, t=T)
        for name, (P, schemes, long_) in SHAPES.items():
            for scheme in schemes:
                for rule in MEMBRANES:
                    e = panel_errors(P, mat, scheme, rule, plate_refine=2)
                    rows.append(
                        dict(shape=name, scheme=scheme, nu=nu, rule=rule, elongated=long_,
                             **{m: float(e[m]) for m in MODES})
                    )  # fmt: skip
    return rows


def bending_rows(quick: bool = False) -> list[dict]:
    """Corner-warping errors against the Morley plate, per bending rule (polygons with >= 4
    corners). ``filipov/2`` is F17 with each N5B8 half-diagonal hinge given half the
    diagonal's stiffness (energy is linear in k, so its error is ``(1 + e) / 2 - 1``)."""
    rows = []
    for nu in QUICK_NUS if quick else NUS:
        mat = Material(E=1.0, nu=nu, t=T)
        for name, (P, schemes, _) in SHAPES.items():
            if len(P) < 4:
                continue
            for scheme in schemes:
                w = {
                    b: float(panel_errors(P, mat, scheme, "fit", b, plate_refine=4)["warp"])
                    for b in ("filipov", "kirchhoff", "plate")
                }
                half = (1.0 + w["filipov"]) / 2.0 - 1.0 if scheme == "N5B8" else float("nan")
                rows.append(dict(shape=name, scheme=scheme, nu=nu, half=half, **w))
    return rows


def worst_case(
    rows: list[dict], elongated: bool = True, nu: float | None = None
) -> dict[tuple[str, str], float]:
    """(rule, scheme) -> max |error| over shapes, nu (or only ``nu``) and modes (elongated
    panels included or not)."""
    out: dict[tuple[str, str], float] = {}
    for r in rows:
        if (r["elongated"] and not elongated) or (nu is not None and r["nu"] != nu):
            continue
        key = (r["rule"], r["scheme"])
        out[key] = max(out.get(key, 0.0), max(abs(r[m]) for m in MODES))
    return out


def _f(x: float) -> str:
    return "–" if not np.isfinite(x) else f"{x:+.3f}".replace("-0.000", "+0.000")


def _modes_row(head: list[str], r: dict) -> str:
    """A table row: ``head`` cells, the four modes' errors, the worst."""
    worst = max(abs(r[m]) for m in MODES)
    return "| " + " | ".join([*head, *(_f(r[m]) for m in MODES), f"{worst:.3f}"]) + " |"


def render(mrows: list[dict], brows: list[dict], rrows: list[dict] | None = None) -> str:
    out = [
        generated_stamp("python scripts/calibration_table.py"),
        "",
        "### Worst-case membrane error of each membrane rule",
        "",
        "Maximum `|U_bar/U_ref − 1|` over the four homogeneous modes and ν ∈ "
        f"{{{', '.join(f'{n:g}' for n in NUS)}}}:",
        "",
        "| rule | scheme | compact panels (no 2:1, 4:1, right isosceles), ν = 0.3 | "
        "compact panels, all ν | all panels, all ν |",
        "|---|---|---|---|---|",
    ]
    w3, wc = worst_case(mrows, False, 0.3), worst_case(mrows, elongated=False)
    wa = worst_case(mrows)
    for key in sorted(wa):
        out.append(f"| {key[0]} | {key[1]} | {w3[key]:.3f} | {wc[key]:.3f} | {wa[key]:.3f} |")
    out += [
        "",
        "### Table 1 — homogeneous membrane modes (corner displacements `u = ε x`)",
        "",
        "| shape | scheme | ν | rule | dilation | uniax. x | uniax. y | shear | worst |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in mrows:
        out.append(_modes_row([r["shape"], r["scheme"], f"{r['nu']:g}", r["rule"]], r))
    out += [
        "",
        "### Table 2 — corner warping against the Morley plate, per bending rule",
        "",
        "| shape | scheme | ν | filipov | filipov/2 | kirchhoff | plate |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in brows:
        out.append(
            f"| {r['shape']} | {r['scheme']} | {r['nu']:g} | "
            + " | ".join(_f(r[k]) for k in ("filipov", "half", "kirchhoff", "plate"))
            + " |"
        )
    if rrows:
        out += [
            "",
            "### Table 4 — N5B8 panels cut into m × m cells (ν = 0.3)",
            "",
            "Boundary displaced by `u = ε x`, every inner node free:",
            "",
            "| shape | rule | m | dilation | uniax. x | uniax. y | shear | worst |",
            "|---|---|---|---|---|---|---|---|",
        ]
        out += [_modes_row([r["shape"], r["rule"], str(r["m"])], r) for r in rrows]
    return "\n".join(out) + "\n"


def parse_doc(text: str) -> dict[tuple, list[float]]:
    """The numbers of Tables 1 and 2 of the doc, keyed ``("membrane", shape, scheme, nu,
    rule)`` and ``("bending", shape, scheme, nu)`` (NaN for '–')."""
    body = text[text.index(START) : text.index(END)]
    out: dict[tuple, list[float]] = {}

    def num(s: str) -> float:
        s = s.strip()
        return float("nan") if s == "–" else float(s)

    for line in body.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 9 and cells[3] in MEMBRANES:
            out[("membrane", cells[0], cells[1], float(cells[2]), cells[3])] = [
                num(c) for c in cells[4:8]
            ]
        elif len(cells) == 7 and cells[1] in ("N4B5", "N5B8") and re.match(r"[\d.]+$", cells[2]):
            out[("bending", cells[0], cells[1], float(cells[2]))] = [num(c) for c in cells[3:]]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--print", action="store_true", help="print instead of writing the doc")
    args = ap.parse_args()
    table = render(membrane_rows(), bending_rows(), refined_rows())
    if args.print:
        print(table)
        return
    write_between(DOC, START, END, table)


if __name__ == "__main__":
    main()
