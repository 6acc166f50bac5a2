"""Helpers shared by the sweep tests: a study of sweep_points:square and checks of its output."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from barhinge.sweep import point_id, read_records

HERE = Path(__file__).resolve().parent


def write_study(
    folder: Path,
    xs: list[int],
    *,
    delay: float = 0.0,
    fail_on: int = -1,
    batch_size: int = 1,
) -> Path:
    """A study of sweep_points:square over x in xs with markers in folder/markers."""
    markers = folder / "markers"
    markers.mkdir(exist_ok=True)
    text = f"""
[study]
name = "squares"
function = "sweep_points:square"
paths = ["{HERE}"]
out = "out"
batch_size = {batch_size}

[grid]
x = {json.dumps(xs)}

[fixed]
marker_dir = "{markers}"
delay = {delay}
fail_on = {fail_on}
"""
    path = folder / "study.toml"
    path.write_text(text)
    return path


def markers_of(folder: Path) -> dict[int, int]:
    """Number of executions per x (marker files x-attempt)."""
    counts: dict[int, int] = {}
    for f in (folder / "markers").glob("*-*"):
        if f.name.startswith("interrupt"):
            continue
        x = int(f.name.split("-")[0])
        counts[x] = counts.get(x, 0) + 1
    return counts


def summary_rows(out: Path) -> list[dict[str, str]]:
    with (out / "summary.csv").open() as fh:
        return list(csv.DictReader(fh))


def assert_each_point_once(out: Path, xs: list[int]) -> None:
    """One ok record per point, y = x^2, and the summary has each point id exactly once."""
    recs = read_records(out)
    by_x = {r["params"]["x"]: r for r in recs.values()}
    assert sorted(by_x) == sorted(xs) and len(recs) == len(xs)
    for x, r in by_x.items():
        assert r["status"] == "ok" and r["result"]["y"] == x * x
        assert r["id"] == point_id(r["params"])
    rows = summary_rows(out)
    ids = [r["id"] for r in rows]
    assert len(ids) == len(set(ids)) == len(xs)
    assert {int(r["x"]): int(r["y"]) for r in rows} == {x: x * x for x in xs}
    assert not list((out / "points").glob(".*.tmp"))
