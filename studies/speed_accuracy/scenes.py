"""The three scenes of the speed-accuracy study and one run of each (pure functions).

Every ``*_run`` function builds the pattern and the model, solves and measures, and returns a
record ``{"error": relative error of the scene's quantity, "time_s": wall time, ...}``. Wall
time covers everything a user pays for that answer (pattern, model, solve, post-processing).

Scenes and their references
---------------------------
* ``miura``: a 3 x 3 Miura-ori (a = b = 1, sector angle 60 deg) folded from facet angle 10 to
  40 deg by the creases of one straight crease line. Quantity: the in-plane Poisson's ratio
  ``nu_SL`` at the last state, from the path by the three-point backward difference of the
  cell dimensions L, S (second order in the step). Reference: Schenk & Guest 2013, PNAS
  110(9):3276, Eq. 2, ``nu_SL = -cos^2(theta) tan^2(gamma)``. Also recorded: the error of the
  cell dimensions L, S against their Eq. 1 (no step error: a converged state).
* ``yoshimura``: a 4 x 3 Yoshimura arch folded from fold = 5 to 30 deg by the 12 actuators
  that ``bh.dof`` suggests (the pattern has 12 rigid DOF). Quantity: the folded form, RMS
  vertex distance after best-fit rigid alignment (Kabsch) divided by the arch's size.
  Reference: the closed-form rigidly folded arch ``bh.families.yoshimura(fold=30)`` (rows are
  regular polygons of circumradius ``w / (2 sin beta)`` spaced ``sqrt(h^2 - (w/2)^2
  tan^2(beta/2))``).
* ``roof``: a 3 x 3 Miura roof folded to facet angle 45 deg, pinned along its two edges
  y = min and y = max, under a uniform load per unit sheet area (downwards) large enough that
  the linear deflection is 2 % of the span. Quantity: the largest downward deflection.
  Reference: the converged N5B8 solution (64 load steps, tolerances 1e-12); rigid kinematics
  cannot carry a load (error 100 %).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

GAMMA = 60.0
MIURA_N = 3
TH0, TH1 = 10.0, 40.0
YOSHI = {"nx": 4, "ny": 3, "w": 1.0, "h": 0.5}
FOLD0, FOLD1 = 5.0, 30.0
ROOF_THETA = 45.0
ROOF_SAG = 0.02  # linear deflection / span that fixes the roof load
MATERIAL = {"E": 1e6, "nu": 0.3, "t": 0.01}
FOLD_STIFFNESS = 1e-2


def _material():
    import barhinge as bh

    return bh.Material(**MATERIAL)


def kabsch_rms(X: np.ndarray, Y: np.ndarray) -> float:
    """RMS distance between point sets X, Y (n, 3) after the best rigid motion of X onto Y
    (Kabsch 1976, Acta Cryst. A32:922; reflections excluded)."""
    Xc, Yc = X - X.mean(0), Y - Y.mean(0)
    U, _, Vt = np.linalg.svd(Xc.T @ Yc)
    d = np.sign(np.linalg.det(U @ Vt))
    R = U @ np.diag([1.0, 1.0, d]) @ Vt
    return float(np.sqrt(((Xc @ R - Yc) ** 2).sum(1).mean()))


# ------------------------------------------------------------------------------ Miura
def miura_dims(X: np.ndarray, n: int = MIURA_N) -> tuple[float, float]:
    """Cell half-length L (x) and half-width S (y) from the middle row / column of an
    n x n Miura sheet (vertex (i, j) has id j (2 n + 1) + i; see ``bh.families.miura``)."""
    ni = nj = 2 * n + 1
    vid = lambda i, j: j * ni + i  # noqa: E731
    L = np.linalg.norm(X[vid(ni - 1, n)] - X[vid(0, n)]) / (2 * n)
    S = np.linalg.norm(X[vid(n, nj - 1)] - X[vid(n, 0)]) / (2 * n)
    return float(L), float(S)


def nu_from_path(X: np.ndarray) -> float:
    """nu_SL = -(dL/L)/(dS/S) at the last state of a path (n_states, n_nodes, 3) whose states
    are equally spaced in the path parameter: three-point backward differences
    ``f' ~ (3 f_k - 4 f_{k-1} + f_{k-2}) / (2 h)`` (error O(h^2); h cancels in the ratio)."""
    (L0, S0), (L1, S1), (L2, S2) = (miura_dims(X[i]) for i in (-3, -2, -1))
    dL, dS = 3 * L2 - 4 * L1 + L0, 3 * S2 - 4 * S1 + S0
    return float(-(dL / L2) / (dS / S2))


def miura_run(method: str, steps: int, tol: float, ratio: float | None = None) -> dict[str, Any]:
    """One Miura fold. ``method``: "rigid", "N4B5" or "N5B8"; ``tol``: the rigid closure
    tolerance or the solver's force and displacement tolerance; ``ratio``: stiffness ratio of
    bars and panels (bar-and-hinge only)."""
    import barhinge as bh
    from barhinge.families import miura_line_creases
    from barhinge.kinematics.path import RigidOptions

    t0 = time.perf_counter()
    cp0 = bh.families.miura(MIURA_N, MIURA_N, alpha=GAMMA, fold=TH0)
    rho1 = np.asarray(bh.families.miura(MIURA_N, MIURA_N, alpha=GAMMA, fold=TH1).fold_angles)
    edges = miura_line_creases(cp0)
    if method == "rigid":
        opts = RigidOptions(tol=tol, check_rank=False)
        path = bh.rigid_fold(cp0, edges, rho1[edges], steps=steps, options=opts)
    else:
        model = bh.BarHingeModel.from_pattern(
            cp0, method, _material(), fold_stiffness=FOLD_STIFFNESS, stiffness_ratio=ratio
        )
        acts = bh.Actuators(edges=edges, targets_deg=rho1[edges])
        options = {"tol_force": tol, "tol_disp": tol}
        path = bh.solve(bh.Scene(model, actuators=acts, steps=steps, options=options))
    X = path.X[:, : cp0.n_vertices]
    nu = nu_from_path(X)
    L, S = miura_dims(X[-1])
    elapsed = time.perf_counter() - t0
    g = bh.families.miura_geometry(1.0, 1.0, GAMMA, TH1)
    return {
        "error": abs(nu - g.nu_SL) / abs(g.nu_SL),
        "time_s": elapsed,
        "value": nu,
        "reference": g.nu_SL,
        "error_dims": max(abs(L - g.L) / g.L, abs(S - g.S) / g.S),
    }


