"""``barhinge fold --accuracy`` on the roofs: the model :func:`choose_model` picks for a target,
its estimated error, its error against the consistent model's own converged limit (from the
finer levels m = 8, 16, 32, Richardson) and its distance to the shell reference of
``shell_check.py`` (a different model: see docs/roofs.md, "Against a shell model").

Run: ``python studies/roofs/accuracy_check.py [ROOF:STATE ...]`` (default pleats:90).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import roofs  # noqa: E402


def roof_scene(family: str, state: float):
    """The study's roof as a Scene: N5B8, pinned supported edges, plan load lumped."""
    import barhinge as bh
    from barhinge.scene import Scene

    cp, flat_xy, _ = roofs.folded(family, state)
    c = flat_xy[:, roofs.FAMILIES[family]["axis"]]
    tol = 1e-6 * float(np.ptp(c))
    sv = np.flatnonzero((c <= c.min() + tol) | (c >= c.max() - tol))
    model = bh.BarHingeModel.from_pattern(cp, "N5B8", roofs.material())
    S = np.zeros((model.n_nodes, 3), bool)
    S[sv] = True
    return Scene(model=model, supports=S, loads=roofs.plan_load(model, roofs.Q), name=family)


def main(specs: list[str]) -> None:
    from barhinge.analysis.accuracy import _response, choose_model, richardson, subdivided_scene
    from barhinge.errors import ConvergenceError

    print("| roof | target | chosen | estimated error | error vs m = 8, 16, 32 limit | time (s) |")
    print("|---|---|---|---|---|---|")
    for spec in specs:
        fam, st = spec.split(":")
        scene = roof_scene(fam, float(st))
        fine = [_response(subdivided_scene(scene, m))[0]["stiffness"] for m in (8, 16, 32)]
        ref = richardson(fine)[0]
        for target in ("20%", "10%", "5%", "2%"):
            t0 = time.perf_counter()
            try:
                ch = choose_model(scene, target)
            except ConvergenceError as exc:
                print(f"| {fam} {st} | {target} | none ({exc}) | | | |")
                continue
            c = ch.chosen
            print(
                f"| {fam} {st} | {target} | {c.name} | {100 * c.error:.2f} % | "
                f"{100 * (c.values['stiffness'] / ref - 1):+.2f} % | "
                f"{time.perf_counter() - t0:.1f} |"
            )


if __name__ == "__main__":
    main(sys.argv[1:] or ["pleats:90"])
