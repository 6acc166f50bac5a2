"""Property-based fuzzing of scene loading: a valid scene with some values replaced by wrong
types, NaN / inf, negative, huge, wrong-length lists, bools and strings; only barhinge's own
errors may escape (issue 16: 164 of 600 mutated scenes raised TypeError / ValueError /
OverflowError before)."""

from __future__ import annotations

import copy
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import barhinge as bh
from barhinge.errors import BarhingeError
from barhinge.scene import load_scene, scene_from_dict

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _scenes import BASE, to_toml  # noqa: E402

WEIRD: list[Any] = [
    "x",
    "",
    "creases",
    True,
    False,
    float("nan"),
    float("inf"),
    float("-inf"),
    -1,
    -1.0,
    0,
    0.0,
    0.5,
    2.7,
    179.9,
    1e308,
    -1e308,
    10**18,
    2**63 - 1,
    [],
    [1.0],
    [1.0, 2.0],
    [1.0, 2.0, 3.0, 4.0],
    ["a"],
    [[1.0]],
    [True, False, True],
    [float("nan"), 1.0, 0.0],
    {"k": 1},
    {},
]


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key and list index of the mapping, leaves and tables alike."""
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*prefix, i))
    return out


PATHS = _paths(BASE)
# keys that exist in the format but not in BASE
EXTRA = (
    [
        ("solve", "options", k)
        for k in ("max_iter", "max_cutbacks", "reuse_factorization", "augmentation", "predictor")
    ]
    + [("model", k) for k in ("stiffness_ratio", "fold_limits_deg", "bar_EA", "fold_k")]
    + [
        ("actuators", "table_deg"),
        ("pattern", "frame"),
        ("supports", 0, "nodes"),
        ("supports", 0, "edges"),
    ]
)

mutation = st.tuples(
    st.sampled_from(PATHS + EXTRA),
    st.one_of(st.sampled_from(WEIRD), st.integers(-3, 40), st.floats(allow_nan=True)),
    st.booleans(),  # delete instead of replace
)


def _apply(d: dict[str, Any], path: tuple[Any, ...], value: Any, delete: bool) -> None:
    node = d
    for k in path[:-1]:
        try:
            node = node[k]
        except (KeyError, IndexError, TypeError):
            return  # an earlier mutation replaced a parent
    if not isinstance(node, dict | list):
        return
    last = path[-1]
    if isinstance(node, list) and (not isinstance(last, int) or last >= len(node)):
        return
    if delete:
        if isinstance(node, dict):
            node.pop(last, None)
        return
    node[last] = copy.deepcopy(value)


def _only_barhinge_errors(fn, *args):
    try:
        fn(*args)
    except BarhingeError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg, msg
    # anything else propagates and fails the test


@settings(
    max_examples=200,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(st.lists(mutation, min_size=1, max_size=3))
def test_mutated_scene_mapping_raises_only_barhinge_errors(mutations):
    d = copy.deepcopy(BASE)
    for path, value, delete in mutations:
        _apply(d, path, value, delete)
    _only_barhinge_errors(scene_from_dict, d)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(mutation, min_size=1, max_size=2))
def test_mutated_scene_file_raises_only_barhinge_errors(mutations):
    d = copy.deepcopy(BASE)
    for path, value, delete in mutations:
        _apply(d, path, value, delete)
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "scene.toml"
        f.write_text(to_toml(d))
        _only_barhinge_errors(load_scene, f)


_SCENE = scene_from_dict(copy.deepcopy(BASE))
_N = _SCENE.model.n_nodes

array_values = st.one_of(
    st.sampled_from(WEIRD),
    st.just(np.zeros((_N, 2))),
    st.just(np.full((_N, 3), np.nan)),
    st.just(np.full((_N, 3), np.inf)),
    st.just(np.ones((_N, 3), bool)),
    st.just(np.zeros((_N, 3), int)),
    st.just(np.array([["a", "b", "c"]] * _N)),
)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.dictionaries(
        st.sampled_from(["supports", "loads", "prescribed", "steps", "control", "options", "name"]),
        array_values,
        min_size=1,
        max_size=3,
    )
)
def test_scene_construction_raises_only_barhinge_errors(changes):
    _only_barhinge_errors(lambda: _SCENE.with_(**changes))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.sampled_from(["edges", "targets_deg", "table_deg"]),
    st.one_of(st.sampled_from(WEIRD), st.floats(allow_nan=True)),
)
def test_actuators_and_material_raise_only_barhinge_errors(key, value):
    kw = {"edges": [21], "targets_deg": [10.0]}
    if key == "table_deg":
        kw.pop("targets_deg")
    kw[key] = value
    _only_barhinge_errors(lambda: bh.Actuators(**kw))
    for name in ("E", "nu", "t"):
        _only_barhinge_errors(lambda name=name: bh.Material(**{name: value}))
