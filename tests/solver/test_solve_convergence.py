"""The convergence test of a Newton increment (barhinge.solver.convergence): a state whose
force and actuator tests pass is accepted when its *next* Newton correction (one
back-substitution with the last factorisation) is below the displacement tolerance, whatever
the size of the last correction; and states accepted so lie within the displacement
tolerance of the tightly converged path."""

from __future__ import annotations

import numpy as np

import barhinge as bh
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene, select_vertices
from barhinge.solver.context import SolveContext
from barhinge.solver.convergence import Convergence
from barhinge.solver.state import State


def _roof(**options) -> Scene:
    """A Yoshimura barrel roof on its two end edges under nodal gravity loads."""
    cp = bh.families.yoshimura(3, 2, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", bar_EA=100.0, bend_k=1.0, fold_k=0.05)
    S = np.zeros((model.n_nodes, 3), bool)
    for side in ("bottom", "top"):
        S[select_vertices(model, side)] = True
    P = np.zeros((model.n_nodes, 3))
    P[: cp.n_vertices, 2] = -0.05
    return Scene(model, supports=S, loads=P, steps=4, options=options)


def test_a_state_that_passes_the_force_test_is_judged_by_its_next_correction():
    scene = _roof(tol_force=1e-12, tol_disp=1e-13)
    path = bh.solve(scene)
    ctx = SolveContext(scene)
    conv = Convergence(ctx)
    st = State(path.X[-1].ravel().copy(), np.zeros(0), 1.0, 1.0)
    e = ctx.evaluate(st)
    tol_x = ctx.opts.tol_disp * ctx.size
    big = np.full(ctx.free.sum(), 1e3 * tol_x)  # a last correction far above the tolerance
    small = np.zeros(ctx.free.sum())
    assert conv.converged(e, st, big, lambda: small)
    assert not conv.converged(e, st, big, lambda: big)
    # the force test fails: no correction accepts the state
    off = State(st.x.copy(), st.mu, st.lam, st.t)
    off.x[ctx.free] += 1e-3
    e_off = ctx.evaluate(off)
    assert not conv.converged(e_off, off, small, lambda: small)


def test_states_accepted_by_the_next_correction_lie_within_the_tolerance():
    tol = 1e-8
    loose = bh.solve(_roof(tol_disp=tol))
    tight = bh.solve(_roof(tol_disp=1e-13, tol_force=1e-13))
    size = float(np.ptp(loose.X[0], axis=0).max())
    for a, b in zip(loose.X[1:], tight.X[1:], strict=True):
        assert float(np.linalg.norm(a - b)) <= 3 * tol * size
