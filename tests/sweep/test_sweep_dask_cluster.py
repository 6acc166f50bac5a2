"""A sweep on a real Dask cluster (scheduler + two workers as separate processes on loopback);
one worker is killed mid-task and every point still ends with exactly one record."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from barhinge.sweep import read_records

distributed = pytest.importorskip("distributed")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from sweep_helpers import assert_each_point_once, markers_of, write_study  # noqa: E402

DASK = Path(sys.executable).with_name("dask")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def stop(procs: list[subprocess.Popen]) -> None:
    """End the processes this test started (by pid): workers first, SIGTERM then SIGKILL."""
    for p in reversed(procs):  # workers were started after the scheduler
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
        try:
            p.wait(timeout=3)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait(timeout=10)


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[tuple[str, list[subprocess.Popen]]]:
    """``dask scheduler`` and two ``dask worker --no-nanny`` processes on 127.0.0.1."""
    if not DASK.exists():
        pytest.skip(f"{DASK} is absent")
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = tmp_path / "logs"
    logs.mkdir()
    procs: list[subprocess.Popen] = []

    def start(name: str, args: list[str]) -> subprocess.Popen:
        p = subprocess.Popen(
            [str(DASK), *args],
            stdout=subprocess.DEVNULL,
            stderr=(logs / f"{name}.log").open("w"),
            start_new_session=True,
        )
        procs.append(p)
        return p

    try:
        start(
            "scheduler", ["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"]
        )
        workers = [
            start(
                f"worker{i}",
                [
                    "worker",
                    address,
                    "--host",
                    "127.0.0.1",
                    "--nthreads",
                    "1",
                    "--no-nanny",
                    "--no-dashboard",
                    "--name",
                    f"w{i}",
                ],
            )  # fmt: skip
            for i in (1, 2)
        ]
        client = distributed.Client(address, timeout="30s")
        try:
            client.wait_for_workers(2, timeout=60)
        finally:
            client.close()
        yield address, workers
    finally:
        stop(procs)


def test_worker_killed_mid_sweep_each_point_once(
    tmp_path: Path, cluster: tuple[str, list[subprocess.Popen]]
) -> None:
    address, workers = cluster
    xs = list(range(6))
    path = write_study(tmp_path, xs, delay=1.0)  # the kill lands well inside a point
    out = tmp_path / "out"
    victim = workers[0]
    cmd = [sys.executable, "-m", "barhinge.cli", "study", str(path), "--scheduler", address]
    sweep = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    killed_x = None
    try:
        deadline = time.monotonic() + 60
        while killed_x is None:  # kill the victim as soon as it has started a point
            assert sweep.poll() is None, "the sweep ended before a worker was killed"
            assert time.monotonic() < deadline, "no point started on the victim worker"
            for f in (tmp_path / "markers").glob("*-1"):
                try:
                    pid = int(f.read_text() or -1)
                except (OSError, ValueError):
                    continue
                if pid == victim.pid:
                    victim.kill()
                    killed_x = int(f.name.split("-")[0])
                    break
            time.sleep(0.01)
        victim.wait(timeout=10)
        # the point was in flight: it had no record when its worker died
        assert not any(r["params"]["x"] == killed_x for r in read_records(out).values())
        stdout, stderr = sweep.communicate(timeout=90)
    finally:
        if sweep.poll() is None:
            os.kill(sweep.pid, signal.SIGKILL)
            sweep.wait(timeout=10)
    assert sweep.returncode == 0, stderr
    assert_each_point_once(out, xs)
    runs = markers_of(tmp_path)
    assert runs[killed_x] == 2  # Dask ran the killed point again on the surviving worker
    assert all(runs[x] == 1 for x in xs if x != killed_x)
    survivor = workers[1].pid
    rec = next(r for r in read_records(out).values() if r["params"]["x"] == killed_x)
    assert rec["result"]["attempt"] == 2 and rec["result"]["pid"] == survivor
