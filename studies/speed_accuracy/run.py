"""Speed against accuracy: the same quantity by rigid kinematics and by bar-and-hinge models
(N4B5, N5B8) at several step counts, tolerances and stiffness ratios, error against wall time.

Scenes, quantities and references: see ``scenes.py`` (Miura fold: Poisson's ratio against
Schenk & Guest 2013 Eq. 2; Yoshimura arch: folded form against its closed form; loaded Miura
roof: deflection against the converged N5B8 solution).

Results at module level: ``RECORDS`` (list of dicts, one per run: scene, method, steps, tol,
ratio, error, time_s, ...), ``PARETO`` (scene -> records on the Pareto front of error against
time), ``NEEDS`` (scene -> the cheapest method whose error is within ``TARGET``).

Run: ``python studies/speed_accuracy/run.py [--quick]``. Full mode repeats every run
``REPEAT`` times (median wall time) and writes docs/speed-accuracy.csv and
docs/img/speed_accuracy.png; quick mode (what the test imports) runs a subset once.
"""

from __future__ import annotations

import csv
import statistics
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import scenes  # noqa: E402

MAIN = __name__ == "__main__"
QUICK = not MAIN or "--quick" in sys.argv
#: load-step counts of the converged roof runs whose median is the roof's reference
ROOF_REFERENCE_STEPS = (1, 8, 32, 64)
#: spread of each reference's runs over its value (filled by the run)
REFERENCE_SPREAD: dict[str, float] = {}
REPEAT = 1 if QUICK else 5
TARGET = 1e-2  # relative error a user asks for when choosing the model
FLOOR = 1e-16  # errors below this are plotted at it
ROUNDOFF = 1e-12  # errors below this count as equal on the Pareto front
ROOT = HERE.parents[1]

# ------------------------------------------------------------------------------ grids
# (method, steps, tol, ratio); ratio None = model as calibrated
if QUICK:
    MIURA_RIGID_STEPS = [4, 8, 16, 32]
    # the 1/r regime starts near r = 100 with the plate-calibrated panel bending (default)
    MIURA_RATIOS = [100.0, 1000.0, 10000.0]
    GRID_MIURA = [("rigid", s, 1e-13, None) for s in MIURA_RIGID_STEPS]
    GRID_MIURA += [("N5B8", 8, 1e-8, r) for r in MIURA_RATIOS]
    YOSHI_RATIOS = [10.0, 100.0, 1000.0]
    GRID_YOSHI = [("rigid", 4, 1e-13, None)] + [("N5B8", 4, 1e-8, r) for r in YOSHI_RATIOS]
    GRID_ROOF = [("rigid", 0, 0.0), ("linear-N5B8", 1, 0.0), ("linear-N4B5", 1, 0.0)]
    GRID_ROOF += [("N5B8", 1, t) for t in (1e-2, 1e-4, 1e-8)] + [("N5B8", 4, 1e-8)]
    GRID_ROOF += [("N4B5", 1, 1e-8)]
else:
    MIURA_RIGID_STEPS = [4, 8, 16, 32, 64]
    MIURA_RATIOS = [1.0, 10.0, 100.0, 1000.0, 10000.0]
    GRID_MIURA = [("rigid", s, 1e-13, None) for s in MIURA_RIGID_STEPS]
    GRID_MIURA += [("rigid", 16, 1e-6, None)]
    for m in ("N4B5", "N5B8"):
        GRID_MIURA += [(m, 8, 1e-8, r) for r in MIURA_RATIOS]
        GRID_MIURA += [(m, s, 1e-8, 1000.0) for s in (4, 16, 32)]
        GRID_MIURA += [(m, 8, 1e-4, 100.0)]
    YOSHI_RATIOS = [1.0, 10.0, 100.0, 1000.0]
    GRID_YOSHI = [("rigid", s, 1e-13, None) for s in (2, 4, 8)] + [("rigid", 4, 1e-6, None)]
    for m in ("N4B5", "N5B8"):
        GRID_YOSHI += [(m, 4, 1e-8, r) for r in YOSHI_RATIOS]
        GRID_YOSHI += [(m, s, 1e-8, 100.0) for s in (2, 8)] + [(m, 4, 1e-4, 100.0)]
    GRID_ROOF = [("rigid", 0, 0.0), ("linear-N5B8", 1, 0.0), ("linear-N4B5", 1, 0.0)]
    for m in ("N4B5", "N5B8"):
        GRID_ROOF += [(m, s, t) for s in (1, 4, 16) for t in (1e-2, 1e-4, 1e-8)]


