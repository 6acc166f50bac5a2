"""Sweeps in this process and on a local Dask cluster: records, failures, resume, interrupts."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from barhinge.cli import app
from barhinge.errors import ConfigError
from barhinge.sweep import Study, load_study, point_id, read_records, run_study, write_summary

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sweep_helpers import assert_each_point_once, markers_of, summary_rows, write_study  # noqa: E402


def test_point_id_is_a_hash_of_canonical_json() -> None:
    p = {"b": 2.0, "a": [1, 2], "c": "s"}
    canonical = '{"a":[1,2],"b":2.0,"c":"s"}'
    assert point_id(p) == hashlib.sha256(canonical.encode()).hexdigest()[:16]
    assert point_id(dict(reversed(list(p.items())))) == point_id(p)
    assert point_id({"a": 1}) != point_id({"a": 1.0})


def test_expand_product_points_and_repeats() -> None:
    s = Study(
        function="m:f",
        grid={"a": [1, 2], "b": ["u", "v", "w"]},
        fixed={"c": 0},
        points=({"a": 9, "b": "z"}, {"a": 1, "b": "u"}),
    )
    pts = s.expand()
    assert [(p.params["a"], p.params["b"]) for p in pts] == [
        (1, "u"), (1, "v"), (1, "w"), (2, "u"), (2, "v"), (2, "w"), (9, "z"),
    ]  # fmt: skip
    assert all(p.params["c"] == 0 for p in pts)
    assert len({p.id for p in pts}) == 7


def test_study_file_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\nfunction = "m:f"\nbogus = 1\n')
    with pytest.raises(ConfigError, match="bogus"):
        load_study(bad)
    bad.write_text('[study]\nfunction = "no_colon"\n')
    with pytest.raises(ConfigError, match="module:function"):
        load_study(bad)
    bad.write_text('[study]\nfunction = "m:f"\n[grid]\nx = []\n')
    with pytest.raises(ConfigError, match="non-empty list"):
        load_study(bad)


def test_serial_failure_is_recorded_and_rerun_resumes(tmp_path: Path) -> None:
    xs = [0, 1, 2, 3, 4]
    study = load_study(write_study(tmp_path, xs, fail_on=2))
    rep = run_study(study, mode="serial")
    assert (rep.done, rep.failed, rep.skipped) == (4, 1, 0)
    failed = [r for r in read_records(study.out).values() if r["status"] == "failed"]
    assert len(failed) == 1 and failed[0]["params"]["x"] == 2
    assert failed[0]["error"] == {"type": "ValueError", "message": "x = 2 is unlucky"}
    rows = {int(r["x"]): r for r in summary_rows(study.out)}
    assert rows[2]["status"] == "failed" and rows[2]["error_type"] == "ValueError"
    assert rows[3]["y"] == "9" and json.loads(rows[3]["vec"]) == [3, 6]
    # rerun: nothing executes again
    rep2 = run_study(study, mode="serial")
    assert (rep2.skipped, rep2.done, rep2.failed) == (5, 0, 0)
    assert markers_of(tmp_path) == dict.fromkeys(xs, 1)
    # retry the failed one only
    rep3 = run_study(study, mode="serial", retry_failed=True)
    assert (rep3.skipped, rep3.failed) == (4, 1)
    assert markers_of(tmp_path) == {0: 1, 1: 1, 2: 2, 3: 1, 4: 1}


def test_keyboard_interrupt_then_resume_through_cli(tmp_path: Path) -> None:
    xs = list(range(6))
    path = write_study(tmp_path, xs)
    (tmp_path / "markers" / "interrupt-3").touch()  # point x = 3 raises KeyboardInterrupt once
    runner = CliRunner()
    r1 = runner.invoke(app, ["study", str(path), "--serial"])
    assert r1.exit_code == 130, r1.output
    out = tmp_path / "out"
    assert sorted(r["params"]["x"] for r in read_records(out).values()) == [0, 1, 2]
    assert [r["status"] for r in summary_rows(out)] == ["ok"] * 3 + ["pending"] * 3
    r2 = runner.invoke(app, ["study", str(path), "--serial", "--json"])
    assert r2.exit_code == 0, r2.output
    counts = json.loads(r2.stdout)
    assert (counts["skipped"], counts["done"], counts["failed"]) == (3, 3, 0)
    assert_each_point_once(out, xs)
    # executions: the interrupted point twice (it never finished the first time), others once
    assert markers_of(tmp_path) == {0: 1, 1: 1, 2: 1, 3: 2, 4: 1, 5: 1}


def test_killed_sweep_process_resumes(tmp_path: Path) -> None:
    """SIGKILL the process running a serial sweep after >= 3 points, then resume."""
    xs = list(range(8))
    path = write_study(tmp_path, xs, delay=0.4)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "barhinge.cli", "study", str(path), "--serial"]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 60
        while len(list((out / "points").glob("*.json"))) < 3:
            assert proc.poll() is None, "the sweep ended before it was killed"
            assert time.monotonic() < deadline, "the sweep did not start"
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
    before = {r["params"]["x"] for r in read_records(out).values()}
    assert 3 <= len(before) < len(xs)
    result = CliRunner().invoke(app, ["study", str(path), "--serial"])
    assert result.exit_code == 0, result.output
    assert_each_point_once(out, xs)
    runs = markers_of(tmp_path)
    assert all(runs[x] == 1 for x in before)  # finished points were not recomputed
    assert sum(runs.values()) <= len(xs) + 1  # at most the one in flight ran twice


def test_local_cluster_with_batches(tmp_path: Path) -> None:
    """Default mode: a Dask LocalCluster of two worker processes; 7 points in batches of 3."""
    pytest.importorskip("distributed")
    xs = list(range(7))
    study = load_study(write_study(tmp_path, xs, batch_size=3))
    rep = run_study(study, mode="local", workers=2)
    assert (rep.done, rep.failed) == (7, 0)
    assert_each_point_once(study.out, xs)
    recs = {r["params"]["x"]: r for r in read_records(study.out).values()}
    assert all(recs[x]["worker"] != f"{os.uname().nodename}:{os.getpid()}" for x in xs)
    for batch in ([0, 1, 2], [3, 4, 5]):  # a batch runs in one task, hence one process
        assert len({recs[x]["worker"] for x in batch}) == 1


def test_unreachable_scheduler_is_a_config_error(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    study = load_study(write_study(tmp_path, [1]))
    with pytest.raises(ConfigError, match="cannot connect to the Dask scheduler"):
        run_study(study, scheduler=f"tcp://127.0.0.1:{port}", connect_timeout_s=1.0)


def test_summary_keeps_long_results_in_the_records_only(tmp_path: Path) -> None:
    pts = Study(function="m:f", grid={"a": [1, 2]}).expand()
    recs = {
        p.id: {"id": p.id, "params": p.params, "status": "ok", "error": None,
               "result": {"a": "clash", "big": list(range(500)), "small": [1, 2]}}
        for p in pts
    }  # fmt: skip
    rows = {int(r["a"]): r for r in summary_rows(write_summary(tmp_path, pts, recs).parent)}
    assert rows[1]["big"] == "(see points/<id>.json)" and json.loads(rows[1]["small"]) == [1, 2]
    assert rows[2]["result.a"] == "clash"  # a result key clashing with a parameter is renamed
