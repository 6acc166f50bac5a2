"""Result folders are written atomically and marked by a manifest; Ctrl-C keeps the converged
part of a solve; ``FoldPath.save`` replaces its file in one step."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app
from barhinge.errors import ConfigError
from barhinge.output.folder import MANIFEST, check_output_folder, read_manifest, result_folder
from barhinge.results import Interrupted

SCENE = """name = "{name}"

[pattern]
family = "miura"
params = {{ nx = {n}, ny = {n}, a = 1.0, b = 1.0, alpha = 60.0, fold = 5.0 }}

[model]
scheme = "N4B5"
material = {{ E = 1.0e6, nu = 0.3, t = 0.01 }}
fold_stiffness = 1.0e-3

[actuators]
edges = [{edge}]
targets_deg = [{target}]

[solve]
steps = {steps}
control = "fold_angle"
"""


def miura_scene(folder: Path, n: int = 2, steps: int = 4, target: float = 40.0) -> Path:
    """A small Miura scene TOML (n x n, its first crease (a valley) actuated)."""
    edge = int(bh.families.miura(n, n, fold=5.0).crease_edges[0])
    f = folder / f"miura{n}_{steps}.toml"
    f.write_text(SCENE.format(name=f"miura-{n}x{n}", n=n, steps=steps, target=target, edge=edge))
    return f


@pytest.fixture(autouse=True)
def _no_pictures(monkeypatch):
    monkeypatch.setenv("BARHINGE_PICTURES", "0")


def _fold(args: list[str]):
    return CliRunner().invoke(app, ["fold", *args])


# --------------------------------------------------------------------------- the folder
def test_result_folder_swaps_whole_runs(tmp_path):
    out = tmp_path / "out"
    with result_folder(out) as run:
        for i in range(3):
            (run.path / f"frame_{i}.vtu").write_text("a" * i)
        run.manifest["scene"] = "first"
        assert not out.exists()  # nothing visible while writing
    assert read_manifest(out)["files"] == {"frame_0.vtu": 0, "frame_1.vtu": 1, "frame_2.vtu": 2}
    with result_folder(out) as run:
        (run.path / "frame_0.vtu").write_text("b")
        run.manifest["scene"] = "second"
    man = read_manifest(out)
    assert man["scene"] == "second" and sorted(os.listdir(out)) == [MANIFEST, "frame_0.vtu"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no temporary sibling left


def test_result_folder_keeps_the_old_run_on_an_exception(tmp_path):
    out = tmp_path / "out"
    with result_folder(out) as run:
        (run.path / "a.txt").write_text("old")
    for exc in (RuntimeError("boom"), KeyboardInterrupt()):
        with pytest.raises(type(exc)), result_folder(out) as run:
            (run.path / "a.txt").write_text("new")
            raise exc
        assert (out / "a.txt").read_text() == "old" and read_manifest(out)
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_output_folder_checks(tmp_path, monkeypatch):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ConfigError, match="is a file"):
        check_output_folder(tmp_path / "file")
    with pytest.raises(ConfigError, match="is a file"):
        check_output_folder(tmp_path / "file" / "sub")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    with pytest.raises(ConfigError, match=r"not a barhinge result folder.*--overwrite"):
        check_output_folder(mine)
    assert check_output_folder(mine, overwrite=True) == mine
    (tmp_path / "empty").mkdir()
    check_output_folder(tmp_path / "empty")
    with result_folder(tmp_path / "run") as run:
        (run.path / "a.txt").write_text("a")
    check_output_folder(tmp_path / "run")
    (tmp_path / "run" / "notes.txt").write_text("user file")  # added by hand: not replaced
    with pytest.raises(ConfigError, match=r"not part of its barhinge run \(notes.txt\)"):
        check_output_folder(tmp_path / "run")
    with pytest.raises(ConfigError, match="not of the run: notes.txt"):
        read_manifest(tmp_path / "run")
    monkeypatch.chdir(tmp_path / "empty")
    for where in (".", ".."):  # never renamed away from under the process, even if empty
        with pytest.raises(ConfigError, match="working folder"):
            check_output_folder(Path(where), overwrite=True)


def test_a_killed_runs_leftover_is_removed_by_the_next_run(tmp_path):
    out = tmp_path / "out"
    dead = tmp_path / ".out.barhinge-tmp-999999999-abcd"  # no such process
    dead.mkdir()
    (dead / "half.vtu").write_text("x")
    alive = tmp_path / f".out.barhinge-tmp-{os.getpid()}-abcd"  # a run still writing
    alive.mkdir()
    with result_folder(out) as run:
        (run.path / "a.txt").write_text("a")
    assert not dead.exists() and alive.exists()


def test_foldpath_save_is_atomic(tmp_path, monkeypatch):
    p = bh.FoldPath(X=np.zeros((2, 3, 3)), fold_angles_deg=np.zeros((2, 3)))
    f = p.save(tmp_path / "p.npz")
    before = f.read_bytes()

    def broken(*a, **k):
        raise KeyboardInterrupt

    with monkeypatch.context() as m, pytest.raises(KeyboardInterrupt):
        m.setattr(np, "savez_compressed", broken)
        bh.FoldPath(X=np.ones((1, 3, 3)), fold_angles_deg=np.zeros((1, 3))).save(f)
    assert f.read_bytes() == before and os.listdir(tmp_path) == ["p.npz"]
    assert p.save(tmp_path / "q") == tmp_path / "q.npz"  # the suffix is added as before
    assert oct((tmp_path / "q.npz").stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    m = os.umask(0)
    os.umask(m)
    return m


# --------------------------------------------------------------------------- fold
def test_fold_rerun_replaces_the_folder_whole(tmp_path):
    out = tmp_path / "out"
    assert _fold([str(miura_scene(tmp_path, n=3, steps=5)), "--out", str(out)]).exit_code == 0
    assert len(list(out.glob("fold_path_*.vtu"))) == 6
    res = _fold([str(miura_scene(tmp_path, n=2, steps=2)), "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    man = read_manifest(out)
    assert man["scene"] == "miura-2x2" and man["converged"] and man["reason"] is None
    assert sorted(p.name for p in out.glob("fold_path_*.vtu")) == [
        f"fold_path_{s:04d}.vtu" for s in range(3)
    ]  # no stale frames of the 3 x 3 run
    assert str(out / MANIFEST) in json.loads(res.stdout)["files"]


def test_fold_refuses_a_foreign_folder_before_solving(tmp_path, monkeypatch):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    from barhinge.solver import newton

    called = []
    with monkeypatch.context() as m:
        m.setattr(newton, "solve", lambda *a, **k: called.append(1))
        res = _fold([str(miura_scene(tmp_path)), "--out", str(out)])
    assert res.exit_code != 0 and not called
    assert "--overwrite" in str(res.exception) and (out / "notes.txt").is_file()
    res = _fold([str(miura_scene(tmp_path)), "--out", str(out), "--overwrite"])
    assert res.exit_code == 0, res.output
    assert not (out / "notes.txt").exists() and read_manifest(out)["converged"]


def test_fold_form_only_writes_a_manifest(tmp_path):
    out = tmp_path / "out"
    res = _fold([str(miura_scene(tmp_path)), "--form-only", "--out", str(out)])
    assert res.exit_code == 0, res.output
    man = read_manifest(out)
    assert man["kind"] == "rigid" and set(man["files"]) == {
        "fold_path.npz", "fold_path.fold", "summary.json", "states.csv", "viewer.html"}  # fmt: skip


# --------------------------------------------------------------------------- Ctrl-C
def test_solve_interrupted_carries_the_converged_steps(tmp_path):
    scene = bh.load_scene(miura_scene(tmp_path, steps=6))

    def progress(done, total, value):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(Interrupted) as info:
        bh.solve(scene, progress=progress)
    part = info.value.last_state
    assert isinstance(info.value, KeyboardInterrupt)  # never swallowed by `except Exception`
    assert part.n_states == 4 and not part.converged and part.meta["stopped"] == "interrupted"
    assert "interrupted" in part.message


def test_fold_interrupted_writes_partial_results_and_exits_130(tmp_path, monkeypatch):
    from barhinge.solver import newton

    real = newton.solve

    def interrupted_solve(scene, progress=None, on_iteration=None):
        def stop(done, total, value):
            if done == 2:
                raise KeyboardInterrupt

        return real(scene, progress=stop, on_iteration=on_iteration)

    monkeypatch.setattr(newton, "solve", interrupted_solve)
    out = tmp_path / "out"
    res = _fold([str(miura_scene(tmp_path, steps=5)), "--out", str(out)])
    assert res.exit_code == 130, res.output
    man = read_manifest(out)
    assert man["converged"] is False and man["reason"] == "interrupted" and man["n_states"] == 3
    assert bh.FoldPath.load(out / "fold_path.npz").n_states == 3
    assert json.loads((out / "summary.json").read_text())["reason"] == "interrupted"


def test_fold_not_converged_is_marked_in_the_manifest(tmp_path):
    text = miura_scene(tmp_path).read_text()
    f = tmp_path / "fail.toml"
    f.write_text(text.replace('control = "fold_angle"', 'control = "fold_angle"\n'
                              "options = { max_iter = 1, max_cutbacks = 0 }"))  # fmt: skip
    out = tmp_path / "out"
    res = _fold([str(f), "--out", str(out)])
    assert isinstance(res.exception, bh.ConvergenceError)
    man = read_manifest(out)
    assert man["converged"] is False and man["reason"] == "not converged"


@pytest.mark.slow
def test_render_into_a_result_folder_keeps_it_one_run(tmp_path, monkeypatch):
    monkeypatch.setenv("BARHINGE_OFFSCREEN", "0")  # matplotlib pictures: fast and GL-free
    out = tmp_path / "out"
    assert _fold([str(miura_scene(tmp_path, steps=2)), "--out", str(out)]).exit_code == 0
    res = CliRunner().invoke(app, ["render", str(out / "fold_path.npz"), "--no-gif", "--json"])
    assert res.exit_code == 0, res.output
    files = read_manifest(out)["files"]  # the pictures are listed; nothing half written
    assert "fold_path_charts.png" in files and "fold_path_fold_angle_deg_0002.png" in files
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
