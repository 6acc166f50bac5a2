"""Scene: a bar-and-hinge model with supports, loads, prescribed displacements, actuators
and a control schedule; TOML loading; the built-in default scene.

Every driven quantity follows one path parameter ``t`` in [0, 1] reached in ``steps`` equal
requested steps: loads are ``t * loads`` (the load factor is ``t``), prescribed displacements
are ``t * prescribed`` and actuator fold angles follow their schedule (linear in ``t`` or a
per-step table). Under arc-length control the load factor is an unknown instead of ``t``.
"""

from __future__ import annotations

import dataclasses
import inspect
import tomllib
import typing
from pathlib import Path
from typing import Any

import numpy as np

from barhinge import _check
from barhinge._typing import ControlKind
from barhinge.actuators import Actuators
from barhinge.errors import BarhingeError, ConfigError, PatternError
from barhinge.loads import FollowerPressure, combine, line_load, pressure_load, projected_load
from barhinge.solver_options import SolverOptions

__all__ = [
    "Imperfection",
    "Scene",
    "default_scene",
    "load_scene",
    "restraint_321",
    "scene_from_dict",
    "select_vertices",
    "self_weight",
]


#: amplitude rules of an imperfection: "panel/N" (EN 1993-1-5, Annex C, C.5) or "span/N"
AMPLITUDE_RULES = ("panel", "span")


@dataclasses.dataclass(frozen=True)
class Imperfection:
    """An initial geometric imperfection a scene asks for: the structure is made stress-free
    in the shape of its ``mode``-th linear buckling mode under the scene's loads, scaled to a
    largest nodal displacement ``amplitude`` (applied by
    :func:`barhinge.analysis.imperfection.seed_imperfection`; ``barhinge fold`` does).

    Parameters
    ----------
    mode : int
        Which buckling mode (1 = lowest factor).
    amplitude : float or str
        A length in the model's units (>= 0), or a rule: ``"panel/N"`` (the median over the
        facets of each facet's shortest side, over N: EN 1993-1-5:2006, Annex C, C.5 takes
        N = 200 for a plate panel) or ``"span/N"`` (twice the largest plan distance from a
        node to the supports, supported nodes and pattern edges between two of them, over
        N: the span of a roof on two supported edges; EN 1993-1-1:2005, Table 5.1 gives
        N = 300 for a bow of curve a).
    """

    mode: int = 1
    amplitude: float | str = "panel/200"

    def __post_init__(self) -> None:
        _check.integer(self.mode, "imperfection.mode", 1, 1000)
        a = self.amplitude
        if isinstance(a, str):
            rule, _, den = a.partition("/")
            try:
                n = float(den)
            except ValueError:
                n = float("nan")
            if rule not in AMPLITUDE_RULES or not (np.isfinite(n) and n > 0):
                raise ConfigError(
                    f"imperfection.amplitude = {a!r}; expected a length or 'panel/N' or "
                    "'span/N' with N > 0"
                )
        else:
            object.__setattr__(
                self, "amplitude", _check.number(a, "imperfection.amplitude", lo=0.0)
            )

    def rule(self) -> tuple[str, float] | None:
        """(``"panel"`` or ``"span"``, N) of a rule amplitude; None for a length."""
        if not isinstance(self.amplitude, str):
            return None
        rule, _, den = self.amplitude.partition("/")
        return rule, float(den)


