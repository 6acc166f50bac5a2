"""Control curves: actuator fold angles that put the actuator points on a curve.

A *section* of a pleated or corrugated pattern is a straight line in the flat pattern along a
unit direction ``e`` (default +x). Each actuated crease line crosses it at an *actuator point*
``P_i`` with flat section coordinate ``x_i`` (``x_0 < x_1 < ...``); the section ends (the
pattern boundary) are ``x_start < x_0`` and ``x_end > x_{n-1}``. When only the actuators fold
and the strips between them stay flat, the folded section is a polyline whose vertices are the
actuator points and whose straight segments keep their flat lengths ``d_i = x_{i+1} - x_i``
(paper does not stretch).

A *control curve* ``C`` lives in the section plane with coordinates ``(x, z)`` (``z`` = the
side a valley fold closes towards, the +z side of a flat pattern). The **turning mapping**
places the chain on ``C``:

1. the anchor point (the chain point whose flat coordinate is nearest 0, or a chosen one)
   goes to ``C(u = x_anchor)``, where ``u`` is the curve's parameter (arc length from the apex
   for a circle, the abscissa ``x`` for a parabola or spline);
2. walking away from the anchor, each next point is the first point of ``C`` at the chord
   distance ``d_i`` (exact flat length) from the previous one;
3. the fold angle of actuator ``i`` is the signed turning (exterior) angle of the polyline at
   ``P_i``: ``Phi_i = atan2(t1 x t2, t1 . t2)`` with ``t1 = P_i - P_{i-1}``,
   ``t2 = P_{i+1} - P_i`` and ``a x b = a_x b_z - a_z b_x``. ``Phi_i > 0`` (valley) when the
   polyline turns towards +z (counter-clockwise in the ``(x, z)`` plane).

Then every actuator point lies exactly on ``C``. For a circle of curvature ``kappa`` and equal
spacing ``d`` every chord subtends the central angle ``2 arcsin(kappa d / 2)`` (chord length
``2 R sin(theta/2)``, elementary geometry), which equals the turning angle between consecutive
chords: ``Phi = 2 arcsin(kappa d / 2)``.

The **height mapping** is the alternative: ``rho_i = amplitude * z(x_i) / max_j |z(x_j)|``
(the curve's height at the actuator's flat coordinate, normalised). The **synchronised** mode
gives all actuators the same angle. See docs/control-curves.md.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from scipy.interpolate import CubicSpline

from barhinge import _check
from barhinge.actuators import Actuators
from barhinge.errors import ConfigError, PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = [
    "Chain",
    "CircularArc",
    "ControlCurve",
    "ControlSurface",
    "Parabola",
    "SplineCurve",
    "chain_on_curve",
    "current_angles_deg",
    "curve_actuators",
    "curve_angles_deg",
    "curve_schedule",
    "height_angles_deg",
    "section_crossings",
    "section_lines",
    "spaced_lines",
    "surface_actuators",
    "synchronised",
    "turning_angles",
]

Mapping = Literal["turning", "height"]


# ------------------------------------------------------------------------------ curves
class ControlCurve:
    """A planar curve ``u -> (x, z)`` in the section plane (base class)."""

    def point(self, u: np.ndarray | float) -> np.ndarray:
        """Points of the curve, shape ``(*u.shape, 2)`` as ``(x, z)``."""
        raise NotImplementedError

    def height(self, x: np.ndarray | float) -> np.ndarray:
        """Height ``z`` of the curve at the parameter ``u = x`` (used by the height mapping)."""
        return self.point(x)[..., 1]

    def scaled(self, s: float) -> ControlCurve:
        """The same family with its bending scaled by ``s`` (``s = 0``: the straight line)."""
        raise NotImplementedError


@dataclasses.dataclass(frozen=True)
class CircularArc(ControlCurve):
    """Circle of signed curvature ``kappa`` (1/length) with its apex at the origin.

    ``C(u) = (sin(kappa u) / kappa, (1 - cos(kappa u)) / kappa)``; ``u`` is the arc length from
    the apex, the tangent at the apex is +x, ``kappa > 0`` bends towards +z (valley side).
    ``kappa = 0`` is the x axis.
    """

    kappa: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "kappa", _check.number(self.kappa, "kappa"))

    def point(self, u: np.ndarray | float) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        k = float(self.kappa)
        # sin(ku)/k = u sinc(ku/pi); (1 - cos ku)/k = 2 sin^2(ku/2)/k = (ku/2) u sinc^2(ku/2pi)
        x = u * np.sinc(k * u / np.pi)
        z = 0.5 * k * u * u * np.sinc(k * u / (2.0 * np.pi)) ** 2
        return np.stack([x, z], axis=-1)

    def scaled(self, s: float) -> CircularArc:
        return CircularArc(self.kappa * s)


@dataclasses.dataclass(frozen=True)
class Parabola(ControlCurve):
    """Parabola ``z = c x^2 / 2`` (curvature ``c`` at the apex, the origin); ``u = x``."""

    c: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "c", _check.number(self.c, "c"))

    def point(self, u: np.ndarray | float) -> np.ndarray:
        x = np.asarray(u, dtype=float)
        return np.stack([x, 0.5 * self.c * x * x], axis=-1)

    def scaled(self, s: float) -> Parabola:
        return Parabola(self.c * s)


@dataclasses.dataclass(frozen=True, eq=False)
class SplineCurve(ControlCurve):
    """Cubic spline ``z(x)`` through user points (scipy ``CubicSpline``, not-a-knot ends).

    Parameters
    ----------
    x, z : (k,) float
        Points the curve passes through, ``x`` strictly increasing, ``k >= 2``. Outside
        ``[x[0], x[-1]]`` the end polynomials are extrapolated. ``u = x``.
    """

    x: Sequence[float] | np.ndarray
    z: Sequence[float] | np.ndarray
    _spline: CubicSpline = dataclasses.field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        x = _check.float_array(self.x, "spline x").ravel()
        z = _check.float_array(self.z, "spline z").ravel()
        if len(x) != len(z) or len(x) < 2:
            raise ConfigError(
                f"spline needs >= 2 points and len(x) == len(z), got {len(x)}, {len(z)}"
            )
        if np.any(np.diff(x) <= 0):
            raise ConfigError(f"spline x must be strictly increasing, got {x.tolist()}")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "z", z)
        bc = "not-a-knot" if len(x) > 2 else "natural"
        object.__setattr__(self, "_spline", CubicSpline(x, z, bc_type=bc, extrapolate=True))

    def point(self, u: np.ndarray | float) -> np.ndarray:
        x = np.asarray(u, dtype=float)
        return np.stack([x, self._spline(x)], axis=-1)

    def scaled(self, s: float) -> SplineCurve:
        return SplineCurve(self.x, np.asarray(self.z) * s)


# ------------------------------------------------------------------------------ chain
@dataclasses.dataclass(frozen=True)
class Chain:
    """A polyline inscribed in a control curve.

    Attributes
    ----------
    x : (m,) float
        Flat section coordinates of the chain points (section start, actuators, section end).
    u : (m,) float
        Curve parameter of each chain point.
    points : (m, 2) float
        Chain points ``(x, z)`` in the section plane; all on the curve.
    angles : (m - 2,) float
        Turning angle at each interior point (the actuators), radians, valley > 0.
    """

    x: np.ndarray
    u: np.ndarray
    points: np.ndarray
    angles: np.ndarray

    @property
    def angles_deg(self) -> np.ndarray:
        """(m - 2,) turning angles at the actuators, degrees."""
        return np.degrees(self.angles)


def turning_angles(points: np.ndarray) -> np.ndarray:
    """Signed exterior angles of a planar polyline at its interior vertices.

    Parameters
    ----------
    points : (m, 2) float
        Polyline vertices ``(x, z)``.

    Returns
    -------
    (m - 2,) float
        Radians in ``(-pi, pi]``; positive when the polyline turns counter-clockwise (towards
        +z when walking towards +x): the valley sign of the FOLD convention.
    """
    P = np.asarray(points, dtype=float)
    t1 = P[1:-1] - P[:-2]
    t2 = P[2:] - P[1:-1]
    cross = t1[:, 0] * t2[:, 1] - t1[:, 1] * t2[:, 0]
    dot = np.einsum("ij,ij->i", t1, t2)
    return np.arctan2(cross, dot)


def _next_parameter(curve: ControlCurve, u0: float, P0: np.ndarray, d: float, sign: int) -> float:
    """First parameter beyond ``u0`` (towards ``sign``) where the chord from ``P0`` equals ``d``."""

    def g(u: float) -> float:
        return float(np.hypot(*(curve.point(u) - P0)) - d)

    h = d / 8.0
    lo = u0
    for k in range(1, 8 * 16 + 1):  # scan up to 16 chord lengths of parameter
        hi = u0 + sign * k * h
        if g(hi) >= 0.0:
            a, b = sorted((lo, hi))
            from scipy.optimize import brentq  # lazy: scipy.optimize costs ~0.15 s to import

            return float(brentq(g, a, b, xtol=1e-15 * max(1.0, abs(u0) + d), rtol=1e-15))
        lo = hi
    raise ConfigError(
        f"the control curve has no point at chord distance {d:g} from u = {u0:g}; "
        "reduce the curvature or the actuator spacing"
    )


def chain_on_curve(
    curve: ControlCurve, x: Sequence[float] | np.ndarray, anchor: int | None = None
) -> Chain:
    """Inscribe the chain of flat section coordinates ``x`` in ``curve`` (turning mapping).

    Parameters
    ----------
    curve : ControlCurve
    x : (m,) float
        Strictly increasing flat section coordinates of the chain points (length unit); the
        consecutive differences are the segment lengths kept exactly.
    anchor : int, optional
        Index of the point placed at ``curve.point(x[anchor])``; default: the point with the
        smallest ``|x|``.

    Returns
    -------
    Chain
        Points on the curve with ``|P_{i+1} - P_i| = x_{i+1} - x_i`` (to round-off) and the
        turning angles at the ``m - 2`` interior points.
    """
    x = _check.float_array(x, "section coordinates").ravel()
    if len(x) < 3:
        raise ConfigError(f"a chain needs >= 3 points (two ends and an actuator), got {len(x)}")
    gaps = np.diff(x)
    if np.any(gaps <= 0):
        i = int(np.flatnonzero(gaps <= 0)[0])
        raise ConfigError(
            f"section coordinates must increase: x[{i}] = {x[i]}, x[{i + 1}] = {x[i + 1]}"
        )
    a = int(np.argmin(np.abs(x))) if anchor is None else int(anchor)
    if not 0 <= a < len(x):
        raise ConfigError(f"anchor {a} is not a chain index in [0, {len(x)})")
    u = np.empty_like(x)
    P = np.empty((len(x), 2))
    u[a] = x[a]
    P[a] = curve.point(x[a])
    for i in range(a + 1, len(x)):
        u[i] = _next_parameter(curve, u[i - 1], P[i - 1], gaps[i - 1], +1)
        P[i] = curve.point(u[i])
    for i in range(a - 1, -1, -1):
        u[i] = _next_parameter(curve, u[i + 1], P[i + 1], gaps[i], -1)
        P[i] = curve.point(u[i])
    return Chain(x=x, u=u, points=P, angles=turning_angles(P))


def height_angles_deg(
    curve: ControlCurve, x: Sequence[float] | np.ndarray, amplitude_deg: float
) -> np.ndarray:
    """Height mapping: ``rho_i = amplitude_deg * z(x_i) / max_j |z(x_j)|`` (degrees).

    ``x`` (n,) are the actuators' flat section coordinates; all zeros if the curve is flat
    there.
    """
    z = np.asarray(curve.height(np.asarray(x, dtype=float)), dtype=float)
    zmax = float(np.max(np.abs(z))) if z.size else 0.0
    if zmax == 0.0:
        return np.zeros_like(z)
    return float(amplitude_deg) * z / zmax


def curve_angles_deg(
    curve: ControlCurve,
    x: Sequence[float] | np.ndarray,
    ends: tuple[float, float],
    *,
    mapping: Mapping = "turning",
    amplitude_deg: float = 90.0,
    anchor: int | None = None,
) -> np.ndarray:
    """Fold angles (degrees, valley > 0) of actuator points at flat section coordinates ``x``.

    Parameters
    ----------
    curve : ControlCurve
    x : (n,) float
        Strictly increasing section coordinates of the actuator points.
    ends : (2,) float
        Section coordinates of the chain ends (``ends[0] < x[0]``, ``ends[1] > x[-1]``).
    mapping : "turning" or "height"
        See :func:`chain_on_curve` and :func:`height_angles_deg`.

    Returns
    -------
    (n,) float
    """
    x = _check.float_array(x, "section coordinates").ravel()
    amplitude_deg = _check.number(
        amplitude_deg, "amplitude_deg", -180.0, 180.0, lo_open=True, hi_open=True
    )
    if mapping == "turning":
        chain = chain_on_curve(
            curve, np.concatenate([[float(ends[0])], x, [float(ends[1])]]), anchor=anchor
        )
        return chain.angles_deg
    if mapping == "height":
        return height_angles_deg(curve, x, amplitude_deg)
    raise ConfigError(f"mapping must be 'turning' or 'height', got {mapping!r}")


# ------------------------------------------------------------------------------ patterns
def _flat_xy(cp: CreasePattern) -> np.ndarray:
    if not cp.is_flat:
        raise PatternError(
            "control curves need the flat state of the pattern (vertices with z = 0)"
        )
    return np.asarray(cp.vertices, dtype=float)[:, :2]


def _unit(direction: Sequence[float]) -> np.ndarray:
    e = np.asarray(direction, dtype=float).ravel()
    if e.shape != (2,) or not np.isfinite(e).all() or np.hypot(*e) == 0.0:
        raise ConfigError(f"section direction must be a non-zero 2-vector, got {list(direction)}")
    return e / np.hypot(*e)


def section_lines(
    cp: CreasePattern,
    edges: Sequence[int] | np.ndarray,
    direction: Sequence[float] = (1.0, 0.0),
    origin: float | None = None,
) -> tuple[np.ndarray, list[np.ndarray], tuple[float, float]]:
    """Group crease edges into actuator lines by their section coordinate.

    The section coordinate of an edge is ``(midpoint - o) . e`` in the flat pattern; edges
    whose coordinates agree to ``1e-9 * cp.size`` form one actuator line (one point ``P``).
    Edges must cross the section direction (not run along it).

    Parameters
    ----------
    cp : CreasePattern, flat
    edges : (k,) int
    direction : (2,) float
        Section direction ``e`` (normalised here).
    origin : float, optional
        Coordinate subtracted from all section coordinates; default: the centre of the
        pattern's extent along ``e``.

    Returns
    -------
    x : (n,) float
        Sorted section coordinates of the actuator lines.
    groups : list of (k_i,) int arrays
        The edges of each line.
    ends : (2,) float
        Section coordinates of the pattern's extent along ``e`` (the section ends).
    """
    V = _flat_xy(cp)
    e = _unit(direction)
    E = np.asarray(edges, dtype=np.int64).ravel()
    if E.size == 0:
        raise ConfigError("no actuator edges given")
    if E.min() < 0 or E.max() >= cp.n_edges:
        raise ConfigError(f"actuator edge ids must be in [0, {cp.n_edges}), got {E.tolist()}")
    s_vert = V @ e
    o = 0.5 * (s_vert.min() + s_vert.max()) if origin is None else float(origin)
    a, b = cp.edges[E, 0], cp.edges[E, 1]
    tol = 1e-9 * max(cp.size, 1e-300)
    s = 0.5 * (s_vert[a] + s_vert[b]) - o
    order = np.argsort(s, kind="stable")
    xs: list[float] = []
    groups: list[list[int]] = []
    for k in order:
        if xs and abs(s[k] - xs[-1]) <= tol:
            groups[-1].append(int(E[k]))
        else:
            xs.append(float(s[k]))
            groups.append([int(E[k])])
    ends = (float(s_vert.min() - o), float(s_vert.max() - o))
    return np.array(xs), [np.array(g, dtype=np.int64) for g in groups], ends


def spaced_lines(
    cp: CreasePattern,
    candidates: Sequence[int] | np.ndarray,
    spacing: float,
    direction: Sequence[float] = (1.0, 0.0),
    offset: float = 0.0,
) -> np.ndarray:
    """Choose actuator edges among ``candidates`` at a spacing ``d`` along the section.

    The candidate lines (see :func:`section_lines`) nearest to the targets
    ``x_first + offset + k * spacing`` (k = 0, 1, ...) are kept, each line at most once.

    Returns
    -------
    (k,) int
        Edge ids of the chosen lines (all edges of each line).
    """
    spacing = _check.number(spacing, "spacing", 0.0, lo_open=True)
    offset = _check.number(offset, "offset")
    x, groups, _ = section_lines(cp, candidates, direction)
    targets = np.arange(x[0] + offset, x[-1] + 0.5 * spacing, spacing)
    chosen = sorted({int(np.argmin(np.abs(x - t))) for t in targets})
    return np.concatenate([groups[i] for i in chosen])


def section_crossings(
    cp: CreasePattern,
    direction: Sequence[float] = (1.0, 0.0),
    offset: float | None = None,
    edges: Sequence[int] | np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    """Actuator points where a section line crosses creases of a flat pattern.

    The section line runs along ``e = direction`` at the signed distance ``offset`` (along
    ``n = (-e_y, e_x)``) from the centre of the pattern's bounding box; ``offset=None`` picks
    the middle between the two vertex levels nearest the centre, so the line meets no vertex.
    Each crease crossed strictly inside gives one actuator point.

    Parameters
    ----------
    cp : CreasePattern, flat
    direction : (2,) float
    offset : float, optional
    edges : (k,) int, optional
        Creases to consider (default ``cp.crease_edges``).

    Returns
    -------
    edges : (n,) int
        The crossed creases, sorted along the section.
    x : (n,) float
        Section coordinates of the crossings (from the bounding-box centre).
    ends : (2,) float
        Section coordinates of the pattern's extent along ``e`` (the chain ends).
    """
    V = _flat_xy(cp)
    e = _unit(direction)
    nrm = np.array([-e[1], e[0]])
    c = 0.5 * (V.min(0) + V.max(0))
    s = (V - c) @ e
    h = (V - c) @ nrm
    tol = 1e-9 * max(cp.size, 1e-300)
    if offset is None:
        levels = np.unique(np.round(h / tol) * tol)
        below, above = levels[levels <= 0.0], levels[levels > 0.0]
        if len(below) == 0 or len(above) == 0:
            raise PatternError("the pattern has no extent across the section direction")
        offset = 0.5 * (below.max() + above.min())
    E = cp.crease_edges if edges is None else np.asarray(edges, dtype=np.int64).ravel()
    a, b = cp.edges[E, 0], cp.edges[E, 1]
    ha, hb = h[a] - offset, h[b] - offset
    cross = (ha * hb < 0) & (np.abs(ha) > tol) & (np.abs(hb) > tol)
    t = ha[cross] / (ha[cross] - hb[cross])
    x = s[a[cross]] + t * (s[b[cross]] - s[a[cross]])
    order = np.argsort(x, kind="stable")
    ends = (float(s.min()), float(s.max()))
    return E[cross][order], x[order], ends


def curve_actuators(
    cp: CreasePattern,
    edges: Sequence[int] | np.ndarray,
    curve: ControlCurve,
    *,
    direction: Sequence[float] = (1.0, 0.0),
    origin: float | None = None,
    ends: tuple[float, float] | None = None,
    mapping: Mapping = "turning",
    amplitude_deg: float = 90.0,
    anchor: int | None = None,
) -> Actuators:
    """Actuators on ``edges`` with the fold angles the control curve gives.

    Parameters
    ----------
    cp : CreasePattern, flat state
    edges : (k,) int
        Actuated creases; edges on one line across the section share one actuator point.
    curve : ControlCurve
        In the section plane ``(x, z)``, ``x`` measured from ``origin`` along ``direction``.
    direction, origin : see :func:`section_lines`.
    ends : (2,) float, optional
        Section coordinates of the chain ends; default: the pattern's extent along the
        section.
    mapping : "turning" or "height"
        ``turning``: fold angle = turning angle of the inscribed chain (the actuator points lie
        on the curve); ``height``: :func:`height_angles_deg` with ``amplitude_deg``.
    anchor : int, optional
        Chain index placed at ``curve.point(x_anchor)`` (0 = the start end); default: the chain
        point nearest ``x = 0``.

    Returns
    -------
    Actuators
        ``targets_deg`` per edge (valley > 0).
    """
    x, groups, pattern_ends = section_lines(cp, edges, direction, origin)
    angles = curve_angles_deg(
        curve,
        x,
        pattern_ends if ends is None else ends,
        mapping=mapping,
        amplitude_deg=amplitude_deg,
        anchor=anchor,
    )
    E = np.concatenate(groups)
    T = np.concatenate([np.full(len(g), a) for g, a in zip(groups, angles, strict=True)])
    return Actuators(edges=E, targets_deg=T)


def curve_schedule(
    cp: CreasePattern,
    edges: Sequence[int] | np.ndarray,
    curve: ControlCurve,
    steps: int,
    **kwargs: Any,
) -> Actuators:
    """Actuators whose step ``k`` puts the points on ``curve.scaled(k / steps)``.

    Unlike the linear ramp of :meth:`Actuators.schedule`, every intermediate state of the
    turning mapping then also has its actuator points on a curve of the family (for a circle:
    curvature ``k kappa / steps``). Keyword arguments go to :func:`curve_actuators`.

    Returns
    -------
    Actuators
        With ``table_deg`` of shape (steps, n_edges); ``schedule(steps)`` starts flat.
    """
    steps = _check.integer(steps, "steps", 1)
    rows = [
        curve_actuators(cp, edges, curve.scaled(k / steps), **kwargs) for k in range(1, steps + 1)
    ]
    table = np.vstack([np.asarray(r.targets_deg, dtype=float) for r in rows])
    return Actuators(edges=rows[0].edges, table_deg=table)


def synchronised(edges: Sequence[int] | np.ndarray, angle_deg: float) -> Actuators:
    """All actuators folded alike: ``targets_deg = angle_deg`` for every edge."""
    E = _check.int_array(edges, "actuators.edges", lo=0)
    angle = _check.number(angle_deg, "angle_deg", -180.0, 180.0, lo_open=True, hi_open=True)
    return Actuators(edges=E, targets_deg=np.full(len(E), angle))


def current_angles_deg(cp: CreasePattern, edges: Sequence[int] | np.ndarray) -> np.ndarray:
    """Fold angles of ``edges`` in the pattern's current geometry (degrees): a schedule start.

    Use as ``actuators.schedule(steps, start_deg=current_angles_deg(cp, actuators.edges))`` to
    ramp from the current state instead of the flat one.
    """
    return cp.state_fold_angles()[np.asarray(edges, dtype=np.int64)]


# ------------------------------------------------------------------------------ surfaces
@dataclasses.dataclass(frozen=True)
class ControlSurface:
    """Paraboloid ``z = (kx x^2 + ky y^2) / 2`` over the flat pattern (origin: its centre).

    ``kx``, ``ky`` (1/length) are the principal curvatures at the apex, along the section
    directions ``e`` and ``n = (-e_y, e_x)``: ``kx * ky > 0`` asks for a synclastic (dome,
    ``K > 0``) form, ``kx * ky < 0`` for an anticlastic (saddle, ``K < 0``) one. Its two
    principal sections through the apex are the control curves ``Parabola(kx)`` and
    ``Parabola(ky)`` (see :func:`surface_actuators`).
    """

    kx: float
    ky: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "kx", _check.number(self.kx, "kx"))
        object.__setattr__(self, "ky", _check.number(self.ky, "ky"))

    @property
    def gaussian_curvature(self) -> float:
        """``kx * ky``: the Gaussian curvature asked for at the apex (1/length^2)."""
        return self.kx * self.ky

    def sections(self) -> tuple[Parabola, Parabola]:
        """The principal sections through the apex, along ``e`` and along ``n``."""
        return Parabola(self.kx), Parabola(self.ky)

    def scaled(self, s: float) -> ControlSurface:
        return ControlSurface(self.kx * s, self.ky * s)


def surface_actuators(
    cp: CreasePattern,
    surface: ControlSurface,
    *,
    direction: Sequence[float] = (1.0, 0.0),
    edges: tuple[Sequence[int] | np.ndarray, Sequence[int] | np.ndarray] | None = None,
    mapping: Mapping = "turning",
    amplitude_deg: float = 90.0,
) -> Actuators:
    """Actuators on two crossing sections whose fold angles put them on a control surface.

    The first section runs along ``e = direction`` through the middle of the pattern and its
    crossed creases (:func:`section_crossings`) get the turning angles of the section curve
    ``Parabola(kx)``; the second runs along ``n = (-e_y, e_x)`` with ``Parabola(ky)``. A
    crease crossed by both sections keeps the first one's angle.

    Parameters
    ----------
    cp : CreasePattern, flat
    surface : ControlSurface
    direction : (2,) float
        Direction ``e`` of the first section.
    edges : pair of (k,) int, optional
        Actuated creases of each section (default: every crease each section line crosses).
    mapping, amplitude_deg : see :func:`curve_actuators`.

    Returns
    -------
    Actuators
        ``targets_deg`` per edge (valley > 0): the rotation angles only; add a base fold for
        a folded form.
    """
    e = _unit(direction)
    n = np.array([-e[1], e[0]])
    out_e: list[np.ndarray] = []
    out_t: list[np.ndarray] = []
    for k, (d, curve) in enumerate(zip((e, n), surface.sections(), strict=True)):
        if edges is None:
            E, _, _ = section_crossings(cp, direction=tuple(d))
        else:
            E = np.asarray(edges[k], dtype=np.int64).ravel()
        if out_e:
            E = E[~np.isin(E, np.concatenate(out_e))]
        if E.size == 0:
            continue
        acts = curve_actuators(
            cp, E, curve, direction=tuple(d), mapping=mapping, amplitude_deg=amplitude_deg
        )
        out_e.append(np.asarray(acts.edges, dtype=np.int64))
        out_t.append(np.asarray(acts.targets_deg, dtype=float))
    if not out_e:
        raise PatternError("neither section of the control surface crosses a crease")
    return Actuators(edges=np.concatenate(out_e), targets_deg=np.concatenate(out_t))
