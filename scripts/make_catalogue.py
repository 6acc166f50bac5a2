"""Regenerate the pattern catalogue: data/patterns/*.fold, docs/img/patterns/*.png and
docs/patterns.md.

Usage::

    python scripts/make_catalogue.py            # everything
    python scripts/make_catalogue.py --no-images   # FOLD files and the table only

Generated patterns are written as FOLD files whose key frame is the flat pattern (with target
fold angles) and, for families with an exact rigid folding, a second frame holding the folded
state. Real patterns from ``tests/data/crease-patterns`` are copied (SVG ones converted to FOLD)
with their author, source and licence in the file metadata and in data/patterns/LICENSES.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

import barhinge as bh
from barhinge.families import FAMILIES
from barhinge.families.properties import degree_counts
from barhinge.pattern.crease import CreasePattern

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO / "tests" / "data" / "crease-patterns"
OUT = REPO / "data" / "patterns"
IMG = REPO / "docs" / "img" / "patterns"
DOC = REPO / "docs" / "patterns.md"


@dataclasses.dataclass(frozen=True)
class Entry:
    """One catalogue instance: a family with parameters and, optionally, a folded state."""

    name: str
    family: str
    kwargs: dict[str, Any]
    folded: dict[str, Any] | None = None  # extra kwargs giving the exact folded state


ENTRIES: list[Entry] = [
    Entry("miura_4x4_a60", "miura", {"nx": 4, "ny": 4, "alpha": 60.0}, {"fold": 50.0}),
    Entry("miura_6x4_a45", "miura", {"nx": 6, "ny": 4, "alpha": 45.0}, {"fold": 40.0}),
    Entry(
        "miura_3x6_a75_b05", "miura", {"nx": 3, "ny": 6, "alpha": 75.0, "b": 0.5}, {"fold": 60.0}
    ),  # fmt: skip
    Entry("miura_8x8_a70", "miura", {"nx": 8, "ny": 8, "alpha": 70.0}, {"fold": 30.0}),
    Entry("miura_2x2_a55", "miura", {"nx": 2, "ny": 2, "alpha": 55.0, "a": 1.5}, {"fold": 70.0}),
    Entry("miura_arc_4x3_d10", "miura_arc", {"nx": 4, "ny": 3, "delta": 10.0}, {"fold": 120.0}),
    Entry(
        "miura_arc_6x2_d16",
        "miura_arc",
        {"nx": 6, "ny": 2, "delta": 16.0, "alpha": 55.0},
        {"fold": 100.0},
    ),  # fmt: skip
    Entry(
        "miura_arc_graded_5x2",
        "miura_arc",
        {"nx": 5, "ny": 2, "delta": 8.0, "grade": 8.0},
        {"fold": 110.0},
    ),  # fmt: skip
    Entry("miura_nonuniform_default", "miura_nonuniform", {}, {"fold": 45.0}),
    Entry(
        "miura_nonuniform_graded",
        "miura_nonuniform",
        {"a": [0.4, 0.6, 0.8, 1.0, 1.2, 1.4], "b": [1.0, 0.8, 0.6, 0.8, 1.0], "alpha": 65.0},
        {"fold": 50.0},
    ),  # fmt: skip
    Entry("miura_tachi_arch", "miura_tachi", {}, {"folded": True}),
    Entry(
        "miura_tachi_wave",
        "miura_tachi",
        {
            "curve": [[x, 0.6 * np.sin(x)] for x in np.linspace(0, 6.0, 11)],
            "ny": 3,
            "depth": 0.35,
            "offset": 0.25,
            "spacing": 0.5,
        },
        {"folded": True},
    ),  # fmt: skip
    Entry(
        "miura_tachi_flat_arch",
        "miura_tachi",
        {
            "curve": [[x, -0.08 * (x - 4) ** 2] for x in np.linspace(0, 8, 13)],
            "ny": 4,
            "depth": 0.5,
            "offset": 0.3,
            "spacing": 0.6,
        },
        {"folded": True},
    ),  # fmt: skip
    Entry("yoshimura_4x3", "yoshimura", {"nx": 4, "ny": 3}, {"fold": 40.0}),
    Entry("yoshimura_8x4", "yoshimura", {"nx": 8, "ny": 4, "w": 1.0, "h": 0.8}, {"fold": 25.0}),
    Entry(
        "yoshimura_6x6_steep", "yoshimura", {"nx": 6, "ny": 6, "w": 1.0, "h": 1.2}, {"fold": 50.0}
    ),  # fmt: skip
    Entry("pleats_6", "pleats", {"n": 6}, {"fold": 90.0}),
    Entry("pleats_12_narrow", "pleats", {"n": 12, "w": 0.4, "length": 3.0}, {"fold": 120.0}),
    Entry("curved_pleats_90", "curved_pleats", {}),
    Entry("curved_pleats_180", "curved_pleats", {"n": 8, "sweep": 180.0, "segments": 12}),
    Entry("eggbox_3x3_a60", "eggbox", {"nx": 3, "ny": 3, "alpha": 60.0}),
    Entry("eggbox_4x2_a45", "eggbox", {"nx": 4, "ny": 2, "alpha": 45.0, "fold": 65.0}),
    Entry("eggbox_3x3_a75", "eggbox", {"nx": 3, "ny": 3, "alpha": 75.0, "b": 1.4}),
    Entry("resch_6x6", "resch", {"nx": 6, "ny": 6}),
    Entry("resch_12x9", "resch", {"nx": 12, "ny": 9}),
    Entry("waterbomb_4x4", "waterbomb", {"nx": 4, "ny": 4}),
    Entry("waterbomb_8x4", "waterbomb", {"nx": 8, "ny": 4}),
    Entry("waterbomb_3x6", "waterbomb", {"nx": 3, "ny": 6}),
    Entry("square_twist_1x1", "square_twist", {"nx": 1, "ny": 1}),
    Entry("square_twist_3x3", "square_twist", {"nx": 3, "ny": 3}),
    Entry("square_twist_4x3_t20", "square_twist", {"nx": 4, "ny": 3, "twist": 20.0, "a": 1.0}),
    Entry("kresling_6x3", "kresling", {}),
    Entry("kresling_8x4", "kresling", {"n": 8, "stories": 4, "height": 0.6, "shift": 0.45}),
    Entry("kresling_5x2", "kresling", {"n": 5, "stories": 2, "height": 1.0, "shift": 0.7}),
    Entry("diagonal_6x4", "diagonal", {}),
    Entry("diagonal_8x3_long", "diagonal", {"nx": 8, "ny": 3, "a": 1.0, "b": 1.6}),
    Entry("hypar_5", "hypar", {}),
    Entry("hypar_9", "hypar", {"n": 9}),
    Entry("russo_pleat_5x4", "russo_pleat", {}, {"fold": 50.0}),
    Entry(
        "russo_pleat_8x6_steep",
        "russo_pleat",
        {"pleats": 8, "strips": 6, "width": 0.2, "height": 0.8, "angle": 35.0},
        {"fold": 60.0},
    ),  # fmt: skip
]

#: real patterns: (output name, source file, author/source line, licence folder)
REAL: list[tuple[str, str, str, str]] = [
    ("fold-spec_squaretwist", "fold-spec/squaretwist.fold",
     "FOLD specification examples (Demaine, Ku, Lang), squaretwist.fold", "fold-spec"),
    ("fold-spec_simple", "fold-spec/simple.fold",
     "FOLD specification examples (Demaine, Ku, Lang), simple.fold", "fold-spec"),
    ("fold-spec_diagonal-cp", "fold-spec/diagonal-cp.fold",
     "FOLD specification examples (Demaine, Ku, Lang), diagonal-cp.fold", "fold-spec"),
    ("os_miura-ori", "origami-simulator/miura-ori.svg",
     "Origami Simulator examples (Amanda Ghassaei), miura-ori.svg", "origami-simulator"),
    ("os_waterbomb", "origami-simulator/waterbomb.svg",
     "Origami Simulator examples (Amanda Ghassaei), waterbomb.svg", "origami-simulator"),
    ("os_reschTriTessellation", "origami-simulator/reschTriTessellation.svg",
     "Origami Simulator examples (Amanda Ghassaei), reschTriTessellation.svg",
     "origami-simulator"),
    ("os_hypar", "origami-simulator/hypar.svg",
     "Origami Simulator examples (Amanda Ghassaei), hypar.svg", "origami-simulator"),
    ("os_squaretwistManyAngles", "origami-simulator/squaretwistManyAngles.svg",
     "Origami Simulator examples (Amanda Ghassaei), squaretwistManyAngles.svg",
     "origami-simulator"),
    ("os_huffmanWaterbomb", "origami-simulator/huffmanWaterbomb.svg",
     "Origami Simulator examples (Amanda Ghassaei), huffmanWaterbomb.svg", "origami-simulator"),
    ("os_langOvalTessellation", "origami-simulator/langOvalTessellation.svg",
     "Origami Simulator examples (Amanda Ghassaei), langOvalTessellation.svg",
     "origami-simulator"),
]  # fmt: skip


def _folded_of(entry: Entry) -> CreasePattern | None:
    if entry.folded is None:
        return None
    return FAMILIES[entry.family](**entry.kwargs, **entry.folded)


def make_entry(entry: Entry) -> tuple[CreasePattern, CreasePattern | None]:
    """(flat or reference pattern, folded state or None) of a catalogue entry."""
    return FAMILIES[entry.family](**entry.kwargs), _folded_of(entry)


def _read_real(src: Path) -> CreasePattern:
    return bh.read_fold(src) if src.suffix == ".fold" else bh.read_svg(src)


def stats(cp: CreasePattern) -> dict[str, Any]:
    """Counts for the catalogue table."""
    return {
        "N_V": cp.n_vertices,
        "N_E": cp.n_edges,
        "N_F": cp.n_faces,
        "interior": len(cp.interior_vertices),
        "degrees": degree_counts(cp),
        "M": int((cp.assignment == "M").sum()),
        "V": int((cp.assignment == "V").sum()),
        "developable": bool(cp.developable),
    }


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-images", action="store_true", help="skip the PNG pictures")
    args = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    IMG.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    for entry in ENTRIES:
        cp, folded = make_entry(entry)
        bh.write_fold(cp, OUT / f"{entry.name}.fold", frames=[folded] if folded else None)
        rows.append({"name": entry.name, "family": entry.family, "kwargs": entry.kwargs,
                     "folded": folded is not None or cp.vertices.shape[1] == 3,
                     "source": "generated", **stats(cp)})  # fmt: skip
        if not args.no_images:
            _pictures(entry.name, cp, folded)
    licences: dict[str, list[str]] = {}
    for name, rel, source, lic in REAL:
        src = SHARED / rel
        if not src.exists():
            continue
        cp = _read_real(src)
        meta = dict(cp.meta)
        meta["file_author"] = meta.get("file_author") or source.split("(")[1].split(")")[0]
        meta["file_description"] = f"{source}; licence: MIT (see data/patterns/LICENSES.md)"
        meta["barhinge:source"] = f"tests/data/crease-patterns/{rel}"
        cp = cp.replaced(meta=meta)
        bh.write_fold(cp, OUT / f"{name}.fold")
        licences.setdefault(lic, []).append(f"`{name}.fold` from `{rel}`: {source}")
        rows.append({"name": name, "family": "(real)", "kwargs": {}, "source": source,
                     "folded": not cp.is_flat, **stats(cp)})  # fmt: skip
        if not args.no_images:
            _pictures(name, cp, None)
    _write_licences(licences)
    _write_doc(rows)
    (OUT / "catalogue.json").write_text(json.dumps(rows, indent=1, default=str) + "\n")
    print(f"{len(rows)} patterns written to {OUT}")


def _pictures(name: str, cp: CreasePattern, folded: CreasePattern | None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from barhinge.plot.pattern import draw_folded, draw_pattern

    draw_pattern(cp, path=IMG / f"{name}.png", dpi=70)
    state = folded if folded is not None else (cp if not cp.is_flat else None)
    if state is not None:
        draw_folded(state, path=IMG / f"{name}_folded.png", dpi=70)


def _write_licences(licences: dict[str, list[str]]) -> None:
    lines = [
        "# Sources and licences of the real patterns in this folder",
        "",
        "Files not listed here are generated by `barhinge.families` (MIT, this project) with",
        "`python scripts/make_catalogue.py`.",
        "",
    ]
    for folder, items in licences.items():
        lic = (SHARED / folder / "LICENSE").read_text().strip()
        lines += [f"## From `tests/data/crease-patterns/{folder}/`", ""]
        lines += [f"- {it}" for it in items]
        lines += ["", "Licence of these files:", "", "```", lic, "```", ""]
    (OUT / "LICENSES.md").write_text("\n".join(lines))


def _fmt_kwargs(kw: dict[str, Any]) -> str:
    parts = []
    for k, v in kw.items():
        if isinstance(v, (list, tuple, np.ndarray)):
            v = f"[{len(v)} values]"
        parts.append(f"{k}={v}")
    return ", ".join(parts) or "defaults"


INTRO = """# Pattern catalogue

