"""Folded roofs: geometry of each family at a fold state, scaled to a common span, and the
linear response of the supported roof to self-weight and a uniform load (pure functions).

Common specification (module constants): span ``SPAN`` between two supported edges, aluminium
sheet (``MATERIAL``, ``DENSITY``), uniform load ``Q`` per unit plan area, downwards. Each
pattern spans in its structural direction: Miura-ori sheets and corrugations along their
ridges (y), the Yoshimura arch and the arched Miura across their arch (x), the Ron Resch and
waterbomb textures along x. The supported edges are the sheet's two boundary lines across the
span (vertices at the flat pattern's extreme coordinate along the span), pinned (x, y, z fixed).

Folded states
-------------
* ``miura`` (sector angle 60 and 75 deg), ``miura_arc``, ``yoshimura``: the exact rigidly
  folded states of ``bh.patterns`` (``fold=``).
* ``pleats``: a corrugation with panels subdivided into ``n_strip`` strips across and segments
  along the span (:func:`corrugation`; flat ``F`` lines, stiffness ``D l / s``, see there).
* ``resch``, ``waterbomb``: these patterns are not rigidly foldable along their target
  angles, so the folded state is *formed*: every crease gets the rest angle ``s`` times its
  target fold angle and the sheet (bars and panels 10 x stiffer than the folds) relaxes to
  the minimum of its bar-and-hinge energy (trust-region Newton, ``scipy.optimize``), with the
  rest angles raised in increments. The state is nearly developable (bar strains ~1e-5) and
  becomes the roof's stress-free reference.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

SPAN = 4.0  # m, between the supported edges
MATERIAL = {"E": 70e9, "nu": 0.33, "t": 2e-3}  # aluminium sheet, 2 mm
DENSITY = 2700.0  # kg/m^3
Q = 1000.0  # N/m^2 per unit plan area (snow-like), downwards
G = 9.81

# family -> (generator kwargs, span axis 0 = x / 1 = y, fold states, fold-state label)
FAMILIES: dict[str, dict[str, Any]] = {
    "miura60": {"gen": "miura", "kw": {"nx": 4, "ny": 6, "alpha": 60.0}, "axis": 1,
                "states": [15.0, 30.0, 45.0, 60.0, 75.0], "label": "facet angle theta"},
    "miura75": {"gen": "miura", "kw": {"nx": 3, "ny": 6, "alpha": 75.0}, "axis": 1,
                "states": [15.0, 30.0, 45.0, 60.0, 75.0], "label": "facet angle theta"},
    "miura_arc": {"gen": "miura_arc", "kw": {"nx": 6, "ny": 3}, "axis": 0,
                  "states": [30.0, 60.0, 90.0, 120.0], "label": "straight-crease fold"},
    "yoshimura": {"gen": "yoshimura", "kw": {"nx": 6, "ny": 4, "w": 1.0, "h": 0.5}, "axis": 0,
                  "states": [10.0, 20.0, 30.0, 40.0, 50.0], "label": "arch angle 2 beta"},
    "pleats": {"gen": "corrugation", "kw": {"n": 8, "w": 0.5, "m_seg": 8, "n_strip": 1},
               "axis": 1, "states": [30.0, 60.0, 90.0, 120.0, 150.0], "label": "fold angle"},
    "resch": {"gen": "resch", "kw": {"nx": 6, "ny": 6}, "axis": 0,
              "states": [0.15, 0.3, 0.45, 0.6], "label": "rest angle / target"},
    "waterbomb": {"gen": "waterbomb", "kw": {"nx": 4, "ny": 2}, "axis": 0,
                  "states": [0.15, 0.3, 0.45, 0.6], "label": "rest angle / target"},
}  # fmt: skip


def material():
    import barhinge as bh

    return bh.Material(**MATERIAL)


# ------------------------------------------------------------------------------ patterns
def corrugation(
    n: int = 8, w: float = 1.0, length: float = 4.0, fold: float = 90.0, m_seg: int = 16,
    n_strip: int = 1,
):  # fmt: skip
    """Straight pleats (as ``bh.patterns.pleats``, exact folded state, creases along y) with
    each of the ``n`` panels cut into ``n_strip`` strips along y and ``m_seg`` segments across,
    by flat ``F`` lines so that a panel's in-plane bending and the span are resolved.

    Returns (cp, crease_mask (n_edges,) bool of the M/V creases).
    """
    from barhinge.pattern.crease import CreasePattern

    k = np.arange(n * n_strip + 1)  # lines along y, at x = k w / n_strip in the flat sheet
    phi = np.radians(fold) / 2 * np.where(np.arange(n) % 2 == 0, -1.0, 1.0)  # panel tilt
    dx = np.concatenate([[0.0], np.full(n * n_strip, w / n_strip)])
    tilt = np.concatenate([[0.0], phi[(k[1:] - 1) // n_strip]])  # of the strip before line k
    xs = np.cumsum(dx * np.cos(tilt))
    zs = np.cumsum(dx * np.sin(tilt))
    ys = np.linspace(0.0, length, m_seg + 1)
    ni = len(k)
    vid = lambda i, j: j * ni + i  # noqa: E731
    X = np.column_stack([np.tile(xs, m_seg + 1), np.repeat(ys, ni), np.tile(zs, m_seg + 1)])
    edges, asg, rho = [], [], []
    for j in range(m_seg + 1):  # lines across (x), between segments
        for i in range(ni - 1):
            edges.append((vid(i, j), vid(i + 1, j)))
            asg.append("B" if j in (0, m_seg) else "F")
            rho.append(0.0)
    for i in range(ni):  # lines along y: creases, strip lines, boundaries
        crease = i % n_strip == 0 and 0 < i < ni - 1
        sign = 1.0 if (i // n_strip) % 2 == 1 else -1.0  # as pleats: first crease valley
        for j in range(m_seg):
            edges.append((vid(i, j), vid(i, j + 1)))
            if i in (0, ni - 1):
                asg.append("B")
                rho.append(0.0)
            elif crease:
                asg.append("V" if sign > 0 else "M")
                rho.append(sign * fold)
            else:
                asg.append("F")
                rho.append(0.0)
    faces = [(vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1))
             for j in range(m_seg) for i in range(ni - 1)]  # fmt: skip
    cp = CreasePattern(vertices=X, edges=np.array(edges), assignment=np.array(asg),
                       fold_angles=np.array(rho), faces=faces)  # fmt: skip
    return cp, np.isin(cp.assignment, ["M", "V"])


def _formed(cp, s: float, increments: int = 3, ratio: float = 10.0, seed: int = 0):
    """Folded state of a flat pattern formed by crease rest angles ``s`` x target (see the
    module docstring). Returns the (n_vertices, 3) coordinates."""
    import scipy.optimize as so

    import barhinge as bh
    from barhinge.scene import restraint_321

    rng = np.random.default_rng(seed)
    V = np.asarray(cp.vertices, float)
    Z = np.column_stack([V, 1e-3 * rng.standard_normal(len(V))])  # leave the flat saddle
    cpp = cp.replaced(vertices=Z, developable=False)
    m = bh.BarHingeModel.from_pattern(cpp, "N5B8", bh.Material(E=1e6, nu=0.3, t=0.01),
                                      stiffness_ratio=ratio)  # fmt: skip
    fold = m.hinge_kind == "fold"
    tgt = np.zeros(m.n_hinges)
    tgt[fold] = np.radians(np.asarray(cp.fold_angles)[m.hinge_edge[fold]])
    free = ~restraint_321(m).ravel()
    X = m.X0.ravel().copy()
    for frac in np.linspace(s / increments, s, increments):
        mm = m.with_(rest_angle=np.where(fold, frac * tgt, m.rest_angle))

        def fun(x, mm=mm):
            Y = X.copy()
            Y[free] = x
            ev = mm.evaluate(Y, tangent=False)
            return ev.energy, ev.force[free]

        def hess(x, mm=mm):
            Y = X.copy()
            Y[free] = x
            return mm.tangent(Y)[free][:, free].toarray()

        res = so.minimize(fun, X[free], jac=True, hess=hess, method="trust-exact",
                          options={"gtol": 1e-7, "maxiter": 400})  # fmt: skip
        X[free] = res.x
    return X.reshape(-1, 3)[: cp.n_vertices]


def folded(family: str, state: float, **override):
    """(cp at the folded state scaled to SPAN, flat coordinates (n, 2), crease mask)."""
    import barhinge as bh

    spec = FAMILIES[family]
    kw = {**spec["kw"], **override}
    gen = spec["gen"]
    if gen == "corrugation":
        cp, crease = corrugation(fold=state, length=1.0, **kw)
        flat, _ = corrugation(fold=0.0, length=1.0, **kw)
        flat_xy = np.asarray(flat.vertices)[:, :2]
        # the span is the crease length: set it to SPAN, keep the profile as generated
        X = np.asarray(cp.vertices, float).copy()
        scale_profile = None
    else:
        fn = bh.patterns.FAMILIES[gen]
        flat_cp = fn(**kw)
        flat_xy = np.asarray(flat_cp.vertices)[:, :2]
        if gen in ("resch", "waterbomb"):
            X = _formed(flat_cp, state)
            cp = flat_cp.replaced(vertices=X, developable=False,
                                  fold_angles=np.zeros(flat_cp.n_edges))  # fmt: skip
            cp = cp.replaced(fold_angles=cp.state_fold_angles(), developable=False)
        else:
            cp = fn(**kw, fold=state)
        X = np.asarray(cp.vertices3d if hasattr(cp, "vertices3d") else cp.vertices, float)
        scale_profile = True
        crease = np.isin(cp.assignment, ["M", "V"])
    ax = spec["axis"]
    if scale_profile is None:  # corrugation: stretch along the creases only (still exact)
        X[:, 1] *= SPAN / np.ptp(X[:, 1])
        sc = 1.0
        flat_xy = flat_xy * np.array([1.0, SPAN])
    else:
        sc = SPAN / float(np.ptp(X[:, ax]))
        X = X * sc
        flat_xy = flat_xy * sc
    dev = getattr(cp, "developable", True) and gen not in ("resch", "waterbomb")
    cp = cp.replaced(vertices=X, developable=dev)
    return cp, flat_xy, crease


# ------------------------------------------------------------------------------ analysis
def supports(model, flat_xy: np.ndarray, axis: int, dofs: str = "xyz") -> np.ndarray:
    """(n_nodes, 3) bool: the vertices at the flat pattern's min and max coordinate along the
    span axis, fixed in ``dofs``."""
    c = flat_xy[:, axis]
    tol = 1e-6 * float(np.ptp(c))
    ids = np.flatnonzero((c <= c.min() + tol) | (c >= c.max() - tol))
    S = np.zeros((model.n_nodes, 3), bool)
    S[np.ix_(ids, ["xyz".index(d) for d in dofs])] = True
    return S


def plan_load(model, q: float) -> np.ndarray:
    """(n_nodes, 3) nodal loads of a uniform downward load ``q`` per unit *plan* area: each
    facet's horizontal projection times q, shared equally by its corners."""
    cp = model.pattern
    X = np.asarray(model.X0, float)
    F = np.zeros_like(X)
    for f in cp.faces:
        P = X[list(f)]
        az = 0.5 * abs(float(np.cross(P, np.roll(P, -1, axis=0)).sum(0)[2]))
        F[list(f), 2] -= q * az / len(f)
    return F


