"""Folded roofs: geometry of each family at a fold state, scaled to a common span, and the
linear response of the supported roof to self-weight and a uniform load (pure functions).

Common specification (module constants): span ``SPAN`` between two supported edges, aluminium
sheet (``MATERIAL``, ``DENSITY``), uniform load ``Q`` per unit plan area, downwards. Each
pattern spans in its structural direction: Miura-ori sheets and corrugations along their
ridges (y), the Yoshimura arch and the arched Miura across their arch (x), the Ron Resch and
waterbomb textures along x. The supported edges are the sheet's two ends across the span
(:func:`support_lines`: the boundary between the vertices at the flat pattern's extreme
coordinate along the span, following a jagged end), pinned (x, y, z fixed).

Folded states
-------------
* ``miura`` (sector angle 60 and 75 deg), ``miura_arc``, ``yoshimura``: the exact rigidly
  folded states of ``bh.families`` (``fold=``).
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
    "miura60": {
        "gen": "miura",
        "kw": {"nx": 4, "ny": 6, "alpha": 60.0},
        "axis": 1,
        "states": [15.0, 30.0, 45.0, 60.0, 75.0],
        "label": "facet angle theta",
    },
    "miura75": {
        "gen": "miura",
        "kw": {"nx": 3, "ny": 6, "alpha": 75.0},
        "axis": 1,
        "states": [15.0, 30.0, 45.0, 60.0, 75.0],
        "label": "facet angle theta",
    },
    "miura_arc": {
        "gen": "miura_arc",
        "kw": {"nx": 6, "ny": 3},
        "axis": 0,
        "states": [30.0, 60.0, 90.0, 120.0],
        "label": "straight-crease fold",
    },
    "yoshimura": {
        "gen": "yoshimura",
        "kw": {"nx": 6, "ny": 4, "w": 1.0, "h": 0.5},
        "axis": 0,
        "states": [10.0, 20.0, 30.0, 40.0, 50.0],
        "label": "arch angle 2 beta",
    },
    "pleats": {
        "gen": "corrugation",
        "kw": {"n": 8, "w": 0.5, "m_seg": 8, "n_strip": 1},
        "axis": 1,
        "states": [30.0, 60.0, 90.0, 120.0, 150.0],
        "label": "fold angle",
    },
    "flat": {
        "gen": "flat",
        "kw": {"n": 8, "w": 0.5, "m_seg": 8, "n_strip": 1},
        "axis": 1,
        "states": [0.0],
        "label": "flat sheet (baseline)",
    },
    "resch": {
        "gen": "resch",
        "kw": {"nx": 6, "ny": 6},
        "axis": 0,
        "states": [0.15, 0.3, 0.45, 0.6],
        "label": "rest angle / target",
    },
    "waterbomb": {
        "gen": "waterbomb",
        "kw": {"nx": 4, "ny": 2},
        "axis": 0,
        "states": [0.15, 0.3, 0.45, 0.6],
        "label": "rest angle / target",
    },
}


def material():
    import barhinge as bh

    return bh.Material(**MATERIAL)


# ------------------------------------------------------------------------------ patterns
def corrugation(
    n: int = 8,
    w: float = 1.0,
    length: float = 4.0,
    fold: float = 90.0,
    m_seg: int = 16,
    n_strip: int = 1,
    flat: bool = False,
):
    """Straight pleats (as ``bh.families.pleats``, exact folded state, creases along y) with
    each of the ``n`` panels cut into ``n_strip`` strips along y and ``m_seg`` segments across,
    by flat ``F`` lines so that a panel's in-plane bending and the span are resolved.

    ``flat=True`` makes every interior line a flat ``F`` line (a flat sheet, fold ignored).

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
        crease = i % n_strip == 0 and 0 < i < ni - 1 and not flat
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
    faces = [
        (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1))
        for j in range(m_seg)
        for i in range(ni - 1)
    ]
    cp = CreasePattern(
        vertices=X,
        edges=np.array(edges),
        assignment=np.array(asg),
        fold_angles=np.array(rho),
        faces=faces,
    )
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
    m = bh.BarHingeModel.from_pattern(
        cpp, "N5B8", bh.Material(E=1e6, nu=0.3, t=0.01), stiffness_ratio=ratio
    )
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

        res = so.minimize(
            fun,
            X[free],
            jac=True,
            hess=hess,
            method="trust-exact",
            options={"gtol": 1e-7, "maxiter": 400},
        )
        # trust-exact stops with "bad approximation" when round-off limits the last step;
        # accept that when the residual force is small against the fold moments' scale
        g_ref = float(np.max(np.abs(mm.evaluate(mm.X0, tangent=False).force)))
        g_max = float(np.max(np.abs(res.jac)))
        if not res.success and g_max > 1e-6 * g_ref:
            raise ArithmeticError(
                f"forming at rest angle {frac:.3g} x target: {res.message} "
                f"(residual {g_max:.1e}, scale {g_ref:.1e})"
            )
        X[free] = res.x
    return X.reshape(-1, 3)[: cp.n_vertices]