@dataclasses.dataclass(frozen=True, eq=False)
class Scene:
    """What to solve: a model and how it is held, loaded and driven.

    Parameters
    ----------
    model : BarHingeModel
        The structure (anything with ``X0``, ``evaluate``, ``hinges`` ... see ``solve``).
    supports : (n_nodes, 3) bool, optional
        Fixed DOFs (True = fixed at its initial position). ``None`` with no prescribed
        displacements gives the minimal 3-2-1 restraint of :func:`restraint_321`.
    loads : (n_nodes, 3) float, optional
        Reference nodal loads, scaled by the load factor.
    prescribed : (n_nodes, 3) float, optional
        Prescribed displacement of each DOF at the end of the path (NaN = not prescribed);
        reached linearly. Prescribed DOFs are eliminated like supports.
    actuators : Actuators, optional
        Creases whose fold angles follow a schedule (Lagrange-multiplier constraints).
    steps : int
        Number of requested steps (states 1..steps of the result).
    control : str
        ``"fold_angle"``, ``"displacement"``, ``"load"``, ``"arc_length"`` or ``"auto"``
        (fold angle if actuators, else displacement if prescribed, else load).
    options : SolverOptions or dict, optional
    name : str
    load_cases : dict str -> (n_nodes, 3) float, optional
        Named load cases and factored combinations (reference loads); pick one with
        :meth:`with_load_case`.
    follower : FollowerPressure, optional
        A pressure along the facets' current normals, scaled by the load factor with
        ``loads`` (a follower load: re-evaluated at every iterate).
    imperfection : Imperfection, optional
        An initial imperfection in a buckling mode of ``loads``; the solver refuses a scene
        whose model has not been seeded with it
        (:func:`barhinge.analysis.imperfection.seed_imperfection`).
    """

    model: Any
    supports: np.ndarray | None = None
    loads: np.ndarray | None = None
    prescribed: np.ndarray | None = None
    actuators: Actuators | None = None
    steps: int = 50
    control: str = "auto"
    options: SolverOptions | dict | None = None
    name: str = "scene"
    load_cases: dict[str, np.ndarray] | None = None
    follower: FollowerPressure | None = None
    imperfection: Imperfection | None = None

    def __post_init__(self) -> None:
        if not hasattr(self.model, "n_nodes") or not hasattr(self.model, "X0"):
            raise ConfigError(f"model must be a BarHingeModel, got {type(self.model).__name__}")
        n = int(self.model.n_nodes)
        auto = False
        if self.prescribed is not None:
            P = _node_array(self.prescribed, n, "prescribed", float)
        else:
            P = np.full((n, 3), np.nan)
        if self.supports is None:
            S = np.zeros((n, 3), bool)
            if not np.isfinite(P).any():
                S = restraint_321(self.model)
                auto = True
        else:
            S = _node_array(self.supports, n, "supports", bool)
        both = S & np.isfinite(P)
        if both.any():
            i, c = np.argwhere(both)[0]
            raise ConfigError(f"node {i} component {'xyz'[c]} is both supported and prescribed")
        L = np.zeros((n, 3)) if self.loads is None else _node_array(self.loads, n, "loads", float)
        _check.integer(self.steps, "steps", 1, MAX_STEPS)
        _check.text(self.name, "name")
        acts = self.actuators
        if acts is not None and not isinstance(acts, Actuators):
            raise ConfigError(f"actuators must be an Actuators object, got {type(acts).__name__}")
        if acts is not None and acts.n:
            ne = len(self.model.fold_hinge_of_edge)
            bad = [int(e) for e in acts.edges if e < 0 or e >= ne]
            if bad:
                raise ConfigError(f"actuator edge {bad[0]} is not an edge id (0..{ne - 1})")
            no_hinge = [int(e) for e in acts.edges if self.model.fold_hinge_of_edge[e] < 0]
            if no_hinge:
                raise ConfigError(f"actuator edge {no_hinge[0]} has no fold hinge (not a crease)")
            if acts.table_deg is not None and len(acts.table_deg) != self.steps:
                raise ConfigError(
                    f"actuators.table_deg has {len(acts.table_deg)} rows, but steps = "
                    f"{self.steps}; give one row per step"
                )
        control = _check.choice(self.control, "control", CONTROLS)
        if control == "auto":
            if acts is not None and acts.n:
                control = "fold_angle"
            elif np.isfinite(P).any():
                control = "displacement"
            else:
                control = "load"
        if control == "fold_angle" and (acts is None or not acts.n):
            raise ConfigError("control 'fold_angle' needs actuators")
        if control == "displacement" and not np.isfinite(P).any():
            raise ConfigError("control 'displacement' needs prescribed displacements")
        fol = self.follower
        if fol is not None and not isinstance(fol, FollowerPressure):
            raise ConfigError(f"follower must be a FollowerPressure, got {type(fol).__name__}")
        if fol is not None:
            fol.force(self.model, self.model.X0)  # checks the faces
        if control in ("load", "arc_length") and not np.any(L) and (fol is None or fol.p == 0):
            raise ConfigError(f"control {control!r} needs nonzero loads")
        imp = self.imperfection
        if imp is not None and not isinstance(imp, Imperfection):
            raise ConfigError(f"imperfection must be an Imperfection, got {type(imp).__name__}")
        if imp is not None and not np.any(L):
            raise ConfigError(
                "imperfection needs nonzero loads: its shape is a buckling mode of the loads"
            )
        opts = self.options
        if opts is None or isinstance(opts, dict):
            opts = SolverOptions.from_dict(opts)
        elif not isinstance(opts, SolverOptions):
            raise ConfigError(f"options must be SolverOptions or a dict, got {type(opts).__name__}")
        cases = {}
        for cname, arr in (self.load_cases or {}).items():
            _check.text(cname, "load case name")
            cases[cname] = _node_array(arr, n, f"load case {cname!r}", float)
        object.__setattr__(self, "load_cases", cases or None)
        object.__setattr__(self, "supports", S)
        object.__setattr__(self, "loads", L)
        object.__setattr__(self, "prescribed", P)
        object.__setattr__(self, "control", control)
        object.__setattr__(self, "options", opts)
        object.__setattr__(self, "steps", int(self.steps))
        object.__setattr__(self, "_auto_restrained", auto)

    @property
    def auto_restrained(self) -> bool:
        """True when the supports are the automatic 3-2-1 restraint."""
        return bool(self._auto_restrained)  # type: ignore[attr-defined]

    @property
    def fixed(self) -> np.ndarray:
        """(n_nodes, 3) bool: DOFs removed from the unknowns (supports and prescribed)."""
        return self.supports | np.isfinite(self.prescribed)

    def actuator_hinges(self) -> np.ndarray:
        """(n_act,) int: model hinge index of each actuator."""
        if self.actuators is None:
            return np.zeros(0, np.int64)
        return np.asarray(self.model.fold_hinge_of_edge, np.int64)[self.actuators.edges]

    def actuator_schedule_deg(self) -> np.ndarray:
        """(steps + 1, n_act) prescribed actuator angles (row 0 = angles of ``model.X0``)."""
        if self.actuators is None or not self.actuators.n:
            return np.zeros((self.steps + 1, 0))
        start = np.degrees(self.model.hinge_angles(self.model.X0)[self.actuator_hinges()])
        return self.actuators.schedule(self.steps, start_deg=start)

    def with_load_case(self, name: str) -> Scene:
        """A copy whose reference loads are the load case or combination ``name``."""
        cases = self.load_cases or {}
        if name not in cases:
            raise ConfigError(f"load case {name!r} is unknown; the scene has {sorted(cases)}")
        return self.with_(loads=cases[name])

    def with_(self, **changes: Any) -> Scene:
        """A copy with some fields replaced."""
        kw = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        kw.update(changes)
        if "supports" not in changes and self.auto_restrained:
            kw["supports"] = None
        return Scene(**kw)