def _timed(fn, *args, **kw) -> dict:
    """Run ``fn`` REPEAT times; the last record with the median wall time."""
    recs = [fn(*args, **kw) for _ in range(REPEAT)]
    rec = dict(recs[-1])
    rec["time_s"] = statistics.median(r["time_s"] for r in recs)
    return rec


def run_all() -> list[dict]:
    records: list[dict] = []
    for method, steps, tol, ratio in GRID_MIURA:
        rec = _timed(scenes.miura_run, method, steps, tol, ratio)
        records.append(
            {"scene": "miura", "method": method, "steps": steps, "tol": tol, "ratio": ratio, **rec}
        )
    edges = scenes.yoshimura_actuators()
    for method, steps, tol, ratio in GRID_YOSHI:
        rec = _timed(scenes.yoshimura_run, method, steps, tol, ratio, edges=edges)
        records.append(
            {
                "scene": "yoshimura",
                "method": method,
                "steps": steps,
                "tol": tol,
                "ratio": ratio,
                **rec,
            }
        )
    q = scenes.roof_load_scale()
    # reference: the median of converged runs at tolerance 1e-12 with several load-step counts
    # (the soft roof's equilibrium is ill-conditioned: one count may stop up to ~1e-7 away)
    refs = [scenes.roof_run("N5B8", n, 1e-12, q)["value"] for n in ROOF_REFERENCE_STEPS]
    ref = float(np.median(refs))
    REFERENCE_SPREAD["roof"] = float((max(refs) - min(refs)) / abs(ref))
    for method, steps, tol in GRID_ROOF:
        rec = _timed(scenes.roof_run, method, steps, tol, q, ref)
        records.append(
            {"scene": "roof", "method": method, "steps": steps, "tol": tol, "ratio": None, **rec}
        )
    return records


def pareto(records: list[dict]) -> list[dict]:
    """Records not dominated in (time, error): sorted by time, each more accurate than every
    faster one (by more than 1 %)."""
    front, best = [], np.inf
    timed = [r for r in records if r["time_s"] > 0]  # rigid roof: no computation, no time
    for r in sorted(timed, key=lambda r: (r["time_s"], r["error"])):
        err = max(r["error"], ROUNDOFF)
        if err < 0.99 * best:  # 1 %: ignore round-off-level differences
            front.append(r)
            best = err
    return front


#: models from the least to the most a scene can need
MODEL_ORDER = ("rigid", "linear-N4B5", "N4B5", "linear-N5B8", "N5B8")


def needs(records: list[dict], target: float = TARGET) -> dict | None:
    """Model "no more than a scene needs": the first model of ``MODEL_ORDER`` with a run whose
    error is within ``target``, and its fastest such run (None if no run reaches it). Chosen
    by capability, not by the (noisy) wall time."""
    for m in MODEL_ORDER:
        ok = [r for r in records if r["method"] == m and r["error"] <= target]
        if ok:
            return min(ok, key=lambda r: r["time_s"])
    return None


def label(r: dict) -> str:
    s = r["method"]
    if r["method"] in ("rigid", "N4B5", "N5B8") and r["steps"]:
        s += f" n={r['steps']}"
    if r.get("ratio"):
        s += f" r={r['ratio']:g}"
    if r["method"] == "rigid" and r["tol"] and r["tol"] != 1e-13:
        s += f" tol={r['tol']:g}"
    if r["method"] != "rigid" and not r["method"].startswith("linear") and r["tol"]:
        s += f" tol={r['tol']:g}"
    return s


RECORDS = run_all()
SCENES = ("miura", "yoshimura", "roof")
BY_SCENE = {s: [r for r in RECORDS if r["scene"] == s] for s in SCENES}
PARETO = {s: pareto(BY_SCENE[s]) for s in SCENES}
NEEDS = {s: needs(BY_SCENE[s]) for s in SCENES}
COLUMNS = (
    "scene",
    "method",
    "steps",
    "tol",
    "ratio",
    "error",
    "time_s",
    "value",
    "reference",
    "error_dims",
    "pareto",
)


