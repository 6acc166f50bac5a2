"""Linear buckling factors of the Yoshimura roofs under 1 kN/m^2 plus self-weight
(``barhinge.analysis.buckling.linear_buckling`` at the stress-free folded state, N5B8, the
study's supports and loads). The factor is the first bifurcation load of the linearised
pre-buckling state; a shallow roof's limit point (arc length) lies somewhat below it.

Run: ``python studies/roofs/buckling_check.py``; ``FACTORS`` holds the results.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import roofs  # noqa: E402

STATES = [10.0, 20.0, 30.0]


def factors(state: float, n_modes: int = 3) -> np.ndarray:
    import barhinge as bh
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.scene import self_weight

    cp, flat_xy, _ = roofs.folded("yoshimura", state)
    m = bh.BarHingeModel.from_pattern(cp, "N5B8", roofs.material())
    S = roofs.supports(m, flat_xy, 0)
    g = (0.0, 0.0, -roofs.G)
    P = roofs.plan_load(m, roofs.Q) + self_weight(m, roofs.DENSITY * roofs.MATERIAL["t"], g=g)
    return linear_buckling(m, P, S, n_modes=n_modes).factors


FACTORS = {s: factors(s) for s in STATES}

if __name__ == "__main__":
    for s, f in FACTORS.items():
        print(f"yoshimura 2 beta = {s:g} deg: linear buckling factors {np.round(f, 3).tolist()}")
