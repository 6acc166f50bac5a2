"""FOLD read/write: round trips, unknown keys, degrees, frames, malformed input (fuzzed)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from barhinge.errors import ConfigError, PatternError
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.fold import read_fold, read_fold_path, write_fold, write_fold_path
from barhinge.results import FoldPath

ATOL = 1e-12

SIMPLE = {
    "file_spec": 1.1,
    "file_creator": "hand",
    "frame_unit": "mm",
    "frame_classes": ["creasePattern"],
    "vertices_coords": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
    "edges_assignment": ["B", "B", "B", "B", "V"],
    "edges_foldAngle": [0, 0, 0, 0, 90],
    "faces_vertices": [[0, 1, 2], [0, 2, 3]],
    "myapp:note": {"anything": [1, 2, 3]},
}


def test_read_simple_keeps_degrees_and_unknown_keys(tmp_path: Path) -> None:
    cp = read_fold(SIMPLE)
    # degrees stay degrees (not radians): 90 in the file is 90 here
    np.testing.assert_array_equal(cp.fold_angles, [0, 0, 0, 0, 90])
    assert cp.meta["frame_unit"] == "mm"
    assert cp.meta["myapp:note"] == {"anything": [1, 2, 3]}
    out = write_fold(cp, tmp_path / "a.fold")
    data = json.loads(out.read_text())
    for k, v in SIMPLE.items():
        if k == "vertices_coords":
            np.testing.assert_allclose(data[k], v, rtol=0, atol=ATOL)
        else:
            assert data[k] == v, k


def test_missing_assignment_angles_and_faces() -> None:
    d = {k: SIMPLE[k] for k in ("vertices_coords", "edges_vertices")}
    cp = read_fold(d)
    assert cp.assignment.tolist() == ["U"] * 5
    np.testing.assert_array_equal(cp.fold_angles, 0.0)
    assert sorted(tuple(sorted(f)) for f in cp.faces) == [(0, 1, 2), (0, 2, 3)]


def test_clockwise_faces_are_normalised() -> None:
    d = dict(SIMPLE, faces_vertices=[[0, 2, 1], [0, 3, 2]], faces_edges=[[4, 1, 0], [3, 2, 4]])
    cp = read_fold(d)
    assert cp.faces == ((0, 1, 2), (0, 2, 3))
    assert "faces_edges" not in cp.meta  # stale after re-ordering
    assert cp.face_normals[:, 2].min() == pytest.approx(1.0)


def test_null_fold_angles_and_old_key() -> None:
    d = dict(SIMPLE, edges_foldAngle=[None, None, None, None, 45])
    np.testing.assert_array_equal(read_fold(d).fold_angles, [0, 0, 0, 0, 45])
    d = dict(SIMPLE)
    d["edges_foldAngles"] = d.pop("edges_foldAngle")
    np.testing.assert_array_equal(read_fold(d).fold_angles, [0, 0, 0, 0, 90])


def test_developable_flag_round_trips(tmp_path: Path) -> None:
    cp = read_fold(SIMPLE).replaced(developable=False)
    back = read_fold(write_fold(cp, tmp_path / "x.fold"))
    assert back.developable is False


def test_frames_round_trip(tmp_path: Path) -> None:
    cp = read_fold(SIMPLE)
    # the diagonal valley folded rigidly to 90 deg: vertex 3 rotates about the 0-2 axis
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    p = np.array([0.0, 1.0, 0.0])
    t = np.radians(90)
    r = p - axis * (p @ axis)
    q = axis * (p @ axis) + r * np.cos(t) + np.cross(axis, r) * np.sin(t)
    X1 = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], q])
    folded = CreasePattern(X1, cp.edges, cp.assignment, [0, 0, 0, 0, 90], cp.faces)
    assert abs(folded.state_fold_angles()[4]) == pytest.approx(90, abs=1e-9)
    out = write_fold(cp, tmp_path / "frames.fold", frames=[folded, X1 * 2])
    data = json.loads(out.read_text())
    assert [f["frame_inherit"] for f in data["file_frames"]] == [True, True]
    f1 = read_fold(out, frame=1)
    np.testing.assert_allclose(f1.vertices, X1, rtol=0, atol=ATOL)
    np.testing.assert_array_equal(f1.edges, cp.edges)  # inherited from the key frame
    assert f1.faces == cp.faces
    f2 = read_fold(out, frame=2)
    np.testing.assert_allclose(f2.vertices, 2 * X1, rtol=0, atol=ATOL)
    np.testing.assert_array_equal(f2.fold_angles, cp.fold_angles)
    with pytest.raises(PatternError, match="frame 3 requested"):
        read_fold(out, frame=3)
    # the key frame keeps the other frames in meta: rewriting it keeps them
    again = write_fold(read_fold(out), tmp_path / "again.fold")
    f2b = read_fold(again, frame=2)
    np.testing.assert_allclose(f2b.vertices, 2 * X1, rtol=0, atol=ATOL)


def test_fold_path_round_trip(tmp_path: Path) -> None:
    cp = read_fold(SIMPLE)
    rng = np.random.default_rng(0)
    n_states = 4
    X = np.repeat(cp.vertices3d[None], n_states, axis=0) + 0.01 * rng.random((n_states, 4, 3))
    A = rng.uniform(-30, 30, (n_states, cp.n_edges))
    A[1, 0] = np.nan  # an angle not measured: written as null, read back as NaN
    path = FoldPath(X=X, fold_angles_deg=A, kind="rigid")
    out = write_fold_path(cp, path, tmp_path / "path.fold")
    data = json.loads(out.read_text())
    assert len(data["file_frames"]) == n_states
    assert all(f["frame_inherit"] and f["frame_parent"] == 0 for f in data["file_frames"])
    cp2, X2, A2 = read_fold_path(out)
    np.testing.assert_allclose(X2, X, rtol=0, atol=ATOL)
    np.testing.assert_allclose(A2, A, rtol=0, atol=ATOL)
    np.testing.assert_allclose(cp2.vertices, cp.vertices, rtol=0, atol=ATOL)
    # a state read as a pattern (validation off: these states are bent)
    s2 = read_fold(out, frame=3, validate=False)
    np.testing.assert_allclose(s2.vertices, X[2], rtol=0, atol=ATOL)
    np.testing.assert_allclose(s2.fold_angles, A[2], rtol=0, atol=ATOL)
    assert data["file_frames"][1]["edges_foldAngle"][0] is None
    # the numbers survive the file exactly (shortest round-trip decimal form)
    np.testing.assert_array_equal(X2, X)
    # a coordinate that is not finite has no JSON form: refused, naming the state and vertex
    X[2, 3, 1] = np.inf
    with pytest.raises(PatternError, match="state 2: vertex 3 has a non-finite coordinate"):
        write_fold_path(cp, FoldPath(X=X, fold_angles_deg=A, kind="rigid"), tmp_path / "b.fold")


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"vertices_coords": [[0, 0], [1]]}, r"vertices_coords\[1\] has 1 entries"),
        ({"vertices_coords": "abc"}, "vertices_coords must be a list"),
        ({"edges_vertices": [[0, 1, 2]]}, r"edges_vertices\[0\] has 3 entries"),
        ({"edges_vertices": [[0, 9]] * 5}, "references vertex"),
        ({"edges_assignment": ["B"] * 4}, "len.edges_assignment. = 4"),
        ({"edges_assignment": ["B", "B", "B", "B", "J"]}, "join"),
        ({"edges_assignment": ["B", "B", "B", "B", "Q"]}, "assignment 'Q'"),
        ({"edges_foldAngle": [0, 0, 0, 0, "x"]}, "must be a list of numbers"),
        ({"edges_foldAngle": [0, 0, 0, 0, -90]}, "valley .* fold angle -90"),
        ({"faces_vertices": [[0, 1, 7]]}, "references a vertex outside"),
        ({"faces_vertices": [[0, True, 2]]}, "list of integers"),
    ],
)
def test_malformed(change: dict, match: str) -> None:
    d = dict(SIMPLE, **change)
    with pytest.raises(PatternError, match=match):
        read_fold(d)


def test_missing_keys_and_bad_files(tmp_path: Path) -> None:
    with pytest.raises(PatternError, match="no vertices_coords"):
        read_fold({"edges_vertices": []})
    with pytest.raises(PatternError, match="no edges_vertices"):
        read_fold({"vertices_coords": []})
    bad = tmp_path / "bad.fold"
    bad.write_text("{not json")
    with pytest.raises(PatternError, match="not valid JSON"):
        read_fold(bad)
    bad.write_text("[1, 2]")
    with pytest.raises(PatternError, match="JSON object"):
        read_fold(bad)
    with pytest.raises(PatternError, match="cannot read"):
        read_fold(tmp_path / "missing.fold")


# ----------------------------------------------------------------------------- fuzzing
json_leaf = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=3),
)  # fmt: skip
json_any = st.recursive(
    json_leaf,
    lambda ch: st.lists(ch, max_size=5) | st.dictionaries(st.text(max_size=4), ch, max_size=4),
    max_leaves=20,
)
KEYS = ["vertices_coords", "edges_vertices", "edges_assignment", "edges_foldAngle",
        "faces_vertices", "file_frames", "frame_unit"]  # fmt: skip


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    changes=st.dictionaries(st.sampled_from(KEYS), json_any, max_size=3),
    drop=st.lists(st.sampled_from(KEYS), max_size=2),
    frame=st.integers(0, 2),
)
def test_fuzz_mutated_fold(changes: dict, drop: list, frame: int) -> None:
    d = dict(SIMPLE, **changes)
    for k in drop:
        d.pop(k, None)
    try:
        read_fold(d, frame=frame)
    except (PatternError, ConfigError):
        pass


small_int = st.integers(-1, 5)
small_num = st.one_of(st.integers(-2, 3), st.floats(-2, 3), st.none())


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    V=st.lists(st.lists(small_num, max_size=4), max_size=6),
    E=st.lists(st.lists(small_int, max_size=3), max_size=8),
    A=st.one_of(
        st.none(), st.lists(st.sampled_from(["M", "V", "B", "F", "U", "C", "x", 3]), max_size=8)
    ),  # fmt: skip
    Fa=st.one_of(st.none(), st.lists(small_num, max_size=8)),
    faces=st.one_of(st.none(), st.lists(st.lists(small_int, max_size=5), max_size=4)),
)
def test_fuzz_structured_fold(V, E, A, Fa, faces) -> None:
    d = {"vertices_coords": V, "edges_vertices": E}
    for k, v in (("edges_assignment", A), ("edges_foldAngle", Fa), ("faces_vertices", faces)):
        if v is not None:
            d[k] = v
    try:
        read_fold(d)
    except (PatternError, ConfigError):
        pass


@settings(max_examples=60, deadline=None)
@given(text=st.one_of(st.text(max_size=60), st.binary(max_size=60).map(repr)))
def test_fuzz_file_text(tmp_path_factory, text: str) -> None:
    p = tmp_path_factory.mktemp("fz") / "x.fold"
    p.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        read_fold(p)
    except (PatternError, ConfigError):
        pass