def folded(family: str, state: float, **override):
    """(cp at the folded state scaled to SPAN, flat coordinates (n, 2) scaled alike, crease
    mask (n_edges,) of the M/V creases). Vertex order is the same in both states."""
    import barhinge as bh

    spec = FAMILIES[family]
    kw = {**spec["kw"], **override}
    gen = spec["gen"]
    if gen == "flat":
        cp, crease = corrugation(fold=0.0, length=SPAN, flat=True, **kw)
        return cp, np.asarray(cp.vertices)[:, :2], crease
    if gen == "corrugation":
        # the span is the crease length: stretch along the creases only (still exact)
        cp, crease = corrugation(fold=state, length=SPAN, **kw)
        flat, _ = corrugation(fold=0.0, length=SPAN, **kw)
        return cp, np.asarray(flat.vertices)[:, :2], crease
    fn = bh.families.FAMILIES[gen]
    flat_cp = fn(**kw)
    if gen in ("resch", "waterbomb"):
        X = _formed(flat_cp, state)
        cp = flat_cp.replaced(vertices=X, developable=False)
        cp = cp.replaced(fold_angles=cp.state_fold_angles(), developable=False)
    else:
        cp = fn(**kw, fold=state)
    X = np.asarray(cp.vertices3d, float)
    sc = SPAN / float(np.ptp(X[:, spec["axis"]]))
    cp = cp.replaced(vertices=X * sc, developable=cp.developable)
    crease = np.isin(cp.assignment, ["M", "V"])
    return cp, np.asarray(flat_cp.vertices)[:, :2] * sc, crease


