"""A scene's ``[imperfection]``: the TOML key, the amplitude rules, the seeded model and the
fold command that seeds it; the solver refuses a scene whose imperfection was not applied."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.analysis.buckling import linear_buckling
from barhinge.analysis.imperfection import amplitude_length, seed_imperfection, span
from barhinge.cli import app
from barhinge.errors import ConfigError
from barhinge.scene import Imperfection, Scene, load_scene, scene_from_dict
from barhinge.verify import rigid_link_strut

ROOF = """
name = "roof-imperfect"
[pattern]
family = "yoshimura"
params = {{ nx = 3, ny = 2, fold = 30.0 }}
[model]
scheme = "N5B8"
material = {{ E = 1.0e6, nu = 0.3, t = 0.01 }}
fold_stiffness = 1.0
[[supports]]
where = "bottom"
dofs = "xyz"
[[supports]]
where = "top"
dofs = "xyz"
[[loads]]
self_weight = {{ area_density = 0.1, g = [0.0, 0.0, -9.81] }}
{imperfection}
[solve]
steps = 3
control = "load"
"""


def _roof(tmp_path: Path, imperfection: str) -> Path:
    f = tmp_path / "roof.toml"
    f.write_text(ROOF.format(imperfection=imperfection))
    return f


def test_span_of_a_strut_is_its_length_and_of_a_cantilever_twice_it():
    """Twice the largest plan distance to the nearest support: a 4-link strut held at both
    ends spans its length 4; held at one end only it is a cantilever of length 4, whose
    span (effective length of a bow) is 8."""
    m, S, _ = rigid_link_strut(4)
    assert span(m.X0, S) == pytest.approx(4.0, rel=1e-12)
    one_end = S.copy()
    one_end[[4, 9]] = False  # release the roller end (nodes x = 4)
    assert span(m.X0, one_end) == pytest.approx(8.0, rel=1e-12)


@pytest.mark.parametrize("alpha", [0.25, 0.75])
def test_seeded_strut_scene_amplifies_by_the_closed_form(alpha):
    """The scene route (Imperfection -> seed_imperfection -> solve) reproduces the crooked
    column's amplification ``a alpha / (1 - alpha)`` (Timoshenko & Gere 1961, sec. 1.12) for
    a first-mode imperfection of amplitude ``a = 1e-3 l``, to the O(a / l) of the linearised
    closed form (tests/analysis/test_imperfection.py)."""
    m, S, P = rigid_link_strut(5)
    p1 = float(linear_buckling(m, P, S, n_modes=1).factors[0])
    a = 1e-3
    scene = Scene(m, supports=S, loads=alpha * p1 * P, control="load", steps=10,
                  imperfection=Imperfection(mode=1, amplitude=a))  # fmt: skip
    seeded = seed_imperfection(scene)
    rec = seeded.model.meta["imperfection"]
    assert rec["buckling_factor"] == pytest.approx(1.0 / alpha, rel=1e-7)  # eigensolver
    assert rec["amplitude"] == a and rec["rule"] is None
    path = bh.solve(seeded)
    assert path.meta["imperfection"] == rec
    s = seeded.model.X0 - m.X0
    i = int(np.argmax(np.abs(s[:, 2])))
    assert abs(s[i, 2]) == pytest.approx(a, rel=1e-12)
    w = (path.X[-1][i, 2] - path.X[0][i, 2]) / np.sign(s[i, 2])
    assert w == pytest.approx(a * alpha / (1.0 - alpha), rel=2e-3)


def test_second_mode_is_the_second_buckling_mode():
    """mode = 2 seeds the strut's second mode: its factor is the second buckling factor and
    the shape is antisymmetric about mid-span (a pinned strut's second mode has a node
    there)."""
    m, S, P = rigid_link_strut(4)
    b = linear_buckling(m, P, S, n_modes=2)
    wanted = Imperfection(mode=2, amplitude=0.01)
    seeded = seed_imperfection(Scene(m, supports=S, loads=P, control="load", imperfection=wanted))
    assert seeded.model.meta["imperfection"]["buckling_factor"] == pytest.approx(b.factors[1])
    w = (seeded.model.X0 - m.X0)[:5, 2]  # the bottom line, x = 0 .. 4
    tol = 1e-6 * 0.01  # the eigenvector's accuracy (ARPACK), relative to the amplitude
    np.testing.assert_allclose(w, -w[::-1], atol=tol)
    assert abs(w[2]) <= tol and abs(w[1]) == pytest.approx(0.01)


def test_the_solver_refuses_a_scene_whose_imperfection_is_not_applied():
    m, S, P = rigid_link_strut(3)
    scene = Scene(m, supports=S, loads=P, control="load",
                  imperfection=Imperfection(amplitude=0.01))  # fmt: skip
    with pytest.raises(ConfigError, match="seed_imperfection"):
        bh.solve(scene)


def test_toml_rules_resolve_on_the_roof(tmp_path):
    """``span/300`` of a roof held on its bottom and top edges is its plan extent between
    them over 300 (the pattern has a row of nodes at mid-span); ``panel/200`` is the median
    facet's shortest side over 200."""
    scene = load_scene(_roof(tmp_path, '[imperfection]\namplitude = "span/300"'))
    assert scene.imperfection == Imperfection(mode=1, amplitude="span/300")
    y = scene.model.X0[:, 1]
    assert amplitude_length(scene) == pytest.approx((y.max() - y.min()) / 300.0, rel=1e-12)
    scene = load_scene(_roof(tmp_path, '[imperfection]\nmode = 2\namplitude = "panel/200"'))
    cp = scene.model.pattern
    sides = []
    for f in cp.faces:
        P = np.asarray(cp.vertices, float)[list(f)]
        sides.append(min(np.linalg.norm(P[k] - P[k - 1]) for k in range(len(f))))
    assert amplitude_length(scene) == pytest.approx(float(np.median(sides)) / 200.0)
    assert scene.imperfection.mode == 2


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ("[imperfection]\nmode = 1", "needs amplitude"),
        ('[imperfection]\namplitude = "chord/300"', "imperfection.amplitude"),
        ('[imperfection]\namplitude = "span/0"', "imperfection.amplitude"),
        ("[imperfection]\namplitude = -0.01", "imperfection.amplitude"),
        ("[imperfection]\namplitude = 0.01\nmode = 0", "imperfection.mode"),
        ("[imperfection]\namplitude = 0.01\nshape = 1", "unknown key 'shape'"),
    ],
)
def test_bad_imperfections_in_toml_are_named(tmp_path, body, match):
    with pytest.raises(ConfigError, match=match):
        load_scene(_roof(tmp_path, body))