Generated by `python scripts/make_catalogue.py` (do not edit by hand; edit the script). Every
file is in `data/patterns/`; generated ones carry the flat pattern (target fold angles from the
assignment) and, where the family has an exact rigid folding, a second FOLD frame with the
folded state. Mountain red, valley blue, boundary black, facet lines grey.
Write any family yourself with `barhinge patterns NAME --param k=v --out FILE.fold`
(`barhinge patterns` lists the families and their parameters), or from Python:
`bh.families.miura(4, 4, alpha=60, fold=40)`.

## Conventions shared by the generators

- Angles in degrees, lengths in your unit. Fold angles follow FOLD: valley > 0, mountain < 0.
  Faces are counter-clockwise seen from +z in the flat state; boundary edges are `B`.
- `fold=None` gives the flat pattern; its `fold_angles` are *targets* (the exact state at the
  documented `target` for families with a closed-form folding, `+-target` otherwise).
  `fold=value` gives the exact rigidly folded state (vertices (n, 3)) whose `fold_angles` are
  that state's fold angles.
- Grid families (Miura and variations, pleats, egg-box, Russo pleat, diagonal) number vertex
  (i, j) as `j * ni + i` and list the row edges (i, j)-(i+1, j) before the column edges
  (i, j)-(i, j+1); `bh.families.grid_layout(cp)` returns the index map with the
  `left/right/bottom/top` vertex and edge groups (`miura_layout(nx, ny)` adds
  `straight_edges` and `zigzag_edges`).

