"""Kill tests: ``barhinge fold`` killed (SIGKILL) at random points, also while it writes,
leaves its output folder absent, the complete previous run or the complete new run, never a
mix; Ctrl-C (SIGINT) writes the converged steps and exits with code 130."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.output.folder import read_manifest

sys.path.insert(0, str(Path(__file__).parent))
from test_output_folder import miura_scene  # noqa: E402

pytestmark = pytest.mark.skipif(os.name != "posix", reason="SIGKILL / SIGINT are POSIX")

ENV = {**os.environ, "BARHINGE_PICTURES": "0", "BARHINGE_OFFSCREEN": "0"}
FOLD = [sys.executable, "-m", "barhinge.cli", "fold"]


def _points(vtu: Path) -> int:
    m = re.search(rb'NumberOfPoints="(\d+)"', vtu.read_bytes()[:4096])
    assert m, f"{vtu.name}: no NumberOfPoints"
    return int(m.group(1))


def one_run(out: Path, nodes: dict[str, int]) -> str | None:
    """The scene of the run in ``out`` (None if absent), after checking that the folder is
    exactly one complete run: the manifest matches the files, and the npz, the summary and
    every VTU frame belong to that run's model."""
    if not out.exists():
        return None
    man = read_manifest(out)  # every listed file with its size, nothing else
    scene, n = man["scene"], man["n_nodes"]
    assert nodes[scene] == n
    fp = bh.FoldPath.load(out / "fold_path.npz")
    assert fp.X.shape[1] == n and fp.n_states == man["n_states"]
    assert json.loads((out / "summary.json").read_text())["scene"] == scene
    frames = sorted(out.glob("fold_path_*.vtu"))
    assert [f.name for f in frames] == [f"fold_path_{s:04d}.vtu" for s in range(fp.n_states)]
    assert {_points(f) for f in frames} == {n}
    return scene


def _start(scene: Path, out: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [*FOLD, str(scene), "--out", str(out)],
        env=ENV,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )


def _writing(out: Path, pid: int) -> bool:
    """Whether process ``pid`` has started writing its run (its temporary folder exists)."""
    return any(out.parent.glob(f".{out.name}.barhinge-tmp-{pid}-*"))


def _timed_run(scene: Path, out: Path) -> tuple[float, float]:
    """Run to the end; (seconds until the temporary folder appears, seconds of writing)."""
    t0 = time.perf_counter()
    p = _start(scene, out)
    t_tmp = None
    while p.poll() is None:
        if t_tmp is None and _writing(out, p.pid):
            t_tmp = time.perf_counter() - t0
        time.sleep(0.002)
    t_end = time.perf_counter() - t0
    assert p.returncode == 0, p.stderr.read().decode()
    t_tmp = t_end if t_tmp is None else t_tmp
    return t_tmp, t_end - t_tmp


@pytest.mark.slow
def test_sigkill_never_leaves_a_mixed_folder(tmp_path):
    old = miura_scene(tmp_path, n=2, steps=3)
    new = miura_scene(tmp_path, n=3, steps=5)
    nodes = {"miura-2x2": 25, "miura-3x3": 49}
    out = tmp_path / "out"
    _timed_run(old, out)
    assert one_run(out, nodes) == "miura-2x2"
    t_tmp, t_write = _timed_run(new, tmp_path / "reference")
    assert one_run(tmp_path / "reference", nodes) == "miura-3x3"
    _timed_run(old, out)  # out holds the previous (2 x 2) run again

    rng = np.random.default_rng(16)
    seen = []
    for seed in range(6):
        p = _start(new, out)
        t0 = time.perf_counter()
        if seed % 2:  # while writing: wait for the temporary folder, then a random delay
            while p.poll() is None and not _writing(out, p.pid):
                time.sleep(0.001)
            time.sleep(rng.uniform(0.0, t_write))
        else:  # anywhere in the run
            time.sleep(rng.uniform(0.0, t_tmp + t_write))
        p.send_signal(signal.SIGKILL)
        p.wait()
        killed_at = time.perf_counter() - t0
        seen.append((round(killed_at, 2), p.returncode, one_run(out, nodes)))
        if seen[-1][2] == "miura-3x3":  # a new run got in: put the previous one back
            _timed_run(old, out)
    assert all(s[2] in ("miura-2x2", "miura-3x3") for s in seen), seen
    assert any(s[1] == -signal.SIGKILL for s in seen), seen  # some kills hit a running process
    _timed_run(new, out)  # the next run completes and removes the killed runs' leftovers
    assert one_run(out, nodes) == "miura-3x3"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


SIGINT_AT_STEP = """
import os, signal, sys
from barhinge.solver import newton

# a shell that starts a job in the background sets SIGINT to "ignore" for it, and Python
# then leaves it ignored: give the child the handler an interactive terminal's process has
signal.signal(signal.SIGINT, signal.default_int_handler)

real = newton.solve


def solve(scene, progress=None, on_iteration=None):
    def at_step(done, total, value):
        if done == 3:  # a real SIGINT through Python's own handler, as Ctrl-C sends it
            os.kill(os.getpid(), signal.SIGINT)
    return real(scene, progress=at_step, on_iteration=on_iteration)


newton.solve = solve
from barhinge.cli import main

sys.argv = ["barhinge", "fold", *sys.argv[1:]]
main()
"""


def test_sigint_writes_the_converged_steps_and_exits_130(tmp_path):
    scene = miura_scene(tmp_path, n=2, steps=8)
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, "-c", SIGINT_AT_STEP, str(scene), "--out", str(out)],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 130, r.stderr
    assert "interrupted (Ctrl-C) after 3 converged steps" in r.stderr
    assert "Traceback" not in r.stderr
    man = read_manifest(out)
    assert man["converged"] is False and man["reason"] == "interrupted"
    assert one_run(out, {"miura-2x2": 25}) == "miura-2x2" and man["n_states"] == 4


SIGTERM_AT_STEP = SIGINT_AT_STEP.replace("signal.SIGINT", "signal.SIGTERM").replace(
    "Ctrl-C sends it", "kill PID sends it"
)


def test_sigterm_behaves_like_ctrl_c_and_exits_143(tmp_path):
    """``kill PID`` (SIGTERM) during the solve writes the converged steps through the atomic
    writer, as Ctrl-C does, and exits with 143 (128 + 15)."""
    scene = miura_scene(tmp_path, n=2, steps=8)
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, "-c", SIGTERM_AT_STEP, str(scene), "--out", str(out)],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 143, r.stderr
    assert "interrupted (SIGTERM) after 3 converged steps" in r.stderr
    assert "Traceback" not in r.stderr
    man = read_manifest(out)
    assert man["converged"] is False and man["reason"] == "interrupted"
    assert "SIGTERM" in man["message"]
    assert one_run(out, {"miura-2x2": 25}) == "miura-2x2" and man["n_states"] == 4
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
