"""Scenes (TOML, supports, loads), the FoldPath npz round trip and the `fold` command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app
from barhinge.errors import ConfigError
from barhinge.scene import restraint_321, scene_from_dict, self_weight

SCENES = Path(__file__).resolve().parents[2] / "data" / "scenes"

ROOF = {
    "name": "roof",
    "pattern": {"family": "yoshimura", "params": {"nx": 2, "ny": 1, "fold": 30.0}},
    "model": {"scheme": "N5B8", "fold_stiffness": 1.0},
    "supports": [{"where": "bottom"}, {"where": "top", "dofs": "z"}],
    "loads": [{"self_weight": {"area_density": 0.1}}],
    "solve": {"steps": 3, "control": "load"},
}


def test_toml_scene_solves_with_equilibrium(tmp_path):
    scene = bh.load_scene(SCENES / "yoshimura_roof.toml")
    assert scene.control == "load" and scene.steps == 5 and not scene.auto_restrained
    path = bh.solve(scene)
    assert path.converged and path.n_states == 6
    np.testing.assert_allclose(path.load_factor, np.linspace(0, 1, 6), atol=1e-14)
    # sum of the applied loads + reactions vanishes at every step (self-equilibrated
    # internal forces); compared with the total weight
    W = np.abs(scene.loads.sum(0)).max()
    for i in range(path.n_states):
        total = (path.load_factor[i] * scene.loads + path.reactions[i]).sum(0)
        np.testing.assert_allclose(total, 0.0, atol=1e-8 * W)
    # elastic: the work of the loads equals the stored energy (trapezoid, 5 steps)
    assert path.external_work[-1] == pytest.approx(path.energy[-1], rel=1e-3)


def test_self_weight_total_equals_area_times_density():
    scene = scene_from_dict(ROOF)
    cp = scene.model.pattern
    F = self_weight(scene.model, 2.0, (0.0, 0.0, -10.0))
    area = 0.0
    X = scene.model.X0
    for f in cp.faces:  # shoelace in 3D: half the norm of the summed cross products
        P = X[list(f)]
        area += 0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, 0)).sum(0))
    np.testing.assert_allclose(F.sum(0), [0.0, 0.0, -20.0 * area], rtol=1e-12)


@pytest.mark.parametrize(
    ("where", "change", "key"),
    [
        ((), {"bogus": 1}, "bogus"),
        (("model",), {"stiffnes_ratio": 3}, "stiffnes_ratio"),
        (("solve",), {"stepz": 3}, "stepz"),
        (("pattern", "params"), {"nxx": 3}, "nxx"),
    ],
)
def test_unknown_keys_are_named(where, change, key):
    d = json.loads(json.dumps(ROOF))
    node = d
    for w in where:
        node = node[w]
    node.update(change)
    with pytest.raises(ConfigError, match=key):
        scene_from_dict(d)


def test_bad_shapes_and_controls_are_config_errors():
    scene = scene_from_dict(ROOF)
    n = scene.model.n_nodes
    with pytest.raises(ConfigError, match=r"\(n_nodes, 3\)"):
        bh.Scene(scene.model, loads=np.zeros((n, 2)))
    with pytest.raises(ConfigError, match="needs actuators"):
        bh.Scene(scene.model, loads=np.ones((n, 3)), control="fold_angle")
    with pytest.raises(ConfigError, match="both supported and prescribed"):
        S = np.zeros((n, 3), bool)
        S[0, 0] = True
        U = np.full((n, 3), np.nan)
        U[0, 0] = 0.1
        bh.Scene(scene.model, supports=S, prescribed=U)


def test_automatic_321_restraint_removes_exactly_the_rigid_body_modes():
    scene = scene_from_dict(
        {**ROOF, "supports": None}
        if False
        else {k: v for k, v in ROOF.items() if k not in ("supports", "loads", "solve")}
        | {
            "actuators": {
                "edges": [int(bh.families.yoshimura(2, 1, fold=30.0).crease_edges[0])],
                "targets_deg": [40.0],
            }
        }
    )
    S = scene.supports
    assert scene.auto_restrained and S.sum() == 6
    assert np.array_equal(S, restraint_321(scene.model))
    # the tangent restricted to the free DOFs is nonsingular (no rigid-body mode left)
    K = scene.model.evaluate(scene.model.X0).K.toarray()
    free = ~S.ravel()
    ev = np.linalg.eigvalsh(K[np.ix_(free, free)])
    assert ev.min() > 1e-9 * ev.max()


def _pushed_roof(steps: int):
    return scene_from_dict(
        {
            "pattern": {"family": "yoshimura", "params": {"nx": 2, "ny": 2, "fold": 30.0}},
            "model": {"scheme": "N5B8", "fold_stiffness": 1.0},
            "supports": [{"where": "bottom"}],
            "prescribed": [{"where": "top", "displacement": [0.0, -0.02, 0.0]}],
            "solve": {"steps": steps},
        }
    )


def test_prescribed_displacement_control_reaches_the_targets():
    scene = _pushed_roof(4)
    assert scene.control == "displacement"
    path = bh.solve(scene)
    top = np.flatnonzero(np.isfinite(scene.prescribed[:, 1]))
    assert len(top) >= 2
    np.testing.assert_allclose(
        path.X[-1, top] - path.X[0, top], [[0.0, -0.02, 0.0]] * len(top), atol=1e-14
    )
    assert path.energy[-1] > 0


def test_work_of_reactions_converges_to_stored_energy_at_third_order():
    """External work -> stored energy like h^3: the solver integrates F . dq with Simpson's
    rule on quadratic interpolants through three consecutive states (the first increment by
    the trapezoidal rule, whose local error is also O(h^3))."""
    steps = np.array([4, 8, 16])
    err = []
    for n in steps:
        path = bh.solve(_pushed_roof(int(n)))
        err.append(abs(path.external_work[-1] / path.energy[-1] - 1))
    slope = np.polyfit(np.log(1.0 / steps), np.log(err), 1)[0]
    assert slope == pytest.approx(3.0, abs=0.2)
    assert err[-1] < 1e-4


def test_foldpath_npz_round_trip_is_lossless(tmp_path):
    path = bh.solve(scene_from_dict(ROOF))
    f = path.save(tmp_path / "p.npz")
    back = bh.FoldPath.load(f)
    for name in (
        "X",
        "fold_angles_deg",
        "actuator_edges",
        "actuator_targets_deg",
        "actuator_moments",
        "energy_bars",
        "energy_bend",
        "energy_fold",
        "reactions",
        "load_factor",
        "iterations",
        "wall_time",
        "external_work",
    ):
        a, b = getattr(path, name), getattr(back, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert back.residual_norms == path.residual_norms
    assert back.meta == path.meta and back.kind == "bar-hinge" and back.converged


def _write_scene(tmp_path: Path, extra: str = "") -> Path:
    text = (SCENES / "yoshimura_roof.toml").read_text().replace("steps = 5", "steps = 2")
    f = tmp_path / "s.toml"
    f.write_text(text + extra)
    return f


def test_cli_fold_writes_outputs(tmp_path):
    out = tmp_path / "out"
    res = CliRunner().invoke(
        app, ["fold", str(_write_scene(tmp_path)), "--out", str(out), "--json"]
    )
    assert res.exit_code == 0, res.output
    info = json.loads(res.stdout)
    assert info["converged"] and info["n_states"] == 3
    for name in ("fold_path.npz", "summary.json", "states.csv"):
        assert (out / name).is_file()
    assert bh.FoldPath.load(out / "fold_path.npz").n_states == 3
    from barhinge.linalg.backends import available_backends

    assert info["linear_solver"] == available_backends()[0]  # "auto": the fastest importable
    table = CliRunner().invoke(app, ["fold", str(_write_scene(tmp_path)), "--out", str(out)])
    assert table.exit_code == 0 and "linear solver" in table.stdout


def test_cli_fold_exit_codes(tmp_path):
    import subprocess
    import sys

    bad = _write_scene(tmp_path, "\n[extra]\nx = 1\n")
    cmd = [sys.executable, "-m", "barhinge.cli", "fold"]
    r = subprocess.run(
        [*cmd, str(bad), "--out", str(tmp_path / "o1")], capture_output=True, text=True
    )
    assert r.returncode == 2 and "extra" in r.stderr
    text = (
        _write_scene(tmp_path)
        .read_text()
        .replace(
            'control = "load"', 'control = "load"\noptions = { max_iter = 1, max_cutbacks = 0 }'
        )
    )
    f = tmp_path / "fail.toml"
    f.write_text(text)
    r = subprocess.run(
        [*cmd, str(f), "--out", str(tmp_path / "o2")], capture_output=True, text=True
    )
    assert r.returncode == 3 and "did not converge" in r.stderr
    part = bh.FoldPath.load(tmp_path / "o2" / "fold_path.npz")
    assert not part.converged and part.n_states >= 1
