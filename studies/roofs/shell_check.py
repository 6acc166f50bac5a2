"""Bar-and-hinge roofs against an independent shell model of the same folded sheet.

For each roof (geometry, supports and load of ``roofs.py``: span 4 m, aluminium 2 mm, pinned
along the two supported edges, 1 kN/m^2 per unit plan area) the linear stiffness
``k = Q_t^2 / (f . u)`` (total load squared over the compliance) of

* the bar-and-hinge model (N5B8, the study's calibration) with every panel cut into
  ``m x m`` sub-panels by flat lines (:func:`barhinge.pattern.subdivide.subdivided`; flat
  lines get the plate-strip stiffness ``D l / s`` of ``roofs.flat_line_stiffness``), m = 1, 2,
  4, (8);
* the facet shell (:mod:`barhinge.model.shell`: CST membrane + Morley plate on each facet,
  each facet edge cut into ``2^r`` elements), with the creases given the bar-and-hinge fold
  stiffness per unit length (the same structure), r = 1, 2, 3, (4, 5); its converged value is
  extrapolated (Richardson, with the observed rate of the three finest levels).

The shell refinement of one Miura roof is also split into its parts (membranes or plates
made 1000 times stiffer, :func:`membrane_bending_split`) to show which sets its slow
convergence, and so is the Yoshimura roof's graded refinement, to show why it is not
monotone.

The bar-and-hinge error against the shell reference and its observed rate
(``polyfit`` of log error against log m) go to docs/roofs.md (``--publish``).

Run: ``python studies/roofs/shell_check.py [--quick] [--publish]``. Importing the module
runs the quick mode (one roof, coarse levels); its results stay at module level in
``RESULTS``.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from barhinge.analysis.accuracy import MIN_ORDER

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import roofs  # noqa: E402

MAIN = __name__ == "__main__"
if MAIN:  # a mistyped option or --help must not start the full run
    from barhinge._study_args import check_study_argv

    check_study_argv(__doc__, flags=("--quick", "--publish"), valued=("--cache",))
QUICK = not MAIN or "--quick" in sys.argv
PUBLISH = MAIN and "--publish" in sys.argv
ROOT = HERE.parents[1]
DOC = ROOT / "docs" / "roofs.md"
START, END = "<!-- shell_check:start -->", "<!-- shell_check:end -->"

#: bar-and-hinge variants: name -> BarHingeModel.from_pattern keywords
VARIANTS = roofs.BENDING_RULES
#: variants whose bend and flat-line hinges follow barhinge.model.plate_hinges
CONSISTENT = ("consistent", "coupled")
#: the rule each roof is refined with for its limit (couplings: the sheet's Poisson ratio)
MAIN_RULE = "coupled"
#: the roofs' shell reference: facet meshes graded towards the corners (``roofs.SHELL_GRADING``);
#: uniform meshes are refined beside it for comparison
SHELL_GRADING = roofs.SHELL_GRADING

#: the main rule is refined past its fixed levels until its stiffness changes by less than
#: ``roofs.REFINE_TOL`` or the next level would exceed this many DOFs
DOF_BUDGET = 7_000 if QUICK else roofs.REFINE_DOF_BUDGET
#: the graded shell reference is refined past ``SHELL_LEVELS`` (r + 1) until its Richardson
#: estimate holds (observed order at least ``accuracy.MIN_ORDER``, correction below
#: ``roofs.REFINE_TOL``) or the next level would exceed this many DOFs (about 12 GB of memory
#: at 3.6 million)
SHELL_DOF_BUDGET = 20_000 if QUICK else 4_000_000

if QUICK:
    ROOFS = [("pleats", 90.0)]
    BH_LEVELS, SHELL_LEVELS = [1, 2], [2, 3, 4]
    LEVELS = {v: BH_LEVELS for v in VARIANTS}
else:
    ROOFS = [
        ("miura60", 45.0),
        ("miura75", 45.0),
        ("yoshimura", 20.0),
        ("pleats", 90.0),
        ("pleats", 60.0),
        ("miura_arc", 60.0),
        ("miura75", 75.0),
    ]
    BH_LEVELS, SHELL_LEVELS = [1, 2, 4, 8, 16], [1, 2, 3, 4, 5]
    LEVELS = {
        "plate": [1, 2, 4, 8],
        "kirchhoff": [1, 2, 4, 8],
        "consistent": BH_LEVELS,
        "coupled": BH_LEVELS,
    }


def support_sets(cp, flat_xy: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """(supported vertex ids, supported pattern edges): the study's two line supports
    (:func:`roofs.support_lines`)."""
    return roofs.support_lines(cp, flat_xy, axis)


def bar_hinge(cp, sv, se, m: int, variant: str = "plate", scheme: str = "N5B8") -> dict:
    """Stiffness of the bar-and-hinge roof with m x m sub-panels (bending rule ``variant``,
    :func:`roofs.subdivided_roof`)."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response

    t0 = time.perf_counter()
    model, S, residual = roofs.subdivided_roof(cp, sv, se, m, variant, scheme)
    # the creases' own springs (the plate-consistent rules put them in series with the strip)
    base = bh.BarHingeModel.from_pattern(cp, scheme, roofs.material())
    crease_k = roofs.crease_stiffness_per_length(base)
    F = roofs.plan_load(model, roofs.Q)
    U, _ = linear_response(model, F, S)
    Qt = float(-F[:, 2].sum())
    return {
        "m": m,
        "membrane": membrane(variant),
        "stiffness": Qt**2 / float(np.sum(F * U)),
        "n_dof": 3 * model.n_nodes,
        "time_s": time.perf_counter() - t0,
        "crease_k": crease_k,
        "patch_residual": residual,
    }


def membrane(variant: str) -> str:
    """The membrane (``bar_calibration``) of a bending rule's models."""
    return roofs.BENDING_RULES[variant].get("bar_calibration", "fit")


