"""Point functions of the transformations study (imported by the sweep, also on workers).

See run.py for the study and docs/transformations.md for the results.

* ``point(pattern, spacing, curve, kappa_L, ky_L, model, quick, steps)`` folds one pattern
  with actuators on a control curve (or, with ``ky_L``, a control surface) with one model:
  ``model="rigid"`` is the energy-minimising rigid limit (``bh.rigid_fold``, incompatible
  targets met in least squares), ``model=r`` (a number) the bar-and-hinge model (N5B8) with
  bars and panel bending ``r`` times the default (``stiffness_ratio``).
* ``actuator_k`` (any model): compliant actuators, springs of stiffness ``actuator_k`` x the
  stiffest crease's fold stiffness pulling each actuator towards its target, instead of
  held actuators. Both models then minimise the same fold-plus-actuator-spring energy, so the
  bar-and-hinge model converges to the rigid limit as its panels stiffen even where the
  targets are incompatible.
* ``placement_point(pattern, quick, count, placement)`` folds a pattern to a reference rigid
  form with ``count`` actuators chosen by the DOF analysis (``bh.dof``) or along section
  lines, and returns the form error.
"""

from __future__ import annotations

import importlib

import numpy as np

BASE_DEG = 30.0
MATERIAL = {"E": 1e6, "nu": 0.3, "t": 0.01}

# name -> (module of barhinge.families, generator, keyword arguments quick, full)
PATTERNS: dict[str, tuple[str, str, dict, dict]] = {
    "miura": ("miura", "miura", {"nx": 3, "ny": 3}, {"nx": 5, "ny": 5}),
    "miura_arc": ("miura_arc", "miura_arc", {"nx": 3, "ny": 3}, {"nx": 5, "ny": 4}),
    "miura_nonuniform": (
        "miura_nonuniform",
        "miura_nonuniform",
        {"a": [1.0, 0.6, 1.0, 0.6], "b": [1.0, 0.5, 1.0, 0.5]},
        {"a": [1.0, 0.6, 1.0, 0.6, 1.0, 0.6], "b": [1.0, 1.0, 0.5, 0.5, 1.0, 1.0]},
    ),
    "russo_pleat": ("russo", "russo_pleat", {"pleats": 3, "strips": 2}, {}),
    "yoshimura": ("yoshimura", "yoshimura", {"nx": 3, "ny": 3}, {"nx": 5, "ny": 4}),
    "resch": ("resch", "resch", {"nx": 4, "ny": 4}, {}),
}

CURVES = ("circle", "parabola", "spline")
#: stiffness of the compliant actuators, in units of the stiffest crease's fold stiffness
COMPLIANT_K = 100.0
#: Newton iterations of the rigid limit's energy minimisation per step
ENERGY_MAX_ITER = 200


def make_pattern(name: str, quick: bool):
    """The flat crease pattern of a study pattern (quick or full size)."""
    module, func, kq, kf = PATTERNS[name]
    gen = getattr(importlib.import_module(f"barhinge.families.{module}"), func)
    return gen(**(kq if quick else kf))


def make_curve(curve: str, kappa: float, L: float):
    """The control curve ``curve`` with curvature ``kappa`` at its apex (x = 0).

    ``circle``: circle of curvature kappa; ``parabola``: ``z = kappa x^2 / 2``; ``spline``: a
    cubic spline through five points of the lopsided parabola ``z = kappa x^2 (1 + x / L) / 2``
    (curvature ``kappa`` at the apex, ``2 kappa`` at the +x end, 0 at the -x end).
    """
    from barhinge.actuators.curves import CircularArc, Parabola, SplineCurve

    if curve == "circle":
        return CircularArc(kappa)
    if curve == "parabola":
        return Parabola(kappa)
    if curve == "spline":
        xs = np.linspace(-0.5 * L, 0.5 * L, 5)
        return SplineCurve(xs, 0.5 * kappa * xs * xs * (1.0 + xs / L))
    raise ValueError(f"curve must be one of {CURVES}, got {curve!r}")


def nonsync_deg(cp, rho_deg: np.ndarray) -> float:
    """Spread of fold angles among repeated creases (degrees).

    Creases are grouped into classes of equal assignment, flat direction (1 deg) and length
    (1e-6 of the sheet size): in a periodic sheet each class holds the copies of one crease of
    the unit cell. Returns the size-weighted mean of the standard deviation of the fold angles
    within classes of two or more creases (0 = perfectly synchronised local folding).
    """
    E = cp.crease_edges
    V = np.asarray(cp.vertices, float)[:, :2]
    d = V[cp.edges[E, 1]] - V[cp.edges[E, 0]]
    ang = np.round(np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 180.0).astype(int) % 180
    length = np.round(np.hypot(d[:, 0], d[:, 1]) / (1e-6 * cp.size)).astype(np.int64)
    keys: dict = {}
    for e, a, n, asg in zip(E, ang, length, cp.assignment[E], strict=True):
        keys.setdefault((asg, a, n), []).append(e)
    num = den = 0.0
    for members in keys.values():
        if len(members) >= 2:
            num += len(members) * float(np.std(rho_deg[members]))
            den += len(members)
    return num / den if den else 0.0


