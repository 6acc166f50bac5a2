"""Property-based fuzzing of study loading (issue 16): a valid study file with values
replaced by wrong types, NaN / inf, dates, empty or nested lists, deleted keys, or its text
cut and spliced; ``load_study`` and the expansion of its points raise only barhinge's own
errors, with a one-line message."""

from __future__ import annotations

import copy
import datetime as dt
import sys
import tempfile
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from barhinge.errors import BarhingeError
from barhinge.sweep import load_study

HERE = Path(__file__).resolve().parents[1] / "inputs"
sys.path.insert(0, str(HERE))
from _scenes import _key, _value  # noqa: E402

BASE: dict[str, Any] = {
    "study": {
        "name": "demo",
        "function": "sweep_points:square",
        "paths": ["."],
        "out": "results",
        "batch_size": 2,
    },
    "grid": {"x": [1, 2, 3], "kappa": [0.0, 0.1]},
    "fixed": {"delay": 0.0, "label": "a", "nested": {"k": [1, 2]}},
    "points": [{"x": 7, "kappa": 0.5}, {"x": 8}],
}

WEIRD: list[Any] = [
    "x",
    "",
    "a:b:c",
    "no_colon",
    ":",
    True,
    False,
    float("nan"),
    float("inf"),
    float("-inf"),
    -1,
    0,
    0.5,
    2**63 - 1,
    -(2**63),
    [],
    [[]],
    [1, "a"],
    [float("nan")],
    [{"k": float("inf")}],
    {},
    {"k": 1},
    {"k": {"j": float("nan")}},
    dt.date(2020, 1, 2),
    dt.datetime(2020, 1, 2, 3, 4, 5),
    dt.time(1, 2, 3),
    [dt.date(2020, 1, 2)],
    {"when": dt.datetime(2020, 1, 2, 3, 4, 5, tzinfo=dt.UTC)},
]


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*prefix, i))
    return out


PATHS = _paths(BASE) + [("study", "bogus"), ("bogus",), ("grid", "new"), ("points", 0, "new")]

mutation = st.tuples(
    st.sampled_from(PATHS),
    st.one_of(st.sampled_from(WEIRD), st.integers(-3, 10), st.floats(allow_nan=True)),
    st.booleans(),  # delete instead of replace
)


def _apply(d: dict[str, Any], path: tuple[Any, ...], value: Any, delete: bool) -> None:
    node: Any = d
    for k in path[:-1]:
        try:
            node = node[k]
        except (KeyError, IndexError, TypeError):
            return
    last = path[-1]
    if isinstance(node, list) and isinstance(last, int) and last < len(node):
        node[last] = copy.deepcopy(value)
    elif isinstance(node, dict):
        if delete:
            node.pop(last, None)
        else:
            node[last] = copy.deepcopy(value)


def _toml_value(v: Any) -> str:
    if isinstance(v, dt.date | dt.time):  # TOML dates and times are bare
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(str(k))} = {_toml_value(x)}" for k, x in v.items()) + " }"
    return _value(v)


def to_toml(d: dict[str, Any]) -> str:
    return "".join(f"{_key(str(k))} = {_toml_value(v)}\n" for k, v in d.items())


def _load(text: str | bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "study.toml"
        if isinstance(text, bytes):
            f.write_bytes(text)
        else:
            f.write_text(text, encoding="utf-8")
        try:
            study = load_study(f)
            points = study.expand()  # ids need JSON-able parameters
        except BarhingeError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg, msg
            return
        assert points and all(len(p.id) == 16 for p in points)
    # anything else propagates and fails the test


def test_the_base_study_loads():
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "study.toml"
        f.write_text(to_toml(BASE))
        assert len(load_study(f).expand()) == 6 + 2


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(mutation, min_size=1, max_size=3))
def test_mutated_study_raises_only_barhinge_errors(mutations):
    d = copy.deepcopy(BASE)
    for path, value, delete in mutations:
        _apply(d, path, value, delete)
    _load(to_toml(d))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_spliced_study_text_raises_only_barhinge_errors(data):
    text = to_toml(BASE).encode()
    for _ in range(data.draw(st.integers(1, 3))):
        i = data.draw(st.integers(0, len(text)))
        j = data.draw(st.integers(i, min(len(text), i + 20)))
        junk = data.draw(st.binary(max_size=6) | st.sampled_from([b"[", b"]", b"=", b'"', b"\n"]))
        text = text[:i] + junk + text[j:]
    _load(text)


def test_what_the_fuzzing_found(tmp_path):
    """A TOML date as a parameter (TypeError in point_id before) and ``batch_size = true``
    (silently 1 before) are one-line ConfigErrors naming the key."""
    from barhinge.errors import ConfigError

    f = tmp_path / "s.toml"
    f.write_text('[study]\nfunction = "m:f"\n[grid]\nx = [1, 2020-01-02]\n')
    with pytest.raises(ConfigError, match=r"study \[grid\] x\[1\] = datetime.date\(2020, 1, 2\)"):
        load_study(f)
    f.write_text('[study]\nfunction = "m:f"\n[fixed]\nt = {at = 10:00:00}\n')
    with pytest.raises(ConfigError, match=r"study \[fixed\] t.at = datetime.time"):
        load_study(f)
    f.write_text('[study]\nfunction = "m:f"\nbatch_size = true\n')
    with pytest.raises(ConfigError, match="batch_size must be an integer >= 1, got True"):
        load_study(f)
