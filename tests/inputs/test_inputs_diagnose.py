"""Pre-solve diagnosis: separate parts, free rigid-body motions named, scale-free tolerances
(issue 16, item 3)."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.pattern.crease import CreasePattern
from barhinge.scene import restraint_321
from barhinge.solver.diagnose import diagnose, free_rigid_motions


def _miura_scene(supported, dofs="xyz", **kw):
    cp = bh.families.miura(3, 3, fold=20.0)
    m = bh.BarHingeModel.from_pattern(cp, fold_stiffness=1.0)
    S = np.zeros((m.n_nodes, 3), bool)
    for v in supported:
        S[v, ["xyz".index(c) for c in dofs]] = True
    L = np.zeros((m.n_nodes, 3))
    L[10, 2] = -1.0
    return bh.Scene(m, supports=S, loads=L, steps=2, control="load", **kw)


def test_miura_with_two_supported_nodes_names_the_free_rotation():
    scene = _miura_scene([0, 6])  # both on the bottom row: the axis through them is free
    d = diagnose(scene)
    assert len(d.parts) == 1 and len(d.problems) == 1
    assert "rotation about" in d.problems[0] and "add supports" in d.problems[0]
    assert "translation" not in d.problems[0]
    with pytest.raises(ConfigError, match="rotation about .* is free: add supports"):
        bh.solve(scene)  # before: "no convergence in 25 iterations" / "singular tangent"


@pytest.mark.parametrize(
    ("dofs_fixed", "words"),
    [
        ("z", "translation in x and y and rotation about z are free"),
        ("xz", "translation in y and rotation about z are free"),
    ],
)
def test_sheet_held_only_in_some_directions_names_each_free_motion(dofs_fixed, words):
    cp = bh.families.miura(2, 2, fold=20.0)
    m = bh.BarHingeModel.from_pattern(cp, fold_stiffness=1.0)
    S = np.zeros((m.n_nodes, 3), bool)
    S[: cp.n_vertices, "xyz".index("z")] = True
    if "x" in dofs_fixed:
        S[0, 0] = True
    L = np.zeros((m.n_nodes, 3))
    L[12, 2] = -1.0
    d = diagnose(bh.Scene(m, supports=S, loads=L, steps=1))
    assert d.problems and words in d.problems[0], d.problems


def test_free_rigid_motions_of_points():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    assert free_rigid_motions(X, np.ones((4, 3), bool)) == ""
    assert free_rigid_motions(X, np.zeros((4, 3), bool)) == (
        "translation in x, y and z and rotation about x, y and z"
    )
    F = np.zeros((4, 3), bool)
    F[0] = True  # a pin: the three rotations about it
    assert free_rigid_motions(X, F) == "rotation about x, y and z"


def test_default_321_restraint_and_prescribed_displacements_hold_the_model():
    cp = bh.families.miura(2, 2, fold=20.0)
    m = bh.BarHingeModel.from_pattern(cp, fold_stiffness=1.0)
    a = int(cp.crease_edges[12])
    acts = bh.Actuators(edges=[a], targets_deg=float(cp.fold_angles[a]) * 1.2)
    assert diagnose(bh.Scene(m, actuators=acts, steps=2)).ok
    # prescribed displacements count as constraints: all of the bottom row in x, y and z
    P = np.full((m.n_nodes, 3), np.nan)
    P[:5] = 0.0
    assert diagnose(bh.Scene(m, prescribed=P, steps=2)).ok


def _two_sheets(gap=3.0):
    V = [[0, 0], [1, 0], [1, 1], [0, 1], [gap, 0], [gap + 1, 0], [gap + 1, 1], [gap, 1]]
    E = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [4, 5], [5, 6], [6, 7], [7, 4], [4, 6]]
    A = ["B", "B", "B", "B", "V", "B", "B", "B", "B", "V"]
    F = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
    return CreasePattern(np.array(V, float), np.array(E), np.array(A), faces=F)


def test_two_separate_sheets_are_named():
    cp = _two_sheets()
    m = bh.BarHingeModel.from_pattern(cp, fold_stiffness=1.0)
    acts = bh.Actuators(edges=[4], targets_deg=10.0)
    scene = bh.Scene(m, actuators=acts, steps=2)  # 3-2-1 restraint holds only one sheet
    d = diagnose(scene)
    assert len(d.parts) == 2
    msg = d.problems[0]
    assert "the model has 2 separate parts: nodes 0..3 and nodes 4..7" in msg, msg
    assert "free" in msg
    with pytest.raises(ConfigError, match="2 separate parts"):
        bh.solve(scene)
    # each sheet held on its own: solvable, no problem reported
    S = np.zeros((m.n_nodes, 3), bool)
    S[[0, 1, 3, 4, 5, 7]] = True
    assert diagnose(bh.Scene(m, supports=S, actuators=acts, steps=2)).ok


@pytest.mark.parametrize("scale", [1e12, 1e-6])
def test_restraint_and_solve_are_scale_free(scale):
    """a = b = 1e12 used to give "its vertices are collinear" (absolute tolerance). The sheet
    is drawn in other units: lengths and thickness times ``scale``, the fold stiffness per
    unit length (a moment per radian per length, ~ E t^3) times ``scale^2``, so the
    mechanics are the same at every scale."""
    cp = bh.families.miura(2, 2, a=scale, b=scale, fold=20.0)
    mat = bh.Material(t=bh.Material().t * scale)
    m = bh.BarHingeModel.from_pattern(cp, "N5B8", mat, fold_stiffness=scale**2)
    S = restraint_321(m)
    assert S.sum() == 6
    e = int(cp.crease_edges[12])
    acts = bh.Actuators(edges=[e], targets_deg=float(cp.fold_angles[e]) * 1.5)
    scene = bh.Scene(m, actuators=acts, steps=2)
    assert diagnose(scene).ok
    path = bh.solve(scene)
    assert path.converged
    assert path.fold_angles_deg[-1, e] == pytest.approx(1.5 * cp.fold_angles[e], abs=1e-6)