# ------------------------------------------------------------------------------ Yoshimura
def yoshimura_actuators() -> np.ndarray:
    """Edge ids of the 12 actuators ``bh.dof`` suggests at the start state."""
    import barhinge as bh

    return np.asarray(bh.dof(bh.families.yoshimura(**YOSHI, fold=FOLD0)).actuators)


def yoshimura_run(
    method: str, steps: int, tol: float, ratio: float | None = None, edges=None
) -> dict[str, Any]:
    """One Yoshimura arch fold (arguments as :func:`miura_run`)."""
    import barhinge as bh
    from barhinge.kinematics.path import RigidOptions

    t0 = time.perf_counter()
    cp0 = bh.families.yoshimura(**YOSHI, fold=FOLD0)
    cp1 = bh.families.yoshimura(**YOSHI, fold=FOLD1)
    rho1 = np.asarray(cp1.fold_angles)
    edges = yoshimura_actuators() if edges is None else edges
    if method == "rigid":
        opts = RigidOptions(tol=tol, check_rank=False)
        path = bh.rigid_fold(cp0, edges, rho1[edges], steps=steps, options=opts)
    else:
        model = bh.BarHingeModel.from_pattern(
            cp0, method, _material(), fold_stiffness=FOLD_STIFFNESS, stiffness_ratio=ratio
        )
        acts = bh.Actuators(edges=edges, targets_deg=rho1[edges])
        options = {"tol_force": tol, "tol_disp": tol}
        path = bh.solve(bh.Scene(model, actuators=acts, steps=steps, options=options))
    Y = np.asarray(cp1.vertices3d)
    err = kabsch_rms(path.X[-1, : cp0.n_vertices], Y)
    elapsed = time.perf_counter() - t0
    size = float(np.linalg.norm(np.ptp(Y, axis=0)))
    return {"error": err / size, "time_s": elapsed, "value": err, "reference": 0.0}


# ------------------------------------------------------------------------------ roof
def roof_setup(scheme: str):
    """(model, supports, unit load): the Miura roof, pinned along y = min and y = max, with a
    downward load of 1 per unit sheet area (lumped to the facet corners)."""
    import barhinge as bh
    from barhinge.scene import select_vertices, self_weight

    cp = bh.families.miura(MIURA_N, MIURA_N, alpha=GAMMA, fold=ROOF_THETA)
    model = bh.BarHingeModel.from_pattern(cp, scheme, _material())
    S = np.zeros((model.n_nodes, 3), bool)
    S[select_vertices(model, "bottom")] = True
    S[select_vertices(model, "top")] = True
    F = self_weight(model, 1.0, g=(0.0, 0.0, -1.0))
    return model, S, F


def roof_span() -> float:
    import barhinge as bh

    return float(
        np.ptp(
            np.asarray(
                bh.families.miura(MIURA_N, MIURA_N, alpha=GAMMA, fold=ROOF_THETA).vertices3d
            )[:, 1]
        )
    )


def roof_load_scale() -> float:
    """Load intensity q (per unit sheet area) whose linear N5B8 deflection is ROOF_SAG x span."""
    from barhinge.analysis.stiffness import linear_response

    model, S, F = roof_setup("N5B8")
    U, _ = linear_response(model, F, S)
    return ROOF_SAG * roof_span() / float(np.max(-U[:, 2]))


def roof_run(
    method: str, steps: int, tol: float, q: float, reference: float | None = None
) -> dict[str, Any]:
    """One loaded-roof analysis. ``method``: "rigid" (no deflection), "linear-N4B5",
    "linear-N5B8" (one linear solve at the unloaded state) or "N4B5" / "N5B8" (geometrically
    nonlinear, load control in ``steps`` steps with tolerance ``tol``). ``reference``: the
    converged deflection (None: return the value only)."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response

    t0 = time.perf_counter()
    if method == "rigid":
        defl = 0.0
    elif method.startswith("linear-"):
        model, S, F = roof_setup(method.removeprefix("linear-"))
        U, _ = linear_response(model, q * F, S)
        defl = float(np.max(-U[:, 2]))
    else:
        model, S, F = roof_setup(method)
        options = {"tol_force": tol, "tol_disp": tol}
        scene = bh.Scene(
            model, supports=S, loads=q * F, steps=steps, control="load", options=options
        )
        path = bh.solve(scene)
        defl = float(np.max(-(path.X[-1, :, 2] - model.X0[:, 2])))
    elapsed = 0.0 if method == "rigid" else time.perf_counter() - t0
    err = float("nan") if reference is None else abs(defl - reference) / abs(reference)
    return {"error": err, "time_s": elapsed, "value": defl, "reference": reference}
