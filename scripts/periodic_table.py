"""Regenerate the tables of docs/periodic.md (between the ``<!-- periodic-table:start -->``
and ``<!-- periodic-table:end -->`` markers).

Usage::

    python scripts/periodic_table.py            # rewrite the tables in docs/periodic.md
    python scripts/periodic_table.py --print    # print them instead

Table 1: Miura-ori periodic cells (:func:`barhinge.analysis.periodic.periodic_cell`, 2 x 2-cell
N5B8 sheets) against Schenk & Guest (2013, Eq. 2) in the rigid-panel limit (panels 1e6 x the
folds) and the isometric limit (bars a further 1e6 x panel bending). Table 2: finite n x n
sheets with the macroscopic field on their boundary
(:func:`barhinge.analysis.periodic.kinematic_abd`), relative excess over the periodic cell,
and the slope of log(excess) against log(n). Table 3: free-edge n x n sheets under a uniform
end load (resultant near the mid-plane): centre-cell strains against the periodic compliance.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from barhinge import families
from barhinge._publish import generated_stamp, write_between
from barhinge.analysis.periodic import kinematic_abd, periodic_cell
from barhinge.analysis.stiffness import linear_response
from barhinge.families.miura import miura_geometry
from barhinge.model.model import BarHingeModel
from barhinge.scene import restraint_321

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "periodic.md"
START, END = "<!-- periodic-table:start -->", "<!-- periodic-table:end -->"

GEOMETRIES = ((1.0, 1.5, 60.0, 50.0), (1.0, 1.0, 60.0, 30.0), (1.0, 1.0, 45.0, 60.0))
SHEET = (1.0, 1.5, 60.0, 50.0)
NS = (2, 4, 8, 16)
FREE_NS = (8, 16, 32)
TERMS = ((0, 0, "A11"), (1, 1, "A22"), (2, 2, "A66"), (3, 3, "D11"), (4, 4, "D22"), (5, 5, "D66"))


def _model(geom, n, **kw):
    a, b, gam, th = geom
    cp = families.miura(n, n, a=a, b=b, alpha=gam, fold=th)
    return BarHingeModel.from_pattern(cp, "N5B8", **kw)


def _lattice(geom):
    g = miura_geometry(*geom)
    return g, [[2 * g.L, 0.0, 0.0], [0.0, 2 * g.S, 0.0]]


def limit_rows() -> list[dict]:
    rows = []
    for geom in GEOMETRIES:
        g, T = _lattice(geom)
        nu = periodic_cell(_model(geom, 2, stiffness_ratio=1e6), T).moduli()["nu21"]
        iso = _model(geom, 2, stiffness_ratio=1e3)
        iso = iso.with_(bar_EA=iso.bar_EA * 1e6)
        nb = 1.0 / periodic_cell(iso, T).poisson_bending()
        rows.append({"geom": geom, "ref": g.nu_SL, "nu": nu, "bend": nb})
    return rows


def sheet_rows() -> tuple[np.ndarray, np.ndarray, dict]:
    _, T = _lattice(SHEET)
    cell = periodic_cell(_model(SHEET, 2), T)
    ex = []
    for n in NS:
        abd = kinematic_abd(_model(SHEET, n), n * n * cell.area, cell.frame, cell.z0)
        ex.append([abd[i, j] / cell.ABD[i, j] - 1 for i, j, _ in TERMS])
    ex = np.array(ex)
    slopes = np.polyfit(np.log(NS), np.log(ex), 1)[0]
    return ex, slopes, cell.moduli()


def centre_strain(n: int, d: int) -> np.ndarray:
    """(eps_x, eps_y) of the centre cell of a free-edge n x n sheet under a unit stress
    resultant along x (d = 0: on the two end columns, one per layer) or y (d = 1: end rows);
    eps_x averages the pairs of both layers (mid-plane)."""
    g, _ = _lattice(SHEET)
    m = _model(SHEET, n)
    ni = 2 * n + 1
    vid = np.arange(ni * ni).reshape(ni, ni)  # vid[j, i]
    if d == 0:
        width, e0, e1 = 2 * n * g.S, np.r_[vid[:, 0], vid[:, 1]], np.r_[vid[:, -1], vid[:, -2]]
    else:
        width, e0, e1 = 2 * n * g.L, vid[0, :], vid[-1, :]
    f = np.zeros((m.n_nodes, 3))
    f[e0, d] -= width / len(e0)
    f[e1, d] += width / len(e1)
    U, _ = linear_response(m, f, restraint_321(m))
    i0 = j0 = n - 1
    ex = np.mean([U[vid[j0 : j0 + 3, i + 2], 0] - U[vid[j0 : j0 + 3, i], 0] for i in (i0, i0 + 1)])
    ey = np.mean(U[vid[j0 + 2, i0 : i0 + 3], 1] - U[vid[j0, i0 : i0 + 3], 1])
    return np.array([ex / (2 * g.L), ey / (2 * g.S)])


def free_rows() -> tuple[np.ndarray, np.ndarray]:
    """Relative errors (n, d, component) of the centre strains against the periodic
    compliance column, and their slopes against log(n) (d, component)."""
    _, T = _lattice(SHEET)
    a = periodic_cell(_model(SHEET, 2), T).in_plane_compliance(free_curvature=True)
    err = np.array([[centre_strain(n, d) / a[:2, d] - 1 for d in (0, 1)] for n in FREE_NS])
    slopes = np.polyfit(np.log(FREE_NS), np.log(np.abs(err.reshape(len(FREE_NS), -1))), 1)[0]
    return err, slopes.reshape(2, 2)


def render(
    lim: list[dict],
    ex: np.ndarray,
    slopes: np.ndarray,
    mod: dict,
    free: tuple[np.ndarray, np.ndarray] | None = None,
) -> str:
    out = [
        generated_stamp("python scripts/periodic_table.py"),
        "",
        "### Table 1 — Miura-ori cells against Schenk & Guest (2013)",
        "",
        "| a | b | γ (°) | θ (°) | −cos²θ tan²γ | ν_SL, rigid panels | error "
        "| −κ_L/κ_S, rigid bars | error |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in lim:
        a, b, gam, th = r["geom"]
        out.append(
            f"| {a:g} | {b:g} | {gam:g} | {th:g} | {r['ref']:.9f} | {r['nu']:.9f} | "
            f"{abs(r['nu'] / r['ref'] - 1):.1e} | {r['bend']:.9f} | "
            f"{abs(r['bend'] / -r['ref'] - 1):.1e} |"
        )
    a, b, gam, th = SHEET
    out += [
        "",
        f"### Table 2 — finite n × n sheets (a = {a:g}, b = {b:g}, γ = {gam:g}°, θ = {th:g}°, "
        "default material) with the macroscopic field on their boundary",
        "",
        "Relative excess `ABD_sheet / ABD_cell − 1` of the diagonal terms:",
        "",
        "| n | " + " | ".join(t for _, _, t in TERMS) + " |",
        "|---|" + "---|" * len(TERMS),
    ]
    for n, row in zip(NS, ex, strict=True):
        out.append(f"| {n} | " + " | ".join(f"{v:.3g}" for v in row) + " |")
    out.append(
        "| slope of log(excess) vs log(n) | " + " | ".join(f"{s:.2f}" for s in slopes) + " |"
    )
    out += [
        "",
        "In-plane constants of that cell (curvatures held zero; force per length): "
        + ", ".join(f"{k} = {v:.4g}" for k, v in mod.items())
        + ".",
    ]
    if free is not None:
        err, fs = free
        out += [
            "",
            "### Table 3 — free-edge n × n sheets under a uniform end load (same cell)",
            "",
            "Relative error of the centre cell's strains against the periodic compliance "
            "(`eps = a N`, curvatures free):",
            "",
            "| n | force along x: ε_x | ε_y | force along y: ε_x | ε_y |",
            "|---|---|---|---|---|",
        ]
        for n, e in zip(FREE_NS, err, strict=True):
            out.append(f"| {n} | " + " | ".join(f"{v:+.4f}" for v in e.ravel()) + " |")
        out.append(
            "| slope of log(error) vs log(n) | " + " | ".join(f"{v:.2f}" for v in fs.ravel()) + " |"
        )
    return "\n".join(out) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--print", action="store_true", help="print instead of writing the doc")
    args = ap.parse_args()
    ex, slopes, mod = sheet_rows()
    table = render(limit_rows(), ex, slopes, mod, free_rows())
    if args.print:
        print(table)
        return
    write_between(DOC, START, END, table)


if __name__ == "__main__":
    main()
