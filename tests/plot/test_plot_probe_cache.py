"""The off-screen probe runs once per machine set-up, not once per run: a success is cached
on disk under its key; a failure is not (a machine that gains a GL stack is probed again)."""

from __future__ import annotations

import json
import subprocess

import pytest

from barhinge.plot import render


class FakeRun:
    def __init__(self, code: int) -> None:
        self.code, self.calls = code, 0

    def __call__(self, *a, **k):
        self.calls += 1
        return subprocess.CompletedProcess(a, self.code, b"", b"")


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    monkeypatch.delenv("BARHINGE_OFFSCREEN", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    render.can_render_offscreen.cache_clear()
    yield tmp_path
    render.can_render_offscreen.cache_clear()


def test_a_success_is_probed_once_and_remembered(monkeypatch, fresh):
    run = FakeRun(0)
    monkeypatch.setattr(render.subprocess, "run", run)
    assert render.can_render_offscreen()
    render.can_render_offscreen.cache_clear()  # a new process
    assert render.can_render_offscreen()
    assert run.calls == 1
    saved = json.loads((fresh / "barhinge" / "offscreen.json").read_text())
    assert saved == {render._probe_key(): True}


def test_a_changed_gl_environment_is_probed_again(monkeypatch, fresh):
    run = FakeRun(0)
    monkeypatch.setattr(render.subprocess, "run", run)
    assert render.can_render_offscreen()
    monkeypatch.setenv("LIBGL_ALWAYS_SOFTWARE", "1")
    render.can_render_offscreen.cache_clear()
    assert render.can_render_offscreen()
    assert run.calls == 2


def test_a_failure_is_not_remembered(monkeypatch, fresh):
    run = FakeRun(1)
    monkeypatch.setattr(render.subprocess, "run", run)
    assert not render.can_render_offscreen()
    render.can_render_offscreen.cache_clear()
    assert not render.can_render_offscreen()
    assert run.calls == 2
    assert not (fresh / "barhinge" / "offscreen.json").exists()


def test_an_unwritable_or_corrupt_cache_only_costs_a_probe(monkeypatch, fresh):
    run = FakeRun(0)
    monkeypatch.setattr(render.subprocess, "run", run)
    (fresh / "barhinge").mkdir()
    (fresh / "barhinge" / "offscreen.json").write_text("{not json")
    assert render.can_render_offscreen()
    assert run.calls == 1
    blocked = fresh / "file"
    blocked.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocked))  # a file: the cache dir cannot exist
    render.can_render_offscreen.cache_clear()
    assert render.can_render_offscreen()
