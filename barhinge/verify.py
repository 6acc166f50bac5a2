"""Reference cases: closed forms from the literature, recomputed with barhinge.

Each :class:`Case` names its source, computes one or more quantities with the library
(rigid kinematics, the bar-and-hinge solver, the analyses) and compares every quantity with
its published closed form. ``barhinge verify`` runs them and prints the table; the tests run
it too. A case must take a few seconds at most (the whole suite runs in CI).

Error measure: ``|computed - reference| / |reference|`` (the absolute error when the reference
is 0); a quantity passes when that error is at most its tolerance. Every tolerance carries a
comment saying where the remaining error comes from (round-off of an exact computation, a
solver tolerance, a discretisation, a finite stiffness ratio).

Adding a case: write a function returning ``{quantity: computed}`` and register a
:class:`Case` with one :class:`Quantity` per key in :data:`CASES`.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import time
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from barhinge import families
from barhinge.actuators import Actuators
from barhinge.analysis.curvature import angle_defect, gaussian_curvature
from barhinge.analysis.poisson import grid_pairs, periodic_poisson
from barhinge.analysis.stiffness import effective_stiffness
from barhinge.errors import ConfigError
from barhinge.families.miura import miura_layout
from barhinge.families.properties import maekawa_count
from barhinge.kinematics.dof import dof
from barhinge.kinematics.path import rigid_fold
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern
from barhinge.scene import Scene
from barhinge.solver.newton import solve

__all__ = ["CASES", "Case", "Check", "Quantity", "run", "select", "summary"]

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class Quantity:
    """One published value.

    Attributes
    ----------
    name : str
        Key in the dict returned by the case's ``compute``.
    reference : float
        The closed-form value.
    tolerance : float
        Largest accepted relative error (absolute when ``reference == 0``).
    why : str
        Why the tolerance is what it is.
    formula : str
        The closed form, as printed in the source.
    reference_from : callable () -> float, optional
        Computes the reference when the case runs (an independent computation too slow to
        run at import); ``reference`` is then ignored.
    """

    name: str
    reference: float
    tolerance: float
    why: str
    formula: str = ""
    reference_from: Callable[[], float] | None = None


@dataclasses.dataclass(frozen=True)
class Case:
    """A reference case: a computation with barhinge and the published values it must match.

    Attributes
    ----------
    name : str
    citation : str
        Author(s), year, journal, equation.
    description : str
        What is computed and how (model, control, parameters).
    compute : callable () -> dict[str, float]
    quantities : tuple of Quantity
    quick : bool
        Part of ``barhinge verify --quick``.
    """

    name: str
    citation: str
    description: str
    compute: Callable[[], dict[str, float]]
    quantities: tuple[Quantity, ...]
    quick: bool = True


@dataclasses.dataclass(frozen=True)
class Check:
    """One row of the verification table."""

    case: str
    quantity: str
    citation: str
    reference: float
    computed: float
    error: float
    tolerance: float
    time_s: float
    passed: bool
    why: str = ""
    message: str = ""

    def as_dict(self) -> dict[str, object]:
        return dataclasses.asdict(self)


def _error(computed: float, reference: float) -> float:
    if not math.isfinite(computed):
        return math.inf
    if reference == 0.0:
        return abs(computed)
    return abs(computed - reference) / abs(reference)


def run_case(case: Case) -> list[Check]:
    """Run one case; an exception fails every quantity of the case with its message."""
    t0 = time.perf_counter()
    message = ""
    try:
        values = case.compute()
    except Exception as exc:  # noqa: BLE001 - a failing case is a result, not a crash
        values = {}
        message = f"{type(exc).__name__}: {exc}"
        log.warning("verify case %s raised %s", case.name, message)
    dt = time.perf_counter() - t0
    rows = []
    for q in case.quantities:
        c = float(values.get(q.name, math.nan))
        ref = q.reference
        if q.reference_from is not None:
            try:
                ref = q.reference_from()
            except Exception as exc:  # noqa: BLE001 - reported as a failing quantity
                ref, message = math.nan, message or f"reference: {type(exc).__name__}: {exc}"
        err = _error(c, ref)
        msg = message or ("" if q.name in values else f"case returned no {q.name!r}")
        rows.append(
            Check(
                case=case.name,
                quantity=q.name,
                citation=case.citation,
                reference=float(ref),
                computed=c,
                error=err,
                tolerance=q.tolerance,
                time_s=dt,
                passed=bool(err <= q.tolerance) and not msg,
                why=q.why,
                message=msg,
            )
        )
    return rows


def select(
    cases: Iterable[Case] | None = None,
    *,
    names: Sequence[str] | None = None,
    quick: bool = False,
) -> list[Case]:
    """The cases :func:`run` runs: ``names`` (in that order; unknown names raise
    ConfigError), else the ``quick`` ones if asked, else all of ``cases`` (default
    :data:`CASES`)."""
    pool = list(CASES.values()) if cases is None else list(cases)
    if names:
        known = {c.name: c for c in pool}
        bad = [n for n in names if n not in known]
        if bad:
            raise ConfigError(
                f"unknown verify case {bad[0]!r}; expected one of {', '.join(sorted(known))}"
            )
        return [known[n] for n in names]
    if quick:
        return [c for c in pool if c.quick]
    return pool


def run(
    cases: Iterable[Case] | None = None,
    *,
    names: Sequence[str] | None = None,
    quick: bool = False,
    on_case: Callable[[Case, list[Check]], None] | None = None,
) -> list[Check]:
    """Run reference cases and return one :class:`Check` per quantity.

    Parameters
    ----------
    cases : iterable of Case, optional
        Default: every registered case (:data:`CASES`).
    names : sequence of str, optional
        Only these cases (by name); unknown names raise ConfigError.
    quick : bool
        Only the cases marked ``quick``.
    on_case : callable, optional
        Called after each case with its rows (progress display).
    """
    out: list[Check] = []
    for case in select(cases, names=names, quick=quick):
        rows = run_case(case)
        out.extend(rows)
        if on_case is not None:
            on_case(case, rows)
    return out


def summary(checks: Sequence[Check]) -> dict[str, object]:
    """Counts for a list of checks (JSON-serialisable)."""
    return {
        "n_checks": len(checks),
        "n_cases": len({c.case for c in checks}),
        "n_passed": sum(c.passed for c in checks),
        "n_failed": sum(not c.passed for c in checks),
        "passed": all(c.passed for c in checks),
        "time_s": sum({c.case: c.time_s for c in checks}.values()),
    }


# =============================================================================== helpers
def _material():

    return Material(E=1.0e6, nu=0.3, t=0.01)


def _sg_closed_forms(a: float, b: float, gamma_deg: float, theta_deg: float) -> dict[str, float]:
    """Schenk & Guest (2013) PNAS 110(9):3276, Eq. 1-2, written out here (independently of
    ``barhinge.families.miura_geometry``): cell height H, half width S, half length L,
    zig-zag offset V, straight-crease fold angle and in-plane Poisson's ratio nu_SL."""
    g, th = math.radians(gamma_deg), math.radians(theta_deg)
    xi = math.sqrt(1.0 + math.cos(th) ** 2 * math.tan(g) ** 2)
    return {
        "H": a * math.sin(th) * math.sin(g),
        "S": b * math.cos(th) * math.tan(g) / xi,
        "L": a * math.sqrt(1.0 - math.sin(th) ** 2 * math.sin(g) ** 2),
        "V": b / xi,
        "rho_straight_deg": math.degrees(2.0 * math.atan(math.cos(g) * math.tan(th))),
        "nu_SL": -(math.cos(th) ** 2) * math.tan(g) ** 2,
    }


