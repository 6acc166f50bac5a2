"""What `barhinge fold` writes by default and on request: the viewer always (unless
`--no-viewer`), the final-state picture and the charts (`--pictures png`, the default), the
energy-density picture and the GIF only with `--pictures all`; and the forces of the last
state in the summary, with reactions that balance (under loads:
tests/analysis/test_analysis_forces.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.families import miura_line_creases
from barhinge.output.run import picture_level, write_run
from barhinge.output.summary import summary_rows
from barhinge.scene import Scene


@pytest.fixture(scope="module")
def solved():
    cp = bh.families.miura(2, 2, fold=20.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e3, nu=0.3, t=0.01))
    edges = miura_line_creases(cp)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp.fold_angles)[edges] * 1.5)
    scene = Scene(model, actuators=acts, steps=3, name="miura2")
    return scene, bh.solve(scene)


@pytest.fixture
def mpl(monkeypatch):
    monkeypatch.setenv("BARHINGE_OFFSCREEN", "0")  # matplotlib pictures: fast and GL-free
    from barhinge.plot import render

    render.can_render_offscreen.cache_clear()
    yield
    render.can_render_offscreen.cache_clear()


def names(run) -> set[str]:
    return {p.name for p in run.files}


def test_default_writes_the_viewer_and_no_static_pictures(solved, tmp_path, monkeypatch):
    monkeypatch.delenv("BARHINGE_PICTURES", raising=False)
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out")
    n = names(run)
    assert "viewer.html" in n
    assert not any(p.suffix in (".png", ".gif") for p in run.files)
    html = (tmp_path / "out" / "viewer.html").read_text()
    assert html.lstrip().lower().startswith("<!doctype html") and "http://" not in html.lower()
    manifest = json.loads((tmp_path / "out" / "barhinge-run.json").read_text())
    assert "viewer.html" in json.dumps(manifest)


def test_pictures_png_draws_the_final_state_and_the_charts(solved, tmp_path, mpl):
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="png")
    n = names(run)
    assert {"viewer.html", "fold_path.png", "fold_path_charts.png"} <= n
    assert "fold_path.gif" not in n and "fold_path_energy_density.png" not in n


def test_pictures_none_and_no_viewer(solved, tmp_path):
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    assert not any(p.suffix in (".png", ".gif", ".html") for p in run.files)


def test_pictures_all_adds_the_gif_and_the_energy_picture(solved, tmp_path, mpl):
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="all", viewer=False)
    assert {"fold_path.gif", "fold_path_energy_density.png", "fold_path.png"} <= names(run)


@pytest.mark.parametrize(
    ("env", "want"), [("0", "none"), ("none", "none"), ("png", "png"), ("all", "all"), ("", "none")]
)
def test_picture_level_from_the_environment(monkeypatch, env, want):
    monkeypatch.setenv("BARHINGE_PICTURES", env)
    assert picture_level(None) == want
    assert picture_level(True) == "png" and picture_level(False) == "none"


def test_bad_picture_level_is_a_one_line_error():
    with pytest.raises(ConfigError, match="expected one of none, png, all"):
        picture_level("gif")


def test_summary_forces_balance_for_an_actuated_sheet(solved, tmp_path):
    """Actuators apply self-equilibrated moment pairs: with no loads the reactions must sum
    to zero; the solver's recorded reactions are used (the model's internal force alone
    does not include the actuators' constraint forces)."""
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    f = run.summary["results"]["forces"]
    assert f["applied_load_total"] == [0.0, 0.0, 0.0]
    # internal forces and actuator pairs sum to zero, so sum R = -(sum of the residual the
    # solver left at the free nodes): |sum R| <= sqrt(n_nodes) |r_free| (Cauchy-Schwarz)
    r_last = path.residual_norms[-1][-1]
    bound = np.sqrt(scene.model.n_nodes) * r_last + 1e-13
    assert np.linalg.norm(f["reaction_total"]) <= bound
    assert f["equilibrium_error"] < 1e-6 and f["moment_equilibrium_error"] < 1e-6
    X = path.X[-1]
    u = np.linalg.norm(X - path.X[0], axis=1)
    assert f["max_displacement"] == pytest.approx(u.max(), rel=1e-12)
    assert f["max_displacement_node"] == int(np.argmax(u))
    rows = dict(summary_rows(run.summary))
    assert rows["max displacement (node)"].endswith(f"({int(np.argmax(u))})")


