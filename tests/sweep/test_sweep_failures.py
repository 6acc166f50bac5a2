"""Failures a study records without stopping (issue 16, item 6): a worker killed by one point
fails that point only; non-finite results are failures naming the key; every JSON written by
a study is strict (no NaN or Infinity)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from barhinge.errors import ConfigError
from barhinge.sweep import Study, load_study, read_records, run_study

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from sweep_helpers import markers_of, summary_rows  # noqa: E402


def _reject(constant: str) -> float:
    raise ValueError(f"non-standard JSON constant {constant}")


def strict_load(path: Path) -> object:
    """json.loads that rejects NaN, Infinity and -Infinity, as strict JSON readers do."""
    return json.loads(path.read_text(), parse_constant=_reject)


def assert_strict_folder(out: Path) -> None:
    files = [out / "study.json", *sorted((out / "points").glob("*.json"))]
    assert len(files) > 1
    for f in files:
        strict_load(f)


def test_non_finite_results_are_failures_naming_the_key(tmp_path: Path) -> None:
    study = Study(function="sweep_points:non_finite", grid={"x": [0, 1, 2, 3]}, paths=(str(HERE),))
    rep = run_study(study, out=tmp_path / "out", mode="serial")
    assert (rep.done, rep.failed) == (1, 3)
    assert_strict_folder(tmp_path / "out")
    recs = {r["params"]["x"]: r for r in read_records(tmp_path / "out").values()}
    assert recs[0]["status"] == "ok" and recs[0]["result"]["y"] == 0.0
    msgs = {x: recs[x]["error"]["message"] for x in (1, 2, 3)}
    assert all(recs[x]["error"]["type"] == "NonFiniteResult" for x in (1, 2, 3))
    assert "'y' is nan" in msgs[1]
    assert "'vec[1]' is inf" in msgs[2]
    assert "'nested.z' is -inf" in msgs[3]
    # the finite part of the result is kept; the non-finite values become null
    assert recs[2]["result"]["vec"] == [2.0, None] and recs[2]["result"]["y"] == 4.0
    rows = {int(r["x"]): r for r in summary_rows(tmp_path / "out")}
    assert rows[1]["status"] == "failed" and rows[1]["error_type"] == "NonFiniteResult"
    assert "nan" not in rows[1]["y"].lower()


def test_non_finite_parameters_are_a_config_error(tmp_path: Path) -> None:
    f = tmp_path / "s.toml"
    f.write_text('[study]\nfunction = "m:f"\n[grid]\nx = [1.0, nan]\n')
    with pytest.raises(ConfigError, match=r"x\[1\] = nan"):
        load_study(f)
    f.write_text('[study]\nfunction = "m:f"\n[fixed]\nscale = {a = [inf]}\n')
    with pytest.raises(ConfigError, match=r"\[fixed\] scale.a\[0\] = inf"):
        load_study(f)
    with pytest.raises(ConfigError, match=r"\[\[points\]\] 0: y = -inf"):
        Study(function="m:f", points=({"y": float("-inf")},))


def test_worker_death_fails_only_the_point_that_killed_it(tmp_path: Path) -> None:
    """Point 0 kills its worker; with ``allowed-failures = 0`` the scheduler gives up on every
    task that was on that worker at once (KilledWorker), the innocent ones included. Those
    are run again one at a time: only point 0 kills its worker alone, and only it fails."""
    distributed = pytest.importorskip("distributed")
    import dask

    markers = tmp_path / "markers"
    markers.mkdir()
    xs = list(range(6))
    study = Study(
        function="sweep_points:killer",
        grid={"x": xs},
        fixed={"marker_dir": str(markers), "delay": 0.3, "kill_on": 0},
        paths=(str(HERE),),
    )
    assert distributed.KilledWorker  # the exception the scheduler raises
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        rep = run_study(study, out=tmp_path / "out", mode="local", workers=2)
    recs = {r["params"]["x"]: r for r in read_records(tmp_path / "out").values()}
    assert sorted(recs) == xs and (rep.done, rep.failed) == (5, 1)
    assert all(recs[x]["status"] == "ok" and recs[x]["result"]["y"] == x * x for x in xs[1:])
    err = recs[0]["error"]
    assert err["type"] == "KilledWorker"
    assert err["message"].startswith("worker died (killed 1 time)"), err
    assert "\n" not in err["message"]
    runs = markers_of(tmp_path)
    assert runs[0] == 2  # once among the others, once alone
    assert_strict_folder(tmp_path / "out")


def test_a_record_with_nan_from_an_older_version_is_rerun(tmp_path: Path) -> None:
    study = Study(function="sweep_points:non_finite", grid={"x": [0]}, paths=(str(HERE),))
    out = tmp_path / "out"
    run_study(study, out=out, mode="serial")
    (path,) = (out / "points").glob("*.json")
    old = json.loads(path.read_text())
    path.write_text(json.dumps({**old, "result": {"y": float("nan")}}))  # NaN, as before
    assert read_records(out) == {}  # not strict JSON: not a record
    rep = run_study(study, out=out, mode="serial")
    assert (rep.skipped, rep.done) == (0, 1)
    assert strict_load(path)["result"]["y"] == 0.0


def test_a_key_the_point_function_does_not_take_stops_the_study(tmp_path: Path) -> None:
    """A ``[grid]`` key the function does not accept used to fail every point (TypeError)
    while the study exited 0; now it is a ConfigError before anything runs or is written."""
    out = tmp_path / "out"
    bad = Study(function="sweep_points:square", grid={"x": [1], "bogus": [1]}, paths=(str(HERE),))
    with pytest.raises(ConfigError, match=r"\[grid\] key 'bogus'.*takes x, marker_dir"):
        run_study(bad, out=out, mode="serial")
    assert not out.exists()
    none = Study(function="sweep_points:square", fixed={"delay": 0.0}, paths=(str(HERE),))
    with pytest.raises(ConfigError, match="needs 'x', which no"):
        run_study(none, out=out, mode="serial")
    # a function taking **kwargs accepts any key
    ok = Study(function="json:dumps", grid={"obj": [1], "anything": [2]})
    assert run_study(ok, out=out, mode="serial").failed == 1  # json.dumps(anything=2) fails
