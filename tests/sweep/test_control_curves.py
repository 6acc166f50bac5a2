"""Control curves: the turning mapping puts the actuator points on the requested curve."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from barhinge.actuators.curves import (
    CircularArc,
    Parabola,
    SplineCurve,
    chain_on_curve,
    curve_actuators,
    curve_angles_deg,
    curve_schedule,
    height_angles_deg,
    section_crossings,
    section_lines,
    spaced_lines,
    synchronised,
)
from barhinge.errors import ConfigError
from barhinge.pattern.crease import CreasePattern


def pleat(n: int, d: float = 1.0, width: float = 2.0) -> CreasePattern:
    """A strip of n panels of width d along x with creases at x = d, 2d, ... (alternating V/M)."""
    xs = np.arange(n + 1) * d
    V = np.array([[x, 0.0] for x in xs] + [[x, width] for x in xs])
    E, A = [], []
    for i in range(n + 1):
        E.append([i, i + n + 1])
        A.append("B" if i in (0, n) else ("V" if i % 2 else "M"))
    for i in range(n):
        E += [[i, i + 1], [i + n + 1, i + n + 2]]
        A += ["B", "B"]
    return CreasePattern(V, np.array(E), np.array(A))


def turtle(x0: np.ndarray, heading: float, lengths: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """Points of a polyline from x0: first segment at `heading`, then turn by each angle."""
    P = [np.asarray(x0, float)]
    h = heading
    for k, L in enumerate(lengths):
        if k > 0:
            h += turns[k - 1]
        P.append(P[-1] + L * np.array([np.cos(h), np.sin(h)]))
    return np.array(P)


def on_circle_error(P: np.ndarray, kappa: float) -> float:
    """Max distance of points from the circle of radius 1/kappa centred at (0, 1/kappa)."""
    R = 1.0 / kappa
    return float(np.max(np.abs(np.hypot(P[:, 0], P[:, 1] - R) - abs(R))))


@settings(max_examples=30, deadline=None)
@given(
    kappa=st.floats(0.01, 1.5).flatmap(lambda k: st.sampled_from([k, -k])),
    d=st.floats(0.1, 1.2),
    n=st.integers(1, 9),
)
def test_circle_chord_angle(kappa: float, d: float, n: int) -> None:
    """Equal chords d inscribed in a circle of curvature kappa turn by 2 arcsin(kappa d / 2).

    Elementary geometry (chord length 2 R sin(theta/2), Euclid III.20): each chord subtends the
    central angle theta = 2 arcsin(kappa d / 2), and the exterior angle between consecutive equal
    chords equals theta. The chain rebuilt from the computed angles (turtle, starting at the
    apex with the tangent-chord angle theta/2) lies on the circle to 1e-12.
    """
    x = (np.arange(n + 2) - (n + 1) // 2) * d  # chain point (n+1)//2 sits at the apex x = 0
    chain = chain_on_curve(CircularArc(kappa), x)
    Phi = 2.0 * np.arcsin(kappa * d / 2.0)
    np.testing.assert_allclose(chain.angles, Phi, rtol=0, atol=1e-12)
    a = (n + 1) // 2
    fwd = turtle(np.zeros(2), Phi / 2, np.full(len(x) - 1 - a, d), chain.angles[a:])
    bwd = turtle(np.zeros(2), np.pi - Phi / 2, np.full(a, d), -chain.angles[:a][::-1])
    assert on_circle_error(np.vstack([fwd, bwd]), kappa) < 1e-12
    # and the chain's own points: on the circle, chords exact
    assert on_circle_error(chain.points, kappa) < 1e-12
    np.testing.assert_allclose(np.hypot(*np.diff(chain.points, axis=0).T), d, rtol=0, atol=1e-12)


def test_straight_curve_gives_flat_and_sign_of_mountain() -> None:
    x = np.arange(6.0) - 2.5
    assert np.all(chain_on_curve(CircularArc(0.0), x).angles == 0.0)
    assert np.all(chain_on_curve(CircularArc(-0.4), x).angles < 0)  # bends to -z: mountain


def test_circle_chord_longer_than_diameter_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="chord distance"):
        chain_on_curve(CircularArc(1.0), [-3.0, 0.0, 3.0])


def _roots_step(poly_z: np.ndarray, x0: float, d: float, sign: int) -> float:
    """Independent chord step on z = polyval(poly_z, x): real root of (x-x0)^2+(z-z0)^2 = d^2.

    The nearest real root beyond x0 in the direction sign (numpy polynomial roots).
    """
    z0 = np.polyval(poly_z, x0)
    dz = np.polysub(poly_z, [z0])
    eq = np.polyadd(np.polymul(dz, dz), np.polymul([1.0, -x0], [1.0, -x0]))
    eq = np.polysub(eq, [d * d])
    r = np.roots(eq)
    r = r[np.abs(r.imag) < 1e-9].real
    r = r[sign * (r - x0) > 1e-9]
    return float(r[np.argmin(np.abs(r - x0))])


def _independent_chain(poly_z: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Turning angles (heading differences, np.unwrap) of the chain from polynomial roots."""
    a = int(np.argmin(np.abs(x)))
    X = np.empty_like(x)
    X[a] = x[a]
    for i in range(a + 1, len(x)):
        X[i] = _roots_step(poly_z, X[i - 1], x[i] - x[i - 1], +1)
    for i in range(a - 1, -1, -1):
        X[i] = _roots_step(poly_z, X[i + 1], x[i + 1] - x[i], -1)
    Z = np.polyval(poly_z, X)
    heading = np.unwrap(np.arctan2(np.diff(Z), np.diff(X)))
    return np.diff(heading)


