"""Follower pressure: a pressure along the facets' current normals (closed forms of a hinged
flap, finite-difference load stiffness, work balance)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.loads import FollowerPressure, pressure_load
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene, scene_from_dict

K_FOLD = 0.3
L = np.sqrt(2.0)  # crease length (the diagonal of the unit square)
ARM = 1.0 / np.sqrt(2.0)  # distance of the free corner (0, 1) from the crease


def _flap():
    """A unit square folding along its diagonal (0,0)-(1,1): triangle (0, 1, 2) held, the
    flap (0, 2, 3) free to turn about the crease (only its corner (0, 1) moves)."""
    V = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]])
    cp = bh.CreasePattern(V, E, ["B", "B", "B", "B", "V"])
    model = BarHingeModel.from_pattern(cp, "N4B5", Material(E=1e7, nu=0.3, t=0.01),
                                       fold_stiffness=K_FOLD)  # fmt: skip
    flap = next(i for i, f in enumerate(cp.faces) if 3 in f)
    supports = np.zeros((model.n_nodes, 3), bool)
    supports[[0, 1, 2]] = True
    return model, flap, supports


def test_follower_pressure_turns_the_flap_linearly():
    """Lumped to the flap's corners, the pressure p on its area A = 1/2 puts p A / 3 on the
    free corner, at distance 1/sqrt 2 from the crease. Following the flap it keeps its
    moment, so the fold spring k L rho = p A ARM / 3 at every load factor: rho is linear in
    the load (closed form); a fixed pressure loses moment as cos rho."""
    model, flap, supports = _flap()
    p = 3.0
    scene = Scene(model, supports=supports, follower=FollowerPressure(p, [flap]), steps=5,
                  options={"tol_force": 1e-12, "tol_disp": 1e-12})  # fmt: skip
    path = bh.solve(scene)
    rho = np.abs(np.radians(path.fold_angles_deg[:, 4]))
    lam = np.linspace(0.0, 1.0, 6)
    np.testing.assert_allclose(rho, lam * p * 0.5 * ARM / (3 * K_FOLD * L), rtol=1e-4, atol=1e-9)
    assert rho[-1] > np.radians(40.0)  # a large rotation: the direction matters
    assert not any("work balance" in ev for ev in path.meta["events"])
    # the supports carry the turned load: reactions balance it at the final geometry
    applied = FollowerPressure(p, [flap]).force(model, path.X[-1]).reshape(-1, 3).sum(axis=0)
    np.testing.assert_allclose(path.reactions[-1].sum(axis=0), -applied, atol=1e-9)
    assert abs(applied[0]) > 0.1 * np.linalg.norm(applied)  # it has turned away from z
    arc = bh.solve(Scene(model, supports=supports, follower=FollowerPressure(p, [flap]),
                         steps=8, control="arc_length"))  # fmt: skip
    assert arc.load_factor[-1] == pytest.approx(1.0)
    assert abs(np.radians(arc.fold_angles_deg[-1, 4])) == pytest.approx(rho[-1], rel=1e-4)
    fixed = bh.solve(Scene(model, supports=supports, loads=pressure_load(model, p, [flap]),
                           steps=5, options={"tol_force": 1e-12, "tol_disp": 1e-12}))  # fmt: skip
    want = brentq(lambda r: K_FOLD * L * r - p * 0.5 * ARM / 3 * np.cos(r), 0.0, np.pi / 2)
    assert abs(np.radians(fixed.fold_angles_deg[-1, 4])) == pytest.approx(want, rel=1e-4)
    assert want < 0.85 * rho[-1]


def test_work_of_the_turning_load_converges_to_the_stored_energy():
    """The external work of the follower load, integrated along the path (third order),
    meets the fold energy it stores: the mismatch falls about 8x per halved step."""
    model, flap, supports = _flap()
    mis = []
    for steps in (10, 20):
        opts = {"tol_force": 1e-12, "tol_disp": 1e-12}
        fol = FollowerPressure(3.0, [flap])
        path = bh.solve(Scene(model, supports=supports, follower=fol, steps=steps, options=opts))
        mis.append(path.meta["work_balance"]["rel_mismatch"])
    assert mis[0] < 2e-4 and 6.0 < mis[0] / mis[1] < 10.0


def test_follower_load_stiffness_matches_finite_differences():
    cp = bh.families.miura(2, 2, fold=25.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", Material(E=1e6, nu=0.3, t=0.01))
    fp = FollowerPressure(2.0)
    X = np.asarray(model.X0, float)
    np.testing.assert_allclose(fp.force(model, X), pressure_load(model, 2.0).ravel(), atol=1e-14)
    Xp = X + 0.05 * np.random.default_rng(0).normal(size=X.shape)
    K = fp.stiffness(model, Xp).toarray()
    h = 1e-6
    fd = np.empty_like(K)
    for j in range(X.size):
        e = np.zeros(X.size)
        e[j] = h
        fd[:, j] = (fp.force(model, Xp.ravel() + e) - fp.force(model, Xp.ravel() - e)) / (2 * h)
    np.testing.assert_allclose(K, fd, atol=1e-8 * np.abs(K).max())
    assert np.abs(K - K.T).max() > 1e-3  # open surface: not symmetric


def test_scene_toml_follower_pressure_and_its_errors():
    base = {"pattern": {"family": "miura", "params": {"nx": 2, "ny": 2}}, "solve": {"steps": 2}}
    group = {"pressure": 0.5, "follower": True, "faces": [0, 1]}
    scene = scene_from_dict({**base, "supports": [{"where": "left"}], "loads": [group]})
    assert scene.follower is not None and scene.follower.p == 0.5 and scene.control == "load"
    bad = [
        ({"loads": [{"pressure": 1.0, "follower": "yes"}]}, "expected true/false"),
        ({"loads": [{"follower": True, "force": [0, 0, 1], "nodes": [0]}]}, "pressure"),
        ({"loads": [{"pressure": 1.0, "follower": True, "faces": [999]}]}, "faces"),
        ({"load_cases": {"a": [{"pressure": 1.0, "follower": True}]}}, "not in load cases"),
    ]
    for extra, words in bad:
        with pytest.raises(ConfigError, match=words):
            scene_from_dict({**base, "supports": [{"where": "left"}], **extra})