## Closed forms and constructions

- **Miura-ori** (Schenk & Guest 2013, PNAS 110(9):3276, Eq. 1-2): with facet angle theta,
  H = a sin(theta) sin(gamma), S = b cos(theta) tan(gamma) / sqrt(1 + cos^2(theta) tan^2(gamma)),
  L = a sqrt(1 - sin^2(theta) sin^2(gamma)), V = b / sqrt(1 + cos^2(theta) tan^2(gamma)),
  nu_SL = -cos^2(theta) tan^2(gamma). Vertex (i, j) folds to (i L + (j mod 2) V, j S,
  (i mod 2) H). Zig-zag creases fold by 2 theta, straight creases by
  2 arctan(cos(gamma) tan(theta)). `bh.families.miura_geometry(a, b, alpha, theta)`.
- **Non-uniform Miura** and **Russo pleat**: every vertex keeps the Miura sector angles, so
  every facet folds as a Schenk & Guest facet of its own side lengths.
- **Arc Miura**: straight rows, zig-zag lines with their own sector angles gamma_i. In the
  folded state all straight creases share one fold angle rho_s; rows lie in planes
  y = j h cos(rho_s / 2) and the section turns by 2 arccos(b_i cos(gamma_i) / lambda_i) at
  zig-zag i (lambda_i = sqrt(b_i^2 - s^2)); face planarity holds because
  lambda_i sin(tau_i / 2) = sqrt(h^2 - s^2) for every i. Unequal valley/mountain angles
  (delta) bend the section into an arch.