def _miura_dims(X: np.ndarray, ni: int) -> dict[str, float]:
    """Frame-independent H, S, L, V of the Miura cell at the corner of a grid-numbered sheet
    (vertex (i, j) has id j * ni + i; see barhinge.families.miura)."""

    def v(i: int, j: int) -> np.ndarray:
        return X[j * ni + i]

    eL = v(2, 0) - v(0, 0)
    eS = v(0, 2) - v(0, 0)
    L = float(np.linalg.norm(eL)) / 2
    S = float(np.linalg.norm(eS)) / 2
    eL, eS = eL / (2 * L), eS / (2 * S)
    n = np.cross(eL, eS)
    n /= np.linalg.norm(n)
    return {
        "H": abs(float((v(1, 0) - v(0, 0)) @ n)),
        "S": S,
        "L": L,
        "V": abs(float((v(0, 1) - v(0, 0)) @ eL)),
    }


# =============================================================================== cases
# Miura-ori cell used by the Miura cases: a = 1, b = 1.5, gamma = 60 deg, theta = 50 deg.
_MA, _MB, _MG, _MT = 1.0, 1.5, 60.0, 50.0
_SG = _sg_closed_forms(_MA, _MB, _MG, _MT)
_SG_CITE = "Schenk & Guest 2013, PNAS 110(9):3276, Eq. 1-2"


def _miura_rigid() -> dict[str, float]:
    """Rigid path of one flat Miura cell, driven by its first interior zig-zag crease to
    -2 theta (the zig-zag fold angle of S&G's theta), then theta +- 0.05 deg for nu_SL."""

    cp = families.miura(1, 1, a=_MA, b=_MB, alpha=_MG)
    lay = miura_layout(1, 1)
    ez = int(lay.interior_zigzag_edges[0])
    es = int(lay.interior_straight_edges[0])
    sign = math.copysign(1.0, float(cp.fold_angles[ez]))
    d = 0.05
    tab = np.r_[np.linspace(10.0, 2 * (_MT - d), 5), 2 * _MT, 2 * (_MT + d)]
    path = rigid_fold(cp, Actuators(edges=[ez], table_deg=sign * tab[:, None]), steps=len(tab))
    out = _miura_dims(path.X[-2], lay.ni)
    out["rho_straight_deg"] = abs(float(path.fold_angles_deg[-2, es]))
    lo, hi = _miura_dims(path.X[-3], lay.ni), _miura_dims(path.X[-1], lay.ni)
    # central difference of ln L against ln S (error O(d^2) ~ 1e-6)
    out["nu_SL"] = -math.log(hi["L"] / lo["L"]) / math.log(hi["S"] / lo["S"])
    # the same through the library's analysis (pairs one period apart, np.gradient)

    pairs_L, pairs_S = grid_pairs(cp)
    out["nu_SL_analysis"] = float(periodic_poisson(path, pairs_S, pairs_L).nu[-2])
    return out


_EXACT = "rigid path closes the loop equations to 1e-13: round-off only"

_miura_rigid_case = Case(
    name="miura_rigid",
    citation=_SG_CITE,
    description=(
        "Rigid folding path (rigid_fold) of a flat 1x1 Miura cell (a=1, b=1.5, "
        "gamma=60 deg) to theta=50 deg; cell dimensions measured frame-free from the vertices"
    ),
    compute=_miura_rigid,
    quantities=(
        Quantity("H", _SG["H"], 1e-9, _EXACT, "H = a sin(theta) sin(gamma)"),
        Quantity(
            "S", _SG["S"], 1e-9, _EXACT,
            "S = b cos(theta) tan(gamma) / sqrt(1 + cos^2(theta) tan^2(gamma))",
        ),
        Quantity("L", _SG["L"], 1e-9, _EXACT, "L = a sqrt(1 - sin^2(theta) sin^2(gamma))"),
        Quantity("V", _SG["V"], 1e-9, _EXACT, "V = b / sqrt(1 + cos^2(theta) tan^2(gamma))"),
        Quantity(
            "rho_straight_deg", _SG["rho_straight_deg"], 1e-9, _EXACT,
            "tan(rho_s/2) = cos(gamma) tan(theta)",
        ),
        Quantity(
            "nu_SL", _SG["nu_SL"], 1e-5,
            "central difference over theta +- 0.05 deg: truncation O(d^2) ~ 2e-6",
            "nu_SL = -cos^2(theta) tan^2(gamma)",
        ),
        Quantity(
            "nu_SL_analysis", _SG["nu_SL"], 1e-5,
            "barhinge.analysis.poisson.periodic_poisson, central difference: O(d^2) ~ 2e-6",
            "nu_SL = -cos^2(theta) tan^2(gamma)",
        ),
    ),
)  # fmt: skip


def _miura_barhinge() -> dict[str, float]:
    """Bar-and-hinge (N5B8) model of the same cell, bars and bending stiffened 1e4 x relative
    to the folds, folded by fold-angle control of the same zig-zag crease."""

    cp = families.miura(1, 1, a=_MA, b=_MB, alpha=_MG)
    lay = miura_layout(1, 1)
    ez = int(lay.interior_zigzag_edges[0])
    sign = math.copysign(1.0, float(cp.fold_angles[ez]))
    model = BarHingeModel.from_pattern(cp, scheme="N5B8", material=_material(), stiffness_ratio=1e4)
    scene = Scene(model, actuators=Actuators(edges=[ez], targets_deg=[sign * 2 * _MT]), steps=8)
    path = solve(scene)
    return _miura_dims(path.X[-1], lay.ni)


_RL = "finite stiffness ratio 1e4: panels strain by O(k_fold/k_panel); measured 2.9e-4"
_miura_bh_case = Case(
    name="miura_barhinge_rigid_limit",
    citation=_SG_CITE,
    description=(
        "solve, fold-angle control, N5B8 Miura cell with stiffness_ratio=1e3 (rigid-panel "
        "limit of Filipov et al. 2017), folded to theta=50 deg"
    ),
    compute=_miura_barhinge,
    quantities=(
        Quantity("H", _SG["H"], 2e-3, _RL, "H = a sin(theta) sin(gamma)"),
        Quantity("S", _SG["S"], 2e-3, _RL, "S = b cos(theta) tan(gamma) / xi"),
        Quantity("L", _SG["L"], 2e-3, _RL, "L = a sqrt(1 - sin^2(theta) sin^2(gamma))"),
    ),
    quick=False,
)

# 3 x 3 Miura sheet (a = b = 1, gamma = 60 deg) folded from flat to half its pattern target:
# the zig-zag creases' target is 2 x 60 deg (families.miura's default theta), half of it
# is S&G's theta = 30 deg.
_FS_N, _FS_THETA, _FS_RATIOS, _FS_STEPS = 3, 30.0, (1e5, 1e6), 6
_FS_SG = _sg_closed_forms(1.0, 1.0, _MG, _FS_THETA)


def _flat_start_gaps(fold_deg: np.ndarray, want: np.ndarray, lay) -> dict[str, np.ndarray]:
    """Fold angles (n_edges,) degrees, signed by the M/V assignment ``want`` (+1 V, -1 M),
    of the interior zig-zag and straight creases, and their gaps to the rigid closed forms."""
    f = want * fold_deg
    zz = f[lay.interior_zigzag_edges]
    st = f[lay.interior_straight_edges]
    return {
        "zigzag": zz,
        "straight": st,
        "gap": np.abs(np.r_[zz - 2 * _FS_THETA, st - _FS_SG["rho_straight_deg"]]),
    }


