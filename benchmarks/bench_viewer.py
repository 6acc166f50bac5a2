"""Viewer file size and opening time: the default scene (solved) and large Miura fold paths
(30 rigidly folded states from the closed form, ``miura(nx, ny, fold=theta)``), opened in
headless Chromium offline (from a blank tab: file read, parse, script, first drawing); "play"
is the mean time of one state change over all states.
The large paths are written twice: with float32 positions and with the default precision
(16-bit positions above ``QUANTISE_ABOVE`` node-states).

    python benchmarks/bench_viewer.py [--repeat 3] [--publish]

``--publish`` writes the table into docs/viewer.md.
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def miura_path(n: int, states: int = 30):
    from barhinge.families import miura
    from barhinge.results import FoldPath

    thetas = np.linspace(5.0, 60.0, states)
    cps = [miura(nx=n, ny=n, fold=float(t)) for t in thetas]
    X = np.stack([cp.vertices3d for cp in cps])
    ang = np.stack([cp.fold_angles for cp in cps])
    return FoldPath(X=X, fold_angles_deg=ang, kind="rigid", meta={"scene": f"miura {n}x{n}"}), cps[
        0
    ]


def open_time(drv, html: Path, repeat: int) -> tuple[float, float]:
    opens, plays = [], []
    for _ in range(repeat):
        drv.get("about:blank")  # the previous page's teardown is not part of opening this one
        t = time.perf_counter()
        drv.get(html.as_uri())
        assert drv.execute_script("return barhingeViewer.ready")
        opens.append(time.perf_counter() - t)
        plays.append(drv.execute_script(
            "const v = barhingeViewer, n = +document.getElementById('state').max + 1;"
            "const t = performance.now(); for (let s = 0; s < n; s++) v.setState(s);"
            "return (performance.now() - t) / 1000 / n;"))  # fmt: skip
    return statistics.median(opens), statistics.median(plays)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--publish", action="store_true", help="rewrite the table in docs/viewer.md")
    args = ap.parse_args()
    import barhinge as bh
    from barhinge.output.run import write_run
    from barhinge.scene import default_scene
    from barhinge.view import write_viewer

    spec = importlib.util.spec_from_file_location("test_viewer", ROOT / "tests/test_viewer.py")
    tv = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tv)
    drv = tv.open_browser()
    head = ("case", "nodes", "states", "MB", "write s", "open s", "play s/state")
    rows = []
    print(
        f"{head[0]:<28} "
        + " ".join(f"{h:>{w}}" for h, w in zip(head[1:], (7, 6, 7, 8, 7, 12), strict=True))
    )
    try:
        with tempfile.TemporaryDirectory() as tmp:
            cases = []
            scene = default_scene()
            out = Path(tmp) / "run"
            write_run(bh.solve(scene), scene, out)
            cases.append(("default scene (result folder)", out, {}))
            for n in (100, 141):
                fp, cp = miura_path(n)
                name = f"Miura {n}x{n} rigid path"
                cases.append((f"{name}, float32", fp, {"pattern": cp, "precision": "float32"}))
                cases.append((f"{name}, 16-bit", fp, {"pattern": cp}))
            for name, src, kw in cases:
                html = Path(tmp) / "v.html"
                t = time.perf_counter()
                write_viewer(src, html, **kw)
                tw = time.perf_counter() - t
                d = tv.load_view_data(src, **{k: v for k, v in kw.items() if k != "precision"})
                to, tp = open_time(drv, html, args.repeat)
                mb = html.stat().st_size / 1e6
                print(f"{name:<28} {d.X.shape[1]:>7} {d.n_states:>6} {mb:>7.2f} {tw:>8.2f} "
                      f"{to:>7.2f} {tp:>12.3f}")  # fmt: skip
                rows.append((name, d.X.shape[1], d.n_states, mb, tw, to, tp))
    finally:
        drv.quit()
    if args.publish:
        publish(rows, args.repeat)


def publish(rows, repeat: int) -> None:
    """The table between the viewer-bench markers of docs/viewer.md."""
    doc = ROOT / "docs/viewer.md"
    lines = [
        "<!-- viewer-bench:start -->",
        f"Written by `python benchmarks/bench_viewer.py --publish` (headless Chromium with its "
        f"software renderer, 2 shared cores; open: from a blank tab to the first drawing, median "
        f"of {repeat}):",
        "",
        "| path | nodes | states | file MB | write s | open s | s per state change |",
        "|---|---:|---:|---:|---:|---:|---:|",
        *(
            f"| {r[0]} | {r[1]:,} | {r[2]} | {r[3]:.1f} | {r[4]:.2f} | {r[5]:.2f} | {r[6]:.3f} |"
            for r in rows
        ),  # fmt: skip
        "<!-- viewer-bench:end -->",
    ]
    text = doc.read_text()
    a, b = text.index("<!-- viewer-bench:start -->"), text.index("<!-- viewer-bench:end -->")
    doc.write_text(text[:a] + "\n".join(lines) + text[b + len("<!-- viewer-bench:end -->") :])


if __name__ == "__main__":
    main()