def test_loaded_scene_summary_has_its_linear_buckling_factors_and_modes(tmp_path):
    """The summary's factors are those of `linear_buckling` on the scene (checked against
    the strut closed form in tests/analysis/test_analysis_buckling.py); one VTU per mode."""
    from pathlib import Path

    from barhinge.analysis.buckling import linear_buckling
    from barhinge.scene import load_scene

    scene = load_scene(Path(__file__).parents[2] / "data/scenes/yoshimura_roof.toml")
    path = bh.solve(scene)
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    rec = run.summary["results"]["buckling"]
    want = linear_buckling(scene.model, scene.loads, scene.fixed, n_modes=3).factors
    np.testing.assert_allclose(rec["factors"], want, rtol=1e-8)
    assert rec["factors"][0] > 0
    assert {f"buckling_mode_{i}.vtu" for i in (1, 2, 3)} <= names(run)
    assert "linear buckling factor (state 0)" in dict(summary_rows(run.summary))


def test_unloaded_scene_has_no_buckling_record(solved, tmp_path):
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    assert "buckling" not in run.summary["results"]


def test_summary_reports_factorisations_per_step(solved, tmp_path):
    """The step-control record of the solver (counted independently in
    tests/solver/test_newton_stats.py) reaches summary.json and the printed table."""
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    nw = run.summary["newton"]
    assert nw["iterations"] == [int(i) for i in path.iterations[1:]]
    assert nw["total_factorizations"] == sum(nw["factorizations"]) >= len(nw["factorizations"])
    row = dict(summary_rows(run.summary))["factorisations (per step; failed increments)"]
    assert row.startswith(f"{nw['total_factorizations']} (")


def test_summary_names_the_slowest_steps(solved, tmp_path):
    """summary.json names the longest steps of the solve from the path's own per-state
    clock (the differences of ``FoldPath.wall_time``), the longest first, and the printed
    table lists them."""
    scene, path = solved
    run = write_run(path, scene, tmp_path / "out", pictures="none", viewer=False)
    slow = run.summary["slowest_steps"]
    dt = np.diff(np.asarray(path.wall_time))
    assert [d["step"] for d in slow] == (np.argsort(-dt, kind="stable")[:3] + 1).tolist()
    for d in slow:
        assert d["wall_s"] == pytest.approx(dt[d["step"] - 1])
        assert d["share"] == pytest.approx(dt[d["step"] - 1] / path.wall_time[-1])
    assert [d["wall_s"] for d in slow] == sorted((d["wall_s"] for d in slow), reverse=True)
    assert 0.0 < sum(d["share"] for d in slow) <= 1.0
    row = dict(summary_rows(run.summary))["slowest steps"]
    assert row.startswith(f"{slow[0]['step']}: ")


def test_slowest_steps_of_a_clock_without_steps_are_none():
    from barhinge.output.summary import slowest_steps

    assert slowest_steps(np.array([0.5])) == []
    assert slowest_steps(np.array([0.0, np.nan])) == []
    assert slowest_steps(np.array([0.0, 1.0, 4.0, 4.5])) == [
        {"step": 2, "wall_s": 3.0, "share": 3.0 / 4.5},
        {"step": 1, "wall_s": 1.0, "share": 1.0 / 4.5},
        {"step": 3, "wall_s": 0.5, "share": 0.5 / 4.5},
    ]
    assert [d["step"] for d in slowest_steps(np.array([0.0, 2.0, 4.0, 7.0]), k=2)] == [3, 1]