def _model(cp, ratio: float | None):
    import barhinge as bh

    return bh.BarHingeModel.from_pattern(
        cp, scheme="N5B8", material=bh.Material(**MATERIAL), stiffness_ratio=ratio
    )


def rigid_weights(cp) -> np.ndarray:
    """(n_edges,) fold-spring stiffness of the bar-and-hinge model per edge, normalised to a
    largest crease value of 1 (the rigid limit of that model; the energy minimum does not
    depend on the scale)."""
    from barhinge.solver.branch import fold_weights

    w, _ = fold_weights(_model(cp, None))
    return w / float(w[cp.crease_edges].max())


def fold_scale(cp) -> float:
    """Fold stiffness of the stiffest crease of the default bar-and-hinge model (force x
    length / rad): the unit of ``actuator_k``."""
    from barhinge.solver.branch import fold_weights

    w, _ = fold_weights(_model(cp, None))
    return float(w[cp.crease_edges].max())


def rigid_limit(cp, acts, steps: int):
    """The energy-minimising rigid fold (incompatible targets met in least squares)."""
    import barhinge as bh
    from barhinge.kinematics.path import RigidOptions

    opts = RigidOptions(
        check_actuators=False, over_actuated="least_squares", energy_max_iter=ENERGY_MAX_ITER
    )
    return bh.rigid_fold(cp, acts, steps=steps, fold_stiffness=rigid_weights(cp), options=opts)


def _targets(
    cp,
    spacing: int,
    curve: str,
    kappa_L: float,
    ky_L: float | None,
    base_deg: float = BASE_DEG,
    actuator_k: float | None = None,
):
    """Actuators of one cell: base fold s_i * base_deg plus the control rotation angles;
    compliant with stiffness ``actuator_k`` (in the rigid limit's units: the stiffest
    crease's fold stiffness is 1) when given."""
    import barhinge as bh
    from barhinge.actuators.curves import (
        ControlSurface,
        curve_angles_deg,
        section_crossings,
        surface_actuators,
    )

    edges, x, ends = section_crossings(cp)
    L = ends[1] - ends[0]
    if ky_L is None:
        pick = np.arange(0, len(edges), int(spacing))
        edges, x = edges[pick], x[pick]
        phi = curve_angles_deg(make_curve(curve, kappa_L / L, L), x, ends)
        d = float(np.mean(np.diff(x))) if len(x) > 1 else None
    else:
        ey, _, ends_y = section_crossings(cp, direction=(0.0, 1.0))
        Ly = ends_y[1] - ends_y[0]
        ey = ey[~np.isin(ey, edges)]
        acts = surface_actuators(
            cp,
            ControlSurface(kappa_L / L, ky_L / Ly),
            edges=(edges[:: int(spacing)], ey[:: int(spacing)]),
        )
        edges, phi = acts.edges, acts.targets_deg
        d = None
    sign = np.where(cp.assignment[edges] == "M", -1.0, 1.0)
    acts = bh.Actuators(edges=edges, targets_deg=sign * base_deg + phi, stiffness=actuator_k)
    return acts, L, d