def test_imperfection_needs_loads():
    d = {"pattern": {"family": "miura", "params": {"nx": 2, "ny": 2}},
         "imperfection": {"amplitude": 0.01}}  # fmt: skip
    with pytest.raises(ConfigError, match="needs nonzero loads"):
        scene_from_dict(d)


def test_fold_seeds_the_scene_and_reports_it(tmp_path):
    """``barhinge fold`` on a scene with ``[imperfection]``: the path starts at the perfect
    reference moved by span/300 along the first buckling mode of the perfect roof, whose
    factor the summary states."""
    f = _roof(tmp_path, '[imperfection]\nmode = 1\namplitude = "span/300"')
    perfect = load_scene(f).with_(imperfection=None)
    lam = float(linear_buckling(perfect.model, perfect.loads, perfect.fixed, n_modes=1).factors[0])
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["fold", str(f), "--out", str(out), "--no-viewer"])
    assert res.exit_code == 0, res.output
    assert "imperfection: buckling mode 1" in res.output
    rec = json.loads((out / "summary.json").read_text())["imperfection"]
    y = perfect.model.X0[:, 1]
    assert rec["amplitude"] == pytest.approx((y.max() - y.min()) / 300.0, rel=1e-12)
    assert rec["rule"] == "span/300" and rec["mode"] == 1
    assert rec["buckling_factor"] == pytest.approx(lam, rel=1e-9)
    X0 = bh.FoldPath.load(out / "fold_path.npz").X[0]
    moved = np.linalg.norm(X0 - perfect.model.X0, axis=1)
    assert moved.max() == pytest.approx(rec["amplitude"], rel=1e-9)


def test_the_example_scene_of_the_docs_folds():
    """docs/solver.md's example: data/scenes/yoshimura_roof_imperfect.toml, seeded and
    solved in Python, reaches its load with the imperfection recorded on the path."""
    f = Path(__file__).resolve().parents[2] / "data" / "scenes" / "yoshimura_roof_imperfect.toml"
    scene = bh.seed_imperfection(bh.load_scene(f))
    path = bh.solve(scene)
    assert path.converged and path.load_factor[-1] == pytest.approx(1.0)
    assert path.meta["imperfection"]["rule"] == "span/300"


def test_span_needs_real_supports_and_a_length_needs_no_rule():
    """``span/N`` on the automatic 3-2-1 restraint is refused (it has no span); a length is
    used as given, and the summary line names no rule for it."""
    from barhinge.output.summary import imperfection_text

    m, _, P = rigid_link_strut(3)
    free = Scene(m, loads=P, control="load", imperfection=Imperfection(amplitude="span/300"))
    assert free.auto_restrained
    with pytest.raises(ConfigError, match="span/N' needs supports"):
        amplitude_length(free)
    given = free.with_(imperfection=Imperfection(amplitude=0.02))
    assert amplitude_length(given) == 0.02
    rec = {"mode": 1, "buckling_factor": 2.0, "amplitude": 0.02, "rule": None}
    assert imperfection_text(rec) == "buckling mode 1 (factor 2), amplitude 0.02"
    assert imperfection_text({**rec, "rule": "span/300"}).endswith("= span/300")
