"""Draw barhinge's import graph by layer: docs/img/import_graph.png.

The graph and the layers are those of tests/test_architecture.py (read with ``ast``,
module- and function-level imports). A box is a package folder or a top-level module; an
arrow ``a -> b`` means some module of ``a`` imports some module of ``b``. Every arrow points
down (the test keeps it so).

    python scripts/import_graph.py [--out docs/img/import_graph.png]
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: boxes a row holds side by side before it staggers them
CROWDED = 6


def _architecture():
    """The module tests/test_architecture.py (its graph reader and its LAYERS)."""
    spec = importlib.util.spec_from_file_location(
        "test_architecture", ROOT / "tests" / "test_architecture.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def rooms():
    """(layer names bottom first, boxes by layer, arrows between boxes).

    A box is a package folder, or a top-level module; a module kept in a package of another
    layer would get a box of its own.
    """
    arch = _architecture()
    graph = arch.import_graph()
    names = [n for n, _ in arch.LAYERS]

    def box(m: str) -> str:
        parts = m.split(".")
        if m == "barhinge":
            return "barhinge/__init__.py"
        pkg = ".".join(parts[:2])
        if not (ROOT / "barhinge" / parts[1]).is_dir():
            return f"{parts[1]}.py"
        if arch.layer_of(m) != arch.layer_of(pkg):
            return "/".join(parts[1:]) + ".py"
        return f"{parts[1]}/"

    where = {m: box(m) for m in graph}
    by_layer: dict[str, list[str]] = {n: [] for n in names}
    for m, r in sorted(where.items()):
        row = by_layer[names[arch.layer_of(m)]]
        if r not in row:
            row.append(r)
    arrows = {(where[a], where[b]) for a, ts in graph.items() for b in ts if where[a] != where[b]}
    return names, by_layer, sorted(arrows)


def draw(out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyArrowPatch

    names, by_layer, arrows = rooms()
    pos: dict[str, tuple[float, float]] = {}
    for y, lay in enumerate(names):
        row = by_layer[lay]
        for i, r in enumerate(row):
            # rows zig-zag so that arrows crossing several layers do not run through boxes;
            # a crowded row staggers its boxes up and down so that their labels do not meet
            dy = 0.2 * (-1) ** i if len(row) > CROWDED else 0.0
            pos[r] = ((i + 1) / (len(row) + 1) + 0.09 * (-1) ** y, y + dy)
    fig, ax = plt.subplots(figsize=(11, 0.62 * len(names) + 0.8))
    for a, b in arrows:
        (x0, y0), (x1, y1) = pos[a], pos[b]
        ax.add_patch(
            FancyArrowPatch(
                (x0, y0 - 0.18),
                (x1, y1 + 0.18),
                arrowstyle="-|>",
                mutation_scale=7,
                lw=0.5,
                color="0.55",
                alpha=0.6,
                connectionstyle="arc3,rad=0.05",
            )
        )
    for r, (x, y) in pos.items():
        ax.text(
            x,
            y,
            r,
            ha="center",
            va="center",
            fontsize=8,
            family="monospace",
            bbox={"boxstyle": "round,pad=0.3", "fc": "#e8eef7", "ec": "#4a6fa5", "lw": 0.8},
            zorder=3,
        )
    for y, lay in enumerate(names):
        ax.text(-0.08, y, lay, ha="right", va="center", fontsize=9, color="#4a6fa5")
        ax.axhline(y, color="0.93", lw=0.6, zorder=0)
    ax.set_xlim(-0.2, 1.1)
    ax.set_ylim(-0.6, len(names) - 0.4)
    ax.axis("off")
    ax.set_title(
        f"barhinge imports, layers bottom to top ({len(arrows)} arrows between boxes, all down)",
        fontsize=10,
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130, bbox_inches="tight")
    plt.close(fig)
    return out


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=ROOT / "docs" / "img" / "import_graph.png")
    print(draw(p.parse_args().out))