def _multi_cell_flat_start(flat_start: str = "rigid") -> dict[str, float]:
    """A 3 x 3 N5B8 Miura sheet started exactly flat, driven by one interior zig-zag crease to
    half its pattern target in 6 steps, at stiffness ratios 1e5 and 1e6: creases against the
    M/V assignment at any state of either run; at 1e6 the zig-zag and straight crease
    farthest from the rigid closed forms; the observed order of the gap between the two
    ratios. ``flat_start`` is the solver option (the tests show "tangent" fails the case)."""

    cp = families.miura(_FS_N, _FS_N, alpha=_MG)
    lay = families.miura_layout(_FS_N, _FS_N)
    ez = int(lay.interior_zigzag_edges[0])
    target = 0.5 * float(cp.fold_angles[ez])
    if abs(abs(target) - 2 * _FS_THETA) > 1e-9:
        raise ValueError(f"half the pattern target is {target} deg, expected +-{2 * _FS_THETA}")
    asg = np.asarray(cp.assignment)
    want = np.where(asg == "V", 1.0, np.where(asg == "M", -1.0, 0.0))
    against: set[int] = set()
    gaps = {}
    for ratio in _FS_RATIOS:
        model = BarHingeModel.from_pattern(
            cp, scheme="N5B8", material=_material(), stiffness_ratio=ratio
        )
        scene = Scene(
            model,
            actuators=Actuators(edges=[ez], targets_deg=[target]),
            steps=_FS_STEPS,
            options={"flat_start": flat_start},
        )
        path = solve(scene)
        against.update(np.flatnonzero((want * path.fold_angles_deg < -1e-6).any(axis=0)))
        gaps[ratio] = _flat_start_gaps(path.fold_angles_deg[-1], want, lay)
    g = gaps[_FS_RATIOS[-1]]
    zz, st = g["zigzag"], g["straight"]
    return {
        "creases_against_assignment": float(len(against)),
        "rho_zigzag_deg": float(zz[np.argmax(np.abs(zz - 2 * _FS_THETA))]),
        "rho_straight_deg": float(st[np.argmax(np.abs(st - _FS_SG["rho_straight_deg"]))]),
        "gap_order": math.log10(
            gaps[_FS_RATIOS[0]]["gap"].max() / gaps[_FS_RATIOS[1]]["gap"].max()
        ),
    }


_FS_GAP = (
    "stiffness ratio 1e6: bars and panels strain by O(1/ratio) (order checked by gap_order); "
    "measured {:.1e} ({:.3f} deg); tolerance ~6x"
)
_flat_start_case = Case(
    name="multi_cell_flat_start",
    citation=(
        f"{_SG_CITE} (rigid Miura: one folding mode with the M/V assignment of the sheet, "
        "fold angles of every cell from theta); rigid-panel limit of Filipov, Liu, Tachi, "
        "Schenk & Paulino 2017, IJSS 124:26"
    ),
    description=(
        "solve from the exact flat state, fold-angle control of one interior zig-zag crease "
        "to half its pattern target (theta = 30 deg) in 6 steps; 3x3 Miura (gamma = 60 deg), "
        "N5B8, Material(E=1e6, nu=0.3, t=0.01), stiffness ratios 1e5 and 1e6"
    ),
    compute=_multi_cell_flat_start,
    quantities=(
        Quantity(
            "creases_against_assignment", 0.0, 0.0,
            "integer count (fold angle against its M or V by > 1e-6 deg at any state of "
            "either run): exact",
            "sign(rho) = sign of the M/V assignment on all 60 creases",
        ),
        Quantity(
            "rho_zigzag_deg", 2 * _FS_THETA, 2e-3, _FS_GAP.format(3.2e-4, 0.019),
            "rho_z = 2 theta (the zig-zag crease farthest from it)",
        ),
        Quantity(
            "rho_straight_deg", _FS_SG["rho_straight_deg"], 2e-3, _FS_GAP.format(3.8e-4, 0.012),
            "tan(rho_s/2) = cos(gamma) tan(theta) (the straight crease farthest from it)",
        ),
        Quantity(
            "gap_order", 1.0, 0.15,
            "rigid-limit gap ~ 1/ratio; measured 0.999",
            "log10(gap(1e5) / gap(1e6)) = 1, gap = max |rho - rho_SG| over all creases",
        ),
    ),
    quick=False,
)  # fmt: skip

# generic flat-foldable degree-4 vertex: sector angles alpha, beta, pi - alpha, pi - beta
_D4A, _D4B = 70.0, 50.0