def _node_array(a: Any, n: int, what: str, dtype: type) -> np.ndarray:
    if dtype is bool:
        arr = np.asarray(a)
        if arr.dtype != bool:
            raise ConfigError(f"{what} must be a boolean array, got dtype {arr.dtype}")
    else:
        # prescribed: NaN = free; loads: finite
        arr = _check.float_array(a, what, allow_nan=what == "prescribed")
    if arr.shape != (n, 3):
        raise ConfigError(f"{what} must have shape (n_nodes, 3) = ({n}, 3), got {arr.shape}")
    return arr.copy()


# ------------------------------------------------------------------------------ supports
def restraint_321(model: Any) -> np.ndarray:
    """Minimal 3-2-1 restraint of a free-floating model, (n_nodes, 3) bool.

    Node A (the pattern vertex nearest the centroid) is fixed in x, y, z; node B (farthest
    from A) in the two components across AB; node C (farthest from line AB) in the component
    along the normal of the plane ABC, which stops the rotation about AB. Removes exactly the
    six rigid-body modes (checked by rank) and adds no stress.
    """
    X = np.asarray(model.X0, float)
    nv = len(model.pattern.vertices) if hasattr(model, "pattern") else len(X)
    V = X[:nv]
    a = int(np.argmin(np.linalg.norm(V - V.mean(0), axis=1)))
    b = int(np.argmax(np.linalg.norm(V - V[a], axis=1)))
    ab = V[b] - V[a]
    cross = np.cross(ab, V - V[a])
    c = int(np.argmax(np.linalg.norm(cross, axis=1)))
    S = np.zeros((len(X), 3), bool)
    S[a] = True
    S[b, np.argsort(np.abs(ab))[:2]] = True
    S[c, int(np.argmax(np.abs(cross[c])))] = True
    # check: the six rigid-body velocities restricted to the fixed DOFs have rank 6; the
    # rotations act on coordinates relative to the centroid over the pattern's size, so the
    # test is scale-free (a = b = 1e12 and a = b = 1e-12 sheets alike)
    size = float(np.linalg.norm(np.ptp(V, axis=0)))
    if not size > 0 or not np.isfinite(size):
        raise PatternError("cannot restrain the pattern automatically (it has no extent)")
    rows = []
    for node in (a, b, c):
        x = (X[node] - V.mean(0)) / size
        modes = np.hstack([np.eye(3), -_skew(x)])  # v = t + w x r  -> [I, -[r]x] @ (t, w)
        rows.append(modes[S[node]])
    if np.linalg.matrix_rank(np.vstack(rows), tol=1e-9) < 6:
        raise PatternError("cannot restrain the pattern automatically (its vertices are collinear)")
    return S


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def select_vertices(model: Any, where: str | list[str], tol: float = 1e-6) -> np.ndarray:
    """Vertex ids chosen by name, intersected over a list of names.

    Names: ``all``, ``boundary``, ``left``/``right`` (min/max x), ``bottom``/``top`` (min/max
    y), ``zmin``/``zmax`` (min/max z), evaluated on the pattern's vertices at ``model.X0``
    with tolerance ``tol`` times the pattern size.
    """
    words = [where] if isinstance(where, str) else list(where)
    cp = model.pattern
    V = np.asarray(model.X0, float)[: cp.n_vertices]
    size = float(np.linalg.norm(np.ptp(V, axis=0))) or 1.0
    eps = tol * size
    keep = np.ones(len(V), bool)
    for w in words:
        if w == "all":
            m = np.ones(len(V), bool)
        elif w == "boundary":
            m = np.zeros(len(V), bool)
            m[cp.boundary_vertices] = True
        elif w in _AXES:
            ax, side = _AXES[w]
            ext = V[:, ax].min() if side < 0 else V[:, ax].max()
            m = np.abs(V[:, ax] - ext) <= eps
        else:
            raise ConfigError(
                f"unknown vertex set {w!r}; expected all, boundary, {', '.join(_AXES)}"
            )
        keep &= m
    return np.flatnonzero(keep)