# ------------------------------------------------------------------------------ analysis
def support_lines(cp, flat_xy: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """(vertex ids, edge ids) of the two supported edges of the sheet: at each end of the span,
    the sheet's boundary between its outermost vertices.

    The outermost vertices are those at the flat pattern's min and max coordinate along
    ``axis``. Where an end of the sheet is straight they are joined by boundary edges; where
    it is jagged (the arched Miura's zig-zag feet, the Ron Resch texture's edge) the boundary
    arcs between consecutive outermost vertices at the same end are supported too, so that
    every roof sits on two line supports, never on isolated points (a pinned point of a
    membrane concentrates its reaction and its strain energy diverges under refinement).
    """
    c = flat_xy[:, axis]
    tol = 1e-6 * float(np.ptp(c))
    end = np.where(c <= c.min() + tol, 1, np.where(c >= c.max() - tol, 2, 0))
    E = np.asarray(cp.edges)
    bd = np.asarray(cp.boundary_edges)  # edges with one face
    nxt: dict[int, list[int]] = {}
    for e in bd.tolist():
        a, b = (int(v) for v in E[e])
        nxt.setdefault(a, []).append(e)
        nxt.setdefault(b, []).append(e)
    if any(len(es) != 2 for es in nxt.values()):
        raise ValueError("supports: the sheet's boundary is not one simple loop")
    # walk the boundary loop once from an outermost vertex: (vertex, edge to the next one)
    start = int(np.flatnonzero(end)[0])
    loop_v, loop_e, v, prev = [], [], start, -1
    while True:
        e = next(x for x in nxt[v] if x != prev)
        loop_v.append(v)
        loop_e.append(e)
        v = int(E[e, 1] if E[e, 0] == v else E[e, 0])
        prev = e
        if v == start:
            break
    if len(loop_e) != len(bd):
        raise ValueError("supports: the sheet's boundary is not one simple loop")
    ends = np.flatnonzero(end[loop_v])
    sv, se = set(np.flatnonzero(end).tolist()), []
    for i, j in zip(ends, np.append(ends[1:], ends[0] + len(loop_v)), strict=True):
        if end[loop_v[i]] != end[loop_v[j % len(loop_v)]]:
            continue  # a side of the sheet, from one end to the other
        arc = [(i + k) % len(loop_v) for k in range(j - i)]
        se += [loop_e[k] for k in arc]
        sv.update(loop_v[k] for k in arc)
    return np.array(sorted(sv), np.int64), np.array(sorted(se), np.int64)


def supports(model, flat_xy: np.ndarray, axis: int, dofs: str = "xyz") -> np.ndarray:
    """(n_nodes, 3) bool: the vertices of the two supported edges (:func:`support_lines`),
    fixed in ``dofs``."""
    ids, _ = support_lines(model.pattern, flat_xy, axis)
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
    return float(
        sum(
            0.5 * np.linalg.norm(np.cross(X[list(f)], np.roll(X[list(f)], -1, 0)).sum(0))
            for f in cp.faces
        )
    )


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


#: bending rules of a roof whose panels are cut into sub-panels: name -> keywords of
#: ``BarHingeModel.from_pattern``. ``plate`` and ``kirchhoff`` are per-panel calibrations
#: (flat lines get ``D l / s``); ``consistent`` and ``coupled`` then set every hinge inside
#: and between sub-panels by :mod:`barhinge.model.plate_hinges` (the plate patch test;
#: ``coupled`` also keeps the sheet's Poisson ratio), and converge to the plate. ``coupled``,
#: the refined model of the study, also has the constant-strain-triangle membrane
#: (``REFINED_MEMBRANE``): bars cannot store a uniform strain in cells far from equilateral
#: (docs/calibration.md, Table 4), and refinement keeps the cells' shape
REFINED_MEMBRANE = "cst"
BENDING_RULES: dict[str, dict[str, Any]] = {
    "plate": {},
    "kirchhoff": {"bend_calibration": "kirchhoff"},
    "consistent": {"bend_calibration": "kirchhoff"},
    "coupled": {"bend_calibration": "kirchhoff", "bar_calibration": REFINED_MEMBRANE},
}


#: a roof is refined when its stiffness changes by less than this between two levels
REFINE_TOL = 0.02
#: no refinement level above this many DOFs in the shell comparison and the accuracy check
#: (the largest takes a few minutes and ~6 GB)
REFINE_DOF_BUDGET = 650_000
#: the refinement study's budget (refine.py): m = 128 on the roofs of triangular panels
#: (Yoshimura, Resch, waterbomb: about 1.3 M DOFs) and m = 64 on the parallelogram roofs
#: (miura75, miura_arc: 1.77 M DOFs; miura60: 2.36 M DOFs, a level's process peaking at
#: 17.4 GB: linear analyses hold the stiffness as its upper triangle and drop the assembler
#: before they factorise, ``linear_response``). The
#: next levels (m = 256: over 5 M DOFs) do not fit a machine of 23.5 GB. Solves this fine
#: need the residuals in extended precision (``refined_solve``).
REFINE_STUDY_DOF_BUDGET = 2_400_000


def settled(k: list[float], tol: float = REFINE_TOL) -> bool:
    """Whether a refinement sequence ``k`` (one value per level) has settled: its last change
    is below ``tol`` (relative) *and* it is in its asymptotic range, the same sign as the
    change before and smaller. A sequence that turns (its changes of opposite signs) can
    pass through a small change by chance and needs another level."""
    if len(k) < 3:
        return False
    d1, d2 = k[-2] / k[-3] - 1.0, k[-1] / k[-2] - 1.0
    return abs(d2) < tol and d1 * d2 > 0 and abs(d2) < abs(d1)


def refinement_dofs(cp, m: int) -> int:
    """DOFs of the N5B8 model of ``cp`` with m x m sub-panels, counted without building it."""
    from barhinge.pattern.subdivide import subdivided_size

    return 3 * sum(subdivided_size(cp, m))


def cell_membrane_error(cp, bar_calibration: str = "fit") -> float:
    """Worst relative energy error of the membrane ``bar_calibration`` under a uniform
    membrane strain, over the homogeneous modes and the distinct face shapes of ``cp`` (one
    N5B8 panel each, the sheet's material; :func:`barhinge.model.compare.panel_errors`). A
    panel cut into cells keeps its shape's error (Table 4 of docs/calibration.md), so
    refinement converges to a sheet whose membrane is off by about this much in its worst
    direction (0 for the constant-strain triangle, ``"cst"``)."""
    from barhinge.model.calibrate import face_frames
    from barhinge.model.compare import panel_errors

    X = np.asarray(cp.vertices3d, float)
    shapes: dict[tuple, np.ndarray] = {}
    for fi, f in enumerate(cp.faces):
        e1, e2, _ = face_frames(X, cp.faces, np.array([fi]))
        R = X[list(f)] - X[f[0]]
        Q = np.column_stack([R @ e1[0], R @ e2[0]])
        shapes.setdefault(tuple(np.round(Q / np.abs(Q).max(), 6).ravel()), Q)
    worst = 0.0
    for Q in shapes.values():
        e = panel_errors(Q, material(), "N5B8", bar_calibration, plate_refine=1)
        worst = max(worst, max(abs(v) for k, v in e.items() if k != "warp"))
    return worst


#: the shell reference's facet meshes are graded towards the facets' corners (elements next
#: to a pattern vertex h^2 long), where a folded sheet's stresses are singular
SHELL_GRADING = 2.0


def crease_stiffness_per_length(model) -> float:
    """Fold-hinge stiffness per unit crease length of the M/V creases (uniform; 0 for a
    pattern without any, such as the flat sheet)."""
    asg = np.asarray(model.pattern.assignment)
    X = np.asarray(model.X0)
    h = model.hinges
    f = (model.hinge_kind == "fold") & (model.hinge_edge >= 0)
    f &= np.isin(asg[np.maximum(model.hinge_edge, 0)], ["M", "V"])
    ell = np.linalg.norm(X[h[f, 1]] - X[h[f, 0]], axis=1)
    k = model.hinge_k[f] / ell
    if not len(k):
        return 0.0
    if not np.allclose(k, k[0], rtol=1e-9):
        raise ValueError("crease stiffness per length is not uniform")
    return float(k[0])


def shell_level(
    cp, sv, se, r: int, crease_k: float, sheet: Any = None, grading: float = 1.0
) -> dict[str, Any]:
    """Stiffness ``Q_t^2 / (f . u)`` of the facet shell roof (:mod:`barhinge.model.shell`)
    at refinement ``r`` under the uniform load, creases of ``crease_k`` (moment per radian per
    length), ``sheet`` the study's unless given, facet meshes of ``grading`` (1: uniform)."""
    import time

    from barhinge.model.shell import shell_model

    t0 = time.perf_counter()
    mat = material() if sheet is None else sheet
    sh = shell_model(cp, mat, r, crease_stiffness=crease_k, grading=grading)
    f = sh.surface_load((0.0, 0.0, -Q), per="plan")
    u = sh.solve(f, np.union1d(sh.nodes_on_edges(se), sv))
    Qt = float(-sh.translations(f)[:, 2].sum())
    return {
        "r": r,
        "stiffness": Qt**2 / float(f @ u),
        "n_dof": sh.n_dof,
        "time_s": time.perf_counter() - t0,
        "load": Qt,
    }


def shell_settled(rows: list[dict]) -> bool:
    """Whether the shell levels ``rows`` give a reference: a Richardson estimate
    (:func:`barhinge.analysis.accuracy.richardson`, order at least its ``MIN_ORDER``) whose
    correction is below ``REFINE_TOL``."""
    from barhinge.analysis.accuracy import richardson

    if len(rows) < 3:
        return False
    ref, _, unc = richardson([s_["stiffness"] for s_ in rows])
    return math.isfinite(unc) and unc <= REFINE_TOL * abs(ref)


def shell_extended(
    cp, sv, se, crease_k: float, rows: list[dict], budget: int, grading: float = SHELL_GRADING
) -> list[dict]:
    """The shell levels ``rows`` refined further (r + 1) until :func:`shell_settled` or the
    next level would exceed ``budget`` DOFs (each level has about four times the DOFs of the
    one before)."""
    rows = list(rows)
    while not shell_settled(rows) and 4 * rows[-1]["n_dof"] <= budget:
        rows.append(shell_level(cp, sv, se, rows[-1]["r"] + 1, crease_k, grading=grading))
        print(f"  shell r = {rows[-1]['r']}: {rows[-1]['stiffness'] / 1e3:.2f} kN/m", flush=True)
    return rows


#: the shell reference of every roof (:func:`shell_reference`): these levels, then further
#: until its Richardson estimate settles or the next level would exceed ``SHELL_DOF_BUDGET``
#: DOFs (the refine study's and the ``--accuracy`` check's, so both compare with one reference)
SHELL_LEVELS = (1, 2, 3, 4, 5)
SHELL_DOF_BUDGET = 4_000_000


def shell_reference(
    fam: str, state: float, levels: tuple[int, ...] = SHELL_LEVELS, budget: int = SHELL_DOF_BUDGET
) -> list[dict]:
    """The graded shell levels of one roof (``levels``, then refined further until they settle
    within ``budget`` DOFs; :func:`shell_extended`)."""
    import barhinge as bh

    cp, flat_xy, _ = folded(fam, state)
    sv, se = support_lines(cp, flat_xy, FAMILIES[fam]["axis"])
    ck = crease_stiffness_per_length(bh.BarHingeModel.from_pattern(cp, "N5B8", material()))
    rows = [shell_level(cp, sv, se, r, ck, grading=SHELL_GRADING) for r in levels]
    return shell_extended(cp, sv, se, ck, rows, budget)


#: sub-panels crowded towards the panels' corners with this exponent, on the roofs where that
#: pays (:func:`grading_of`; :func:`barhinge.pattern.subdivide.subdivided`)
SUBPANEL_GRADING = 2.0


def grading_of(cp, grading: float = SUBPANEL_GRADING) -> float:
    """The grading of a roof's sub-panels: ``grading`` where every panel is a parallelogram
    and creases of different directions meet at a vertex (the corners where the plate
    solution concentrates, which grading resolves), else 1.

    Triangles are not graded (:mod:`barhinge.pattern.subdivide`: the coupled rule passes
    its patch test on graded triangles but converges more slowly there); graded trapezoids (the
    arched Miura's panels) passed it but converged more slowly than equal ones (miura_arc 60
    at m = 32: 21.9 kN/m/m graded with p = 2, 27.1 equal, shell 27.6); the pleats' parallel
    creases meet nowhere, and their graded strips did not converge (pleats 30 at m = 2, 4, 8,
    16: 278, 177, 216, 295 kN/m graded, 278, 320, 343, 355 equal). The refined levels, the
    nonlinear checks on refined panels (refine.py) and the imperfect roofs (imperfection.py)
    are all cut this way."""
    X = np.asarray(cp.vertices3d, float)
    for f in cp.faces:
        if len(f) != 4:
            return 1.0
        P = X[list(f)]
        if np.linalg.norm(P[0] - P[1] + P[2] - P[3]) > 1e-9 * np.linalg.norm(P[2] - P[0]):
            return 1.0
    return grading if crease_corners(cp) else 1.0


def crease_corners(cp) -> bool:
    """Whether creases (M, V) of different directions meet at some vertex of the flat
    pattern (directions parallel to within 1e-6 rad counted as one)."""
    E = np.asarray(cp.edges, np.int64)[np.isin(np.asarray(cp.assignment), ("M", "V"))]
    V = np.asarray(cp.vertices, float)[:, :2]
    d = V[E[:, 1]] - V[E[:, 0]]
    d /= np.linalg.norm(d, axis=1)[:, None]
    ends, dirs = np.concatenate([E[:, 0], E[:, 1]]), np.concatenate([d, d])
    order = np.argsort(ends, kind="stable")
    ends, dirs = ends[order], dirs[order]
    # at a vertex with creases of two directions, two neighbours in this order differ
    cross = np.abs(dirs[1:, 0] * dirs[:-1, 1] - dirs[1:, 1] * dirs[:-1, 0])
    return bool(np.any((ends[1:] == ends[:-1]) & (cross > 1e-6)))


def subdivided_roof(
    cp, sv: np.ndarray, se: np.ndarray, m: int, rule: str = "coupled", scheme: str = "N5B8",
    sheet: Any = None, grading: float = 1.0,
) -> tuple[Any, np.ndarray, float]:  # fmt: skip
    """A roof's bar-and-hinge model with every panel cut into ``m x m`` sub-panels.

    Parameters
    ----------
    cp : the folded roof's crease pattern; sv, se : its supported vertices and edges
        (:func:`support_lines`)
    m : sub-panels per panel side (1: the panels as they are)
    rule : a key of ``BENDING_RULES``
    sheet : Material, the sheet (default: the study's, :func:`material`)
    grading : sub-panels crowded towards the panels' corners (1: equal;
        :func:`barhinge.pattern.subdivide.subdivided`)

    Returns
    -------
    model : BarHingeModel
    fixed : (n_nodes, 3) bool, the supported vertices and every new vertex on a supported
        edge, pinned
    patch_residual : largest cell residual of the plate patch test over D (0 for the
        per-panel rules)
    """
    import barhinge as bh
    from barhinge.model.plate_hinges import consistent_hinge_stiffness, coupled_bending
    from barhinge.pattern.subdivide import subdivided

    if rule not in BENDING_RULES:
        raise ValueError(f"bending rule {rule!r}; expected one of {sorted(BENDING_RULES)}")
    cpm, parent = subdivided(cp, m, grading)
    mat = material() if sheet is None else sheet
    model = bh.BarHingeModel.from_pattern(cpm, scheme, mat, **BENDING_RULES[rule])
    residual = 0.0
    if rule == "coupled":
        model = coupled_bending(model)
        residual = float(model.meta["cell_residual"])
    elif rule == "consistent":
        ph = consistent_hinge_stiffness(model)
        model = model.with_(hinge_k=ph.hinge_k)
        residual = float(ph.residual.max(initial=0.0))
    elif "F" in set(np.asarray(cpm.assignment)):
        model = flat_line_stiffness(model, np.isin(np.asarray(cpm.assignment), ["M", "V"]))
    S = np.zeros((model.n_nodes, 3), bool)
    S[np.union1d(sv, np.flatnonzero(np.isin(parent, se)))] = True
    return model, S, residual


def analyse(family: str, state: float, scheme: str = "N5B8", **override) -> dict[str, Any]:
    """Linear response of one roof at its (stress-free) folded state.

    Stiffness ``k`` = total uniform load Q_t / its load-weighted mean deflection
    ``f . u / Q_t`` (= Q_t^2 / compliance; the largest deflection is reported too, but at free
    edges it measures local flapping of the outer panels); per unit width with the effective
    width = plan area / SPAN (so ``k / width = Q SPAN / mean deflection``); per unit sheet
    area (material used). Peak bar strain: linearised, under self-weight plus the
    uniform load. ``equilibrium_error``: |sum of reactions + loads| / |loads|."""
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
    plan = float(-Fq[:, 2].sum()) / Q  # projected area that catches the load
    width = plan / SPAN  # effective width: stiffness / width = Q SPAN / deflection
    A = sheet_area(cp)
    dq = float(np.max(-Uq[:, 2]))
    Qt = float(-Fq[:, 2].sum())
    dmean = float(np.sum(Fq * Uq)) / Qt  # load-weighted mean deflection
    k = Qt / dmean  # = Qt^2 / (f . u): the compliance stiffness
    rho = np.abs(np.asarray(cp.state_fold_angles()))[crease]
    return {
        "family": family,
        "state": state,
        "mean_fold_deg": float(rho.mean()) if len(rho) else 0.0,
        "span": float(np.ptp(V[:, ax])),
        "width": width,
        "depth": float(np.ptp(V[:, 2])),
        "sheet_area": A,
        "plan_area": plan,
        "n_nodes": model.n_nodes,
        "deflection_q": dq,
        "mean_deflection_q": dmean,
        "deflection_sw": float(np.max(-Usw[:, 2])),
        "stiffness": k,
        "stiffness_per_width": k / width,
        "stiffness_per_sheet_area": k / A,
        "peak_strain": float(np.max(np.abs(bar_strains(model, Uq + Usw)))),
        "load_total": float(-(Fq + Fsw)[:, 2].sum()),
        "equilibrium_error": eq_err,
    }


def stability(
    family: str, state: float, scheme: str = "N5B8", steps: int = 10, **override
) -> dict[str, Any]:
    """Stability of one roof under the design load (uniform load plus self-weight).

    ``buckling_factor``: the first linear buckling factor of the stress-free folded state
    (:func:`barhinge.analysis.buckling.linear_buckling`; NaN when there is none); the other
    keys are those of :func:`nonlinear_check` on the one-facet model."""
    import barhinge as bh
    from barhinge.analysis.buckling import linear_buckling
    from barhinge.errors import BarhingeError
    from barhinge.scene import self_weight

    cp, flat_xy, crease = folded(family, state, **override)
    model = bh.BarHingeModel.from_pattern(cp, scheme, material())
    if "F" in set(np.asarray(cp.assignment)):
        model = flat_line_stiffness(model, crease)
    S = supports(model, flat_xy, FAMILIES[family]["axis"])
    P = plan_load(model, Q) + self_weight(model, DENSITY * MATERIAL["t"], g=(0.0, 0.0, -G))
    try:
        lam_b = float(linear_buckling(model, P, S, n_modes=1).factors[0])
    except BarhingeError:
        lam_b = float("nan")
    return {"buckling_factor": lam_b, **nonlinear_check(model, S, P, steps)}


def nonlinear_check(
    model,
    fixed: np.ndarray,
    P: np.ndarray,
    steps: int = 10,
    stop_at_instability: bool = False,
    keep_path: bool = False,
) -> dict[str, Any]:
    """The nonlinear check of a roof model under its design load ``P`` (N per node).

    Arc length (MGDCM) from the unloaded state that stops at the design load (load factor 1)
    or at the first limit point, whichever comes first, and with ``stop_at_instability`` at
    the first state that has lost stability (``arc_stop_instability``); ``steps`` sets the
    first increment (1 / steps of the load).

    Returns
    -------
    dict
        ``limit_load_factor``: the load factor of that limit point, or None when the roof
        carries the design load without one. ``instability_load_factor``: the lowest load
        factor on the path at which the roof is no longer stable, a limit point or the first
        state whose tangent has a negative eigenvalue (a bifurcation), or None.
        ``instability_bracket``: the load factors of the last stable state and of the first
        one with a negative eigenvalue, and ``instability_estimate`` the load factor where
        the tangent interpolated between them turns singular
        (:func:`barhinge.analysis.buckling.critical_between`; None, with the reason in
        ``instability_estimate_error``, where it cannot be found).
        With ``stop_at_instability``, a path whose increments fail where the lowest
        tangent eigenvalue of its last states falls to zero just ahead ends there:
        ``stop`` is ``"critical_ahead"``, ``instability_estimate`` the zero of the squared
        eigenvalue and ``instability_bracket`` that and the zero of the eigenvalue
        (:func:`barhinge.analysis.buckling.critical_ahead`), ``failure`` the solver's
        message; any other failure is raised.
        ``deflection_nonlinear``: the largest deflection at the end of the path (at load
        factor 1 when it is reached), m. ``stop``: the criterion that ended the path.
        ``load_factor_reached``: the path's largest load factor. ``events``: the solver's
        stability events. ``states``, ``iterations``: the path's states and Newton
        iterations. ``path``: the FoldPath itself, with ``keep_path``.
    """
    import barhinge as bh
    from barhinge.analysis.buckling import critical_ahead, critical_between
    from barhinge.errors import BucklingError, ConvergenceError
    from barhinge.scene import Scene

    scene = Scene(model, supports=fixed, loads=P, control="arc_length", steps=steps,
                  options={"arc_stop_load_factor": 1.0, "arc_stop_limit_points": 1,
                           "arc_stop_instability": stop_at_instability,
                           "max_arc_steps": 40 * steps})  # fmt: skip
    ahead = None
    try:
        path = bh.solve(scene)
        stop = path.meta["arc_stop"]["criterion"]
    except ConvergenceError as exc:
        # increments that fail at a critical point: every state is stable, none past it
        path = exc.last_state
        if not (stop_at_instability and isinstance(path, bh.FoldPath)):
            raise
        try:
            ahead = critical_ahead(model, fixed, path.X, path.load_factor)
        except BucklingError:
            raise exc from None
        stop = "critical_ahead"
    lam = np.asarray(path.load_factor)
    U = np.asarray(path.X[-1]) - np.asarray(path.X[0])
    neg = list(path.meta["negative_eigenvalues"])
    first_neg = next((k for k, n in enumerate(neg) if n is not None and n > 0), None)
    limit = float(lam.max()) if stop == "limit_points" else None
    unstable = [v for v in (limit, None if first_neg is None else float(lam[first_neg])) if v]
    bracket, estimate, why = None, None, ""
    if ahead is not None:
        unstable.append(ahead.estimate)
        bracket, estimate = [ahead.estimate, ahead.linear], ahead.estimate
    if first_neg is not None and first_neg > 0:
        k = first_neg
        bracket = [float(lam[k - 1]), float(lam[k])]
        try:
            estimate = critical_between(model, fixed, path.X[k - 1], path.X[k], *bracket)
        except BucklingError as exc:
            why = str(exc).splitlines()[0]
    out = {
        "limit_load_factor": limit,
        "instability_load_factor": min(unstable) if unstable else None,
        "instability_bracket": bracket,
        "instability_estimate": estimate,
        "instability_estimate_error": why,
        "deflection_nonlinear": float(np.max(-U[:, 2])),
        "load_factor_reached": float(lam.max()),
        "stop": stop,
        "failure": "" if ahead is None else str(path.message).splitlines()[0],
        "events": list(path.meta.get("events", [])),
        "states": len(lam),
        "iterations": int(path.meta["newton"]["total_iterations"]),
    }
    return {**out, "path": path} if keep_path else out


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
    return {
        "fold": fold,
        "n_strip": n_strip,
        "stiffness": k,
        "beam": ref["stiffness"],
        "ratio": k / ref["stiffness"],
        "bending_share": ref["bending_share"],
    }


def flat_plate_check(n_strip: int = 1, rigid_panels: bool = False) -> dict:
    """The flat sheet (span SPAN, 8 strips of 0.5 m, panels cut into ``n_strip`` strips) under
    the uniform load against a plate strip. Pinning one line of nodes at each end lets the
    sheet rotate there: simply supported. Mean deflection of a simply supported strip,
    ``q L^4 / (120 D)`` (mean of ``q x (L^3 - 2 L x^2 + x^3) / (24 D)``), so
    ``k / width = q L / mean deflection = 120 D / L^3`` with ``D = E t^3 / (12 (1 - nu^2))``
    (cylindrical bending, plate bound) or ``E t^3 / 12`` (free anticlastic bending, beam
    bound); a square sheet free along its two long edges lies between (Timoshenko &
    Woinowsky-Krieger 1959, ch. 1 and sec. 47). ``rigid_panels``: bending hinges inside the
    panels 1e3 x stiffer, so only the flat lines (``D l / s``) bend: a discrete beam of
    rotational springs whose ``EI`` is ``D`` per unit width."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response

    cp, flat_xy, crease = folded("flat", 0.0, n_strip=n_strip, m_seg=8 * n_strip)
    model = flat_line_stiffness(bh.BarHingeModel.from_pattern(cp, "N5B8", material()), crease)
    if rigid_panels:
        k = np.array(model.hinge_k)
        k[model.hinge_kind == "bend"] *= 1e3
        model = model.with_(hinge_k=k)
    S = supports(model, flat_xy, 1)
    Fq = plan_load(model, Q)
    U, _ = linear_response(model, Fq, S)
    Qt = float(-Fq[:, 2].sum())
    k_w = Q * SPAN / (float(np.sum(Fq * U)) / Qt)
    E, nu, t = MATERIAL["E"], MATERIAL["nu"], MATERIAL["t"]
    D = E * t**3 / (12 * (1 - nu**2))
    return {
        "n_strip": n_strip,
        "rigid_panels": rigid_panels,
        "stiffness_per_width": k_w,
        "plate": 120 * D / SPAN**3,
        "beam": 120 * E * t**3 / 12 / SPAN**3,
    }