def shell(cp, sv, se, r: int, crease_k: float, material=None, grading: float = 1.0) -> dict:
    """Stiffness of the facet shell roof at refinement r (:func:`roofs.shell_level`)."""
    return roofs.shell_level(cp, sv, se, r, crease_k, material, grading)


def navier_plate_stiffness(a: float, D: float, q: float, terms: int = 199) -> float:
    """Compliance stiffness ``Q_t^2 / (f . u) = q a^2 / mean(w)`` of a simply supported
    square plate (side a, rigidity D) under a uniform load q, from Navier's series
    (Timoshenko & Woinowsky-Krieger 1959, Sec. 30): ``mean(w) = 64 q a^4 / (pi^8 D)
    sum_(m, n odd) 1 / (m^2 n^2 (m^2 + n^2)^2)``."""
    k = np.arange(1, terms + 1, 2, dtype=float)
    M, N = np.meshgrid(k, k)
    mean_w = (
        64 * q * a**4 / (np.pi**8 * D) * float(np.sum(1.0 / (M**2 * N**2 * (M**2 + N**2) ** 2)))
    )
    return q * a * a / mean_w


def flat_plate(levels_bh: list[int], levels_shell: list[int]) -> dict:
    """The panel-subdivision rule on a flat square plate (1 m, the roofs' sheet), simply
    supported on its four edges under 1 kN/m^2: stiffness of the subdivided bar-and-hinge
    panel (each variant) and of the shell, over the Navier value."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response
    from barhinge.model.shell import shell_model
    from barhinge.pattern.crease import CreasePattern
    from barhinge.pattern.subdivide import subdivided

    mat = roofs.material()
    ref = navier_plate_stiffness(1.0, mat.bending_rigidity, roofs.Q)
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = CreasePattern(sq, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    out: dict = {"navier": ref, "bar_hinge": {}, "shell": []}
    for v, kw in VARIANTS.items():
        rows = []
        for m in levels_bh:
            cpm, parent = subdivided(cp, m)
            model = bh.BarHingeModel.from_pattern(cpm, "N5B8", mat, **kw)
            if v in CONSISTENT:
                model = _rule(model, v)
            else:
                model = roofs.flat_line_stiffness(model, np.zeros(cpm.n_edges, bool))
            S = np.zeros((model.n_nodes, 3), bool)
            S[np.union1d(np.arange(4), np.flatnonzero(parent >= 0))] = True
            F = roofs.plan_load(model, roofs.Q)
            U, _ = linear_response(model, F, S)
            rows.append({"m": m, "ratio": float(F[:, 2].sum() ** 2 / np.sum(F * U)) / ref})
        out["bar_hinge"][v] = rows
    for r in levels_shell:
        sh = shell_model(cp, mat, r)
        f = sh.surface_load((0.0, 0.0, -roofs.Q))
        u = sh.solve(f, sh.nodes_on_edges(np.arange(4)))
        Qt = float(sh.translations(f)[:, 2].sum())
        out["shell"].append({"r": r, "ratio": Qt**2 / float(f @ u) / ref})
    return out


def _rule(model, variant: str):
    """The model with the hinges of a plate-consistent variant (``CONSISTENT``)."""
    from barhinge.model.plate_hinges import consistent_hinge_stiffness, coupled_bending

    if variant == "coupled":
        return coupled_bending(model)
    return model.with_(hinge_k=consistent_hinge_stiffness(model).hinge_k)


def free_edge_plate(levels_bh: list[int], levels_shell: list[int]) -> dict:
    """The square plate (1 m, the roofs' sheet) simply supported on two opposite edges and
    free on the other two, under 1 kN/m^2: the consistent bar-and-hinge panel against the
    shell (Morley plate, the sheet's nu) and against the same shell with nu = 0 (which is
    the beam strip ``k = 120 D / L^2 * q L ...``: ``q L^4 / (120 D)`` mean deflection), so
    the effect of Poisson's ratio at free edges is visible."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response
    from barhinge.model.shell import shell_model
    from barhinge.pattern.crease import CreasePattern
    from barhinge.pattern.subdivide import subdivided

    mat = roofs.material()
    D = mat.bending_rigidity
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = CreasePattern(sq, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    out: dict = {"strip": 120.0 * D, "bar_hinge": {v: [] for v in CONSISTENT}, "shell": {}}
    for v in CONSISTENT:
        for m in levels_bh:
            cpm, parent = subdivided(cp, m)
            base = bh.BarHingeModel.from_pattern(cpm, "N5B8", mat, bend_calibration="kirchhoff")
            model = _rule(base, v)
            X = np.asarray(model.X0)
            on = (np.abs(X[:, 0]) < 1e-9) | (np.abs(X[:, 0] - 1.0) < 1e-9)
            on[cpm.n_vertices :] = False
            S = np.zeros((model.n_nodes, 3), bool)
            S[on] = True
            F = roofs.plan_load(model, roofs.Q)
            U, _ = linear_response(model, F, S)
            k = float(F[:, 2].sum() ** 2 / np.sum(F * U))
            out["bar_hinge"][v].append({"m": m, "stiffness": k})
    for nu in (mat.nu, 0.0):
        m2 = bh.Material(E=D * 12 * (1 - nu**2) / mat.t**3, nu=nu, t=mat.t)
        rows = []
        for r in levels_shell:
            sh = shell_model(cp, m2, r)
            f = sh.surface_load((0.0, 0.0, -roofs.Q))
            u = sh.solve(f, sh.nodes_on_edges(np.array([1, 3])))
            Qt = float(sh.translations(f)[:, 2].sum())
            rows.append({"r": r, "stiffness": Qt**2 / float(f @ u)})
        out["shell"][f"{nu:g}"] = rows
    return out


def poisson_check(levels_bh: list[int], levels_shell: list[int]) -> dict:
    """The pleats roof with monolithic creases (stiff fold springs, 1e6 N·m/rad per m) in both
    models, with the sheet's nu and with nu = 0: stiffness per level and Richardson limits.
    The hinge energy's Gaussian-curvature coefficient is fixed (module plate_hinges), so the
    gap between the converged models should shrink with the distance of nu from it."""
    import barhinge as bh
    from barhinge.analysis.stiffness import linear_response
    from barhinge.model.shell import shell_model
    from barhinge.pattern.subdivide import subdivided

    kc = 1e6
    cp, flat_xy, _ = roofs.folded("pleats", 90.0)
    sv, se = support_sets(cp, flat_xy, roofs.FAMILIES["pleats"]["axis"])
    out: dict = {}
    for nu in (roofs.MATERIAL["nu"], 0.0):
        mat = bh.Material(E=roofs.MATERIAL["E"], nu=nu, t=roofs.MATERIAL["t"])
        bh_k: dict[str, list[float]] = {v: [] for v in CONSISTENT}
        for v in CONSISTENT:
            for m in levels_bh:
                cpm, parent = subdivided(cp, m)
                model = bh.BarHingeModel.from_pattern(
                    cpm, "N5B8", mat, bend_calibration="kirchhoff", fold_stiffness=kc
                )
                model = _rule(model, v)
                S = np.zeros((model.n_nodes, 3), bool)
                S[np.union1d(sv, np.flatnonzero(np.isin(parent, se)))] = True
                F = roofs.plan_load(model, roofs.Q)
                U, _ = linear_response(model, F, S)
                bh_k[v].append(float(F[:, 2].sum() ** 2 / np.sum(F * U)))
        sh_k = []
        for r in levels_shell:
            sh = shell_model(cp, mat, r, crease_stiffness=kc)
            f = sh.surface_load((0.0, 0.0, -roofs.Q), per="plan")
            u = sh.solve(f, np.union1d(sh.nodes_on_edges(se), sv))
            Qt = float(-sh.translations(f)[:, 2].sum())
            sh_k.append(Qt**2 / float(f @ u))
        out[f"{nu:g}"] = {
            "m": levels_bh,
            "r": levels_shell,
            "bar_hinge": bh_k,
            "shell": sh_k,
            "bar_hinge_limit": {v: extrapolate(k)[0] for v, k in bh_k.items()},
            "shell_limit": extrapolate(sh_k)[0],
        }
    return out


def extrapolate(k: list[float]) -> tuple[float, float, float]:
    """(reference, observed rate p in h, uncertainty) from values on levels h, h/2, h/4...
    (:func:`barhinge.analysis.accuracy.richardson`; one level: uncertainty NaN)."""
    from barhinge.analysis.accuracy import richardson

    ref, p, unc = richardson(list(k))  # below MIN_ORDER: the finest value, unknown error
    return ref, p, unc if len(k) > 1 else float("nan")


def extended(cp, sv, se, rows: list[dict]) -> list[dict]:
    """The ``MAIN_RULE`` levels ``rows`` refined further (m doubled) until the stiffness
    changes by less than ``roofs.REFINE_TOL`` or the next level would exceed ``DOF_BUDGET``."""
    rows = list(rows)
    while not roofs.settled([r["stiffness"] for r in rows]):
        m = 2 * rows[-1]["m"]
        if roofs.refinement_dofs(cp, m) > DOF_BUDGET:
            break
        rows.append(bar_hinge(cp, sv, se, m, MAIN_RULE))
        print(f"  {MAIN_RULE} m = {m}: {rows[-1]['stiffness'] / 1e3:.1f} kN/m", flush=True)
    return rows


def shell_extended(cp, sv, se, crease_k: float, rows: list[dict]) -> list[dict]:
    """The graded shell levels ``rows`` refined further until they settle, within
    ``SHELL_DOF_BUDGET`` (:func:`roofs.shell_extended`)."""
    return roofs.shell_extended(cp, sv, se, crease_k, rows, SHELL_DOF_BUDGET, SHELL_GRADING)


def refined_until(rows: list[dict], tol: float = roofs.REFINE_TOL) -> dict:
    """The first level at which the stiffness has settled (:func:`roofs.settled`: changed by
    less than ``tol`` from the previous level, in the asymptotic range); the finest level
    if none has (``converged`` False)."""
    k = [r["stiffness"] for r in rows]
    for i in range(3, len(rows) + 1):
        if roofs.settled(k[:i], tol):
            return {**rows[i - 1], "converged": True}
    return {**rows[-1], "converged": False}


def run() -> list[dict]:
    out = []
    for fam, state in ROOFS:
        cp, flat_xy, _ = roofs.folded(fam, state)
        sv, se = support_sets(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
        bhr = {v: [bar_hinge(cp, sv, se, m, v) for m in LEVELS[v]] for v in VARIANTS}
        bhr[MAIN_RULE] = extended(cp, sv, se, bhr[MAIN_RULE])
        n4b5 = bar_hinge(cp, sv, se, 1, "plate", scheme="N4B5")
        ck = bhr["plate"][0]["crease_k"]
        shr = [shell(cp, sv, se, r, ck, grading=SHELL_GRADING) for r in SHELL_LEVELS]
        shr = shell_extended(cp, sv, se, ck, shr)
        shu = [shell(cp, sv, se, r, ck) for r in SHELL_LEVELS]
        raw = {"family": fam, "state": state, "bar_hinge": bhr, "n4b5": n4b5}
        out.append(derive({**raw, "shell": shr, "shell_uniform": shu}))
    return out


def derive(raw: dict) -> dict:
    """A roof's results from its raw levels (``family``, ``state``, ``bar_hinge``,
    ``n4b5``, ``shell``, ``shell_uniform``): the shell references, the errors and rates
    against the graded one, the bar-and-hinge limit and the refinement to 2 %."""
    bhr, n4b5, shr, shu = raw["bar_hinge"], raw["n4b5"], raw["shell"], raw["shell_uniform"]
    cp = roofs.folded(raw["family"], raw["state"])[0]
    ref, p, unc = extrapolate([s["stiffness"] for s in shr])
    ref_u, p_u, unc_u = extrapolate([s["stiffness"] for s in shu])
    errors, rates = {}, {}
    for v, rows in bhr.items():
        ms = np.array([b["m"] for b in rows], float)
        err = np.array([b["stiffness"] / ref - 1.0 for b in rows])
        errors[v] = err.tolist()
        # rate over the levels m >= 2 (m = 1 has no flat lines)
        sel = (ms >= 2) if (ms >= 2).sum() >= 2 else np.ones(len(ms), bool)
        sel &= np.abs(err) > 0
        rates[v] = (
            float(-np.polyfit(np.log(ms[sel]), np.log(np.abs(err[sel])), 1)[0])
            if sel.sum() >= 2
            else float("nan")
        )
    cons = [b["stiffness"] for b in bhr[MAIN_RULE] if b["m"] >= 2]
    bh_ref, bh_p, bh_unc = extrapolate(cons)
    return {
        "family": raw["family"],
        "state": raw["state"],
        "bar_hinge": bhr,
        "n4b5": {**n4b5, "error": n4b5["stiffness"] / ref - 1.0},
        "shell": shr,
        "shell_reference": ref,
        "shell_rate": p,
        "shell_uncertainty": unc / ref,
        "shell_uniform": shu,
        "uniform_reference": ref_u,
        "uniform_rate": p_u,
        "uniform_uncertainty": unc_u / ref_u,
        "errors": errors,
        "rate": rates,
        "consistent_reference": bh_ref,
        "consistent_rate": bh_p,
        "consistent_uncertainty": bh_unc / bh_ref,
        "refined": refined_until(bhr[MAIN_RULE]),
        "patch_residual": max(b["patch_residual"] for b in bhr[MAIN_RULE]),
        "membrane_error": roofs.cell_membrane_error(cp, membrane(MAIN_RULE)),
        "bar_membrane_error": roofs.cell_membrane_error(cp, "fit"),
    }


#: the roof whose shell convergence is split into its membrane and bending parts
SPLIT_ROOF = ("miura60", 45.0)
#: the roof whose graded shell sequence is not monotone, split the same way
SIDES_ROOF = ("yoshimura", 20.0)
#: how much stiffer the membranes (or the plates) of the split's variants are
STIFFENED = 1000.0


def split_materials() -> dict:
    """The study's sheet and two variants: membranes (``E t``) or plates (``E t^3``)
    ``STIFFENED`` times stiffer, the other part kept (``E`` and ``t`` changed together)."""
    import barhinge as bh

    mat, s = roofs.MATERIAL, STIFFENED
    E, t = mat["E"], mat["t"]
    return {
        "sheet": bh.Material(**mat),
        "stiff membranes": bh.Material(**{**mat, "E": E * s**1.5, "t": t / s**0.5}),
        "stiff plates": bh.Material(**{**mat, "E": E / s**0.5, "t": t * s**0.5}),
    }


def membrane_bending_split(
    levels: list[int], roof: tuple[str, float] = SPLIT_ROOF, grading: float = 1.0
) -> dict:
    """Shell refinement of ``roof`` (facet meshes of ``grading``) with the sheet as it is and
    with either part made ``STIFFENED`` times stiffer: which part sets the slow convergence.
    Per variant the stiffnesses (N/m) at ``levels`` and the observed order in the element
    size (Richardson over the three finest)."""
    fam, state = roof
    cp, flat_xy, _ = roofs.folded(fam, state)
    sv, se = support_sets(cp, flat_xy, roofs.FAMILIES[fam]["axis"])
    import barhinge as bh

    model = bh.BarHingeModel.from_pattern(cp, "N5B8", roofs.material())
    ck = roofs.crease_stiffness_per_length(model)
    out = {}
    for name, mat in split_materials().items():
        k = [shell(cp, sv, se, r, ck, mat, grading)["stiffness"] for r in levels]
        out[name] = {"levels": list(levels), "stiffness": k, "rate": extrapolate(k)[1]}
    return out


CACHE = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--cache=")), None)
if CACHE and Path(CACHE).exists():
    RESULTS, PLATE = json.loads(Path(CACHE).read_text())
    for r in RESULTS:  # the main rule refined to the criterion where the cache stops short
        rows = r["bar_hinge"][MAIN_RULE]
        cp, flat_xy, _ = roofs.folded(r["family"], r["state"])
        sv, se = support_sets(cp, flat_xy, roofs.FAMILIES[r["family"]]["axis"])
        if any(b.get("membrane", "fit") != membrane(MAIN_RULE) for b in rows):
            # cached with another membrane: the main rule's levels again
            rows = [bar_hinge(cp, sv, se, m, MAIN_RULE) for m in LEVELS[MAIN_RULE]]
            r["bar_hinge"][MAIN_RULE] = rows
            Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))
        r["bar_hinge"][MAIN_RULE] = extended(cp, sv, se, rows)
        n_shell = len(r["shell"])  # and the shell reference, where it has not settled
        ck = r["bar_hinge"]["plate"][0]["crease_k"]
        r["shell"] = shell_extended(cp, sv, se, ck, r["shell"])
        if len(r["bar_hinge"][MAIN_RULE]) > len(rows) or len(r["shell"]) > n_shell:
            Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))
    RESULTS = [derive(r) for r in RESULTS]  # the levels are cached, the rest is re-derived
    if "split" not in PLATE:
        PLATE["split"] = membrane_bending_split([1, 2, 3, 4])
        Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))
    if "poisson" not in PLATE:
        PLATE["poisson"] = poisson_check([4, 8, 16], [2, 3, 4])
        Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))
    if "sides" not in PLATE:
        PLATE["sides"] = membrane_bending_split(SHELL_LEVELS, SIDES_ROOF, SHELL_GRADING)
        Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))
