"""Distributed loads, load cases and combinations in a scene."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.loads import line_load, pressure_load, projected_load
from barhinge.scene import scene_from_dict


def _roof():
    """A folded Miura sheet: facets at many inclinations."""
    cp = bh.families.miura(3, 2, fold=50.0)
    return bh.BarHingeModel.from_pattern(cp, "N4B5")


def _facets(m):
    X = np.asarray(m.X0)
    out = []
    for f in m.pattern.faces:
        P = X[list(f)]
        out.append(0.5 * np.cross(P, np.roll(P, -1, axis=0)).sum(0))
    return np.array(out)  # area vectors A n


def test_pressure_resultant_is_the_sum_of_area_vectors():
    """A uniform pressure on a surface has the resultant p * sum(A n) (the vector area),
    and each facet's share acts along its own normal."""
    m = _roof()
    An = _facets(m)
    F = pressure_load(m, 2.5)
    np.testing.assert_allclose(F.sum(0), 2.5 * An.sum(0), rtol=1e-12)
    F0 = pressure_load(m, 2.5, faces=[0])
    f0 = list(m.pattern.faces[0])
    np.testing.assert_allclose(F0[f0], np.tile(2.5 * An[0] / len(f0), (len(f0), 1)), rtol=1e-12)


def test_projected_load_is_per_unit_plan_area():
    """Snow q per unit plan area: total = q * projected area, downwards, whatever the fold
    (the plan area of a Miura sheet is the area of its planform, computed here from the
    facets' projections independently of the load code)."""
    m = _roof()
    X = np.asarray(m.X0)
    plan = 0.0
    for f in m.pattern.faces:  # shoelace formula in the xy plane
        P = X[list(f)]
        plan += 0.5 * abs(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))
    F = projected_load(m, 0.8)
    np.testing.assert_allclose(F.sum(0), [0.0, 0.0, -0.8 * plan], rtol=1e-12, atol=1e-12)
    # wind-like: along +x, per unit area projected on the yz plane
    Fx = projected_load(m, 1.0, direction=(2.0, 0.0, 0.0))
    assert Fx.sum(0)[0] == pytest.approx(np.abs(_facets(m)[:, 0]).sum(), rel=1e-12)


def test_line_load_resultant_and_share():
    m = _roof()
    E = np.asarray(m.pattern.edges)
    e = np.flatnonzero(np.asarray(m.pattern.assignment) == "B")[:4]
    L = np.linalg.norm(np.asarray(m.X0)[E[e, 1]] - np.asarray(m.X0)[E[e, 0]], axis=1).sum()
    F = line_load(m, [0.0, 0.0, -3.0], e)
    np.testing.assert_allclose(F.sum(0), [0.0, 0.0, -3.0 * L], rtol=1e-12)
    assert set(np.flatnonzero(np.abs(F).sum(1))) == set(E[e].ravel().tolist())


SCENE = {
    "pattern": {"family": "miura", "params": {"nx": 2, "ny": 2, "fold": 50.0}},
    "supports": [{"where": "left"}],
    "load_cases": {
        "dead": [{"self_weight": {"area_density": 2.0}}],
        "snow": [{"projected": 0.5}],
        "wind": [{"pressure": -0.2, "faces": [0, 1]}, {"line_load": [1.0, 0, 0], "edges": [0]}],
    },
    "combinations": {"ULS": {"dead": 1.35, "snow": 1.5}},
    "solve": {"load_case": "ULS", "steps": 2},
}


def test_scene_load_cases_and_combinations():
    sc = scene_from_dict(SCENE)
    c = sc.load_cases
    assert set(c) == {"dead", "snow", "wind", "ULS"}
    np.testing.assert_allclose(c["ULS"], 1.35 * c["dead"] + 1.5 * c["snow"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(sc.loads, c["ULS"], rtol=0, atol=0)
    np.testing.assert_allclose(sc.with_load_case("snow").loads, c["snow"], rtol=0, atol=0)
    g = 9.81 * 2.0
    assert c["dead"].sum(0)[2] == pytest.approx(
        -g
        * sum(
            0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, 0)).sum(0))
            for P in (np.asarray(sc.model.X0)[list(f)] for f in sc.model.pattern.faces)
        ),
        rel=1e-12,
    )


@pytest.mark.parametrize(
    "change, msg",
    [
        ({"combinations": {"ULS": {"ice": 1.0}}}, "ice"),
        ({"solve": {"load_case": "nope"}}, "nope"),
        ({"loads": [{"force": [0, 0, 1], "where": "right"}]}, "either"),
        ({"load_cases": {"w": [{"line_load": [0, 0, 1], "where": "right"}]}}, "edges"),
        ({"load_cases": {"w": [{"faces": [0]}]}}, "needs"),
        ({"load_cases": {"w": [{"pressure": 1.0, "faces": [99]}]}}, "faces"),
    ],
)
def test_bad_load_input_is_a_one_line_error(change, msg):
    d = {**SCENE, **change}
    with pytest.raises(ConfigError, match=msg):
        scene_from_dict(d)
