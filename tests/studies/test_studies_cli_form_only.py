"""``barhinge fold --form-only``: a scene driven by actuators alone is folded by rigid
kinematics (the model it needs, docs/speed-accuracy.md); loads need the compliant model.

Reference: the Miura-ori has one rigid DOF and its fold angles at facet angle theta are
rho_zigzag = 2 theta and tan(rho_straight / 2) = cos(gamma) tan(theta) (Schenk & Guest 2013,
PNAS 110(9):3276), as given by ``bh.families.miura(fold=theta).fold_angles``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app
from barhinge.errors import ConfigError
from barhinge.families import miura_line_creases
from barhinge.results import FoldPath
from barhinge.scene import load_scene
from barhinge.solver.form import form_only_model, rigid_form

SCENES = Path(__file__).resolve().parents[2] / "data" / "scenes"


def _scene_toml(tmp_path: Path) -> Path:
    edges = miura_line_creases(bh.families.miura(3, 3))
    targets = np.asarray(bh.families.miura(3, 3, fold=40.0).fold_angles)[edges]
    text = f"""name = "miura-3x3"
[pattern]
family = "miura"
params = {{ nx = 3, ny = 3, fold = 10.0 }}
[model]
scheme = "N5B8"
material = {{ E = 1.0e6, nu = 0.3, t = 0.01 }}
[actuators]
edges = {edges.tolist()}
targets_deg = {targets.tolist()}
[solve]
steps = 6
"""
    f = tmp_path / "scene.toml"
    f.write_text(text)
    return f


def test_form_only_folds_actuated_scene_rigidly_to_the_closed_form(tmp_path: Path) -> None:
    out = tmp_path / "out"
    res = CliRunner().invoke(
        app, ["fold", str(_scene_toml(tmp_path)), "--form-only", "--json", "--out", str(out)]
    )
    assert res.exit_code == 0, res.output
    info = json.loads(res.stdout)
    assert info["model"] == "rigid" and info["n_states"] == 7
    assert info == {**json.loads((out / "summary.json").read_text()), "files": info["files"]}
    assert info["closure_residual"] < 1e-8
    path = FoldPath.load(out / "fold_path.npz")
    assert path.kind == "rigid"
    ref = np.asarray(bh.families.miura(3, 3, fold=40.0).fold_angles)
    np.testing.assert_allclose(path.fold_angles_deg[-1], ref, rtol=0, atol=1e-8)
    assert (out / "fold_path.fold").is_file()


def test_form_only_keeps_the_compliant_model_for_loaded_scenes() -> None:
    scene = load_scene(SCENES / "yoshimura_roof.toml")
    assert form_only_model(scene)[0] == "bar-hinge"
    assert form_only_model(load_scene(SCENES / "miura_actuated.toml"))[0] == "rigid"


def test_form_only_resolves_free_motions_as_the_rigid_limit(tmp_path: Path) -> None:
    """A Yoshimura arch (12 rigid DOF) driven by its 9 horizontal creases alone leaves free
    motions: rigid kinematics resolves them by minimising the model's fold-spring energy,
    and the form agrees with the bar-and-hinge model made 1e5 x stiffer in its panels (an
    independent solver; the gap is O(1 / ratio))."""
    cp = bh.families.yoshimura(4, 3, fold=5.0)
    flat = np.asarray(bh.families.yoshimura(4, 3).vertices)
    E = np.asarray(cp.edges)
    horizontal = np.flatnonzero(
        (np.abs(flat[E[:, 0], 1] - flat[E[:, 1], 1]) < 1e-9) & np.isin(cp.assignment, ["M", "V"])
    )
    assert len(horizontal) == 9
    target = np.asarray(bh.families.yoshimura(4, 3, fold=30.0).fold_angles)[horizontal]
    acts = bh.Actuators(edges=horizontal, targets_deg=target)
    model = bh.BarHingeModel.from_pattern(cp, "N5B8")
    scene = bh.Scene(model, actuators=acts, steps=2)
    assert form_only_model(scene)[0] == "rigid"
    path = rigid_form(scene)
    assert path.converged and path.meta["free_dof"] == 3
    stiff = bh.BarHingeModel.from_pattern(cp, "N5B8", stiffness_ratio=1e5)
    bar = bh.solve(bh.Scene(stiff, actuators=acts, steps=2))
    gap = np.abs(bar.fold_angles_deg[-1] - path.fold_angles_deg[-1]).max()
    assert gap < 0.01, gap


def test_form_only_falls_back_when_rigid_kinematics_cannot_follow(tmp_path: Path) -> None:
    """Two creases of a 1-DOF Miura driven with targets that contradict each other: rigid
    kinematics refuses (ConfigError) and the CLI falls back to the bar-and-hinge solver."""
    cp = bh.families.miura(2, 2, fold=30.0)
    lay = bh.families.miura_layout(2, 2)
    z, s = int(lay.interior_zigzag_edges[0]), int(lay.interior_straight_edges[0])
    acts = bh.Actuators(
        edges=[z, s], targets_deg=[cp.fold_angles[z] * 1.5, cp.fold_angles[s] * 0.5]
    )
    scene = bh.Scene(bh.BarHingeModel.from_pattern(cp, "N5B8"), actuators=acts, steps=2)
    with pytest.raises(ConfigError):
        rigid_form(scene)
