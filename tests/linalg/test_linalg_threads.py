"""The thread policy: limits applied inside barhinge's public calls and restored after.

Checked against threadpoolctl's own report of the libraries' thread counts (an independent
reading of what the BLAS libraries are set to)."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import threading
import time

import pytest
from threadpoolctl import threadpool_info

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.linalg import threads


def blas_threads() -> dict[str, int]:
    """Threads of each loaded BLAS library (OpenMP runtimes left out: barhinge limits the
    BLAS libraries themselves)."""
    return {
        d["internal_api"]: d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"
    }


@pytest.mark.parametrize(
    ("raw", "want"), [("", "auto"), ("AUTO", "auto"), ("off", "off"), ("3", 3)]
)
def test_policy_from_the_environment(monkeypatch, raw, want):
    monkeypatch.setenv(threads.ENV, raw)
    assert threads.policy() == want


@pytest.mark.parametrize("raw", ["0", "-2", "many", "1.5"])
def test_bad_policy_is_a_one_line_error(monkeypatch, raw):
    monkeypatch.setenv(threads.ENV, raw)
    with pytest.raises(ConfigError, match="BARHINGE_THREADS"):
        threads.policy()


def test_dense_calls_use_one_blas_thread_and_restore(monkeypatch):
    monkeypatch.delenv(threads.ENV, raising=False)
    before = blas_threads()
    with threads.dense_calls():
        inside = blas_threads()
    assert set(inside.values()) == {1}
    assert blas_threads() == before


def test_sparse_solves_match_mkl_to_the_free_cores(monkeypatch):
    pytest.importorskip("pypardiso")  # loads MKL
    monkeypatch.delenv(threads.ENV, raising=False)
    monkeypatch.setattr(threads, "free_cores", lambda: 1)
    before = blas_threads()
    assert "mkl" in before
    with threads.sparse_solves():
        inside = blas_threads()
    assert all(v == 1 for v in inside.values()), inside
    assert blas_threads() == before


def test_off_changes_nothing_and_one_sets_every_library_to_one(monkeypatch):
    before = blas_threads()
    monkeypatch.setenv(threads.ENV, "off")
    with threads.dense_calls(), threads.sparse_solves():
        assert blas_threads() == before
    monkeypatch.setenv(threads.ENV, "1")
    with threads.sparse_solves():
        assert set(blas_threads().values()) == {1}


def test_a_number_sets_mkl_and_keeps_the_dense_calls_on_one_thread(monkeypatch):
    """``n`` gives PARDISO (MKL) n threads whatever the load; the small dense calls keep one
    BLAS thread, whose spinning after each call would take a core from the kernels."""
    pytest.importorskip("pypardiso")  # loads MKL
    monkeypatch.setenv(threads.ENV, "3")
    monkeypatch.setattr(threads, "free_cores", lambda: 1)
    with threads.sparse_solves():
        inside = blas_threads()
    assert inside.pop("mkl") == 3
    assert set(inside.values()) <= {1}
    with threads.dense_calls():
        assert set(blas_threads().values()) == {1}


def test_mkl_threads_sleep_after_a_call_unless_the_user_says_otherwise():
    """The PARDISO backend sets ``KMP_BLOCKTIME=0`` where the environment has none (read in a
    fresh process: the OpenMP runtime reads it when MKL loads)."""
    pytest.importorskip("pypardiso")
    code = (
        "import os; from barhinge.linalg.backends import PardisoBackend; PardisoBackend(); "
        "print(os.environ['KMP_BLOCKTIME'])"
    )
    for given, want in ((None, "0"), ("50", "50")):
        env = {k: v for k, v in os.environ.items() if k != "KMP_BLOCKTIME"}
        if given is not None:
            env["KMP_BLOCKTIME"] = given
        out = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        assert out.stdout.strip() == want


def test_free_cores_subtracts_the_load(monkeypatch):
    monkeypatch.setattr(threads, "cores", lambda: 8)
    monkeypatch.setattr(threads.os, "getloadavg", lambda: (3.4, 0.0, 0.0))
    assert threads.free_cores() == 6  # 8 cores, 3 taken by others, this process counts itself
    monkeypatch.setattr(threads.os, "getloadavg", lambda: (40.0, 0.0, 0.0))
    assert threads.free_cores() == 1


@pytest.mark.parametrize(("raw", "want"), [("3", 3), ("off", 1), ("auto", 5)])
def test_field_files_are_written_by_the_policys_threads(monkeypatch, raw, want):
    """A fixed count is kept, ``off`` writes one file at a time, ``auto`` uses every core the
    process may run on, whatever the load average (a finished solve's own load)."""
    monkeypatch.setenv(threads.ENV, raw)
    monkeypatch.setattr(threads, "cores", lambda: 5)
    monkeypatch.setattr(threads.os, "getloadavg", lambda: (40.0, 0.0, 0.0))
    assert threads.worker_threads() == want


def test_public_calls_run_under_the_policy(monkeypatch):
    """rigid_fold and dof run their dense work with one BLAS thread (read from inside)."""
    monkeypatch.delenv(threads.ENV, raising=False)
    dofmod = importlib.import_module("barhinge.kinematics.dof")

    seen: list[dict[str, int]] = []
    real = dofmod.RigidConstraints

    class Spy(real):  # type: ignore[misc,valid-type]
        def __init__(self, *a, **k):
            seen.append(blas_threads())
            super().__init__(*a, **k)

    monkeypatch.setattr(dofmod, "RigidConstraints", Spy)
    bh.dof(bh.families.miura(2, 2))
    assert seen and all(set(s.values()) == {1} for s in seen)
    assert bh.dof.__name__ == "dof" and "Parameters" in (bh.dof.__doc__ or "")


def test_parallel_map_runs_on_the_worker_threads_in_order(monkeypatch):
    """Results come back in the order of the items, computed on the pool's own threads."""
    monkeypatch.setenv(threads.ENV, "3")
    seen: list[str] = []

    def square(i: int) -> int:
        seen.append(threading.current_thread().name)
        time.sleep(0.001 * (7 - i))  # later items finish first
        return i * i

    assert threads.parallel_map(square, range(7)) == [i * i for i in range(7)]
    assert all(name.startswith("barhinge-worker") for name in seen)


@pytest.mark.parametrize("raw", ["1", "off"])
def test_parallel_map_is_serial_on_one_thread(monkeypatch, raw):
    monkeypatch.setenv(threads.ENV, raw)
    seen: list[str] = []
    out = threads.parallel_map(lambda i: seen.append(threading.current_thread().name) or i, [1, 2])
    assert out == [1, 2]
    assert seen == [threading.current_thread().name] * 2


def test_parallel_map_raises_after_every_item_ran_and_does_not_nest(monkeypatch):
    """An error is raised once all items are done (none is left writing); a map called from
    a worker runs serially there instead of waiting on its own pool (two threads, both
    busy with an outer item each, would otherwise wait on each other for ever)."""
    monkeypatch.setenv(threads.ENV, "2")
    done: list[int] = []

    def item(i: int) -> int:
        if i == 0:
            raise ValueError("item 0 is bad")
        time.sleep(0.01)
        done.append(i)
        return i

    with pytest.raises(ValueError, match="item 0 is bad"):
        threads.parallel_map(item, range(4))
    assert sorted(done) == [1, 2, 3]

    def outer(i: int) -> list[int]:
        return threads.parallel_map(lambda j: 10 * i + j, range(3))

    assert threads.parallel_map(outer, range(2)) == [[0, 1, 2], [10, 11, 12]]


def test_parallel_map_makes_its_pool_again_in_a_forked_process(monkeypatch):
    """A pool's threads do not survive a fork: a new process id gets a new pool."""
    monkeypatch.setenv(threads.ENV, "2")
    threads.parallel_map(abs, [-1, -2])
    first = threads._worker_pool(2)
    assert threads._worker_pool(2) is first
    monkeypatch.setattr(threads.os, "getpid", lambda: -12345)
    assert threads._worker_pool(2) is not first
    assert threads.parallel_map(abs, [-1, -2]) == [1, 2]