else:
    RESULTS = run()
    PLATE = flat_plate([2, 4] if QUICK else [2, 4, 8, 16], [2, 3] if QUICK else [2, 3, 4, 5])
    PLATE["free_edge"] = free_edge_plate(
        [4, 8] if QUICK else [8, 16, 32], [2, 3] if QUICK else [3, 4, 5]
    )
    PLATE["poisson"] = poisson_check(
        [2, 4] if QUICK else [4, 8, 16], [1, 2] if QUICK else [2, 3, 4]
    )
    PLATE["split"] = membrane_bending_split([1, 2, 3] if QUICK else [1, 2, 3, 4])
    PLATE["sides"] = membrane_bending_split(
        [1, 2] if QUICK else SHELL_LEVELS, SIDES_ROOF, SHELL_GRADING
    )
    if CACHE:
        Path(CACHE).write_text(json.dumps([RESULTS, PLATE]))


def poisson_table(pc: dict) -> str:
    lines = [
        "| ν | model | levels | stiffness per level (kN/m) | limit (kN/m) |",
        "|---|---|---|---|---|",
    ]
    for nu, d in pc.items():
        rows = [(f"bar-hinge, {v}", "m", d["bar_hinge"][v], d["bar_hinge_limit"][v])
                for v in d["bar_hinge"]]  # fmt: skip
        rows.append(("shell", "r", d["shell"], d["shell_limit"]))
        for name, lv, ks, lim in rows:
            vals = ", ".join(f"{k / 1e3:.1f}" for k in ks)
            levels = ", ".join(str(x) for x in d[lv])
            lines.append(f"| {nu} | {name} | {lv} = {levels} | {vals} | {lim / 1e3:.1f} |")
    return "\n".join(lines)