def write_csv(path: Path) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for r in RECORDS:
            on = any(r is p for p in PARETO[r["scene"]])
            row = {**r, "pareto": int(on)}
            w.writerow(
                [
                    ""
                    if row.get(c) is None
                    else (f"{row[c]:.6g}" if isinstance(row[c], float) else row[c])
                    for c in COLUMNS
                ]
            )


def chart(path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    colours = {
        "rigid": "tab:green",
        "N4B5": "tab:orange",
        "N5B8": "tab:blue",
        "linear-N4B5": "tab:brown",
        "linear-N5B8": "tab:purple",
    }
    titles = {
        "miura": "Miura fold: $\\nu_{SL}$ vs Schenk & Guest Eq. 2",
        "yoshimura": "Yoshimura arch: form vs closed form",
        "roof": "loaded Miura roof: deflection vs converged N5B8",
    }
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), layout="constrained")
    for ax, s in zip(axes, SCENES, strict=True):
        for m, c in colours.items():
            rs = [r for r in BY_SCENE[s] if r["method"] == m and r["time_s"] > 0]
            if rs:
                ax.scatter(
                    [r["time_s"] for r in rs],
                    [max(r["error"], FLOOR) for r in rs],
                    color=c,
                    label=m,
                    s=28,
                    alpha=0.85,
                )
        fr = [r for r in PARETO[s] if r["time_s"] > 0]
        ax.step(
            [r["time_s"] for r in fr],
            [max(r["error"], FLOOR) for r in fr],
            where="post",
            color="k",
            lw=1,
            ls="--",
            label="Pareto front",
        )
        ax.axhline(TARGET, color="grey", lw=0.8, ls=":")
        nd = NEEDS[s]
        if nd is not None:
            ax.annotate(
                f"needs: {label(nd)}",
                (nd["time_s"], max(nd["error"], FLOOR)),
                xytext=(8, 12),
                textcoords="offset points",
                fontsize=8,
            )
        if s == "roof":
            ax.text(
                0.45,
                0.6,
                "rigid: no deflection (error 100 %)",
                transform=ax.transAxes,
                fontsize=8,
                va="top",
                color="tab:green",
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("wall time (s, median)")
        ax.set_ylabel("relative error")
        ax.set_title(titles[s], fontsize=10)
        ax.legend(fontsize=7, loc="center right" if s == "yoshimura" else "lower left")
    fig.savefig(path, dpi=110)
    plt.close(fig)


if MAIN:
    if QUICK:
        out = HERE / "results-quick"
        out.mkdir(exist_ok=True)
        csv_path, png_path = out / "speed_accuracy.csv", out / "speed_accuracy.png"
    else:
        csv_path = ROOT / "docs" / "speed-accuracy.csv"
        png_path = ROOT / "docs" / "img" / "speed_accuracy.png"
    write_csv(csv_path)
    chart(png_path)
    for s in SCENES:
        print(f"\n{s}:")
        for r in sorted(BY_SCENE[s], key=lambda r: r["time_s"]):
            on = "*" if any(r is p for p in PARETO[s]) else " "
            print(f" {on} {label(r):32s} error {r['error']:9.2e}  time {r['time_s']:7.3f} s")
        nd = NEEDS[s]
        print(f"  needs (error <= {TARGET:g}): {label(nd) if nd else 'nothing reaches it'}")
        if s in REFERENCE_SPREAD:
            print(f"  reference spread over {ROOF_REFERENCE_STEPS} steps: {REFERENCE_SPREAD[s]:.1e}")
    print("\n| scene | model it needs (error <= 1 %) | Pareto front: run, error, median time |")
    print("|---|---|---|")
    for s in SCENES:
        nd = NEEDS[s]
        front = "<br>".join(f"{label(r)}: {r['error']:.1e}, {r['time_s']:.3f} s" for r in PARETO[s])
        print(f"| {s} | {label(nd) if nd else '-'} | {front} |")
    print(f"\nwrote {csv_path} and {png_path}")