def point(
    pattern: str,
    spacing: int = 1,
    curve: str = "circle",
    kappa_L: float = 0.0,
    ky_L: float | None = None,
    model: str | float = "rigid",
    quick: bool = True,
    steps: int = 6,
    actuator_k: float | None = None,
) -> dict:
    """Fold one pattern with one model; returns the global form and how it was reached."""
    import dataclasses

    import barhinge as bh

    cp = make_pattern(pattern, quick)
    acts, L, d = _targets(cp, spacing, curve, kappa_L, ky_L, actuator_k=actuator_k)
    edges, targets = acts.edges, acts.targets_deg
    held = "" if actuator_k is None else f", compliant actuators {actuator_k:g} x stiffest fold"
    if model == "rigid":
        path = rigid_limit(cp, acts, steps)
        curv = bh.gaussian_curvature(path, pattern=cp)
        misfit = path.meta.get("actuator_misfit_deg")
        label = "rigid limit (energy-minimising)" + held
        free = path.meta.get("free_dof")
    else:
        m = _model(cp, float(model))
        if actuator_k is not None:  # the same springs in the model's units
            acts = dataclasses.replace(acts, stiffness=actuator_k * fold_scale(cp))
        path = bh.solve(bh.Scene(m, actuators=acts, steps=steps))
        curv = bh.gaussian_curvature(path, model=m)
        misfit = path.meta.get("actuator_misfit_deg") if actuator_k is not None else None
        label = f"bar-and-hinge N5B8, stiffness ratio {float(model):g}" + held
        free = None
    rho = path.fold_angles_deg[-1]
    g = curv.global_fit
    defect = curv.angle_defect if curv.angle_defect is not None else np.zeros(1)
    act_err = float(np.max(np.abs(rho[edges] - targets)))
    return {
        "model": "rigid" if model == "rigid" else "bar-hinge",
        "model_label": label,
        "actuator_k": actuator_k,
        "stiffness_ratio": None if model == "rigid" else float(model),
        "n_actuators": len(edges),
        "d_mean": d,
        "L": L,
        "K": float(g.K),
        "KL2": float(g.K) * L * L,
        "k1L": float(g.k1) * L,
        "k2L": float(g.k2) * L,
        "curvature_fit": "one quadratic z(x, y) through the facet centroids",
        "actuator_misfit_deg": act_err if misfit is None else float(misfit[-1]),
        "free_dof": free,
        "nonsync_deg": nonsync_deg(cp, rho),
        "max_angle_defect_deg": float(np.degrees(np.nanmax(np.abs(defect)))),
        "rho_deg": np.round(rho[cp.crease_edges], 9),
        "X": np.round(path.X[-1][: cp.n_vertices], 6),
    }


# ------------------------------------------------------------------------------ placement
def section_placement(cp, count: int) -> np.ndarray:
    """``count`` creases along the two middle section lines: evenly spaced crossings of the
    line along x, then (beyond its crossings) of the line along y."""
    from barhinge.actuators.curves import section_crossings

    ex = section_crossings(cp)[0]
    ey = section_crossings(cp, direction=(0.0, 1.0))[0]
    ey = ey[~np.isin(ey, ex)]
    if count <= len(ex):
        return ex[np.unique(np.round(np.linspace(0, len(ex) - 1, count)).astype(int))]
    k = min(count - len(ex), len(ey))
    return np.concatenate([ex, ey[np.unique(np.round(np.linspace(0, len(ey) - 1, k)).astype(int))]])


def reference_form(cp, seed: int = 0, steps: int = 6):
    """A generic rigid form: the DOF analysis's actuators driven to random angles (20-40 deg
    with their assignment's sign). Returns (actuators of bh.dof, path)."""
    import barhinge as bh

    A = np.asarray(bh.dof(cp).mechanism.actuators, dtype=np.int64)
    rng = np.random.default_rng(seed)
    sign = np.where(cp.assignment[A] == "M", -1.0, 1.0)
    acts = bh.Actuators(edges=A, targets_deg=sign * rng.uniform(20.0, 40.0, len(A)))
    return A, rigid_limit(cp, acts, steps)


def placement_point(
    pattern: str, count: int, placement: str, quick: bool = True, steps: int = 6
) -> dict:
    """Fold to the reference form with ``count`` actuators placed by ``placement``.

    ``placement="dof"``: the first ``count`` actuators of ``bh.dof`` (column-pivoted QR order);
    ``"section"``: :func:`section_placement`. Each actuator is driven to its angle in the
    reference form; the other creases follow the energy-minimising rigid limit. Form error:
    the largest fold-angle difference to the reference over all creases.
    """
    import barhinge as bh

    cp = make_pattern(pattern, quick)
    A, ref = reference_form(cp, steps=steps)
    rho_ref = ref.fold_angles_deg[-1]
    E = A[:count] if placement == "dof" else section_placement(cp, count)
    path = rigid_limit(cp, bh.Actuators(edges=E, targets_deg=rho_ref[E]), steps)
    rho = path.fold_angles_deg[-1]
    L = float(np.ptp(np.asarray(cp.vertices)[:, 0]))
    K = bh.gaussian_curvature(path, pattern=cp).global_fit.K
    K_ref = bh.gaussian_curvature(ref, pattern=cp).global_fit.K
    return {
        "model": "rigid",
        "model_label": "rigid limit (energy-minimising)",
        "n_dof": len(A),
        "n_actuators": len(E),
        "edges": E,
        "reference_misfit_deg": float(ref.meta.get("actuator_misfit_deg", [0.0])[-1]),
        "actuator_misfit_deg": float(path.meta.get("actuator_misfit_deg", [0.0])[-1]),
        "form_error_deg": float(np.max(np.abs(rho - rho_ref)[cp.crease_edges])),
        "KL2": float(K) * L * L,
        "KL2_reference": float(K_ref) * L * L,
    }