def _ref(value: float, unc: float) -> str:
    """A reference in kN/m with its relative uncertainty, or "not settled"."""
    if not np.isfinite(unc):
        return f"{value / 1e3:.1f} (finest; not settled)"
    return f"{value / 1e3:.1f} ± {100 * unc:.1f} %"


def _unc(unc: float) -> str:
    return f"± {100 * unc:.1f} %" if np.isfinite(unc) else "not settled"


def _pct(x: float) -> str:
    return "n/a" if not math.isfinite(x) else f"{100 * x:+.1f} %"


def _num(x: float, fmt: str = ".2f") -> str:
    return "n/a" if not math.isfinite(x) else format(x, fmt)


def all_levels(results: list[dict]) -> list[int]:
    """Every bar-and-hinge level of any roof and rule (the rules are refined unevenly)."""
    return sorted({b["m"] for r in results for rows in r["bar_hinge"].values() for b in rows})


def table(results: list[dict]) -> str:
    levels = all_levels(results)
    lines = [
        "| roof | state | shell, finest (kN/m) | shell reference (kN/m) | shell rate | "
        "bending calibration | " + " | ".join(f"m = {m}" for m in levels) + " | rate |",
        "|---|---|---|---|---|---|" + "---|" * len(levels) + "---|",
    ]
    for r in results:
        sh = r["shell"][-1]
        for v in VARIANTS:
            by_m = dict(zip([b["m"] for b in r["bar_hinge"][v]], r["errors"][v], strict=True))
            errs = " | ".join(_pct(by_m[m]) if m in by_m else "–" for m in levels)
            lines.append(
                f"| {r['family']} | {r['state']:g} | {sh['stiffness'] / 1e3:.1f} (r = {sh['r']}) | "
                f"{_ref(r['shell_reference'], r['shell_uncertainty'])} | "
                f"{_num(r['shell_rate'])} | {v} | {errs} | {_num(r['rate'][v])} |"
            )
    return "\n".join(lines)