def sheet_area(cp) -> float:
    X = np.asarray(cp.vertices, float)
    return float(sum(0.5 * np.linalg.norm(np.cross(X[list(f)], np.roll(X[list(f)], -1, 0)).sum(0))
                     for f in cp.faces))  # fmt: skip


def bar_strains(model, U: np.ndarray) -> np.ndarray:
    """(n_bars,) linearised bar strains of displacements U (n_nodes, 3) at X0."""
    X = np.asarray(model.X0)
    b = model.bars
    d = X[b[:, 1]] - X[b[:, 0]]
    L = np.linalg.norm(d, axis=1)
    return np.einsum("bk,bk->b", d, U[b[:, 1]] - U[b[:, 0]]) / L**2


def flat_line_stiffness(model, crease: np.ndarray) -> Any:
    """The model with the fold hinges of flat ``F`` lines given plate-bending stiffness
    ``D l / s`` (l = hinge length, s = distance between the wing nodes across the axis = the
    width of the two half-panels it joins), the moment-rotation of a plate strip of width s
    bent to curvature rotation / s (Kirchhoff)."""
    mat = model.material
    D = mat.E * mat.t**3 / (12 * (1 - mat.nu**2))
    h = model.hinges
    X = np.asarray(model.X0)
    is_f = (model.hinge_kind == "fold") & (model.hinge_edge >= 0)
    is_f &= np.asarray(model.pattern.assignment)[np.maximum(model.hinge_edge, 0)] == "F"
    axis = X[h[:, 1]] - X[h[:, 0]]
    ell = np.linalg.norm(axis, axis=1)
    u = axis / ell[:, None]

    def dist(p):
        r = X[p] - X[h[:, 0]]
        return np.linalg.norm(r - np.einsum("ij,ij->i", r, u)[:, None] * u, axis=1)

    s = dist(h[:, 2]) + dist(h[:, 3])
    k = np.array(model.hinge_k)
    k[is_f] = D * ell[is_f] / s[is_f]
    return model.with_(hinge_k=k)


