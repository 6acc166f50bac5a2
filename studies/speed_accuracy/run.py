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
if MAIN:  # a mistyped option or --help must not start the full run
    from barhinge._study_args import check_study_argv

    check_study_argv(__doc__, flags=("--quick", "--publish"), valued=())
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


def _pick(scene: str, method: str, **kw) -> list[dict]:
    """Records of ``scene`` and ``method`` whose fields equal ``kw``."""
    return [r for r in BY_SCENE[scene] if r["method"] == method
            and all(r.get(k) == v for k, v in kw.items())]  # fmt: skip


def _slope(x: list[float], y: list[float]) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def results_table() -> str:
    """The table of the model each scene needs and its Pareto front."""
    lines = [
        f"| scene | model it needs (error <= {TARGET:.0%}) | Pareto front: run, error, median "
        "time |",
        "|---|---|---|",
    ]
    for s in SCENES:
        nd = NEEDS[s]
        front = "<br>".join(f"{label(r)}: {r['error']:.1e}, {r['time_s']:.3f} s" for r in PARETO[s])
        lines.append(f"| {s} | {label(nd) if nd else '-'} | {front} |")
    return "\n".join(lines)


def convergence_notes() -> str:
    """The convergence findings, every number from ``RECORDS`` (full mode)."""
    out = []
    rig = sorted(_pick("miura", "rigid", tol=1e-13), key=lambda r: r["steps"])
    if len(rig) >= 2:
        n = [r["steps"] for r in rig]
        e = [r["error"] for r in rig]
        out.append(
            f"* **Rigid Miura, ν_SL against the step count n** (n = {', '.join(map(str, n))}): "
            f"relative error {', '.join(f'{v:.2e}' for v in e)}; slope {_slope(n, e):.2f} on "
            "log-log axes, the O(h²) of the difference formula (the states themselves match "
            "S&G Eq. 1 at every n). Tested: slope −2 ± 0.2."
        )
    parts, slopes = [], []
    for m in ("N5B8", "N4B5"):
        rs = sorted(_pick("miura", m, steps=8, tol=1e-8), key=lambda r: r["ratio"])
        if len(rs) < 2:
            continue
        parts.append(f"{m} " + ", ".join(f"{r['error_dims']:.1e}" for r in rs))
        big = [r for r in rs if r["ratio"] >= 100]
        if len(big) >= 2:
            slopes.append(
                f"{m} {_slope([r['ratio'] for r in big], [r['error_dims'] for r in big]):.2f}"
            )
        ratios = ", ".join(f"{r['ratio']:g}" for r in rs)
    if parts:
        nu8 = _pick("miura", "N5B8", steps=8, tol=1e-8, ratio=1000.0)
        nu32 = _pick("miura", "N5B8", steps=32, tol=1e-8, ratio=1000.0)
        tail = (
            f" The ν_SL error adds the step error of the path: at r = 1000 it is "
            f"{nu8[0]['error']:.1e} with 8 steps and {nu32[0]['error']:.1e} with 32 (N5B8)."
            if nu8 and nu32
            else ""
        )
        out.append(
            "* **Bar-and-hinge Miura against the stiffness ratio r** (8 steps): error of the "
            f"cell dimensions at r = {ratios}: {'; '.join(parts)}. Slope over r ≥ 100: "
            f"{', '.join(slopes)}, first order in 1/r (tested: −1 ± 0.15)." + tail
        )
    ys = sorted(_pick("yoshimura", "N5B8", steps=4, tol=1e-8), key=lambda r: r["ratio"])
    if len(ys) >= 2:
        out.append(
            "* **Yoshimura form against r** (r = "
            + ", ".join(format(r["ratio"], "g") for r in ys)
            + "): "
            + ", ".join(format(r["error"], ".1e") for r in ys)
            + " (slope "
            + f"{_slope([r['ratio'] for r in ys], [r['error'] for r in ys]):.2f}; tested "
            "−1 ± 0.15). N4B5 and N5B8 are the same model here (all facets are triangles)."
        )
    tol = sorted(_pick("roof", "N5B8", steps=1), key=lambda r: -r["tol"])
    if tol:
        out.append(
            "* **Roof, tolerance**: with one load step the error is "
            + ", ".join(f"{r['error']:.1e}" for r in tol)
            + " at tolerances "
            + ", ".join(f"{r['tol']:g}" for r in tol)
            + f". The reference is the median of {len(ROOF_REFERENCE_STEPS)} converged runs "
            f"({', '.join(map(str, ROOF_REFERENCE_STEPS))} load steps at 1e-12); their spread, "
            f"{REFERENCE_SPREAD.get('roof', float('nan')):.1e}, is the floor of any single "
            "reference run."
        )
    lin = _pick("roof", "linear-N5B8")
    n4 = _pick("roof", "N4B5", steps=16, tol=1e-8)
    if lin and n4:
        out.append(
            f"* **Roof, model**: the linear solution misses {lin[0]['error']:.0%} (N5B8) of the "
            "deflection at the load of a 2 % linear sag (geometric nonlinearity); N4B5 differs "
            f"from N5B8 by {n4[0]['error']:.0%} at 16 load steps and tolerance 1e-8: a model "
            "difference (N4B5's single diagonal makes the panels anisotropic, see "
            "docs/calibration.md), not a solver error."
        )
    return "\n".join(out)


def needs_notes() -> str:
    """Which model each kind of scene needs, with the measured times (full mode)."""

    def fastest(scene: str, pred) -> dict | None:
        ok = [r for r in BY_SCENE[scene] if pred(r) and r["error"] <= TARGET and r["time_s"] > 0]
        return min(ok, key=lambda r: r["time_s"]) if ok else None

    out = []
    for s in ("yoshimura", "miura"):
        rig = fastest(s, lambda r: r["method"] == "rigid")
        bhm = fastest(s, lambda r: r["method"] in ("N4B5", "N5B8"))
        if rig and bhm:
            out.append(
                f"* {s}: rigid kinematics {label(rig)} in {rig['time_s']:.3f} s; the fastest "
                f"bar-and-hinge run within {TARGET:.0%}, {label(bhm)}, {bhm['time_s']:.3f} s."
            )
    roof = NEEDS.get("roof")
    lin = _pick("roof", "linear-N5B8")
    if roof is not None:
        out.append(
            f"* roof: {label(roof)} reaches {TARGET:.0%} ({roof['error']:.1e}, "
            f"{roof['time_s']:.3f} s)"
            + (f"; a linear solve is {lin[0]['error']:.0%} off." if lin else ".")
        )
    return "\n".join(out)


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
            spread = REFERENCE_SPREAD[s]
            print(f"  reference spread over {ROOF_REFERENCE_STEPS} steps: {spread:.1e}")
    print("\n" + results_table())
    if not QUICK:
        print("\n" + convergence_notes() + "\n\n" + needs_notes())
    if "--publish" in sys.argv and not QUICK:
        from barhinge._publish import generated_stamp, write_between

        doc = ROOT / "docs" / "speed-accuracy.md"
        stamp = generated_stamp("python studies/speed_accuracy/run.py --publish")
        write_between(doc, "<!-- speed-accuracy:start -->", "<!-- speed-accuracy:end -->",
                      stamp + "\n\n" + results_table() + "\n\n" + convergence_notes())  # fmt: skip
        write_between(doc, "<!-- speed-accuracy-needs:start -->",
                      "<!-- speed-accuracy-needs:end -->", needs_notes())  # fmt: skip
        print(f"wrote {doc}")
    print(f"\nwrote {csv_path} and {png_path}")
