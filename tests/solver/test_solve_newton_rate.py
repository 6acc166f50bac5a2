"""Newton's rate with the analytic tangent: the residual falls quadratically.

The rate ``p`` is the slope of ``log r_{k+1}`` against ``log r_k`` (r_{k+1} = C r_k^p) fitted
over the asymptotic tail of one increment's residual sequence: its last three residuals above
the round-off floor (1e-10 here; the floor is ~1e-12). Earlier iterations are outside the
quadratic basin (the soft fold modes make it small) and are not part of the rate. Stiffness
values are moderate (bars 100, panels 1, folds 0.05) so that several iterations fall inside
the quadratic basin.
"""

from __future__ import annotations

import numpy as np

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene, select_vertices

# Newton corrections only (no chord corrections, whose rate is linear by design)
OPTS = {
    "predictor": "tangent",
    "corrector": "newton",
    "tol_force": 1e-13,
    "tol_disp": 1e-14,
    "force_floor": 1e-11,
}


def _rate(res: tuple[float, ...]) -> float:
    r = np.asarray(res, float)
    tail = r[r > 1e-10][-3:]
    assert len(tail) == 3, f"too few iterations above the round-off floor: {res}"
    return float(np.polyfit(np.log(tail[:-1]), np.log(tail[1:]), 1)[0])


def _model(cp):
    return BarHingeModel.from_pattern(cp, "N5B8", bar_EA=100.0, bend_k=1.0, fold_k=0.05)


def test_quadratic_rate_miura_folded_by_actuators():
    cp0 = bh.families.miura(3, 3, alpha=60.0, fold=10.0)
    cp1 = bh.families.miura(3, 3, alpha=60.0, fold=20.0)
    edges = miura_line_creases(bh.families.miura(3, 3, alpha=60.0))
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    path = bh.solve(Scene(_model(cp0), actuators=acts, steps=1, options=OPTS))
    assert _rate(path.residual_norms[1]) >= 1.8


def test_quadratic_rate_loaded_roof():
    """A Yoshimura barrel roof on its two end edges under nodal gravity loads."""
    cp = bh.families.yoshimura(3, 2, fold=30.0)
    model = _model(cp)
    S = np.zeros((model.n_nodes, 3), bool)
    for side in ("bottom", "top"):
        S[select_vertices(model, side)] = True
    P = np.zeros((model.n_nodes, 3))
    P[: cp.n_vertices, 2] = -0.05
    path = bh.solve(Scene(model, supports=S, loads=P, steps=1, options=OPTS))
    assert path.X[-1, :, 2].min() < path.X[0, :, 2].min()  # it sagged
    assert _rate(path.residual_norms[1]) >= 1.8