- **Tachi's generalised Miura**: built folded from a zig-zag section of a target curve and
  mirror-reflected rows; offsets along the section's angle bisectors make every vertex
  developable and flat-foldable; the flat pattern is the isometric unfolding.
- **Yoshimura arch**: rows on polygons of circumradius R = w / (2 sin beta), spacing
  d = sqrt(h^2 - (w/2)^2 tan^2(beta/2)), `fold` = 2 beta.
- **Egg-box** (non-developable): the translational surface P(i) + Q(j) of two zig-zags with
  sin(psi1) sin(psi2) = cos(gamma); it has no flat state (`developable=False`).

## Geometry choices where the sources give pictures only

- **Russo-style optical-illusion pleat**: narrow pleats that lean one way in a strip and the
  other way in the next, reversed at straight strip boundaries, i.e. a Miura-ori with
  alternating narrow/wide panels. Chosen because it reproduces the zig-zag shading of
  Russo's "Optical Illusion" pieces, is developable and flat-foldable at every vertex, and has
  an exact rigid folding that makes it a checkable benchmark.
- **Diagonal pattern** (Buri & Weinand 2008): a rectangular grid with every cell cut by its
  diagonal in the same direction: long straight valley diagonals across the sheet, mountain
  grid lines; flat-foldable at every vertex.