def analyse(family: str, state: float, scheme: str = "N5B8", **override) -> dict[str, Any]:
    """Linear response of one roof: stiffness, per unit width and per unit sheet area,
    deflections and peak bar strains under self-weight and the uniform load."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response, tangent_stiffness
    from barhinge.scene import self_weight

    spec = FAMILIES[family]
    cp, flat_xy, crease = folded(family, state, **override)
    model = bh.BarHingeModel.from_pattern(cp, scheme, material())
    if "F" in set(np.asarray(cp.assignment)):
        model = flat_line_stiffness(model, crease)
    ax = spec["axis"]
    S = supports(model, flat_xy, ax)
    Fq = plan_load(model, Q)
    Fsw = self_weight(model, DENSITY * MATERIAL["t"], g=(0.0, 0.0, -G))
    K = tangent_stiffness(model)
    Uq, Rq = linear_response(model, Fq, S, K=K)
    Usw, Rsw = linear_response(model, Fsw, S, K=K)
    # equilibrium self-check: the reactions balance the applied loads
    F_all = Fq + Fsw
    eq_err = float(np.linalg.norm((Rq + Rsw).sum(0) + F_all.sum(0)) / np.linalg.norm(F_all.sum(0)))
    V = np.asarray(cp.vertices)
    width = float(np.ptp(V[:, 1 - ax]))
    A = sheet_area(cp)
    dq = float(np.max(-Uq[:, 2]))
    k = float(-Fq[:, 2].sum()) / dq
    rho = np.abs(np.asarray(cp.state_fold_angles()))[crease]
    return {
        "family": family,
        "state": state,
        "mean_fold_deg": float(rho.mean()),
        "span": float(np.ptp(V[:, ax])),
        "width": width,
        "depth": float(np.ptp(V[:, 2])),
        "sheet_area": A,
        "plan_area": SPAN * width,
        "n_nodes": model.n_nodes,
        "deflection_q": dq,
        "deflection_sw": float(np.max(-Usw[:, 2])),
        "stiffness": k,
        "stiffness_per_width": k / width,
        "stiffness_per_sheet_area": k / A,
        "peak_strain": float(np.max(np.abs(bar_strains(model, Uq + Usw)))),
        "load_total": float(-(Fq + Fsw)[:, 2].sum()),
        "equilibrium_error": eq_err,
    }


# ------------------------------------------------------------------------------ beam check
def corrugated_beam(n: int, w: float, fold: float, L: float) -> dict[str, float]:
    """Classical estimate for the corrugation as a beam clamped at both ends (all end-section
    nodes pinned stop the end sections rotating) under a uniform load: thin-walled profile of
    ``n`` plates of width ``w`` inclined at phi = fold / 2, all centroids at mid-depth:
    ``I = n t w (w sin phi)^2 / 12``, shear area ``A_s = n t w sin^2 phi`` (a vertical force
    on a crease splits into in-plane forces of the two inclined plates), and the midspan
    deflection ``Q L^3 / (384 E I) + Q L / (8 G A_s)`` (Timoshenko & Gere, *Mechanics of
    Materials*, clamped-clamped beam under uniform load, bending plus shear). Returns the
    stiffness Q / deflection and its two parts."""
    E, nu, t = MATERIAL["E"], MATERIAL["nu"], MATERIAL["t"]
    phi = math.radians(fold) / 2
    I = n * t * w * (w * math.sin(phi)) ** 2 / 12  # noqa: E741
    As = n * t * w * math.sin(phi) ** 2
    Gs = E / (2 * (1 + nu))
    fb = L**3 / (384 * E * I)
    fs = L / (8 * Gs * As)
    return {"stiffness": 1.0 / (fb + fs), "bending_share": fb / (fb + fs), "I": I}


def pleat_beam_check(fold: float, n_strip: int, n: int = 8, w: float = 0.5) -> dict:
    """Bar-and-hinge corrugated roof (N5B8, panels cut into ``n_strip`` strips) against
    :func:`corrugated_beam`: the stiffness is total load over the mean midspan deflection of
    the crease lines (the beam's deflection; panels sag locally between them)."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response

    m_seg = round(SPAN * n_strip / w)  # square sub-panels
    cp, flat_xy, crease = folded("pleats", fold, n=n, m_seg=m_seg, n_strip=n_strip, w=w)
    model = flat_line_stiffness(bh.BarHingeModel.from_pattern(cp, "N5B8", material()), crease)
    S = supports(model, flat_xy, 1)
    Fq = plan_load(model, Q)
    U, _ = linear_response(model, Fq, S)
    V = np.asarray(cp.vertices)
    E = np.asarray(cp.edges)[crease]
    on_crease = np.unique(E)
    mid = on_crease[np.abs(V[on_crease, 1] - SPAN / 2) < 1e-9]
    defl = float(np.mean(-U[mid, 2]))
    k = float(-Fq[:, 2].sum()) / defl
    ref = corrugated_beam(n, w, fold, SPAN)
    return {"fold": fold, "n_strip": n_strip, "stiffness": k, "beam": ref["stiffness"],
            "ratio": k / ref["stiffness"], "bending_share": ref["bending_share"]}  # fmt: skip