def shell_mesh_table(results: list[dict]) -> str:
    """Per roof: the shell refined on uniform and on corner-graded facet meshes, each
    sequence's finest value, Richardson reference and observed order."""
    lines = [
        "| roof | state | uniform: finest (kN/m) | uniform: reference (kN/m) | uniform: rate | "
        f"graded ({SHELL_GRADING:g}): finest (kN/m) | graded: reference (kN/m) | "
        "graded: rate | graded / uniform reference − 1 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        su, sg = r["shell_uniform"][-1], r["shell"][-1]
        lines.append(
            f"| {r['family']} | {r['state']:g} | {su['stiffness'] / 1e3:.1f} (r = {su['r']}) | "
            f"{_ref(r['uniform_reference'], r['uniform_uncertainty'])} | "
            f"{_num(r['uniform_rate'])} | {sg['stiffness'] / 1e3:.1f} (r = {sg['r']}) | "
            f"{_ref(r['shell_reference'], r['shell_uncertainty'])} | "
            f"{_num(r['shell_rate'])} | "
            f"{_pct(r['shell_reference'] / r['uniform_reference'] - 1.0)} |"
        )
    return "\n".join(lines)


def refinement_table(results: list[dict]) -> str:
    """Per roof: the ``MAIN_RULE`` model refined until its stiffness changes < 2 %, its own
    extrapolated limit and rate, and the gap between that limit and the shell's."""
    lines = [
        "| roof | state | cell patch residual / D | membrane error of the cells (bars `fit`) | "
        "refined to (change < 2 %) | stiffness (kN/m) | "
        "bar-hinge limit (kN/m) | its rate | shell reference (kN/m) | limit / shell − 1 |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        f = r["refined"]
        lvl = f"m = {f['m']}" + ("" if f["converged"] else " (not reached: DOF budget)")
        lines.append(
            f"| {r['family']} | {r['state']:g} | {r['patch_residual']:.2f} | "
            f"{r['membrane_error']:.3f} ({r['bar_membrane_error']:.3f}) | {lvl} | "
            f"{f['stiffness'] / 1e3:.1f} | {r['consistent_reference'] / 1e3:.1f} ± "
            f"{100 * r['consistent_uncertainty']:.1f} % | {_num(r['consistent_rate'])} | "
            f"{_ref(r['shell_reference'], r['shell_uncertainty'])} | "
            f"{_pct(r['consistent_reference'] / r['shell_reference'] - 1.0)} |"
        )
    return "\n".join(lines)


def timing(results: list[dict]) -> str:
    lines = [
        "| roof | model | level | DOFs | stiffness (kN/m) | wall time (s) |",
        "|---|---|---|---|---|---|",
    ]
    for r in results:
        b = r["n4b5"]
        lines.append(
            f"| {r['family']} | bar-hinge N4B5, plate | m = 1 | {b['n_dof']} | "
            f"{b['stiffness'] / 1e3:.1f} | {b['time_s']:.2f} |"
        )
        for v, rows in r["bar_hinge"].items():
            for b in rows:
                lines.append(
                    f"| {r['family']} | bar-hinge N5B8, {v} | m = {b['m']} | {b['n_dof']} | "
                    f"{b['stiffness'] / 1e3:.1f} | {b['time_s']:.2f} |"
                )
        for s_ in r["shell"]:
            lines.append(
                f"| {r['family']} | shell | r = {s_['r']} | {s_['n_dof']} | "
                f"{s_['stiffness'] / 1e3:.1f} | {s_['time_s']:.2f} |"
            )
    return "\n".join(lines)


def plate_table(plate: dict) -> str:
    lines = ["| model | level | stiffness / Navier |", "|---|---|---|"]
    for v, rows in plate["bar_hinge"].items():
        for b in rows:
            lines.append(f"| bar-hinge N5B8, {v} | m = {b['m']} | {b['ratio']:.3f} |")
    for s_ in plate["shell"]:
        lines.append(f"| shell | r = {s_['r']} | {s_['ratio']:.4f} |")
    return "\n".join(lines)


def free_edge_table(fe: dict) -> str:
    lines = ["| model | level | stiffness (kN/m) | / beam strip |", "|---|---|---|---|"]
    for v, rows in fe["bar_hinge"].items():
        for b in rows:
            lines.append(
                f"| bar-hinge N5B8, {v} | m = {b['m']} | {b['stiffness'] / 1e3:.3f} | "
                f"{b['stiffness'] / fe['strip']:.4f} |"
            )
    for nu, rows in fe["shell"].items():
        for s_ in rows:
            lines.append(
                f"| shell, ν = {nu} | r = {s_['r']} | {s_['stiffness'] / 1e3:.3f} | "
                f"{s_['stiffness'] / fe['strip']:.4f} |"
            )
    return "\n".join(lines)


def plate_rate(rows: list[dict]) -> tuple[float, float]:
    """(observed order in m of |stiffness / Navier - 1| over the levels, finest error)."""
    ms = np.array([b["m"] for b in rows], float)
    err = np.abs(np.array([b["ratio"] for b in rows]) - 1.0)
    return float(-np.polyfit(np.log(ms[1:]), np.log(err[1:]), 1)[0]), float(err[-1])


def prose(results: list[dict], plate: dict) -> str:
    """The findings, with the numbers of this run."""
    from barhinge.model.plate_hinges import cell_fit

    rates = {v: plate_rate(plate["bar_hinge"][v]) for v in CONSISTENT}
    ki = plate["bar_hinge"]["kirchhoff"][-1]["ratio"]
    fi = plate["bar_hinge"]["plate"][-1]["ratio"]
    m_last = plate["bar_hinge"][MAIN_RULE][-1]["m"]
    fe = plate["free_edge"]
    fe_bh = {
        v: extrapolate([b["stiffness"] for b in rows])[0] for v, rows in fe["bar_hinge"].items()
    }
    fe_sh = {
        nu: extrapolate([s_["stiffness"] for s_ in rows])[0] for nu, rows in fe["shell"].items()
    }
    nu = next(iter(fe_sh))
    nu_s = roofs.MATERIAL["nu"]
    nu_eff = nu_s + cell_fit(np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), nu_s)[1]
    gap = {id(r): r["consistent_reference"] / r["shell_reference"] - 1.0 for r in results}
    # a reference counts when the shell's own refinement has converged to within 5 %
    settled = [r for r in results if r["shell_uncertainty"] <= 0.05]
    within = [r for r in settled if abs(gap[id(r)]) <= 0.05]
    bad = [r for r in results if r["patch_residual"] >= 1e-6]

    def label(r: dict) -> str:
        return f"{r['family']} {r['state']:g}"

    def one(r: dict) -> str:
        ms = ", ".join(str(b["m"]) for b in r["bar_hinge"][MAIN_RULE][-3:])
        return (
            f"{label(r)} {_pct(gap[id(r)])} (m = {ms}; its rate "
            f"{_num(r['consistent_rate'])}, shell "
            f"{_unc(r['shell_uncertainty'])}, shell rate {_num(r['shell_rate'])})"
        )

    pois = plate["poisson"]
    split = plate["split"]
    split_label = f"{SPLIT_ROOF[0]} {SPLIT_ROOF[1]:g}"
    split_roof = next((r for r in results if (r["family"], r["state"]) == SPLIT_ROOF), results[0])
    sp_levels = split["sheet"]["levels"]
    min_part = min(split["stiff membranes"]["rate"], split["stiff plates"]["rate"])
    soft = (
        min(split[v]["stiffness"][-1] for v in ("stiff membranes", "stiff plates"))
        / split["sheet"]["stiffness"][-1]
    )
    return "\n".join(
        [
            "What these numbers say:",
            "",
            "1. **Flat plate.** Both plate-consistent rules converge to Navier's plate: "
            + ", ".join(
                f"{v} at order {rates[v][0]:.2f} in m ({_pct(rates[v][1])} at m = {m_last})"
                for v in CONSISTENT
            )
            + f"; the per-panel rules do not (kirchhoff {ki:.3f}, plate {fi:.3f} of Navier).",
            "2. **Poisson's ratio.** A hinge energy with one stiffness per dihedral angle fixes "
            "the coefficient of the Gaussian-curvature term: on square cells the consistent "
            f"rule is the plate with ν = {nu_eff:.3f} (the sheet's: {nu_s}). The coupled rule "
            "(`coupled_bending`: the angles of each cell coupled, so that it stores the plate "
            "energy with the sheet's ν) removes that. On the plate free on two edges, where "
            "the term counts: coupled "
            f"{fe_bh['coupled'] / 1e3:.3f} kN/m, consistent {fe_bh['consistent'] / 1e3:.3f}, "
            f"shell {fe_sh[nu] / 1e3:.3f} (ν = {nu}) and {fe_sh['0'] / 1e3:.3f} (ν = 0): the "
            f"coupled rule is {_pct(fe_bh['coupled'] / fe_sh[nu] - 1.0)} from the sheet's "
            f"plate, the consistent one {_pct(fe_bh['consistent'] / fe_sh[nu] - 1.0)}.",
            "3. **Monolithic creases.** On the pleats roof with stiff creases the converged "
            "coupled model is "
            + ", ".join(
                f"{_pct(d['bar_hinge_limit']['coupled'] / d['shell_limit'] - 1.0)} from the "
                f"shell at ν = {n} (consistent "
                f"{_pct(d['bar_hinge_limit']['consistent'] / d['shell_limit'] - 1.0)})"
                for n, d in pois.items()
            )
            + ".",
            "4. **Patch test.** "
            + (
                "Every cell of every roof passes it with the coupled rule (largest residual "
                f"{max(r['patch_residual'] for r in results):.1e} D)."
                if not bad
                else "It fails on " + ", ".join(label(r) for r in bad) + "."
            ),
            f"5. **Roofs against the shell.** Limit of the {MAIN_RULE} bar-and-hinge model "
            "(Richardson over its three finest levels) against the shell reference: "
            + "; ".join(one(r) for r in results)
            + f". Of the {len(settled)} roofs whose shell reference is settled to within 5 %, "
            f"{len(within)} are within 5 % of it"
            + (f" ({', '.join(label(r) for r in within)})" if within else "")
            + "".join(
                f". On {label(r)} the {v} rule is within 5 % of it at its finest level "
                f"(m = {r['bar_hinge'][v][-1]['m']}: {_pct(r['errors'][v][-1])})"
                for r in settled
                if r not in within
                for v in CONSISTENT  # the rules that converge to the plate
                if v != MAIN_RULE and abs(r["errors"][v][-1]) <= 0.05
            )
            + ". Where the shell's own refinement converges slowly or not monotonically "
            "(rate below 1 or n/a) the reference is uncertain by the stated amount, below "
            f"order {MIN_ORDER:g} it is not extrapolated (the finest value, not settled), and "
            "the comparison is open."
            + "".join(
                f" On {label(r)} (gap {_pct(gap[id(r)])}) the cells store a uniform membrane "
                f"strain with an error of up to {r['membrane_error']:.2f} in their worst mode "
                "(the bar lattice's own limit for their shape, docs/calibration.md, Table 4), "
                "which refinement keeps"
                + (
                    ": part of its gap is a model error, not a refinement one."
                    if abs(gap[id(r)]) > 0.05
                    else "; this roof's load path does not lean on that mode."
                )
                for r in results
                if r["membrane_error"] > 0.05
            ),
            f"6. **Why the Miura roofs converge slowly.** The shell of {split_label} "
            f"refined (r = {', '.join(str(r) for r in sp_levels)}): "
            + "; ".join(
                f"{name} {', '.join(f'{k / 1e3:.1f}' for k in d['stiffness'])} kN/m, "
                f"order {_num(d['rate'])}"
                for name, d in split.items()
            )
            + f" (membranes or plates {STIFFENED:g} times stiffer, the other part as it is). "
            "Either part alone converges "
            + ("faster than" if min_part > split["sheet"]["rate"] else "no faster than")
            + f" the sheet, which is {soft:.1f} times softer than the softer variant at the "
            "finest level: its load path couples the facets' stretching with their bending. "
            "Where it does, the stresses are singular at the pattern's vertices: on facet "
            f"meshes graded towards the corners the shell of {label(split_roof)} converges at "
            f"order "
            f"{_num(split_roof['shell_rate'])} (uniform: {_num(split_roof['uniform_rate'])}) "
            f"and its reference is settled to ± {100 * split_roof['shell_uncertainty']:.1f} % "
            f"(uniform: ± {100 * split_roof['uniform_uncertainty']:.1f} %). The bar-and-hinge "
            "sub-panels are uniform, so its refinement stays slow on these roofs.",
            sides_finding(
                plate["sides"],
                next((r for r in results if (r["family"], r["state"]) == SIDES_ROOF), None),
            ),
        ]
    )


def _trend(k: list[float]) -> str:
    d = np.diff(k)
    if np.all(d > 0):
        return "rises at every level"
    if np.all(d < 0):
        return "falls at every level"
    return "is not monotone"


def sides_finding(sides: dict, roof: dict | None = None) -> str:
    """Finding 7: the graded shell of ``SIDES_ROOF`` split into its parts (``roof``: its
    results, whose shell may be refined past the split's levels)."""
    label = f"{SIDES_ROOF[0]} {SIDES_ROOF[1]:g}"
    lv = sides["sheet"]["levels"]
    mem, pla = sides["stiff membranes"]["stiffness"], sides["stiff plates"]["stiffness"]
    later = ""
    settled = roof is not None and np.isfinite(roof["shell_uncertainty"])
    if roof is not None and settled and len(roof["shell"]) > len(lv):
        extra = roof["shell"][len(lv) :]
        ks = ", ".join(f"{s_['stiffness'] / 1e3:.1f}" for s_ in extra)
        later = (
            f" Refined further (r = {', '.join(str(s_['r']) for s_ in extra)}: {ks} kN/m, up to "
            f"{extra[-1]['n_dof']:,} DOFs) its changes shrink at order "
            f"{_num(roof['shell_rate'])}, and the reference is "
            f"{roof['shell_reference'] / 1e3:.1f} kN/m ± "
            f"{100 * roof['shell_uncertainty']:.1f} %."
        )
    head = "settles late" if settled else "is not settled"
    return (
        f"7. **Why the {label} shell {head}.** Its graded shell refined "
        f"(r = {', '.join(str(r) for r in lv)}): "
        + "; ".join(
            f"{name} {', '.join(f'{k / 1e3:.1f}' for k in d['stiffness'])} kN/m"
            for name, d in sides.items()
        )
        + f". With stiff membranes, where the plates carry the load, the stiffness "
        f"{_trend(mem)}: Morley's plate is non-conforming and converges from below (as on "
        "the flat plate above). With stiff plates, where the membranes carry it, it "
        f"{_trend(pla)}: the constant-strain membranes are conforming and converge from "
        f"above. The sheet itself {_trend(sides['sheet']['stiffness'])}: its two errors "
        f"have opposite signs and neither dominates yet at r = {lv[-1]}, so no single "
        "order extrapolates these levels." + later
    )


def chart(results: list[dict], path: Path) -> None:
    """Error against the shell reference vs wall time, one panel per roof."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(results), figsize=(4.0 * len(results), 3.6), squeeze=False)
    for ax, r in zip(axes[0], results, strict=True):
        ref = r["shell_reference"]
        b = r["n4b5"]
        ax.loglog([b["time_s"]], [abs(b["error"])], "kv", label="N4B5")
        for v, mk in zip(VARIANTS, ("o-", "s-", "D-", "P-"), strict=True):
            rows = r["bar_hinge"][v]
            ax.loglog(
                [x["time_s"] for x in rows],
                [abs(x["stiffness"] / ref - 1.0) for x in rows],
                mk,
                label=f"N5B8 {v}, m = 1…{rows[-1]['m']}",
            )
        ax.loglog(
            [x["time_s"] for x in r["shell"]],
            [max(abs(x["stiffness"] / ref - 1.0), 1e-4) for x in r["shell"]],
            "k^--",
            label=f"shell (graded {SHELL_GRADING:g}), "
            f"r = {r['shell'][0]['r']}…{r['shell'][-1]['r']}",
        )
        if np.isfinite(r["shell_uncertainty"]):
            ax.axhline(r["shell_uncertainty"], color="grey", lw=0.8, ls=":")
        ax.set_title(f"{r['family']} {r['state']:g}")
        ax.set_xlabel("wall time (s)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("|stiffness / shell reference − 1|")
    axes[0][-1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def section(results: list[dict]) -> str:
    ck = results[0]["bar_hinge"]["plate"][0]["crease_k"]
    return "\n".join(
        [
            START,
            "",
            "Written by `python studies/roofs/shell_check.py --publish`. Stiffness = total load"
            " squared over the compliance, linear, under 1 kN/m² (no self-weight). Creases in both"
            f" models have the fold stiffness {ck:.1f} N·m/rad per metre of crease. Error ="
            " bar-and-hinge stiffness / shell reference − 1 for m × m sub-panels per panel, with"
            " the study's bending calibration (plate, the default), the kirchhoff one, and the"
            " two plate-consistent rules of `barhinge.model.plate_hinges`: *consistent* (every"
            " hinge inside or between cells chosen so that each cell stores the plate energy"
            " of every uniform curvature up to a Gaussian-curvature term) and *coupled* (the"
            " angles of each cell also coupled, so that the energy is the plate's with the"
            f" sheet's ν; its models have the `{membrane(MAIN_RULE)}` membrane, the others"
            " bars calibrated by `fit`); creases in series with the plate strip beside"
            " them; rate = slope of log |error| against log m over m ≥ 2; shell rate ="
            " observed order in the element size of the shell's own refinement (r: 2^r"
            " elements per facet edge, graded towards the facets' corners with grading"
            f" {SHELL_GRADING:g}: the elements next to a pattern vertex are h^2 long;"
            f" r = {SHELL_LEVELS[0]} … {SHELL_LEVELS[-1]}, then further until the"
            f" Richardson correction is below {100 * roofs.REFINE_TOL:g} % or the next"
            f" level would exceed {SHELL_DOF_BUDGET:,} DOFs).",
            "",
            table(results),
            "",
            "The shell reference on uniform and on corner-graded facet meshes (the same"
            " elements and levels; Richardson over the three finest levels):",
            "",
            shell_mesh_table(results),
            "",
            f"Each roof refined with the {MAIN_RULE} rule until its stiffness changes by less"
            " than 2 % between levels, the model's own limit (Richardson) and the gap to the"
            " shell:",
            "",
            refinement_table(results),
            "",
            "![Error against the shell reference vs wall time](img/roofs_error_time.png)",
            "",
            "Error against the shell reference vs wall time (dotted: the shell reference's"
            " own uncertainty):",
            "",
            timing(results),
            "",
            "The subdivision rules on a flat square plate simply supported on its four"
            " edges (closed form: Navier's series): stiffness over the Navier value.",
            "",
            plate_table(PLATE),
            "",
            "The same plate free on two opposite edges (no closed form: the shell with the"
            " sheet's ν and with ν = 0, the beam strip):",
            "",
            free_edge_table(PLATE["free_edge"]),
            "",
            "The pleats roof with monolithic creases (fold springs 1e6 N·m/rad per m) in both"
            " models, with the sheet's ν and with ν = 0:",
            "",
            poisson_table(PLATE["poisson"]),
            "",
            prose(results, PLATE),
            "",
            END,
        ]
    )


if MAIN:
    text = section(RESULTS)
    print(text)
    if PUBLISH and not QUICK:
        doc = DOC.read_text()
        if START in doc:
            a, b = doc.index(START), doc.index(END) + len(END)
            doc = doc[:a] + text + doc[b:]
        else:
            head = "## Against a shell model\n\n" + text + "\n\n"
            at = doc.find("## Limitations and notes")
            doc = doc[:at] + head + doc[at:] if at >= 0 else doc.rstrip("\n") + "\n\n" + head
        DOC.write_text(doc)
        chart(RESULTS, DOC.parent / "img" / "roofs_error_time.png")
        print(f"wrote {DOC}")
