"""Validation: one crafted bad pattern per error, the repair path, and fuzzing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.validate import _crossings, check, findings, holes, merged

SQUARE = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
BORDER = [[0, 1], [1, 2], [2, 3], [3, 0]]


def codes(cp: CreasePattern, severity: str | None = None) -> set[str]:
    return {f.code for f in findings(cp) if severity is None or f.severity == severity}


def raw(V, E, A=None, F=None, faces=None, **kw) -> CreasePattern:
    """A pattern built without validation (to inspect its findings)."""
    A = A if A is not None else ["B"] * len(E)
    return CreasePattern(np.asarray(V, float), np.asarray(E), A, F, faces, validate=False, **kw)


def assert_error(cp: CreasePattern, code: str, match: str) -> None:
    assert code in codes(cp, "error")
    with pytest.raises(PatternError, match=match) as exc:
        check(cp)
    assert "\n" not in str(exc.value)


def test_valid_square_with_diagonal() -> None:
    cp = CreasePattern(SQUARE, [*BORDER, [0, 2]], list("BBBBV"), [0, 0, 0, 0, 90])
    assert findings(cp) == []
    assert cp.n_faces == 2


def test_duplicate_vertex_and_repair() -> None:
    # vertex 4 is 1e-9 away from vertex 2 and closes the square instead of it
    V = np.vstack([SQUARE, [1 + 1e-9, 1]])
    E = [[0, 1], [1, 4], [4, 3], [3, 0], [0, 2]]
    cp = raw(V, E, list("BBBBV"), [0, 0, 0, 0, 90], faces=[[0, 1, 4, 3]])
    assert_error(cp, "duplicate-vertex", "vertices 2 and 4 coincide")
    fixed = merged(cp)
    assert fixed.n_vertices == 4 and fixed.n_edges == 5
    assert codes(fixed, "error") == set()
    assert fixed.faces == ((0, 1, 2, 3),)  # the given face, renumbered
    assert merged(cp, derive_faces=True).n_faces == 2  # the diagonal splits it
    # the constructor option does the same
    same = CreasePattern(V, E, list("BBBBV"), [0, 0, 0, 0, 90], merge_tol=1e-6)
    np.testing.assert_array_equal(same.edges, fixed.edges)


def test_zero_length_edge() -> None:
    V = np.vstack([SQUARE, [1, 1]])
    E = [*BORDER, [2, 4]]
    cp = raw(V, E, faces=[[0, 1, 2, 3]])
    assert_error(cp, "zero-length-edge", "edge 4 .* has length 0")


def test_duplicate_edges() -> None:
    same = raw(SQUARE, [*BORDER, [0, 2], [2, 0]], list("BBBBVV"), [0, 0, 0, 0, 90, 90])
    assert "duplicate-edge" in codes(same, "warning")
    assert codes(same, "error") == set()
    conflict = raw(SQUARE, [*BORDER, [0, 2], [2, 0]], list("BBBBVM"), [0, 0, 0, 0, 90, -90])
    assert_error(conflict, "duplicate-edge-conflict", "edges 4 and 5 join the same vertices")
    with pytest.raises(PatternError, match="different assignments"):
        merged(conflict)
    repaired = merged(same)
    assert repaired.n_edges == 5 and findings(repaired) == []


def test_crossing_edges() -> None:
    cp = raw(SQUARE, [*BORDER, [0, 2], [1, 3]], faces=[[0, 1, 2], [0, 2, 3]])
    assert_error(cp, "crossing-edges", "edges 4 and 5 cross without a vertex")


def test_vertex_on_edge() -> None:
    V = np.vstack([SQUARE, [0.5, 0.5]])
    cp = raw(V, [*BORDER, [0, 2], [1, 4]], faces=[[0, 1, 2], [0, 2, 3]])
    assert_error(cp, "vertex-on-edge", "vertex 4 lies on the interior of edge 4")


def test_face_side_not_edge() -> None:
    cp = raw(SQUARE, BORDER, faces=[[0, 1, 2], [0, 2, 3]])
    assert_error(cp, "face-side-not-edge", r"face 0 has side \(2, 0\), which is not an edge")


def test_face_repeated_vertex() -> None:
    cp = raw(SQUARE, [*BORDER, [0, 2]], faces=[[0, 1, 2, 0, 2, 3]])
    assert_error(cp, "face-repeated-vertex", "face 0 visits vertex")


def test_non_manifold_edge() -> None:
    # three triangles hinged on the edge 0-1 (a 3-D book)
    V = [[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -0.5, 0.8], [0.5, -0.5, -0.8]]
    E = [[0, 1], [1, 2], [2, 0], [0, 3], [3, 1], [0, 4], [4, 1]]
    cp = raw(V, E, faces=[[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert_error(cp, "non-manifold-edge", "edge 0 .* borders 3 faces")


def test_inconsistent_and_clockwise_faces() -> None:
    E = [*BORDER, [0, 2]]
    flipped = raw(SQUARE, E, faces=[[0, 1, 2], [0, 3, 2]])  # second face clockwise
    assert_error(flipped, "face-orientation", "traversed in the same direction")
    clockwise = raw(SQUARE, E, faces=[[0, 2, 1], [0, 3, 2]])
    assert_error(clockwise, "face-orientation", "every face is clockwise")


def test_zero_area_face() -> None:
    V = [[0, 0], [1, 0], [2, 0]]
    cp = raw(V, [[0, 1], [1, 2], [2, 0]], faces=[[0, 1, 2]])
    assert_error(cp, "zero-area-face", "face 0 .* has area 0")


def test_non_planar_face() -> None:
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0.1], [0, 1, 0]]
    cp = raw(V, BORDER, faces=[[0, 1, 2, 3]])
    assert_error(cp, "non-planar-face", "face 0 deviates from its plane")
    # a bent state is accepted when validation is switched off explicitly
    bent = CreasePattern(np.asarray(V), BORDER, list("BBBB"), faces=[[0, 1, 2, 3]], validate=False)
    assert bent.n_faces == 1


def test_assignment_sign_and_range() -> None:
    E = [*BORDER, [0, 2]]
    m = raw(SQUARE, E, list("BBBBM"), [0, 0, 0, 0, 45])
    assert_error(m, "assignment-sign", "edge 4 is a mountain .* with fold angle 45")
    v = raw(SQUARE, E, list("BBBBV"), [0, 0, 0, 0, -45])
    assert_error(v, "assignment-sign", "edge 4 is a valley .* with fold angle -45")
    r = raw(SQUARE, E, list("BBBBV"), [0, 0, 0, 0, 190])
    assert_error(r, "fold-angle-range", "edge 4 has fold angle 190")


def pyramid(h: float) -> tuple[np.ndarray, list, list]:
    """A square pyramid of height h: apex 4 is an interior vertex with sector angles summing
    to 4 * 2 * atan(0.5 / sqrt(0.5**2 + h**2)) < 360 deg (non-developable)."""
    V = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0], [0, 0, h]])
    E = [*BORDER, [0, 4], [1, 4], [2, 4], [3, 4]]
    faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    return V, E, faces


def test_not_developable_vertex() -> None:
    V, E, faces = pyramid(0.5)
    cp = raw(V, E, list("BBBBMMMM"), faces=faces)
    # closed form: each sector angle is 2 atan(half base / slant height)
    expected = 4 * np.degrees(2 * np.arctan(0.5 / np.hypot(0.5, 0.5)))
    assert_error(cp, "not-developable", f"vertex 4 sum to {expected:.6g} deg")
    ok = raw(V, E, list("BBBBMMMM"), faces=faces, developable=False)
    assert codes(ok, "error") == set()
    assert "not-developable" in codes(ok, "info")
    CreasePattern(V, E, list("BBBBMMMM"), faces=faces, developable=False)  # no error


def test_developable_folded_vertex_passes() -> None:
    # four unit squares around vertex 4 (3 x 3 grid), the right column folded by 60 deg about
    # the y axis: a rigid fold keeps the sector angles (sum 360 deg), so no error
    i, j = np.meshgrid([-1.0, 0.0, 1.0], [-1.0, 0.0, 1.0])
    V = np.column_stack([i.ravel(), j.ravel(), np.zeros(9)])
    t = np.radians(60)
    right = V[:, 0] > 0
    V[right] = np.column_stack([V[right, 0] * np.cos(t), V[right, 1], V[right, 0] * np.sin(t)])
    E = [[0, 1], [1, 2], [2, 5], [5, 8], [8, 7], [7, 6], [6, 3], [3, 0],
         [1, 4], [4, 7], [3, 4], [4, 5]]  # fmt: skip
    faces = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
    cp = CreasePattern(V, E, list("BBBBBBBBVVFF"), [0] * 8 + [60, 60, 0, 0], faces)
    assert codes(cp, "error") == set()
    np.testing.assert_allclose(np.abs(cp.state_fold_angles()[[8, 9]]), 60, rtol=0, atol=1e-9)
    np.testing.assert_allclose(cp.state_fold_angles()[[10, 11]], 0, rtol=0, atol=1e-9)


def test_hole_is_reported() -> None:
    # a square frame: outer square 0..3, inner square 4..7, four trapezoids
    V = np.array([[0, 0], [3, 0], [3, 3], [0, 3], [1, 1], [2, 1], [2, 2], [1, 2]], float)
    E = [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4],
         [0, 4], [1, 5], [2, 6], [3, 7]]  # fmt: skip
    faces = [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    cp = CreasePattern(V, E, list("BBBBBBBBFFFF"), faces=faces)
    info = [f for f in findings(cp) if f.code == "hole"]
    assert len(info) == 1 and info[0].severity == "info"
    assert holes(cp) == [[4, 5, 6, 7]]
    assert sorted(cp.interior_vertices.tolist()) == []


def test_warnings() -> None:
    V = np.vstack([SQUARE, [0.5, 0.5], [5, 5]])
    cp = raw(V, [*BORDER, [0, 4]], list("BBMBV"), [0, 0, -90, 0, 90], faces=[[0, 1, 2, 3]])
    assert {"edge-without-face", "crease-on-boundary", "isolated-vertex"} <= codes(cp, "warning")
    assert codes(cp, "error") == set()


def test_flat_folded_state_skips_layout_checks() -> None:
    # the diagonal fold of the unit square folded flat: vertex 2 lands on vertex 0
    V = [[0, 0], [1, 0], [0, 0], [0, 1]]
    E = [[0, 1], [1, 2], [2, 3], [3, 0], [3, 1]]
    cp = CreasePattern(np.asarray(V, float), E, list("BBBBV"), [0, 0, 0, 0, 180],
                       [[0, 1, 3], [1, 2, 3]])  # fmt: skip
    assert codes(cp) == {"flat-folded"}


# ----------------------------------------------------------------------------- properties
def brute_crossings(P: np.ndarray, E: np.ndarray) -> set[tuple[int, int]]:
    """O(m^2) proper-crossing test with exact rational arithmetic on integer coordinates."""
    from fractions import Fraction

    def orient(a, b, c):
        return (Fraction(b[0] - a[0]) * (c[1] - a[1])) - (Fraction(b[1] - a[1]) * (c[0] - a[0]))

    out = set()
    for i in range(len(E)):
        for j in range(i + 1, len(E)):
            a, b = P[E[i, 0]], P[E[i, 1]]
            c, d = P[E[j, 0]], P[E[j, 1]]
            if len({*E[i], *E[j]}) < 4:
                continue
            o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
            if o1 * o2 < 0 and o3 * o4 < 0:
                out.add((i, j))
    return out


@settings(max_examples=40, deadline=None)
@given(
    pts=st.lists(
        st.tuples(st.integers(0, 20), st.integers(0, 20)), min_size=4, max_size=14, unique=True
    ),  # fmt: skip
    data=st.data(),
)
def test_crossings_match_brute_force(pts, data) -> None:
    P = np.array(pts, float)
    n = len(P)
    pairs = data.draw(
        st.lists(
            st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), min_size=1, max_size=25
        )  # fmt: skip
    )
    E = np.array([(a, b) for a, b in pairs if a != b] or [(0, 1)], np.int64)
    E = np.unique(np.sort(E, 1), axis=0)
    got = {tuple(sorted(f.index)) for f in _crossings(P, E, 1e-9) if f.code == "crossing-edges"}
    assert got == brute_crossings(P, E)


finite = st.floats(-10, 10, allow_nan=False)
weird = st.one_of(finite, st.just(float("nan")), st.just(float("inf")), st.just(1e300))


@settings(max_examples=80, deadline=None)
@given(
    V=st.lists(st.lists(weird, min_size=2, max_size=3), min_size=0, max_size=9),
    E=st.lists(st.lists(st.integers(-2, 10), min_size=1, max_size=3), max_size=14),
    A=st.lists(st.sampled_from(list("MVFBUCX")), max_size=14),
    F=st.one_of(st.none(), st.lists(weird, max_size=14)),
    faces=st.one_of(st.none(), st.lists(st.lists(st.integers(-1, 10), max_size=5), max_size=5)),
    developable=st.booleans(),
)
def test_validator_fuzz(V, E, A, F, faces, developable) -> None:
    """Any input either builds a pattern or raises PatternError; findings never crash."""
    try:
        Va = np.array(V, float) if V and len({len(v) for v in V}) == 1 else V
        Ea = np.array(E) if E and len({len(e) for e in E}) == 1 else E
        cp = CreasePattern(Va, Ea, A[: len(E)] if A else A, F, faces, developable=developable,
                           validate=False)  # fmt: skip
    except PatternError:
        return
    except ValueError as exc:  # ragged input rejected by numpy before our checks
        pytest.fail(f"ValueError escaped: {exc}")
    found = findings(cp)
    assert all(f.severity in ("error", "warning", "info") for f in found)
    try:
        check(cp)
    except PatternError as exc:
        assert "\n" not in str(exc)


@settings(max_examples=60, deadline=None)
@given(
    pts=st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6)), min_size=3, max_size=12),
    data=st.data(),
)
def test_validator_fuzz_planar_graphs(pts, data) -> None:
    """Degenerate integer graphs (coincident points, collinear overlaps, crossings): building
    a pattern with derived faces gives a pattern or PatternError, nothing else."""
    n = len(pts)
    E = data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=20))
    A = data.draw(st.lists(st.sampled_from(list("MVFB")), min_size=len(E), max_size=len(E)))
    try:
        cp = CreasePattern(np.array(pts, float), np.array(E, np.int64).reshape(-1, 2), A)
    except PatternError:
        return
    assert codes(cp, "error") == set()


def test_reflex_corner_angles() -> None:
    # L-shaped hexagon: the corner at vertex 3 is reflex (270 deg); interior angles of a
    # simple k-gon sum to (k - 2) * 180 deg
    V = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    cp = CreasePattern(V, [[i, (i + 1) % 6] for i in range(6)], ["B"] * 6)
    ang = np.degrees(cp.face_corner_angles[0])
    np.testing.assert_allclose(ang, [90, 90, 90, 270, 90, 90], rtol=0, atol=1e-12)
    assert ang.sum() == pytest.approx((6 - 2) * 180, abs=1e-9)