def degree4_pattern(fold_angles=None):
    """A flat-foldable degree-4 vertex, sector angles 70, 50, 110, 130 deg; creases 0..3 at
    directions 0, 70, 120, 230 deg, boundary edges 4..7. Assignment M V M M (first branch);
    with ``fold_angles`` (target angles of creases 0..3, choosing a branch) M M V M."""

    a, b = math.radians(_D4A), math.radians(_D4B)
    dirs = [0.0, a, a + b, math.pi + b]
    V = [[0.0, 0.0]] + [[math.cos(d), math.sin(d)] for d in dirs]
    E = [[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]]
    asg = list("MVMM" if fold_angles is None else "MMVM") + list("BBBB")
    F = None if fold_angles is None else list(fold_angles) + [0.0] * 4
    return CreasePattern(
        vertices=V, edges=E, assignment=asg, fold_angles=F,
        faces=[[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
    )  # fmt: skip


_RHO1 = -40.0  # degrees, crease 1 (direction 0, between sectors pi - beta and alpha)


def _degree4() -> dict[str, float]:
    """Rigid path of a single degree-4 vertex driven by crease 1 to -40 deg, once on each of
    its two folding modes (mode 2 chosen by target fold angles: explicit branch choice)."""

    out = {}
    p1 = rigid_fold(degree4_pattern(), [0], targets_deg=[_RHO1], steps=6)
    r = np.radians(p1.fold_angles_deg[-1, :4])
    out["mode1_multiplier"] = math.tan(r[1] / 2) / math.tan(r[0] / 2)
    q = _mult2()
    r2 = math.degrees(2 * math.atan(q * math.tan(math.radians(-20.0) / 2)))
    cp2 = degree4_pattern([-20.0, r2, 20.0, r2])  # branch direction, not the result
    p2 = rigid_fold(cp2, [0], targets_deg=[_RHO1], steps=6)
    r = np.radians(p2.fold_angles_deg[-1, :4])
    out["mode2_multiplier"] = math.tan(r[1] / 2) / math.tan(r[0] / 2)
    return out


def _mult1() -> float:
    a, b = math.radians(_D4A), math.radians(_D4B)
    return -math.cos((a + b) / 2) / math.cos((a - b) / 2)


def _mult2() -> float:
    a, b = math.radians(_D4A), math.radians(_D4B)
    return math.sin((a + b) / 2) / math.sin((a - b) / 2)


_degree4_case = Case(
    name="degree4_vertex",
    citation=(
        "Huffman 1976 IEEE Trans. Computers C-25(10); Evans, Lang, Magleby & Howell 2015 "
        "R. Soc. Open Sci. 2:150067; Tachi & Hull 2017 J. Mech. Robot. 9(2):021008"
    ),
    description=(
        "Flat-foldable degree-4 vertex, sectors 70/50/110/130 deg, rigid path to rho1=-40 deg; "
        "fold-angle multiplier tan(rho2/2)/tan(rho1/2) on both branches"
    ),
    compute=_degree4,
    quantities=(
        Quantity(
            "mode1_multiplier", _mult1(), 1e-9, _EXACT,
            "tan(rho2/2) = -cos((a+b)/2)/cos((a-b)/2) tan(rho1/2)  (rho1 = rho3)",
        ),
        Quantity(
            "mode2_multiplier", _mult2(), 1e-9, _EXACT,
            "tan(rho2/2) = sin((a+b)/2)/sin((a-b)/2) tan(rho1/2)  (rho1 = -rho3)",
        ),
    ),
)  # fmt: skip


def _maekawa_kawasaki() -> dict[str, float]:
    """|#M - #V| and the alternate sector-angle sum at every interior vertex of flat
    Miura (gamma = 60 deg) and Yoshimura sheets; the worst vertex is reported."""

    m, kw = [], []
    for cp in (families.miura(2, 2, alpha=_MG), families.yoshimura(4, 2)):
        m.extend(np.abs(maekawa_count(cp)[cp.interior_vertices]).tolist())
        for v in cp.interior_vertices:
            sec = np.asarray(cp.sector_angles[v])
            kw.append(float(sec[0::2].sum()))
    m_arr, kw_arr = np.asarray(m, float), np.asarray(kw)
    return {
        "max_abs_M_minus_V": float(m_arr.max()),
        "min_abs_M_minus_V": float(m_arr.min()),
        "alternate_sector_sum": float(kw_arr[np.argmax(np.abs(kw_arr - math.pi))]),
    }


_maekawa_case = Case(
    name="maekawa_kawasaki",
    citation=(
        "Maekawa (Justin 1986); Kawasaki 1989; Demaine & O'Rourke 2007, Geometric Folding "
        "Algorithms, Thm 12.2.2 and 12.2.4"
    ),
    description="Vertex conditions of the flat Miura (2x2) and Yoshimura (4x2) generators",
    compute=_maekawa_kawasaki,
    quantities=(
        Quantity("max_abs_M_minus_V", 2.0, 0.0, "integer count: exact", "|M - V| = 2"),
        Quantity("min_abs_M_minus_V", 2.0, 0.0, "integer count: exact", "|M - V| = 2"),
        Quantity(
            "alternate_sector_sum", math.pi, 1e-12, "sum of angles from coordinates: round-off",
            "a1 + a3 + ... = pi",
        ),
    ),
)  # fmt: skip


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    p = (1 + 5**0.5) / 2
    X = np.array(
        [[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
         [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], float,
    )  # fmt: skip
    from scipy.spatial import ConvexHull

    return X, ConvexHull(X).simplices


def _curvature() -> dict[str, float]:
    """Angle defects of a closed polyhedron; global-form curvature of sphere and saddle
    samples (gaussian_curvature, local quadratic fits)."""

    X, T = _icosahedron()
    X = X * (1.0 + 0.05 * np.sin(np.arange(len(X))))[:, None]  # not regular: any polyhedron
    out = {"descartes_sum": float(np.nansum(angle_defect(X, T)))}
    R = 2.0
    g = np.linspace(-0.4, 0.4, 9)
    x, y = (a.ravel() for a in np.meshgrid(g, g))
    centre = int(np.argmin(x * x + y * y))
    sphere = np.column_stack([x, y, R - np.sqrt(R * R - x * x - y * y)])
    out["K_sphere"] = float(gaussian_curvature(sphere).K[centre])
    saddle = np.column_stack([x, y, (x * x - y * y) / (2 * R)])
    out["K_saddle"] = float(gaussian_curvature(saddle).K[centre])
    return out


_curv_tol = "local quadratic fit over radius ~0.25 R of a sphere: O((r/R)^2) bias"
_curvature_case = Case(
    name="curvature",
    citation="Descartes (angle defect theorem); Gauss 1827 (K = 1/R^2 of a sphere, -1/R^2 "
    "at the saddle z=(x^2-y^2)/2R); Meyer et al. 2003",
    description=(
        "Angle-defect sum of a perturbed icosahedron; K at the centre of 9x9 samples of a "
        "sphere (R=2) and a saddle"
    ),
    compute=_curvature,
    quantities=(
        Quantity("descartes_sum", 4 * math.pi, 1e-12, "exact theorem: round-off", "sum = 4 pi"),
        Quantity("K_sphere", 0.25, 2e-2, _curv_tol, "K = 1/R^2"),
        Quantity("K_saddle", -0.25, 2e-2, _curv_tol, "K = -1/R^2"),
    ),
)


def _dof() -> dict[str, float]:

    cp = families.miura(3, 3, alpha=_MG)
    rep = dof(cp)
    fold = rep.folded if rep.folded is not None else rep
    n_e = int(np.isin(cp.assignment, ["M", "V"]).sum())
    n_v = len(cp.interior_vertices)
    return {
        "counted_dof": float(rep.counted_dof),
        "counted_dof_formula_check": float(n_e - 3 * n_v),
        "dof_folded": float(fold.global_dof),
    }


_dof_case = Case(
    name="dof_miura",
    citation="Tachi 2010, 'Geometric considerations for the design of rigid origami "
    "structures', IASS (DOF = E_in - 3 V_in); Schenk & Guest 2013 (Miura: one DOF)",
    description="dof of a 3x3 Miura sheet: counted DOF and the rank DOF at a folded state",
    compute=_dof,
    quantities=(
        # 3x3 Miura: E_in = 5*6 + 5*6 = 60... counted by hand: rows 5 x 6 + columns 5 x 6
        Quantity(
            "counted_dof", 60 - 3 * 25, 0.0, "integer count: exact",
            "E_in - 3 V_in with E_in = 2(2nx-1)(2ny) = 60, V_in = (2nx-1)(2ny-1) = 25",
        ),
        Quantity("dof_folded", 1.0, 0.0, "rank of the loop-closure Jacobian: exact", "1"),
    ),
)  # fmt: skip


_K_FOLD = 2.0  # moment per radian per unit crease length
_RHO_ACT = 90.0


def _fold_moment() -> dict[str, float]:
    """Two square panels joined by one crease of length 1, folded to 90 deg by fold-angle
    control: the actuator moment equals the hinge's linear law."""

    V = [[-1, 0], [0, 0], [1, 0], [1, 1], [0, 1], [-1, 1]]
    E = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [1, 4]]
    cp = CreasePattern(
        vertices=V, edges=E, assignment=list("BBBBBBV"), faces=[[0, 1, 4, 5], [1, 2, 3, 4]]
    )
    model = BarHingeModel.from_pattern(
        cp, scheme="N4B5", material=_material(), fold_stiffness=_K_FOLD
    )
    path = solve(Scene(model, actuators=Actuators(edges=[6], targets_deg=[_RHO_ACT]), steps=4))
    return {"actuator_moment": float(path.actuator_moments[-1, 0])}


_fold_case = Case(
    name="fold_actuator_moment",
    citation="Liu & Paulino 2017, Proc. R. Soc. A 473:20170348 (linear hinge "
    "M = k L (rho - rho0)); Filipov et al. 2017 IJSS 124:26",
    description="Two 1x1 panels, one crease (L=1, k=2), solve fold-angle control to 90 deg",
    compute=_fold_moment,
    quantities=(
        Quantity(
            "actuator_moment", _K_FOLD * 1.0 * math.radians(_RHO_ACT), 1e-6,
            "panels unstressed by a single fold; Newton tolerance 1e-8",
            "M = k L (rho - rho0)",
        ),
    ),
)  # fmt: skip


def _hinge_cantilever() -> dict[str, float]:
    """The two-panel model of ``fold_actuator_moment``: left panel clamped, a line load at
    the free edge of the right panel (distance 1 from the crease); linear effective
    stiffness (barhinge.analysis.stiffness.effective_stiffness) of the free edge. The panel
    also bends along its diagonal, a compliance proportional to 1/ratio (ratio = panel / fold
    stiffness): computed at ratios 1e4 and 1e5 and extrapolated to the rigid panel."""

    V = [[-1, 0], [0, 0], [1, 0], [1, 1], [0, 1], [-1, 1]]
    E = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [1, 4]]
    cp = CreasePattern(
        vertices=V, edges=E, assignment=list("BBBBBBV"), faces=[[0, 1, 4, 5], [1, 2, 3, 4]]
    )
    k = []
    for ratio in (1e4, 1e5):
        model = BarHingeModel.from_pattern(
            cp, scheme="N4B5", material=_material(), fold_stiffness=_K_FOLD, stiffness_ratio=ratio
        )
        fixed = np.zeros((model.n_nodes, 3), bool)
        fixed[[0, 1, 4, 5]] = True
        P = np.zeros((model.n_nodes, 3))
        P[[2, 3], 2] = 0.5
        k.append(effective_stiffness(model, P, fixed, at=np.array([2, 3])).stiffness)
    # compliance c(r) = c0 + c1 / r: Richardson extrapolation to r -> infinity
    c0 = (10.0 / k[1] - 1.0 / k[0]) / 9.0
    return {"edge_stiffness": 1.0 / c0, "edge_stiffness_ratio_1e5": k[1]}


_cantilever_case = Case(
    name="hinge_cantilever",
    citation="Howell 2001, Compliant Mechanisms (pseudo-rigid-body model: rigid link on a "
    "torsional spring, M = K theta); Filipov et al. 2017 (fold hinge K = k L)",
    description=(
        "Two 1x1 N4B5 panels, one crease (L=1, k=2), left panel clamped, unit load at the "
        "free edge; linear stiffness of the edge, extrapolated to rigid panels"
    ),
    compute=_hinge_cantilever,
    quantities=(
        Quantity(
            "edge_stiffness", _K_FOLD * 1.0 / 1.0**2, 1e-6,
            "extrapolated in 1/ratio from 1e4 and 1e5: O(1/ratio^2) remainder; measured 2e-8",
            "K_edge = k L_crease / L_panel^2",
        ),
        Quantity(
            "edge_stiffness_ratio_1e5", _K_FOLD, 5e-5,
            "panel diagonal bending at stiffness ratio 1e5: 1/ratio; measured 9.5e-6",
            "K_edge = k L_crease / L_panel^2",
        ),
    ),
)  # fmt: skip

_SW, _SH, _SN = 1.0, 1.2, 4  # strip of 4 panels 1 x 1.2 (x by y)


def _membrane_strip() -> dict[str, float]:
    """Strip of 4 rectangular N5B8 panels (F17 bars), left edge held in x (one node also
    in y), all nodes held in z, pulled at the right edge by a tiny load; axial stiffness."""

    n = _SN
    V = [[i * _SW, j * _SH] for j in (0, 1) for i in range(n + 1)]
    faces = [[i, i + 1, n + 2 + i, n + 1 + i] for i in range(n)]
    edges = [[i, i + 1] for i in range(n)] + [[n + 1 + i, n + 2 + i] for i in range(n)]
    edges += [[i, n + 1 + i] for i in range(n + 1)]
    asg = ["B"] * (2 * n) + ["B"] + ["F"] * (n - 1) + ["B"]
    cp = CreasePattern(vertices=V, edges=edges, assignment=asg, faces=faces)
    mat = _material()
    model = BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat, bar_calibration="filipov")
    nn = model.n_nodes
    S = np.zeros((nn, 3), bool)
    S[:, 2] = True
    left, right = [0, n + 1], [n, 2 * n + 1]
    S[left, 0] = True
    S[0, 1] = True
    P = np.zeros((nn, 3))
    F = 1e-6 * mat.E * mat.t * _SH  # strain 1e-6: geometric nonlinearity ~1e-6
    P[right, 0] = F / 2
    path = solve(Scene(model, supports=S, loads=P, control="load", steps=1))
    u = float(path.X[-1, right, 0].mean() - model.X0[right, 0].mean())
    return {"axial_stiffness": F / u}


_strip_case = Case(
    name="membrane_strip",
    citation="Filipov et al. 2017 IJSS 124:26 (N5B8 bar areas, exact in extension); "
    "uniaxial plane stress k = E t W / L",
    description="4-panel strip 4 x 1.2, N5B8 with F17 bar areas, end load at strain 1e-6",
    compute=_membrane_strip,
    quantities=(
        Quantity(
            "axial_stiffness", 1.0e6 * 0.01 * _SH / (_SN * _SW), 1e-4,
            "Green-strain nonlinearity at strain 1e-6 and Newton tolerance",
            "k = E t W / L",
        ),
    ),
)  # fmt: skip


def _filipov_areas() -> dict[str, float]:

    W, H = 1.0, 1.2
    cp = CreasePattern(
        vertices=[[0, 0], [W, 0], [W, H], [0, H]],
        edges=[[0, 1], [1, 2], [2, 3], [3, 0]],
        assignment=list("BBBB"),
        faces=[[0, 1, 2, 3]],
    )
    mat = _material()
    m = BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat, bar_calibration="filipov")
    A = np.asarray(m.bar_EA) / mat.E
    L = np.asarray(m.bar_L0)
    pick = lambda length: float(A[np.argmin(np.abs(L - length))])  # noqa: E731
    return {"A_W": pick(W), "A_H": pick(H), "A_X": pick(math.hypot(W, H) / 2)}