@pytest.mark.parametrize("c", [0.8, -0.3, 0.05])
def test_parabola_against_polynomial_roots(c: float) -> None:
    x = np.array([-2.3, -1.5, -0.7, 0.1, 0.6, 1.4, 2.0])
    chain = chain_on_curve(Parabola(c), x)
    expected = _independent_chain(np.array([c / 2, 0.0, 0.0]), x)
    np.testing.assert_allclose(chain.angles, expected, rtol=0, atol=1e-10)


def test_spline_reproduces_a_cubic_against_polynomial_roots() -> None:
    """A not-a-knot cubic spline through samples of a cubic is that cubic (de Boor 2001,
    A Practical Guide to Splines, ch. IV): its chain must match the independent root chain."""
    poly = np.array([0.05, 0.2, -0.1, 0.3])
    xs = np.linspace(-3.0, 3.0, 7)
    curve = SplineCurve(xs, np.polyval(poly, xs))
    x = np.array([-2.0, -1.2, -0.5, 0.0, 0.9, 1.7, 2.5])
    chain = chain_on_curve(curve, x)
    np.testing.assert_allclose(chain.angles, _independent_chain(poly, x), rtol=0, atol=1e-10)
    np.testing.assert_allclose(chain.points[:, 1], np.polyval(poly, chain.points[:, 0]), atol=1e-12)


def test_pleat_actuators_fold_onto_the_circle_with_fold_sign() -> None:
    """Folding the pleat strip by the targets (3-D geometry) puts the crease lines on the circle,
    and CreasePattern.state_fold_angles recovers the targets with their sign (valley > 0)."""
    n, d, kappa = 6, 1.0, 0.35
    cp = pleat(n, d)
    acts = curve_actuators(cp, cp.crease_edges, CircularArc(kappa))
    Phi = np.degrees(2 * np.arcsin(kappa * d / 2))
    np.testing.assert_allclose(acts.targets_deg, Phi, rtol=0, atol=1e-10)
    # fold the strip: panel i is the chain segment i
    x, groups, ends = section_lines(cp, cp.crease_edges)
    chain = chain_on_curve(CircularArc(kappa), np.concatenate([[ends[0]], x, [ends[1]]]))
    xv = cp.vertices[:, 0] - 0.5 * n * d
    seg = np.clip(np.searchsorted(chain.x, xv, side="right") - 1, 0, n - 1)
    t = (xv - chain.x[seg]) / (chain.x[seg + 1] - chain.x[seg])
    XZ = chain.points[seg] + t[:, None] * (chain.points[seg + 1] - chain.points[seg])
    X3 = np.column_stack([XZ[:, 0], cp.vertices[:, 1], XZ[:, 1]])
    folded = cp.replaced(vertices=X3, faces=cp.faces)
    rho = folded.state_fold_angles()[acts.edges]
    np.testing.assert_allclose(rho, acts.targets_deg, rtol=0, atol=1e-9)
    assert on_circle_error(X3[:, [0, 2]], kappa) < 1e-12


