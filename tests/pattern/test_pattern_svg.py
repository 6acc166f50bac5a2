"""SVG import (Origami Simulator convention) on small hand-made drawings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from barhinge.errors import PatternError
from barhinge.pattern.planar import signed_areas
from barhinge.pattern.svg import assignment_of_colour, read_svg
from barhinge.pattern.validate import findings

HEAD = '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 100 100">'


def svg(tmp_path: Path, body: str, name: str = "p.svg") -> Path:
    p = tmp_path / name
    p.write_text(f"{HEAD}\n{body}\n</svg>\n")
    return p


BORDER = '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>'


@pytest.mark.parametrize(
    ("colour", "kind"),
    [
        ("#f00", "M"), ("#FF0000", "M"), ("red", "M"), ("rgb(255,0,0)", "M"),
        ("#00f", "V"), ("blue", "V"), ("#000000", "B"), ("black", "B"),
        ("#0f0", "C"), ("green", "C"), ("lime", "C"), ("#ff0", "F"), ("yellow", "F"),
        ("#f0f", "U"), ("magenta", "U"), ("rgb(250, 5, 3)", "M"),
    ],
)  # fmt: skip
def test_colour_conventions(tmp_path: Path, colour: str, kind: str) -> None:
    body = f'{BORDER}<line x1="0" y1="0" x2="100" y2="100" stroke="{colour}"/>'
    cp = read_svg(svg(tmp_path, body), validate=False)
    diag = [e for e in range(cp.n_edges) if cp.assignment[e] != "B" or kind == "B"]
    assert cp.n_edges == 5
    assert sorted(cp.assignment.tolist()) == sorted(["B"] * 4 + [kind])
    assert diag


def test_unknown_colour_is_skipped(tmp_path: Path) -> None:
    body = f'{BORDER}<line x1="0" y1="0" x2="100" y2="100" stroke="#0ff"/>'
    cp = read_svg(svg(tmp_path, body))
    assert cp.n_edges == 4 and cp.meta["barhinge:svg_skipped_shapes"] == 1
    assert assignment_of_colour((0, 255, 255)) is None


def test_opacity_gives_fold_angle(tmp_path: Path) -> None:
    body = (
        f"{BORDER}"
        '<line x1="0" y1="50" x2="50" y2="50" stroke="#f00" opacity="0.5"/>'
        '<line x1="50" y1="50" x2="100" y2="50" stroke="#00f" opacity="0.5" stroke-opacity="0.5"/>'
        '<line x1="50" y1="0" x2="50" y2="50" stroke="#00f" style="stroke-opacity:0.25"/>'
        '<line x1="50" y1="50" x2="50" y2="100" stroke="#f00"/>'
    )
    cp = read_svg(svg(tmp_path, body))
    P = cp.vertices[cp.edges].mean(1)  # edge midpoints, y up after the flip
    got = {
        (round(x), round(y)): (a, r)
        for (x, y), a, r in zip(P, cp.assignment, cp.fold_angles, strict=True)
    }
    assert got[(25, 50)] == ("M", -90.0)
    assert got[(75, 50)] == ("V", 45.0)
    assert got[(50, 75)] == ("V", 45.0)  # SVG y = 25 is up here
    assert got[(50, 25)] == ("M", -180.0)


def test_y_axis_flipped_and_faces_ccw(tmp_path: Path) -> None:
    # a valley from the SVG's top-left corner to the middle of the top side
    body = f'{BORDER}<polyline points="0,0 50,100" stroke="#00f" fill="none"/>'
    cp = read_svg(svg(tmp_path, body))
    np.testing.assert_allclose(cp.vertices.min(0), [0, 0], rtol=0, atol=1e-12)
    v_edge = int(np.flatnonzero(cp.assignment == "V")[0])
    ends = sorted(map(tuple, cp.vertices[cp.edges[v_edge]].tolist()))
    assert ends == [(0.0, 100.0), (50.0, 0.0)]  # SVG (0,0) is the top-left corner
    assert np.all(signed_areas(cp.vertices, cp.faces) > 0)


def test_group_transforms(tmp_path: Path) -> None:
    body = (
        '<g transform="translate(10,20)"><g transform="scale(2)">'
        '<rect x="0" y="0" width="10" height="10" stroke="black" fill="none"/>'
        '<line x1="0" y1="0" x2="10" y2="10" stroke="red"/></g></g>'
    )
    cp = read_svg(svg(tmp_path, body))
    # the 10 x 10 square scaled to 20 x 20 (translation removed by the shift to the origin)
    np.testing.assert_allclose(cp.vertices.max(0) - cp.vertices.min(0), [20, 20], rtol=0,
                               atol=1e-12)  # fmt: skip
    assert cp.n_faces == 2
    np.testing.assert_allclose(signed_areas(cp.vertices, cp.faces), 200, rtol=0, atol=1e-9)


def test_crossings_split_and_rounding_merged(tmp_path: Path) -> None:
    # two diagonals crossing at the centre; the second one ends 1e-4 away from the corner
    body = (
        f"{BORDER}"
        '<line x1="0" y1="0" x2="100" y2="100" stroke="#f00"/>'
        '<path d="M 100.0001,0 L 0,99.9999" stroke="#00f"/>'
    )
    cp = read_svg(svg(tmp_path, body))
    assert (cp.n_vertices, cp.n_edges, cp.n_faces) == (5, 8, 4)
    centre = np.flatnonzero(cp.vertex_degree == 4)
    np.testing.assert_allclose(cp.vertices[centre[0]], [50, 50], rtol=0, atol=1e-3)
    assert findings(cp) == []


def test_t_junction_and_overlap(tmp_path: Path) -> None:
    # a valley ending on the middle of the red crease, and a crease drawn over the border
    body = (
        f"{BORDER}"
        '<line x1="0" y1="50" x2="100" y2="50" stroke="#f00"/>'
        '<line x1="50" y1="50" x2="50" y2="100" stroke="#00f"/>'
        '<line x1="0" y1="0" x2="100" y2="0" stroke="#f00"/>'
    )
    cp = read_svg(svg(tmp_path, body))
    # 4 corners + 2 side midpoints of the red line + its midpoint (T) + the valley's end on
    # the side = 8; border 7 (two sides split by the red line, one by the valley), red 2,
    # valley 1; faces: the upper half and the lower half split in two = 3
    assert (cp.n_vertices, cp.n_edges, cp.n_faces) == (8, 10, 3)
    assert int((cp.assignment == "B").sum()) == 7  # the border wins over the crease on it
    assert int((cp.assignment == "M").sum()) == 2
    assert findings(cp) == []


def test_polygon_and_curved_path(tmp_path: Path) -> None:
    body = (
        '<polygon points="0,0 100,0 100,100 0,100" stroke="#000" fill="none"/>'
        '<path d="M 0,0 Q 60,40 100,100" stroke="#f00" fill="none"/>'  # chord 0,0 -> 100,100
    )
    cp = read_svg(svg(tmp_path, body))
    assert (cp.n_vertices, cp.n_edges, cp.n_faces) == (4, 5, 2)


def test_hole_dropped(tmp_path: Path) -> None:
    # a square sheet with a square hole, bridged by four creases
    body = (
        f"{BORDER}"
        '<rect x="30" y="30" width="40" height="40" stroke="#000" fill="none"/>'
        '<path d="M0,0 L30,30 M100,0 L70,30 M100,100 L70,70 M0,100 L30,70" stroke="#f00"/>'
    )
    cp = read_svg(svg(tmp_path, body))
    assert cp.n_faces == 4
    assert [f.code for f in findings(cp)] == ["hole"]


def test_mountain_over_valley_is_an_error(tmp_path: Path) -> None:
    body = (
        f"{BORDER}"
        '<line x1="0" y1="0" x2="100" y2="100" stroke="#f00"/>'
        '<line x1="0" y1="0" x2="100" y2="100" stroke="#00f"/>'
    )
    with pytest.raises(PatternError, match="mountain and a valley crease overlap"):
        read_svg(svg(tmp_path, body))


def test_bad_files(tmp_path: Path) -> None:
    with pytest.raises(PatternError, match="no such SVG"):
        read_svg(tmp_path / "nope.svg")
    with pytest.raises(PatternError, match="no crease lines"):
        read_svg(svg(tmp_path, '<circle cx="5" cy="5" r="3" fill="red"/>'))
    bad = tmp_path / "bad.svg"
    bad.write_text("<svg><line x1='0' y1='0' x2='1'")
    with pytest.raises(PatternError):
        read_svg(bad)
    with pytest.raises(PatternError, match="merge_tol"):
        read_svg(svg(tmp_path, BORDER), merge_tol=-1.0)


num = st.one_of(
    st.integers(-5, 105).map(str),
    st.floats(-5, 105).map(lambda x: f"{x:.3f}"),
    st.sampled_from(["nan", "inf", "1e400", "", "abc", "-0"]),
)
colour = st.sampled_from(["#f00", "#00f", "#000", "#0f0", "red", "rgb(1,2,3)", "none", "#zzz"])
opacity = st.sampled_from(["0.5", "1", "0", "2", "-1", "50%", "x", ""])


@st.composite
def shapes(draw) -> str:
    kind = draw(st.sampled_from(["line", "polyline", "path", "rect", "junk"]))
    c, o = draw(colour), draw(opacity)
    xs = draw(st.lists(num, min_size=4, max_size=8))
    if kind == "line":
        xy = f'x1="{xs[0]}" y1="{xs[1]}" x2="{xs[2]}" y2="{xs[3]}"'
        return f'<line {xy} stroke="{c}" opacity="{o}"/>'
    if kind == "polyline":
        pts = " ".join(f"{a},{b}" for a, b in zip(xs[::2], xs[1::2], strict=False))
        return f'<polyline points="{pts}" stroke="{c}" stroke-opacity="{o}" fill="none"/>'
    if kind == "path":
        d = f"M{xs[0]},{xs[1]} L{xs[2]},{xs[3]} Q{xs[0]},{xs[3]} {xs[1]},{xs[2]}"
        return f'<path d="{d}" stroke="{c}"/>'
    if kind == "rect":
        return f'<rect x="{xs[0]}" y="{xs[1]}" width="{xs[2]}" height="{xs[3]}" stroke="{c}"/>'
    return draw(st.text(max_size=20))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(body=st.lists(shapes(), max_size=6), border=st.booleans())
def test_fuzz_svg(tmp_path_factory, body: list[str], border: bool) -> None:
    """Any drawing gives a pattern or a PatternError, never another exception."""
    p = tmp_path_factory.mktemp("svg") / "f.svg"
    p.write_text(f"{HEAD}{BORDER if border else ''}{''.join(body)}</svg>")
    try:
        read_svg(p)
    except PatternError:
        pass