def _f17(W: float = 1.0, H: float = 1.2, t: float = 0.01, nu: float = 0.3) -> dict[str, float]:
    return {
        "A_W": t * (H**2 - nu * W**2) / (2 * H * (1 - nu**2)),
        "A_H": t * (W**2 - nu * H**2) / (2 * W * (1 - nu**2)),
        "A_X": nu * t * (W**2 + H**2) ** 1.5 / (2 * W * H * (1 - nu**2)),
    }


_F17 = _f17()
_LSQ = "areas from a bounded least-squares fit: solver tolerance"
_filipov_case = Case(
    name="filipov_bar_areas",
    citation="Filipov, Liu, Tachi, Schenk & Paulino 2017, IJSS 124:26-45 (N5B8 bar areas)",
    description="Bar areas of one 1 x 1.2 N5B8 panel (bar_calibration='filipov', nu=0.3)",
    compute=_filipov_areas,
    quantities=(
        Quantity("A_W", _F17["A_W"], 1e-8, _LSQ, "A_W = t (H^2 - nu W^2) / (2 H (1 - nu^2))"),
        Quantity("A_H", _F17["A_H"], 1e-8, _LSQ, "A_H = t (W^2 - nu H^2) / (2 W (1 - nu^2))"),
        Quantity("A_X", _F17["A_X"], 1e-8, _LSQ, "A_X = nu t (W^2 + H^2)^1.5 / (2 W H (1 - nu^2))"),
    ),
)

# von Mises two-bar truss: half span a, rise h, EA
_VMA, _VMH, _VMEA = 1.0, 0.3, 1000.0


def von_mises_model(a: float = _VMA, h: float = _VMH, EA: float = _VMEA, spring: float = 0.0):
    """Bar model of the von Mises truss (x-z plane): supports 0, 1 at (-+a, 0, 0), apex 2 at
    (0, 0, h). With ``spring > 0`` a node 3 at (0, 0, 2 h) hangs above the apex on a bar of
    axial stiffness ``spring`` (EA / length) for displacement control through the spring.

    Returns (model, supports (n, 3) bool, apex node id).
    """

    if spring <= 0:
        cp = CreasePattern(
            vertices=[[-a, 0, 0], [a, 0, 0], [0, 0, h]],
            edges=[[0, 1], [1, 2], [2, 0]],
            assignment=list("BBB"),
            faces=[[0, 1, 2]],
        )
        model = BarHingeModel.from_pattern(cp, scheme="N4B5", bar_EA=EA)
    else:
        cp = CreasePattern(
            vertices=[[-a, 0, 0], [a, 0, 0], [0, 0, h], [0, 0, 2 * h]],
            edges=[[0, 1], [1, 2], [2, 0], [2, 3], [3, 0]],
            assignment=list("BBFBB"),
            faces=[[0, 1, 2], [0, 2, 3]],
        )
        m0 = BarHingeModel.from_pattern(cp, scheme="N4B5", bar_EA=EA, fold_stiffness=0.0)
        bars = np.sort(np.asarray(m0.bars), axis=1).tolist()
        EAs = np.full(len(bars), EA)
        EAs[bars.index([2, 3])] = spring * h
        EAs[bars.index([0, 3])] = 1e-9 * EA  # a face needs it; carries nothing
        model = m0.with_(bar_EA=EAs)
    S = np.zeros((model.n_nodes, 3), bool)
    S[[0, 1]] = True
    S[2:, :2] = True
    return model, S, 2