- **Curved pleats**: concentric polygonal arcs alternating M/V with radial facet lines (`F`)
  at the corners, because straight-segment arc pleats cannot fold with the arcs alone
  (Demaine et al. 2011).
"""


def _write_doc(rows: list[dict[str, Any]]) -> None:
    L: list[str] = [
        INTRO,
        "## Families",
        "",
        "| family | generator | exact folded state | source |",
        "|---|---|---|---|",
    ]
    for name, fn in FAMILIES.items():
        mod = fn.__module__
        first = (fn.__doc__ or "").strip().splitlines()[0]
        exact = "yes (`fold=`)" if name in bh.families.FOLDABLE_FAMILIES else (
            "designed state (`folded=True`)" if name == "miura_tachi" else "no (flat)")  # fmt: skip
        src = (__import__(mod, fromlist=["x"]).__doc__ or "").split("Source")[1:2]
        src_line = src[0].split("\n\n")[0].replace("\n", " ").strip(" :s") if src else ""
        L.append(f"| `{name}` | {first} | {exact} | {src_line[:160]} |")
    L += [
        "",
        "## Counts",
        "",
        "N_V vertices, N_E edges, N_F faces, N_int interior vertices, deg: interior vertex "
        "degrees (degree: count).",
        "",
        "| pattern | family | parameters | N_V | N_E | N_F | N_int | deg | M | V |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        deg = ", ".join(f"{d}: {c}" for d, c in r["degrees"].items())
        L.append(
            f"| [{r['name']}](#{r['name'].lower()}) | {r['family']} | {_fmt_kwargs(r['kwargs'])} "
            f"| {r['N_V']} | {r['N_E']} | {r['N_F']} | {r['interior']} | {deg} | {r['M']} "
            f"| {r['V']} |"
        )
    L += ["", "## Pictures", ""]
    for r in rows:
        L += [f"### {r['name']}", ""]
        if r["source"] != "generated":
            L += [f"Source: {r['source']} (MIT; see `data/patterns/LICENSES.md`).", ""]
        else:
            L += [f"`{r['family']}({_fmt_kwargs(r['kwargs'])})`"
                  + ("" if r["developable"] else " (non-developable)"), ""]  # fmt: skip
        pics = f"![{r['name']}](img/patterns/{r['name']}.png)"
        if (IMG / f"{r['name']}_folded.png").exists():
            pics += f" ![{r['name']} folded](img/patterns/{r['name']}_folded.png)"
        L += [pics, ""]
    DOC.write_text("\n".join(L))


if __name__ == "__main__":
    main()