_AXES = {
    "left": (0, -1),
    "right": (0, 1),
    "bottom": (1, -1),
    "top": (1, 1),
    "zmin": (2, -1),
    "zmax": (2, 1),
}


def self_weight(model: Any, area_density: float, g: Any = (0.0, 0.0, -9.81)) -> np.ndarray:
    """Nodal self-weight (n_nodes, 3): each facet's area times ``area_density`` times ``g``,
    shared equally by its corner vertices (lumped; the total force is exact)."""
    cp = model.pattern
    X = np.asarray(model.X0, float)
    F = np.zeros_like(X)
    g = np.asarray(g, float).reshape(3)
    for f in cp.faces:
        P = X[list(f)]
        area = 0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, axis=0)).sum(0))
        F[list(f)] += area * area_density * g / len(f)
    return F


# ------------------------------------------------------------------------------ TOML
_TOP_KEYS = {
    "name",
    "pattern",
    "model",
    "supports",
    "loads",
    "load_cases",
    "combinations",
    "prescribed",
    "actuators",
    "imperfection",
    "solve",
}
#: upper bound of an integer parameter of a pattern family in a scene (cells, stories ...)
MAX_PATTERN_COUNT = 10_000


def load_scene(path: str | Path) -> Scene:
    """Read a scene from a TOML file (see ``data/scenes/*.toml`` and docs/solver.md).

    Every value is checked here for type, finiteness and range; a bad one raises
    :class:`ConfigError` (or :class:`PatternError` for the pattern) with one line naming the
    key as a dotted path (``model.material.E = inf; expected a finite number``).
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            raw = fh.read()
        pattern_kind = _crease_pattern_kind(path, raw)
        if pattern_kind:
            raise ConfigError(
                f"{path.name} is {pattern_kind}, not a scene TOML: to fold a crease pattern, a "
                f'scene reads it with [pattern] file = "{path.name}" and names what drives the '
                f"fold (actuators, supports, loads); `barhinge dof {path.name}` suggests "
                f"actuators, data/scenes/*.toml are examples, docs/solver.md lists every key"
            )
        data = tomllib.loads(raw.decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"scene file {str(path)!r} does not exist") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path.name}: invalid TOML: {exc}") from None
    except OSError as exc:
        raise ConfigError(f"scene file {str(path)!r} cannot be read: {exc.strerror}") from None
    data.setdefault("name", path.stem)
    return scene_from_dict(data, base_dir=path.parent)


def _crease_pattern_kind(path: Path, raw: bytes) -> str:
    """What the file given as a scene is when it is a crease pattern's format rather than
    TOML (by its suffix, or by content: a JSON object or an XML document, which no scene
    TOML starts with): ``"a FOLD file"``, ``"a JSON file"``, ``"an SVG file"``; ``""``
    otherwise."""
    suffix = path.suffix.lower()
    head = raw.lstrip()[:1]
    if suffix == ".svg" or (head == b"<" and suffix != ".toml"):
        return "an SVG file"
    if suffix == ".fold":
        return "a FOLD file"
    if suffix == ".json" or (head == b"{" and suffix != ".toml"):
        return "a JSON file"
    return ""


def _check_keys(d: Any, allowed: set[str], where: str) -> None:
    if not isinstance(d, dict):
        raise ConfigError(f"{where} must be a table, got {type(d).__name__} {_check.show(d)}")
    for k in d:
        if k not in allowed:
            raise ConfigError(
                f"unknown key {k!r} in {where}; expected one of {', '.join(sorted(allowed))}"
            )


def scene_from_dict(d: dict[str, Any], base_dir: str | Path = ".") -> Scene:
    """Build a :class:`Scene` from the TOML mapping (unknown keys raise ConfigError)."""
    _check_keys(d, _TOP_KEYS, "the scene")
    # overflow (a pattern of size 1e300, a density of 1e308) is caught by the finiteness
    # checks, which name the key; numpy's warnings would only repeat it
    with np.errstate(over="ignore", invalid="ignore"):
        return _scene_from_dict(d, Path(base_dir))


def _scene_from_dict(d: dict[str, Any], base_dir: Path) -> Scene:
    name = _check.text(d.get("name", "scene"), "name")
    cp = _pattern_from(d.get("pattern"), base_dir)
    model = _model_from(cp, d.get("model", {}))
    n = model.n_nodes
    supports = None
    if "supports" in d:
        supports = np.zeros((n, 3), bool)
        for i, g in enumerate(_groups(d["supports"], "supports")):
            key = f"supports.{i}"
            _check_keys(g, _SELECT | {"dofs"}, key)
            supports[np.ix_(_nodes(model, g, key), _dofs(g, key))] = True
    loads, follower = (
        _loads_from(model, d["loads"], "loads", follower=True) if "loads" in d else (None, None)
    )
    cases: dict[str, np.ndarray] = {}
    lc = d.get("load_cases", {})
    if not isinstance(lc, dict):
        raise ConfigError(f"load_cases must be a table of named cases, got {_check.show(lc)}")
    for cname, groups in lc.items():
        cases[cname] = _loads_from(model, groups, f"load_cases.{cname}")[0]
    combos = d.get("combinations", {})
    if not isinstance(combos, dict):
        raise ConfigError(f"combinations must be a table, got {_check.show(combos)}")
    for cname, factors in combos.items():
        if cname in cases:
            raise ConfigError(f"combinations.{cname} has the name of a load case")
        if not isinstance(factors, dict):
            raise ConfigError(
                f"combinations.{cname} must be a table case = factor, got {_check.show(factors)}"
            )
        with _check.prefixed(f"combinations.{cname}: "):
            cases[cname] = combine(cases, factors)
    prescribed = None
    if "prescribed" in d:
        prescribed = np.full((n, 3), np.nan)
        for i, g in enumerate(_groups(d["prescribed"], "prescribed")):
            key = f"prescribed.{i}"
            _check_keys(g, _SELECT | {"displacement", "dofs"}, key)
            if "displacement" not in g:
                raise ConfigError(f"{key} needs displacement = [ux, uy, uz]")
            u = _vec3(g["displacement"], f"{key}.displacement")
            idx, comps = _nodes(model, g, key), _dofs(g, key)
            prescribed[np.ix_(idx, comps)] = u[comps]
    actuators = None
    if "actuators" in d:
        a = d["actuators"]
        _check_keys(a, {"edges", "targets_deg", "table_deg", "stiffness"}, "actuators")
        edges = a.get("edges")
        if isinstance(edges, str):
            if edges != "creases":
                raise ConfigError(f"actuators.edges = {edges!r}; expected a list or 'creases'")
            edges = cp.crease_edges
        if edges is None:
            raise ConfigError("actuators needs edges = [...] or edges = 'creases'")
        actuators = Actuators(
            edges=edges,
            targets_deg=a.get("targets_deg"),
            table_deg=a.get("table_deg"),
            stiffness=a.get("stiffness"),
        )
    solve = d.get("solve", {})
    _check_keys(solve, {"steps", "control", "options", "load_case"}, "solve")
    if "load_case" in solve:
        lcn = _check.text(solve["load_case"], "solve.load_case")
        if lcn not in cases:
            raise ConfigError(f"solve.load_case = {lcn!r}; the scene has {sorted(cases)}")
        if loads is not None:
            raise ConfigError("give either [loads] or solve.load_case, not both")
        loads = cases[lcn]
    imperfection = None
    if "imperfection" in d:
        imp = d["imperfection"]
        _check_keys(imp, {"mode", "amplitude"}, "imperfection")
        if "amplitude" not in imp:
            raise ConfigError("imperfection needs amplitude = a length, 'panel/N' or 'span/N'")
        imperfection = Imperfection(mode=imp.get("mode", 1), amplitude=imp["amplitude"])
    steps = _check.integer(solve.get("steps", 50), "solve.steps", 1, MAX_STEPS)
    control = _check.choice(solve.get("control", "auto"), "solve.control", CONTROLS)
    with _check.prefixed("solve.", {"options"}):
        options = SolverOptions.from_dict(solve.get("options"))
    return Scene(
        model,
        supports=supports,
        loads=loads,
        prescribed=prescribed,
        actuators=actuators,
        steps=steps,
        control=control,
        options=options,
        name=name,
        load_cases=cases or None,
        follower=follower,
        imperfection=imperfection,
    )


def _loads_from(
    model: Any, groups: Any, where: str, follower: bool = False
) -> tuple[np.ndarray, FollowerPressure | None]:
    """(n_nodes, 3) reference loads of an array of load groups (forces on selected nodes,
    self-weight, pressure, projected and line loads), and the follower pressure (a group
    with ``pressure`` and ``follower = true``; allowed where ``follower``)."""
    n = model.n_nodes
    loads = np.zeros((n, 3))
    fol: FollowerPressure | None = None
    kinds = {"force", "self_weight", "pressure", "projected", "line_load"}
    for i, g in enumerate(_groups(groups, where)):
        key = f"{where}.{i}"
        _check_keys(g, _SELECT | kinds | {"faces", "follower"}, key)
        if "follower" in g:
            if not isinstance(g["follower"], bool):
                raise ConfigError(
                    f"{key}.follower = {_check.show(g['follower'])}; expected true/false"
                )
            if g["follower"] and set(g) - {"pressure", "faces", "follower"}:
                raise ConfigError(f"{key}: a follower group holds pressure (and faces) only")
            if g["follower"] and "pressure" not in g:
                raise ConfigError(f"{key}.follower = true needs pressure = p")
            if g["follower"] and not follower:
                raise ConfigError(f"{key}: follower pressure goes in [[loads]], not in load cases")
            if g["follower"] and fol is not None:
                raise ConfigError(f"{key}: one follower pressure per scene")
            if g["follower"]:
                with _check.prefixed(f"{key}."):
                    fol = FollowerPressure(g["pressure"], g.get("faces"))
                    fol.force(model, model.X0)  # checks the faces
                continue
        if not set(g) & kinds:
            raise ConfigError(
                f"{key} needs force = [fx, fy, fz], self_weight, pressure, projected or line_load"
            )
        if "self_weight" in g:
            sw = g["self_weight"]
            _check_keys(sw, {"area_density", "g"}, f"{key}.self_weight")
            if "area_density" not in sw:
                raise ConfigError(f"{key}.self_weight needs area_density")
            rho = _check.number(sw["area_density"], f"{key}.self_weight.area_density", 0.0)
            g3 = _vec3(sw.get("g", [0.0, 0.0, -9.81]), f"{key}.self_weight.g")
            loads += self_weight(model, rho, g3)
        faces = g.get("faces")
        if faces is not None and not set(g) & {"pressure", "projected"}:
            raise ConfigError(f"{key}.faces selects faces for pressure or projected loads only")
        with _check.prefixed(f"{key}."):
            if "pressure" in g:
                loads += pressure_load(model, g["pressure"], faces)
            if "projected" in g:
                pr = g["projected"]
                if isinstance(pr, dict):
                    _check_keys(pr, {"q", "direction"}, f"{key}.projected")
                    if "q" not in pr:
                        raise ConfigError(f"{key}.projected needs q")
                    loads += projected_load(
                        model, pr["q"], faces, pr.get("direction", (0.0, 0.0, -1.0))
                    )
                else:
                    loads += projected_load(model, pr, faces)
        if "line_load" in g:
            if "edges" not in g or set(g) & (_SELECT - {"edges"}):
                raise ConfigError(f"{key}.line_load acts on edges = [...] (and nothing else)")
            with _check.prefixed(f"{key}."):
                loads += line_load(model, g["line_load"], g["edges"])
        if "force" in g:
            loads[_nodes(model, g, key)] += _vec3(g["force"], f"{key}.force")
        elif set(g) & _SELECT and "line_load" not in g:
            raise ConfigError(f"{key} selects nodes but gives no force = [fx, fy, fz]")
        if not np.isfinite(loads).all():
            raise ConfigError(f"{key}: the loads overflow floating point")
    return loads, fol


CONTROLS: tuple[str, ...] = (*typing.get_args(ControlKind), "auto")
#: upper bound of ``steps`` (each step is a stored state)
MAX_STEPS = 1_000_000
_SELECT = {"vertices", "nodes", "edges", "where"}


def _groups(v: Any, where: str) -> list[dict[str, Any]]:
    if isinstance(v, dict):
        return [v]
    if isinstance(v, list) and all(isinstance(g, dict) for g in v):
        return v
    raise ConfigError(
        f"{where} must be a table or an array of tables (double brackets around {where}), "
        f"got {_check.show(v)}"
    )


def _nodes(model: Any, g: dict[str, Any], where: str) -> np.ndarray:
    """Node ids of a selection group (union of vertices, nodes, edges' end vertices, where)."""
    n, cp = model.n_nodes, model.pattern
    ids: list[np.ndarray] = []
    if "vertices" in g:
        ids.append(_check.int_array(g["vertices"], f"{where}.vertices", 0, cp.n_vertices - 1))
    if "nodes" in g:
        ids.append(_check.int_array(g["nodes"], f"{where}.nodes", 0, n - 1))
    if "edges" in g:
        e = _check.int_array(g["edges"], f"{where}.edges", 0, cp.n_edges - 1)
        ids.append(np.asarray(cp.edges)[e].ravel())
    if "where" in g:
        w = g["where"]
        if not (isinstance(w, str) or (isinstance(w, list) and all(isinstance(x, str) for x in w))):
            raise ConfigError(f"{where}.where = {_check.show(w)}; expected a name or a list")
        with _check.prefixed(f"{where}.where: "):
            ids.append(select_vertices(model, w))
    if not ids:
        raise ConfigError(f"{where} selects nothing: give vertices, nodes, edges or where")
    out = np.unique(np.concatenate(ids))
    if out.size == 0:
        raise ConfigError(f"{where} selects no node")
    return out


def _dofs(g: dict[str, Any], where: str) -> list[int]:
    s = g.get("dofs", "xyz")
    if not isinstance(s, str) or not s or any(c not in "xyz" for c in s.lower()):
        raise ConfigError(f"{where}.dofs = {_check.show(s)}; expected letters from 'xyz'")
    return sorted({"xyz".index(c) for c in s.lower()})


def _vec3(v: Any, where: str) -> np.ndarray:
    return _check.float_array(v, where, (3,))


def _pattern_from(p: Any, base: Path) -> Any:
    if p is None:
        raise ConfigError("the scene needs a pattern table (family = ... or file = ...)")
    _check_keys(p, {"family", "file", "params", "frame"}, "pattern")
    if ("family" in p) == ("file" in p):
        raise ConfigError("pattern needs exactly one of family or file")
    if "file" in p:
        from barhinge.pattern.fold import read_fold
        from barhinge.pattern.io import read

        if "params" in p:
            raise ConfigError("pattern.params goes with pattern.family, not with pattern.file")
        f = Path(_check.text(p["file"], "pattern.file"))
        f = f if f.is_absolute() else base / f
        if not f.is_file():
            raise ConfigError(f"pattern.file = {str(f)!r} is not a file")
        try:
            if "frame" in p:
                return read_fold(f, frame=_check.integer(p["frame"], "pattern.frame", 0))
            return read(f)
        except OSError as exc:
            raise ConfigError(f"pattern.file = {str(f)!r} cannot be read: {exc.strerror}") from None
    if "frame" in p:
        raise ConfigError("pattern.frame goes with pattern.file, not with pattern.family")
    from barhinge.families import FAMILIES

    fam = p["family"]
    if not isinstance(fam, str) or fam not in FAMILIES:
        raise ConfigError(
            f"pattern.family = {_check.show(fam)} is unknown; expected one of "
            f"{', '.join(sorted(FAMILIES))}"
        )
    params = p.get("params", {})
    _check_keys(params, set(inspect.signature(FAMILIES[fam]).parameters), "pattern.params")
    gen = FAMILIES[fam]
    sig = inspect.signature(gen)
    kw = {
        k: _param(v, sig.parameters[k].annotation, f"pattern.params.{k}") for k, v in params.items()
    }
    try:
        cp = gen(**kw)
    except BarhingeError:
        raise
    except (TypeError, ValueError, ArithmeticError, IndexError) as exc:
        raise PatternError(f"pattern family {fam!r} failed with these params: {exc}") from None
    if not np.isfinite(np.asarray(cp.vertices, float)).all():
        raise PatternError(
            f"pattern family {fam!r}: the vertices overflow floating point (params too large)"
        )
    return cp


def _param(v: Any, annotation: Any, key: str) -> Any:
    """A pattern-family parameter checked against the generator's annotation."""
    ann = str(annotation)
    if ann == "int":
        return _check.integer(v, key, None, MAX_PATTERN_COUNT)
    if ann == "bool":
        return _check.boolean(v, key)
    if ann.startswith("Sequence[Sequence["):
        return _check.float_array(v, key, (None, None)).tolist()
    if ann.startswith("Sequence["):
        return _check.float_array(v, key, (None,)).tolist()
    if ann.startswith("float"):
        return _check.number(v, key)
    return v


def _model_from(cp: Any, m: Any) -> Any:
    from barhinge.model.material import Material
    from barhinge.model.model import BarHingeModel

    sig = inspect.signature(BarHingeModel.from_pattern)
    allowed = (set(sig.parameters) - {"cls", "cp", "pattern", "material"}) | {"material"}
    _check_keys(m, allowed, "model")
    m = dict(m)
    kw: dict[str, Any] = {}
    if "material" in m:
        mat = m.pop("material")
        fields = {f.name for f in dataclasses.fields(Material)}
        _check_keys(mat, fields, "model.material")
        with _check.prefixed("model.", {"material.E", "material.nu", "material.t"}):
            kw["material"] = Material(**mat)
    kw.update(m)
    with _check.prefixed("model.", allowed):
        return BarHingeModel.from_pattern(cp, **kw)


# ------------------------------------------------------------------------------ default
def default_scene(nx: int = 6, ny: int = 6, steps: int = 30) -> Scene:
    """The built-in scene of ``barhinge fold``: a Miura-ori sheet folded by actuators.

    A sheet of ``nx`` x ``ny`` cells (a = b = 1, sector angle 60 deg), N5B8 model with
    fold stiffness 0.1 and stiff bars and panels, starting from the rigidly folded state at
    facet angle 5 deg (just off the flat bifurcation point). The creases of one straight
    crease line are actuated to their rigid-folding angles at facet angle 60 deg
    (Schenk & Guest 2013); the rest of the sheet follows.
    """
    from barhinge.families import miura, miura_line_creases

    cp0 = miura(nx, ny, a=1.0, b=1.0, alpha=60.0, fold=5.0)
    cp1 = miura(nx, ny, a=1.0, b=1.0, alpha=60.0, fold=60.0)
    model = _default_model(cp0)
    edges = miura_line_creases(miura(nx, ny, a=1.0, b=1.0, alpha=60.0))
    acts = Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    return Scene(model, actuators=acts, steps=steps, name="miura-default")


def _default_model(cp: Any) -> Any:
    from barhinge.model.material import Material
    from barhinge.model.model import BarHingeModel

    return BarHingeModel.from_pattern(
        cp, scheme="N5B8", material=Material(E=1e6, nu=0.3, t=0.01), fold_stiffness=1e-3
    )