def rigid_link_strut(
    n: int, ell: float = 1.0, b: float = 0.5, k: float = 2.0, rigid: float = 1e7
) -> tuple[BarHingeModel, np.ndarray, np.ndarray]:
    """A strip of ``n`` panels ``ell x b`` in a row along x, joined by ``n - 1`` transverse
    creases of rotational stiffness ``k``; panels (bars and bending) ``rigid``: a strut of
    rigid links, pinned at x = 0 (the line can rotate about y), on rollers along x at the
    other end.

    Returns (model, supports (n_nodes, 3) bool, load (n_nodes, 3): unit axial compression
    at the roller end).
    """
    xs = ell * np.arange(n + 1)
    V = np.vstack(
        [np.column_stack([xs, np.zeros(n + 1)]), np.column_stack([xs, np.full(n + 1, b)])]
    )
    top = n + 1  # vertex i + top lies above vertex i (y = b)
    edges = [(i, i + 1) for i in range(n)] + [(top + i, top + i + 1) for i in range(n)]
    edges += [(i, top + i) for i in range(n + 1)]
    asg = ["B"] * (2 * n) + ["B" if i in (0, n) else "V" for i in range(n + 1)]
    faces = [[i, i + 1, top + i + 1, top + i] for i in range(n)]
    cp = CreasePattern(V, edges, asg, faces=faces)
    m = BarHingeModel.from_pattern(
        cp, "N4B5", Material(E=1.0, nu=0.3, t=0.01), bar_EA=rigid, bend_k=rigid, fold_k=k
    )
    S = np.zeros((m.n_nodes, 3), bool)
    S[[0, top]] = True  # pinned end: the line x = 0 can rotate about y
    S[[n, top + n], 1:] = True  # roller end: free to move along x
    P = np.zeros((m.n_nodes, 3))
    P[[n, top + n], 0] = -0.5  # unit axial compression
    return m, S, P


def von_mises_limit_load(a: float = _VMA, h: float = _VMH, EA: float = _VMEA) -> float:
    """Limit load of the von Mises truss with Green-strain bars (exact for any rise):
    ``P_max = 2 EA h^3 / (3 sqrt(3) L0^3)``, ``L0 = sqrt(a^2 + h^2)``, at apex height
    ``h / sqrt(3)``."""
    return 2 * EA * h**3 / (3 * math.sqrt(3) * math.hypot(a, h) ** 3)


def _von_mises() -> dict[str, float]:
    """Arc length (MGDCM) through the snap-through of the von Mises truss; the first peak of
    the load factor refined by a parabola through the three states around it."""

    model, S, apex = von_mises_model()
    Pmax = von_mises_limit_load()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -1.5 * Pmax
    scene = Scene(
        model, supports=S, loads=P, control="arc_length", steps=20,
        options={"max_arc_steps": 200},
    )  # fmt: skip
    path = solve(scene)
    lam = path.load_factor
    k = int(np.argmax(np.diff(lam) < 0))
    z = path.X[:, apex, 2]
    c = np.polyfit(z[k - 1 : k + 2], lam[k - 1 : k + 2], 2)
    zs = -c[1] / (2 * c[0])
    return {"limit_load": float(np.polyval(c, zs)) * 1.5 * Pmax, "apex_height_at_limit": zs}


_vm_case = Case(
    name="von_mises_truss",
    citation="Krenk 2009, Non-linear Modeling and Analysis of Solids and Structures, ch. 1 "
    "(two-bar truss, Green strain); Leon, Paulino et al. 2011, Appl. Mech. Rev. 64:040803",
    description=(
        "Two Green-strain bars (half span 1, rise 0.3, EA=1000), arc-length control (MGDCM) "
        "to 1.5 x the limit load; peak from a parabola through 3 states"
    ),
    compute=_von_mises,
    quantities=(
        Quantity(
            "limit_load", von_mises_limit_load(), 1e-3,
            "peak between arc-length states, parabola fit: measured 1e-5",
            "P_max = 2 EA h^3 / (3 sqrt(3) L0^3)",
        ),
        Quantity(
            "apex_height_at_limit", _VMH / math.sqrt(3), 1e-2,
            "location of a flat maximum from a parabola: O(step)",
            "z = h / sqrt(3)",
        ),
    ),
    quick=False,
)  # fmt: skip


# ----------------------------------------------------------------- periodic unit cell
def _periodic_miura() -> dict[str, float]:
    """Periodic cell (barhinge.analysis.periodic) of the Miura cell of the Miura cases, from a
    2 x 2-cell N5B8 sheet: in-plane ratio with panels 1e6x stiffer than the folds (rigid-panel
    limit) and bending ratio with bars a further 1e6x stiffer than panel bending (isometric
    limit)."""
    from barhinge.analysis.periodic import periodic_cell

    g = _SG
    T = [[2 * g["L"], 0.0, 0.0], [0.0, 2 * g["S"], 0.0]]
    cp = families.miura(2, 2, a=_MA, b=_MB, alpha=_MG, fold=_MT)
    rigid = BarHingeModel.from_pattern(cp, "N5B8", material=_material(), stiffness_ratio=1e6)
    iso = BarHingeModel.from_pattern(cp, "N5B8", material=_material(), stiffness_ratio=1e3)
    iso = iso.with_(bar_EA=iso.bar_EA * 1e6)
    return {
        "nu_SL": periodic_cell(rigid, T).moduli()["nu21"],
        "bending_ratio": 1.0 / periodic_cell(iso, T).poisson_bending(),
    }


_periodic_case = Case(
    name="periodic_miura",
    citation=(
        f"{_SG_CITE}; Wei, Guo, Dudte, Liang & Mahadevan 2013, PRL 110:215501 (in-plane and "
        "bending Poisson's ratios equal and opposite)"
    ),
    description=(
        "Periodic unit cell (bh.periodic_cell, homogenised ABD) of the Miura cell a=1, b=1.5, "
        "gamma=60, theta=50 deg, from a 2x2 N5B8 sheet: nu_SL under force along S (panels "
        "1e6x the folds), -kappa_L/kappa_S under a moment about S (bars 1e6x panel bending)"
    ),
    compute=_periodic_miura,
    quantities=(
        Quantity(
            "nu_SL", _SG["nu_SL"], 1e-7,
            "stiffness ratio 1e6: error ~ 1/ratio (measured 7e-10)",
            "nu_SL = -cos^2(theta) tan^2(gamma)",
        ),
        Quantity(
            "bending_ratio", -_SG["nu_SL"], 1e-7,
            "bar / panel-bending ratio 1e6: error ~ 1/ratio (measured 2e-9)",
            "-kappa_L / kappa_S = +cos^2(theta) tan^2(gamma)",
        ),
    ),
)  # fmt: skip


# ---------------------------------------------------------- finite-sheet (end-to-end) ratio
def _end_to_end(n: int) -> float:
    """Finite-sheet Poisson's ratio of an n x n Miura sheet (gamma = 60 deg) on its rigid
    path (rigid_fold, one zig-zag crease driven) at theta0 +- 0.02 deg, where
    cos^2(theta0) tan^2(gamma) = 1, measured between the sheet's end edges."""
    from barhinge.analysis.poisson import end_to_end_poisson, grid_ends

    th0 = math.degrees(math.acos(1.0 / math.tan(math.radians(_MG))))
    cp = families.miura(n, n, alpha=_MG)
    lay = miura_layout(n, n)
    ez = int(lay.interior_zigzag_edges[0])
    sign = math.copysign(1.0, float(cp.fold_angles[ez]))
    d = 0.02
    tab = np.r_[np.linspace(10.0, 2 * (th0 - d), 5), 2 * th0, 2 * (th0 + d)]
    path = rigid_fold(cp, Actuators(edges=[ez], table_deg=sign * tab[:, None]), steps=len(tab))
    (left, right), (bottom, top) = grid_ends(cp)
    X = path.X[-3:]
    return float(end_to_end_poisson(X, (bottom, top), (left, right)).nu[1])


