"""Six tessellations driven by actuators on a control curve: spacing x curvature.

For each pattern (three Miura-ori variations, a Russo-style optical-illusion pleat, Yoshimura
and Ron Resch) a section line across the middle of the flat sheet (along +x) crosses the
creases at points P; every ``spacing``-th crossing is an actuator. Each actuator's target is a
synchronised base fold plus the control-curve rotation angle (barhinge.control):

    rho_i = s_i * BASE_DEG + Phi_i(kappa),    s_i = +1 valley, -1 mountain,

with ``Phi_i`` the turning angle that puts the actuator points on a circle of curvature
``kappa = kappa_L / L`` (``L`` = width of the sheet along the section; ``kappa_L = 0`` is the
synchronised mode). The sheet is folded with rigid kinematics (``bh.rigid_fold``: planar
panels; if that fails, panels may bend along diagonals, ``triangulated=True``); the other
creases follow the minimum-norm motion. Per run: Gaussian curvature of the global form
(``bh.gaussian_curvature``, quadratic fit through facet centroids), the spread of fold angles
among repeated creases (non-synchronised local folding), and the error if the run failed.

Run: ``python studies/transformations/run.py [--quick] [--serial] [--workers N]
[--retry-failed]`` (a rerun skips finished runs; ``--retry-failed`` reruns failed ones; full mode
writes pictures next to this file under results/ and into docs/img/). Importing the module
runs the quick mode (results in ``$BARHINGE_STUDY_OUT`` or a temporary folder).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from transform import PATTERNS, make_pattern  # noqa: E402

MAIN = __name__ == "__main__"
QUICK = not MAIN or "--quick" in sys.argv

SPACINGS = [1] if QUICK else [1, 2, 3]
KAPPA_L = [0.0, 1.0] if QUICK else [-1.0, 0.0, 0.5, 1.0, 1.5]
STEPS = 6 if QUICK else 12
KEYS = ("K", "KL2", "nonsync_deg", "max_angle_defect_deg")


def study():
    from barhinge.sweep import Study

    return Study(
        function="transform:point",
        grid={"pattern": list(PATTERNS), "spacing": SPACINGS, "kappa_L": KAPPA_L},
        fixed={"quick": QUICK, "steps": STEPS},
        name="transformations-quick" if QUICK else "transformations",
        batch_size=1,
        paths=(str(HERE),),
    )


def collect(records: dict) -> tuple[dict, list]:
    """Arrays over the grid (NaN where a run failed) per pattern, and the failures."""
    res = {p: {k: np.full((len(SPACINGS), len(KAPPA_L)), np.nan) for k in KEYS} for p in PATTERNS}
    failed = []
    for rec in records.values():
        prm = rec["params"]
        i, j = SPACINGS.index(prm["spacing"]), KAPPA_L.index(prm["kappa_L"])
        if rec["status"] == "ok":
            for k in KEYS:
                res[prm["pattern"]][k][i, j] = rec["result"][k]
        else:
            failed.append((prm["pattern"], prm["spacing"], prm["kappa_L"], rec["error"]))
    return res, sorted(failed, key=lambda f: (list(PATTERNS).index(f[0]), f[1], f[2]))


# ------------------------------------------------------------------------------ run
from barhinge.sweep import read_records, run_study  # noqa: E402

OUT = Path(
    os.environ.get("BARHINGE_STUDY_OUT")
    or (HERE / ("results-quick" if QUICK else "results") if MAIN else tempfile.mkdtemp())
)
REPORT = run_study(
    study(),
    out=OUT,
    mode="serial" if (QUICK or "--serial" in sys.argv) else "local",
    retry_failed="--retry-failed" in sys.argv,
    workers=int(sys.argv[sys.argv.index("--workers") + 1]) if "--workers" in sys.argv else None,
)
RECORDS = {k: v for k, v in read_records(OUT).items()}
RESULTS, FAILED = collect(RECORDS)


# ------------------------------------------------------------------------------ pictures
def _faces_poly(cp, X):
    return [X[list(f)] for f in cp.faces]


def picture_grid(pattern: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    try:
        cp = make_pattern(pattern, QUICK)
    except ImportError:
        cp = None
    fig = plt.figure(figsize=(2.6 * len(KAPPA_L), 2.4 * len(SPACINGS)), layout="constrained")
    for rec in RECORDS.values():
        prm = rec["params"]
        if prm["pattern"] != pattern:
            continue
        i, j = SPACINGS.index(prm["spacing"]), KAPPA_L.index(prm["kappa_L"])
        ax = fig.add_subplot(len(SPACINGS), len(KAPPA_L), i * len(KAPPA_L) + j + 1,
                             projection="3d")  # fmt: skip
        ax.set_title(f"every {prm['spacing']}, kL = {prm['kappa_L']:g}", fontsize=8)
        ax.set_axis_off()
        if rec["status"] != "ok":
            ax.text2D(0.5, 0.5, "failed:\n" + rec["error"]["type"], ha="center",
                      transform=ax.transAxes, fontsize=8, color="tab:red")  # fmt: skip
            continue
        X = np.asarray(rec["result"]["X"])
        rigid = rec["result"]["model"] == "rigid"
        ax.set_title(f"every {prm['spacing']}, kL = {prm['kappa_L']:g}"
                     + ("" if rigid else " (bar-hinge)"), fontsize=8)  # fmt: skip
        ax.add_collection3d(Poly3DCollection(_faces_poly(cp, X),
                                             facecolor="#9ec5e8" if rigid else "#f5c08a",
                                             edgecolor="k", linewidths=0.2))  # fmt: skip
        lo, hi = X.min(0), X.max(0)
        c, r = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo))
        ax.set(xlim=(c[0] - r, c[0] + r), ylim=(c[1] - r, c[1] + r), zlim=(c[2] - r, c[2] + r))
        ax.view_init(elev=25, azim=-60)
    fig.suptitle(f"{pattern}: actuator spacing (rows) x curvature kappa L (columns)", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def heat_maps(key: str, label: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(11, 6), layout="constrained")
    for ax, p in zip(axes.flat, PATTERNS, strict=True):
        A = RESULTS[p][key]
        if key in ("K", "KL2"):
            m = float(np.nanmax(np.abs(A), initial=0.0)) or 1.0
            im = ax.imshow(A, cmap="coolwarm", vmin=-m, vmax=m, origin="lower")
        else:
            im = ax.imshow(A, cmap="viridis", origin="lower")
        ax.set_xticks(range(len(KAPPA_L)), [f"{k:g}" for k in KAPPA_L])
        ax.set_yticks(range(len(SPACINGS)), [str(s) for s in SPACINGS])
        ax.set_xlabel("kappa L")
        ax.set_ylabel("spacing (crossings)")
        ax.set_title(p, fontsize=10)
        for (i, j), v in np.ndenumerate(A):
            txt = "failed" if np.isnan(v) else ("0" if abs(v) < 1e-9 else f"{v:.2g}")
            ax.text(j, i, txt, ha="center", va="center",
                    fontsize=7)  # fmt: skip
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.suptitle(label)
    fig.savefig(path, dpi=110)
    plt.close(fig)


if MAIN:
    img = OUT / "img"
    img.mkdir(parents=True, exist_ok=True)
    for p in PATTERNS:
        picture_grid(p, img / f"forms_{p}.png")
    heat_maps("KL2", "Gaussian curvature of the global form, K L^2 (L = sheet width)",
              img / "heat_K.png")  # fmt: skip
    heat_maps("nonsync_deg", "Spread of fold angles among repeated creases (deg)",
              img / "heat_nonsync.png")  # fmt: skip
    if not QUICK:  # the pictures of docs/transformations.md
        import shutil

        docs_img = HERE.parents[1] / "docs" / "img"
        docs_img.mkdir(parents=True, exist_ok=True)
        for f in img.glob("*.png"):
            shutil.copy(f, docs_img / f"transformations_{f.name}")
    print(f"{'pattern':>17} {'ok':>3} {'rigid':>5} {'b&h':>4} {'failed':>6} "
          f"{'K L^2 min':>10} {'K L^2 max':>10} {'nonsync max':>11}")  # fmt: skip
    for p in PATTERNS:
        recs = [r for r in RECORDS.values() if r["params"]["pattern"] == p]
        ok = [r["result"] for r in recs if r["status"] == "ok"]
        kl = [q["KL2"] for q in ok] or [np.nan]
        ns = [q["nonsync_deg"] for q in ok] or [np.nan]
        print(f"{p:>17} {len(ok):>3} {sum(q['model'] == 'rigid' for q in ok):>5} "
              f"{sum(q['model'] == 'bar-hinge' for q in ok):>4} {len(recs) - len(ok):>6} "
              f"{min(kl):>10.3g} {max(kl):>10.3g} {max(ns):>11.3g}")  # fmt: skip
    print(f"{REPORT.total} runs ({REPORT.skipped} from before), {len(FAILED)} failed -> {OUT}")
    for f in FAILED:
        print(f"  failed: {f[0]:>17} spacing {f[1]} kappa_L {f[2]:>5}: {f[3]['type']}: "
              f"{f[3]['message'][:150]}")  # fmt: skip