def test_spaced_lines_and_schedule() -> None:
    cp = pleat(10)
    edges = spaced_lines(cp, cp.crease_edges, spacing=2.0)
    np.testing.assert_array_equal(np.sort(cp.vertices[cp.edges[edges, 0], 0]), [1, 3, 5, 7, 9])
    kappa, steps = 0.3, 4
    acts = curve_schedule(cp, edges, CircularArc(kappa), steps)
    table = acts.schedule(steps)
    assert table.shape == (steps + 1, 5)
    # the gaps are 1 (to the ends) and 2; a chord c of a circle of curvature k subtends
    # theta(c) = 2 arcsin(k c / 2) and the exterior angle between chords c1, c2 at their common
    # point is (theta(c1) + theta(c2)) / 2 (inscribed-angle theorem); step j: k = j kappa / steps.
    k = (np.arange(steps + 1) / steps)[:, None] * kappa

    def theta(c: float) -> np.ndarray:
        return 2 * np.arcsin(k * c / 2)

    np.testing.assert_allclose(table[:, 1:-1], np.degrees(np.repeat(theta(2.0), 3, 1)), atol=1e-10)
    ends = np.degrees((theta(1.0) + theta(2.0)) / 2)
    np.testing.assert_allclose(table[:, [0, -1]], np.repeat(ends, 2, 1), atol=1e-10)


def test_height_mapping_and_synchronised() -> None:
    x = np.array([-2.0, -1.0, 0.5, 2.0])
    np.testing.assert_allclose(height_angles_deg(Parabola(0.4), x, 60.0), 60.0 * x**2 / 4.0)
    assert np.all(height_angles_deg(Parabola(0.0), x, 60.0) == 0.0)
    s = synchronised([3, 1, 2], 45.0)
    np.testing.assert_array_equal(s.targets_deg, [45.0, 45.0, 45.0])
    cp = pleat(4)
    h = curve_actuators(cp, cp.crease_edges, Parabola(1.0), mapping="height", amplitude_deg=30.0)
    xs = cp.vertices[cp.edges[h.edges, 0], 0] - 2.0
    np.testing.assert_allclose(h.targets_deg, 30.0 * xs**2 / np.max(xs**2))


def test_figure_is_written(tmp_path) -> None:
    pytest.importorskip("matplotlib")
    from barhinge.plot.curves import plot_control_curve

    curve = CircularArc(0.3)
    chain = chain_on_curve(curve, np.arange(7.0) - 3.0)
    out = tmp_path / "c.png"
    plot_control_curve(curve, chain, path=out)
    assert out.stat().st_size > 1000


def test_section_crossings_of_a_sheared_pleat() -> None:
    """Creases from (i, 0) to (i + s W, W): the middle line y = W/2 meets them at i + s W / 2."""
    n, W, shear = 5, 2.0, 0.3
    cp0 = pleat(n, 1.0, W)
    V = cp0.vertices.copy()
    V[n + 1 :, 0] += shear * W
    cp = cp0.replaced(vertices=V, faces=cp0.faces)
    edges, x, ends = section_crossings(cp)
    centre = 0.5 * (0.0 + n + shear * W)
    np.testing.assert_allclose(x, np.arange(1, n) + shear * W / 2 - centre, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(cp.vertices[cp.edges[edges, 0], 0], np.arange(1, n))
    assert ends == (-centre, centre)
    # angles on those points: a circle through the crossings (equal gaps 1, end gaps differ)
    ang = curve_angles_deg(CircularArc(0.2), x, ends)
    chain = chain_on_curve(CircularArc(0.2), np.concatenate([[ends[0]], x, [ends[1]]]))
    np.testing.assert_allclose(ang, chain.angles_deg, rtol=0, atol=0)
    np.testing.assert_allclose(ang[1:-1], np.degrees(2 * np.arcsin(0.2 / 2)), atol=1e-12)