_e2e_case = Case(
    name="miura_end_to_end",
    citation=f"{_SG_CITE} (sheet of n cells: 2 n L + V by 2 n S)",
    description=(
        "Rigid path of flat 1x1 and 2x2 Miura sheets (gamma=60 deg) through the facet angle "
        "where the periodic ratio is -1; end_to_end_poisson (extents between end edges), "
        "driving S, measuring the extent along L"
    ),
    compute=lambda: {"nu_1_cell": _end_to_end(1), "nu_2_cells": _end_to_end(2)},
    quantities=(
        Quantity(
            "nu_1_cell", -1.0 / 3.0, 1e-5,
            "central difference over theta +- 0.02 deg: truncation ~1e-7",
            "nu = -(2n - 1)/(2n + 1) at cos^2(theta) tan^2(gamma) = 1 (n = 1)",
        ),
        Quantity(
            "nu_2_cells", -3.0 / 5.0, 1e-5,
            "central difference over theta +- 0.02 deg: truncation ~1e-7",
            "nu = -(2n - 1)/(2n + 1) at cos^2(theta) tan^2(gamma) = 1 (n = 2)",
        ),
    ),
)  # fmt: skip


# ------------------------------------------------------------ Kresling bistability
# One story of a hexagonal Kresling tower (a = 1, flat story height 1.6, shift 0.3 a): two
# stress-free states; bars EA = 1, fold hinges without stiffness (the truss model).
_KN, _KH, _KS = 6, 1.6, 0.3


def _kresling_truss_energy(H: float, x0: Sequence[float]) -> tuple[float, np.ndarray]:
    """Truss model of one Kresling story written out (Cai et al. 2015; Yasuda, Tachi, Lee &
    Yang 2017, Nat. Commun. 8:962), reduced by its n-fold symmetry: bottom polygon fixed
    (circumradius R), top polygon of radius r turned by phi at height H; n top sides, n
    slanted bars and n diagonals with the Green-strain bar energy EA L0 eps^2 / 2 (EA = 1).
    Minimised over (r, phi) by BFGS; returns (energy, (r, phi))."""
    from scipy.optimize import minimize

    n, a = _KN, 1.0
    R = a / (2 * math.sin(math.pi / n))
    b0 = math.hypot(_KS * a, _KH)
    c0 = math.hypot(a + _KS * a, _KH)

    def w(L2: float, L0: float) -> float:
        eps = (L2 - L0 * L0) / (2 * L0 * L0)
        return 0.5 * L0 * eps * eps

    def energy(v: np.ndarray) -> float:
        r, phi = v
        top = (2 * r * math.sin(math.pi / n)) ** 2
        b2 = R * R + r * r - 2 * R * r * math.cos(phi) + H * H
        c2 = R * R + r * r - 2 * R * r * math.cos(phi + 2 * math.pi / n) + H * H
        return n * (w(top, a) + w(b2, b0) + w(c2, c0))

    res = minimize(energy, np.asarray(x0, float), method="BFGS", options={"gtol": 1e-13})
    return float(res.fun), res.x


def _kresling_closed_form() -> dict[str, float]:
    """Stable states of Cai et al. (2015), written out: sin(phi + pi/n) = (c^2 - b^2) /
    (4 R^2 sin(pi/n)), H^2 = b^2 - 2 R^2 (1 - cos phi)."""
    n, a = _KN, 1.0
    R = a / (2 * math.sin(math.pi / n))
    b2, c2 = _KS**2 + _KH**2, (1 + _KS) ** 2 + _KH**2
    q = (c2 - b2) / (4 * R * R * math.sin(math.pi / n))
    phi = (math.asin(q) - math.pi / n, math.pi - math.asin(q) - math.pi / n)
    H = tuple(math.sqrt(b2 - 2 * R * R * (1 - math.cos(p))) for p in phi)
    return {"R": R, "phi1": phi[0], "phi2": phi[1], "H1": H[0], "H2": H[1]}


def _kresling_reference() -> dict[str, float]:
    """Barrier and largest compressive force of the reduced truss model: energy on a
    41-point grid of H between the stable states, then a bounded scalar search around the
    grid extremes (force by central differences of the energy, dH = 1e-5)."""
    from scipy.optimize import minimize_scalar

    cf = _kresling_closed_form()
    Hs = np.linspace(cf["H1"], cf["H2"], 41)
    x = np.array([cf["R"], cf["phi1"]])
    xs, Es = [], []
    for H in Hs:
        e, x = _kresling_truss_energy(H, x)
        xs.append(x)
        Es.append(e)
    k = int(np.argmax(Es))
    top = minimize_scalar(
        lambda H: -_kresling_truss_energy(H, xs[k])[0],
        bounds=(Hs[k + 1], Hs[k - 1]), method="bounded", options={"xatol": 1e-10},
    )  # fmt: skip

    def force(H: float, x0: np.ndarray) -> float:  # compressive force -dE/dH
        h = 1e-5
        return -(_kresling_truss_energy(H + h, x0)[0] - _kresling_truss_energy(H - h, x0)[0]) / (
            2 * h
        )

    F = [force(H, xx) for H, xx in zip(Hs, xs, strict=True)]
    j = int(np.argmax(F))
    peak = minimize_scalar(
        lambda H: -force(H, xs[j]),
        bounds=(Hs[j + 1], Hs[j - 1]), method="bounded", options={"xatol": 1e-8},
    )  # fmt: skip
    return {"barrier": -float(top.fun), "limit_force": -float(peak.fun)}


@functools.cache
def _kresling_ref() -> dict[str, float]:
    """:func:`_kresling_reference`, computed once per process."""
    return _kresling_reference()


def _kresling() -> dict[str, float]:
    """Bar-and-hinge Kresling tower (families.kresling(fold=1), one story, EA = 1, fold
    stiffness 0), bottom polygon fixed: (1) displacement control of the top polygon's height
    from the tall to the short stable state in 20 steps; (2) arc-length control under an
    axial load of 1.2x the truss model's largest compressive force, past the limit point."""
    from barhinge.errors import ConvergenceError

    n = _KN
    cf = _kresling_closed_form()
    ref = _kresling_ref()
    cp = families.kresling(n, 1, height=_KH, shift=_KS, fold=1)
    model = BarHingeModel.from_pattern(cp, "N4B5", bar_EA=1.0, fold_k=0.0)
    sup = np.zeros((model.n_nodes, 3), bool)
    sup[:n] = True
    P = np.full((model.n_nodes, 3), np.nan)
    P[n:, 2] = cf["H2"] - cf["H1"]
    path = solve(Scene(model, supports=sup, prescribed=P, control="displacement", steps=20))
    E = np.array([model.energy(X) for X in path.X])
    H = path.X[:, n, 2]
    truss = []
    x = np.array([cf["R"], cf["phi1"]])
    for h in H:
        e, x = _kresling_truss_energy(h, x)
        truss.append(e)
    k = int(np.argmax(E))
    c = np.polyfit(H[k - 1 : k + 2], E[k - 1 : k + 2], 2)
    top = path.X[-1, n:]
    turn = np.arctan2(top[:, 1], top[:, 0]) - 2 * np.pi * np.arange(n) / n
    phi2 = float(np.mean(np.remainder(turn + np.pi, 2 * np.pi) - np.pi))
    # pop-through: arc length past the limit point (stopped by its step cap after the snap)
    Fz = np.zeros((model.n_nodes, 3))
    Fz[n:, 2] = -1.2 * ref["limit_force"] / n
    scene = Scene(
        model, supports=sup, loads=Fz, control="arc_length", steps=20,
        options={"max_arc_steps": 60},
    )  # fmt: skip
    try:
        arc = solve(scene)
    except ConvergenceError as exc:
        arc = exc.last_state
    lam = np.asarray(arc.load_factor)
    j = int(np.argmax(lam))
    if not 0 < j < len(lam) - 1:
        raise ValueError("arc length did not pass the limit point")
    zz = arc.X[:, n, 2]
    cl = np.polyfit(zz[j - 1 : j + 2], lam[j - 1 : j + 2], 2)
    lam_max = float(np.polyval(cl, -cl[1] / (2 * cl[0])))
    return {
        "phi_state2_deg": math.degrees(phi2),
        "energy_state2": float(E[-1]),
        "barrier": float(np.polyval(c, -c[1] / (2 * c[0]))),
        "path_energy_gap": float(np.max(np.abs(E - np.array(truss))) / ref["barrier"]),
        "limit_force": lam_max * 1.2 * ref["limit_force"],
    }


