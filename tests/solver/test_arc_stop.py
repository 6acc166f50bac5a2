"""Arc-length stop criteria: a load factor, a displacement component, a number of limit points,
the first loss of stability.

Reference: the von Mises two-bar truss of ``barhinge.verify`` (half span a = 1, rise h = 0.3,
EA = 1000, Green-strain bars). With Green strain ``eps = (L^2 - L0^2) / (2 L0^2)`` and the
apex at height z, vertical equilibrium gives the closed-form load-deflection curve
``P(z) = EA z (h^2 - z^2) / L0^3`` (positive downwards; Krenk 2009, "Non-linear Modeling and
Analysis of Solids and Structures", ch. 1), with its maximum ``P_max`` at ``z = h / sqrt(3)``
and its minimum ``-P_max`` at ``z = -h / sqrt(3)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError, ConvergenceError
from barhinge.scene import Scene
from barhinge.solver_options import SolverOptions
from barhinge.verify import von_mises_limit_load, von_mises_model

A, H, EA = 1.0, 0.3, 1000.0
L0 = math.hypot(A, H)
P_MAX = von_mises_limit_load()
FACTOR = 1.5  # reference load = 1.5 P_max downwards


def p_closed_form(z: np.ndarray | float) -> np.ndarray | float:
    """Downward apex load in equilibrium at apex height z (Green-strain bars)."""
    return EA * z * (H**2 - z**2) / L0**3


def scene(steps: int = 20, control: str = "arc_length", **opts) -> tuple[Scene, int]:
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -FACTOR * P_MAX
    options = {"max_arc_steps": 400, **opts}
    return Scene(model, supports=S, loads=P, control=control, steps=steps, options=options), apex


def test_every_state_lies_on_the_closed_form_curve():
    sc, apex = scene(arc_stop_displacement={"node": 2, "axis": "z", "value": -0.5})
    p = bh.solve(sc)
    z = p.X[:, apex, 2]
    np.testing.assert_allclose(p.load_factor * FACTOR * P_MAX, p_closed_form(z), atol=1e-8)


def test_displacement_stop_lands_exactly_past_both_limit_points():
    u = -0.5  # apex from z = 0.3 to -0.2: past the maximum and the minimum of the load
    sc, apex = scene(arc_stop_displacement={"node": apex_id(), "axis": "z", "value": u})
    p = bh.solve(sc)
    assert p.converged and p.meta["arc_stop"] == {"criterion": "displacement", "value": u}
    z_end = p.X[-1, apex, 2]
    assert z_end == pytest.approx(H + u, abs=1e-14)
    lam_exact = p_closed_form(H + u) / (FACTOR * P_MAX)
    assert p.load_factor[-1] == pytest.approx(lam_exact, abs=1e-9)
    assert np.all(p.X[:-1, apex, 2] > H + u)  # no state beyond the stop
    events = p.meta["events"]
    assert any(e.startswith("limit point (load maximum)") for e in events), events
    assert any(e.startswith("limit point (load minimum)") for e in events), events


def test_load_factor_stop_lands_exactly_and_replaces_the_default():
    sc, _ = scene(arc_stop_load_factor=0.4)
    p = bh.solve(sc)
    assert p.load_factor[-1] == pytest.approx(0.4, abs=1e-12)
    assert p.meta["arc_stop"] == {"criterion": "load_factor", "value": 0.4}
    assert np.all(p.load_factor <= 0.4 + 1e-12)


def test_limit_point_stop_ends_just_past_the_load_maximum():
    sc, apex = scene(arc_stop_limit_points=1)
    p = bh.solve(sc)
    assert p.meta["arc_stop"]["criterion"] == "limit_points"
    lam = p.load_factor
    assert lam[-1] < lam[-2]  # the load factor has turned
    assert np.all(np.diff(lam[:-1]) > 0)  # and turned once, at the end
    assert lam.max() * FACTOR == pytest.approx(1.0, rel=2e-3)  # the maximum is P_max
    assert p.X[-1, apex, 2] < H / math.sqrt(3) < p.X[-3, apex, 2]


def test_instability_stop_ends_at_the_first_state_past_the_load_maximum():
    """Past ``P_max`` the apex snaps: the first state whose tangent has a negative eigenvalue
    is the first one beyond ``z = h / sqrt(3)``, and the path ends there."""
    sc, apex = scene(arc_stop_instability=True)
    p = bh.solve(sc)
    assert p.converged and p.meta["arc_stop"]["criterion"] == "instability"
    assert p.meta["arc_stop"]["value"] == p.load_factor[-1]
    z = p.X[:, apex, 2]
    assert z[-1] < H / math.sqrt(3) < z[-2]
    neg = p.meta["negative_eigenvalues"]
    assert neg[-1] > 0 and all(n == 0 for n in neg[:-1])
    # every state on the closed-form curve, the one past the maximum too
    np.testing.assert_allclose(p.load_factor * FACTOR * P_MAX, p_closed_form(z), atol=1e-8)
    # the tangent interpolated between the last two states: a load factor inside the
    # bracket, below the closed-form maximum 1 / FACTOR (across a limit point the load
    # factor is not linear in the state, so no closer than that)
    from barhinge.analysis.buckling import critical_between

    model, S, _ = von_mises_model()
    lam, exact = p.load_factor, 1.0 / FACTOR
    crit = critical_between(model, S, p.X[-2], p.X[-1], lam[-2], lam[-1])
    assert min(lam[-2], lam[-1]) <= crit <= exact


def test_instability_stop_alone_replaces_the_default_load_factor():
    o = SolverOptions(arc_stop_instability=True)
    assert o.has_arc_stop() and o.arc_stop_lambda() is None
    with pytest.raises(ConfigError, match="arc_stop_instability"):
        SolverOptions(arc_stop_instability=1)


def test_first_criterion_met_wins():
    sc, _ = scene(
        arc_stop_load_factor=0.5,
        arc_stop_displacement={"node": 2, "axis": "z", "value": -0.5},
    )
    p = bh.solve(sc)
    assert p.meta["arc_stop"]["criterion"] == "load_factor"


def test_step_cap_names_what_was_not_reached():
    sc, _ = scene(max_arc_steps=5, arc_stop_displacement={"node": 2, "axis": "z", "value": -0.5})
    with pytest.raises(ConvergenceError, match="before reaching displacement z = -0.5 of node 2"):
        bh.solve(sc)


def apex_id() -> int:
    return von_mises_model()[2]


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ({"node": 2, "axis": "w", "value": 1.0}, "axis"),
        ({"node": -1, "axis": "z", "value": 1.0}, "node"),
        ({"node": 2, "axis": "z"}, "missing"),
        ({"node": 2, "axis": "z", "value": 1.0, "dof": 3}, "unknown"),
        ({"node": 2, "axis": "z", "value": float("nan")}, "finite"),
        ([2, "z", 1.0], "expected a table"),
    ],
)
def test_bad_displacement_stop_is_a_one_line_error(spec, match):
    with pytest.raises(ConfigError, match=match):
        SolverOptions(arc_stop_displacement=spec)


def test_stop_on_a_missing_node_or_a_fixed_component_is_named():
    sc, _ = scene(arc_stop_displacement={"node": 9, "axis": "z", "value": -0.1})
    with pytest.raises(ConfigError, match="has 3 nodes"):
        bh.solve(sc)
    sc, _ = scene(arc_stop_displacement={"node": 0, "axis": "z", "value": -0.1})
    with pytest.raises(ConfigError, match="fixed by a support"):
        bh.solve(sc)


def test_arc_stops_under_another_control_are_an_error():
    sc, _ = scene(control="load", arc_stop_limit_points=1)
    with pytest.raises(ConfigError, match="arc_length' only"):
        bh.solve(sc)


def test_stops_read_from_a_toml_options_table():
    import tomllib

    d = tomllib.loads(
        'arc_stop_displacement = { node = 2, axis = "z", value = -0.5 }\n'
        "arc_stop_limit_points = 2\n"
    )
    o = SolverOptions.from_dict(d)
    assert o.arc_stop_displacement == {"node": 2, "axis": "z", "value": -0.5}
    assert o.arc_stop_limit_points == 2 and o.arc_stop_lambda() is None
    assert SolverOptions().arc_stop_lambda() == 1.0


def test_a_leap_far_past_the_stop_lands_in_sub_steps():
    """A thin pinned square plate under a transverse load stiffens by orders of magnitude as
    its membrane takes over: its first arc-length increment, sized on the flat plate's
    bending, leaps to a load factor ~1e11 and the direct correction onto 1 fails from both
    sides. The landing then goes from the state before in load-controlled sub-steps, and
    ends on the state a load-controlled solve in 20 steps reaches (an independent path)."""
    from barhinge.pattern.crease import CreasePattern
    from barhinge.pattern.subdivide import subdivided

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = CreasePattern(sq, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    model = bh.BarHingeModel.from_pattern(
        subdivided(cp, 4)[0], "N5B8", bh.Material(E=70e9, nu=0.33, t=1e-4)
    )
    X = np.asarray(model.X0)
    edge = np.isclose(X[:, :2], 0.0).any(axis=1) | np.isclose(X[:, :2], 1.0).any(axis=1)
    S = np.zeros((model.n_nodes, 3), bool)
    S[edge] = True
    P = np.zeros((model.n_nodes, 3))
    P[~edge, 2] = -1e3 / np.count_nonzero(~edge)  # 1 kN in all
    arc = bh.solve(Scene(model, supports=S, loads=P, control="arc_length", steps=10))
    assert arc.converged and arc.load_factor[-1] == 1.0
    ref = bh.solve(Scene(model, supports=S, loads=P, control="load", steps=20))
    w = -ref.X[-1][:, 2].min()
    assert w > 100 * model.material.t  # deep in the membrane regime
    np.testing.assert_allclose(arc.X[-1], ref.X[-1], atol=1e-8 * w)


def test_load_increment_cap_samples_a_stiffening_path():
    """Pulled upwards, the truss stiffens (the bars stretch, ``P ~ z^3``), so MGDCM's
    increments climb ever more load (0.17 .. 0.36 of it from a first 0.1); with
    ``arc_max_load_increment = 0.1`` no increment climbs more, every state still lies on the
    closed-form curve, and the path ends at the same load factor 1 and apex height."""
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = 20.0 * P_MAX  # upwards

    def path(**opts):
        sc = Scene(model, supports=S, loads=P, control="arc_length", steps=10,
                   options={"max_arc_steps": 400, **opts})  # fmt: skip
        return bh.solve(sc)

    free = path()
    capped = path(arc_max_load_increment=0.1)
    assert np.abs(np.diff(free.load_factor)).max() > 0.2
    assert np.abs(np.diff(capped.load_factor)).max() <= 0.1 * (1 + 1e-9)
    assert capped.load_factor[-1] == pytest.approx(1.0, abs=1e-12)
    z = capped.X[:, apex, 2]
    np.testing.assert_allclose(-capped.load_factor * 20.0 * P_MAX, p_closed_form(z), atol=1e-8)
    assert z[-1] == pytest.approx(free.X[-1, apex, 2], abs=1e-9)


@pytest.mark.parametrize("bad", [0.0, -0.1, float("inf")])
def test_load_increment_cap_must_be_positive(bad):
    with pytest.raises(ConfigError, match="arc_max_load_increment"):
        SolverOptions(arc_max_load_increment=bad)
