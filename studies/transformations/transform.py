"""Point function of the transformations study (imported by the sweep, also on workers).

See run.py for the study. ``point(pattern, spacing, kappa_L, quick, steps)`` folds one
pattern and returns a small record.
"""

from __future__ import annotations

import importlib

import numpy as np

BASE_DEG = 30.0


def _material():
    from barhinge.model.calibrate import Material

    return Material(E=1e6, nu=0.3, t=0.01)


# name -> (module of barhinge.patterns, generator, keyword arguments quick, full)
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


def make_pattern(name: str, quick: bool):
    """The flat crease pattern of a study pattern (quick or full size)."""
    module, func, kq, kf = PATTERNS[name]
    try:
        gen = getattr(importlib.import_module(f"barhinge.patterns.{module}"), func)
    except (ImportError, AttributeError):
        raise ImportError(f"barhinge.patterns has no generator {func!r} yet") from None
    return gen(**(kq if quick else kf))


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
    keys = {}
    for e, a, n, asg in zip(E, ang, length, cp.assignment[E], strict=True):
        keys.setdefault((asg, a, n), []).append(e)
    num = den = 0.0
    for members in keys.values():
        if len(members) >= 2:
            num += len(members) * float(np.std(rho_deg[members]))
            den += len(members)
    return num / den if den else 0.0


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0] if lines else ''}"


def fold(cp, acts, steps: int):
    """Rigid kinematics (planar panels) if it can follow the actuators, else bar-and-hinge.

    Returns (path, model or None, rigid failure reason or None).
    """
    import barhinge as bh
    from barhinge.errors import BarhingeError
    from barhinge.kinematics.path import RigidOptions

    try:
        # over-determined actuators fail at the first step; 3 cut-backs tell that quickly
        opts = RigidOptions(check_actuators=False, max_cutbacks=3, over_actuated="error")
        path = bh.rigid_fold(cp, acts, steps=steps, options=opts)
        if path.converged:
            return path, None, None
        reason = f"not converged: {path.message}"
    except (BarhingeError, ArithmeticError, RuntimeError, np.linalg.LinAlgError) as exc:
        reason = _first_line(exc)
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=_material())
    return bh.solve(bh.Scene(model, actuators=acts, steps=steps)), model, reason


def point(pattern: str, spacing: int, kappa_L: float, quick: bool = True, steps: int = 6) -> dict:
    """Fold one pattern with actuators every ``spacing`` crossings on a circle kappa_L / L."""
    import barhinge as bh
    from barhinge.control import CircularArc, curve_angles_deg, section_crossings

    cp = make_pattern(pattern, quick)
    edges, x, ends = section_crossings(cp)
    pick = np.arange(0, len(edges), spacing)
    edges, x = edges[pick], x[pick]
    L = ends[1] - ends[0]
    kappa = kappa_L / L
    phi = curve_angles_deg(CircularArc(kappa), x, ends)
    sign = np.where(cp.assignment[edges] == "M", -1.0, 1.0)
    targets = sign * BASE_DEG + phi
    acts = bh.Actuators(edges=edges, targets_deg=targets)
    path, model, rigid_error = fold(cp, acts, steps)
    rho = path.fold_angles_deg[-1]
    curv = (
        bh.gaussian_curvature(path, pattern=cp)
        if model is None
        else bh.gaussian_curvature(path, model=model)
    )
    g = curv.global_fit
    defect = curv.angle_defect if curv.angle_defect is not None else np.zeros(1)
    return {
        "model": "rigid" if model is None else "bar-hinge",
        "rigid_error": rigid_error,
        "n_actuators": len(edges),
        "d_mean": float(np.mean(np.diff(x))) if len(x) > 1 else float("nan"),
        "kappa": kappa,
        "L": L,
        "K": float(g.K),
        "KL2": float(g.K) * L * L,
        "k1": float(g.k1),
        "k2": float(g.k2),
        "nonsync_deg": nonsync_deg(cp, rho),
        "max_fold_deg": float(np.max(np.abs(rho))),
        "actuator_error_deg": float(np.max(np.abs(rho[edges] - targets))),
        "max_angle_defect_deg": float(np.degrees(np.nanmax(np.abs(defect)))),
        "X": np.round(path.X[-1][: cp.n_vertices], 6),
    }