_KCF = _kresling_closed_form()
_kresling_case = Case(
    name="kresling_bistability",
    citation=(
        "Cai, Deng, Zhou, Feng & Tu 2015, J. Mech. Des. 137(6):061406 (truss model, stable "
        "states); Yasuda, Tachi, Lee & Yang 2017, Nat. Commun. 8:962 (truss model of "
        "triangulated cylindrical origami)"
    ),
    description=(
        "One-story hexagonal Kresling tower (a=1, flat height 1.6, shift 0.3) as bars with "
        "free folds: displacement control from the tall to the short stable state; arc "
        "length under axial load past the limit point (snap). References: closed-form "
        "stable states and the symmetry-reduced truss energy min over (r, phi) by BFGS"
    ),
    compute=_kresling,
    quantities=(
        Quantity(
            "phi_state2_deg", math.degrees(_KCF["phi2"]), 1e-8,
            "top turn found by the solver at the prescribed height: Newton tolerance",
            "sin(phi + pi/n) = (c^2 - b^2) / (4 R^2 sin(pi/n))",
        ),
        Quantity(
            "energy_state2", 0.0, 1e-12,
            "stress-free second state: round-off (absolute, energy units of EA = 1)",
            "b = b0, c = c0 at (H2, phi2)",
        ),
        Quantity(
            "barrier", math.nan, 1e-3,
            "peak of a parabola through 3 of 21 displacement-controlled states: ~2e-4",
            "max_H min_(r, phi) E_truss(H, r, phi)",
            reference_from=lambda: _kresling_ref()["barrier"],
        ),
        Quantity(
            "path_energy_gap", 0.0, 1e-7,
            "full model vs symmetry-reduced truss at the same heights: solver tolerances",
            "E_bh(H) = min_(r, phi) E_truss(H, r, phi)  (relative to the barrier)",
        ),
        Quantity(
            "limit_force", math.nan, 1e-3,
            "peak of a parabola through 3 arc-length states: O(step^2), measured ~1e-5",
            "max_H -dE_truss/dH",
            reference_from=lambda: _kresling_ref()["limit_force"],
        ),
    ),
    quick=False,
)  # fmt: skip


# ------------------------------------------------------------------ vertex pop-through
# Degree-4 conical vertex: a square pyramid (rim radius 1, apex rise 0.3) of four triangular
# panels, rim pinned, creases free to rotate, bars EA = 1000, apex loaded down.
_PN, _PA, _PH, _PEA = 4, 1.0, 0.3, 1000.0
_PL0 = math.hypot(_PA, _PH)
_PMAX = _PN * _PEA * _PH**3 / (3 * math.sqrt(3) * _PL0**3)


def _pop_final_height(factor: float) -> float:
    """Apex height past the snap under ``factor`` x the limit load: the real root of
    ``n EA z (z^2 - h^2) / (2 L0^3) = -factor P_max`` (Green-strain bars), by numpy.roots."""
    c = _PN * _PEA / (2 * _PL0**3)
    r = np.roots([c, 0.0, -c * _PH**2, factor * _PMAX])
    return float(r[np.abs(r.imag) < 1e-12].real.min())


def _vertex_pop_through() -> dict[str, float]:
    """Arc length on the pyramid vertex under 1.5 x the limit load: the load factor peaks,
    falls through the inverted stress-free state and rises again to 1 on the far side."""
    ang = 2 * np.pi * np.arange(_PN) / _PN
    V = np.vstack([np.column_stack([_PA * np.cos(ang), _PA * np.sin(ang), 0 * ang]), [0, 0, _PH]])
    cp = CreasePattern(
        vertices=V,
        edges=[[i, (i + 1) % _PN] for i in range(_PN)] + [[i, _PN] for i in range(_PN)],
        assignment=["B"] * _PN + ["M"] * _PN,
        faces=[[i, (i + 1) % _PN, _PN] for i in range(_PN)],
        developable=False,
    )
    model = BarHingeModel.from_pattern(cp, "N4B5", bar_EA=_PEA, fold_k=0.0)
    sup = np.zeros((model.n_nodes, 3), bool)
    sup[:_PN] = True
    P = np.zeros((model.n_nodes, 3))
    P[_PN, 2] = -1.5 * _PMAX
    scene = Scene(
        model, supports=sup, loads=P, control="arc_length", steps=20,
        options={"max_arc_steps": 300},
    )  # fmt: skip
    path = solve(scene)
    lam = path.load_factor
    z = path.X[:, _PN, 2]
    k = int(np.argmax(np.diff(lam) < 0))
    c = np.polyfit(z[k - 1 : k + 2], lam[k - 1 : k + 2], 2)
    zs = -c[1] / (2 * c[0])
    return {
        "limit_load": float(np.polyval(c, zs)) * 1.5 * _PMAX,
        "apex_height_at_limit": float(zs),
        "apex_height_after_snap": float(z[-1]),
        "apex_lateral_drift": float(np.abs(path.X[:, _PN, :2]).max()),
    }


_pop_case = Case(
    name="vertex_pop_through",
    citation=(
        "Krenk 2009, Non-linear Modeling and Analysis of Solids and Structures, ch. 1 "
        "(two-bar truss with Green-strain bars, exact for any rise; the same equilibrium "
        "with n = 4 bars in space)"
    ),
    description=(
        "Degree-4 conical vertex (square pyramid, rim radius 1, rise 0.3, EA=1000, free "
        "creases), rim pinned, apex pushed by 1.5x the limit load under arc-length control "
        "(MGDCM): passes the limit point, pops through the inverted state and settles below it"
    ),
    compute=_vertex_pop_through,
    quantities=(
        Quantity(
            "limit_load", _PMAX, 1e-3,
            "peak between arc-length states, parabola fit: measured 1e-5",
            "P_max = n EA h^3 / (3 sqrt(3) L0^3)",
        ),
        Quantity(
            "apex_height_at_limit", _PH / math.sqrt(3), 1e-2,
            "location of a flat maximum from a parabola: O(step), measured 1e-4",
            "z = h / sqrt(3)",
        ),
        Quantity(
            "apex_height_after_snap", _pop_final_height(1.5), 1e-8,
            "converged equilibrium at load factor 1: Newton tolerance",
            "n EA z (z^2 - h^2) / (2 L0^3) = -1.5 P_max, real root",
        ),
        Quantity(
            "apex_lateral_drift", 0.0, 1e-9,
            "symmetric path (no bifurcation): round-off (absolute, length)",
            "x = y = 0",
        ),
    ),
    quick=False,
)  # fmt: skip


#: every registered case, by name
CASES: dict[str, Case] = {
    c.name: c
    for c in (
        _miura_rigid_case,
        _miura_bh_case,
        _flat_start_case,
        _degree4_case,
        _maekawa_case,
        _curvature_case,
        _dof_case,
        _fold_case,
        _cantilever_case,
        _strip_case,
        _filipov_case,
        _vm_case,
        _periodic_case,
        _e2e_case,
        _kresling_case,
        _pop_case,
    )
}
