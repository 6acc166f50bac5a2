"""Every crease pattern in tests/data/crease-patterns is read, validated, written to FOLD and read
back equal; counts of several are checked against values counted independently."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from barhinge.pattern.fold import read_fold, write_fold
from barhinge.pattern.io import read
from barhinge.pattern.validate import findings

SVGS = [
    "FTpoly7.svg", "birdBase.svg", "brochurefold.svg", "huffmanExtrudedBoxes.svg",
    "huffmanRectangularWeave.svg", "huffmanWaterbomb.svg", "hypar.svg",
    "langOvalTessellation.svg", "langRattanWeave.svg", "mapfold.svg", "miura-ori.svg",
    "miura_sharpangle.svg", "reschTriTessellation.svg", "russianTriangle.svg",
    "simpleVertex.svg", "singlesquaretwist.svg", "squareBase.svg", "squaretwistManyAngles.svg",
    "waterbomb.svg", "waterbombBase.svg",
]  # fmt: skip
FOLDS = [
    "fold-spec/box.fold", "fold-spec/diagonal-cp.fold", "fold-spec/diagonal-folded.fold",
    "fold-spec/simple.fold", "fold-spec/squaretwist.fold",
    "origami-simulator/BoxPleatInOutWave.fold", "origami-simulator/BoxPleatPyramid.fold",
]  # fmt: skip
ALL = [f"origami-simulator/{s}" for s in SVGS] + FOLDS
ATOL = 1e-12  # FOLD stores floats with repr(): the round trip is exact, allow round-off only


def test_the_list_covers_the_folder(shared_patterns: Path) -> None:
    found = sorted(
        str(p.relative_to(shared_patterns))
        for p in shared_patterns.rglob("*")
        if p.suffix in (".svg", ".fold")
    )
    assert found == sorted(ALL)


@pytest.mark.parametrize("name", ALL)
def test_read_validate_roundtrip(shared_patterns: Path, name: str, tmp_path: Path) -> None:
    # Every shared file is a valid pattern (no errors) under the default settings: all SVGs
    # are flat, developable and hole-free; the FOLD files include folded 3-D states
    # (box, simple, squaretwist), a flat-folded state (diagonal-folded, reported as info),
    # and two flat box-pleat patterns stored in the plane y = 0.
    cp = read(shared_patterns / name)
    errors = [f for f in findings(cp) if f.severity == "error"]
    assert errors == []
    out = write_fold(cp, tmp_path / "out.fold")
    back = read_fold(out)
    assert back.vertices.shape == cp.vertices.shape
    np.testing.assert_allclose(back.vertices, cp.vertices, rtol=0, atol=ATOL)
    np.testing.assert_array_equal(back.edges, cp.edges)
    np.testing.assert_array_equal(back.assignment, cp.assignment)
    np.testing.assert_allclose(back.fold_angles, cp.fold_angles, rtol=0, atol=ATOL)
    assert back.faces == cp.faces
    for k, v in cp.meta.items():
        assert back.meta[k] == v


# Counts by hand from the SVG source (see the element list of each file):
#   simpleVertex: border square; a red line across the middle, a red half-line from the top
#     midpoint to the centre and a blue one from the centre to the bottom midpoint.
#     V = 4 corners + 4 side midpoints + centre = 9; E = 8 border pieces + 2 + 1 + 1 = 12
#     (M 3, V 1); F = 4 quadrants.
#   birdBase: 4 corners, 4 side midpoints, centre, 4 points at half radius = 13; border 8,
#     8 red corner-to-point lines + red cross through the centre (2 + 2) = 12 M, 4 blue
#     midpoint-to-point lines + 2 blue diagonals split at the centre (4, opacity 0.5 -> 90 deg)
#     = 8 V; F = E - V + 1 = 16 (Euler, disc).
#   squareBase: 9 vertices; border 8, red cross 4, one blue diagonal split at the centre 2;
#     faces: 4 quadrants, 2 of them halved = 6.
#   waterbombBase: 9 vertices; border 8, red diagonals 4, blue cross 4 (opacity 0.5); 8 faces.
#   russianTriangle: 4 corners + top, right and bottom points + the end of the red line, which
#     lies on the long blue diagonal (T-junction) = 8; border 7 (left side unsplit), blue 6
#     (the diagonal split in two), red 1; F = 14 - 8 + 1 = 7.
#   mapfold / brochurefold: 3 full-height verticals and a horizontal midline of 4 pieces:
#     V = 4 corners + 3 top + 3 bottom + 2 side midpoints + 3 crossings = 15; border 12,
#     verticals 6 + midline 4 = 10 creases; F = 8. mapfold: V-lines = 2 verticals (4) + 2
#     midline pieces = 6 valleys, 4 mountains; brochurefold: 3 verticals (6) + 2 pieces = 8
#     valleys, 2 mountains.
#   singlesquaretwist: 8 blue, 12 black and 4 red path segments, none crossing: E = 24
#     (V 8, B 12, M 4); 4 corners of the central square + 12 outer points = 16 vertices;
#     F = 24 - 16 + 1 = 9 (central square, 4 parallelograms, 4 corner pieces).
#   squaretwistManyAngles: 9 separate twists drawn the same way (9 x the counts above).
HAND_COUNTS = {
    "singlesquaretwist.svg": (16, 24, 9, {"M": 4, "V": 8, "B": 12}),
    "squaretwistManyAngles.svg": (144, 216, 81, {"M": 36, "V": 72, "B": 108}),
    "simpleVertex.svg": (9, 12, 4, {"M": 3, "V": 1, "B": 8}),
    "birdBase.svg": (13, 28, 16, {"M": 12, "V": 8, "B": 8}),
    "squareBase.svg": (9, 14, 6, {"M": 4, "V": 2, "B": 8}),
    "waterbombBase.svg": (9, 16, 8, {"M": 4, "V": 4, "B": 8}),
    "russianTriangle.svg": (8, 14, 7, {"M": 1, "V": 6, "B": 7}),
    "mapfold.svg": (15, 22, 8, {"M": 4, "V": 6, "B": 12}),
    "brochurefold.svg": (15, 22, 8, {"M": 2, "V": 8, "B": 12}),
}


@pytest.mark.parametrize("name", sorted(HAND_COUNTS))
def test_svg_counts_by_hand(shared_patterns: Path, name: str) -> None:
    cp = read(shared_patterns / "origami-simulator" / name)
    nv, ne, nf, asg = HAND_COUNTS[name]
    assert (cp.n_vertices, cp.n_edges, cp.n_faces) == (nv, ne, nf)
    assert {a: int((cp.assignment == a).sum()) for a in asg} == asg
    assert cp.n_edges == len(cp.assignment)


def test_svg_opacity_gives_fold_angle(shared_patterns: Path) -> None:
    # birdBase: the two blue diagonals have opacity 0.5 -> +90 deg; other valleys +180,
    # mountains -180 (Origami Simulator convention: opacity * 180 deg).
    cp = read(shared_patterns / "origami-simulator" / "birdBase.svg")
    V = cp.vertices[cp.edges]
    d = V[:, 1] - V[:, 0]
    diagonal = np.isclose(np.abs(d[:, 0]), np.abs(d[:, 1])) & (cp.assignment == "V")
    assert diagonal.sum() == 4
    np.testing.assert_array_equal(cp.fold_angles[diagonal], 90.0)
    np.testing.assert_array_equal(cp.fold_angles[(cp.assignment == "V") & ~diagonal], 180.0)
    np.testing.assert_array_equal(cp.fold_angles[cp.assignment == "M"], -180.0)
    np.testing.assert_array_equal(cp.fold_angles[cp.assignment == "B"], 0.0)


@pytest.mark.parametrize(
    "name", ["origami-simulator/BoxPleatPyramid.fold", "origami-simulator/BoxPleatInOutWave.fold"]
)
def test_derived_faces_match_the_file(shared_patterns: Path, name: str) -> None:
    # The face finder (planar graph, half-edges) against the faces stored in the file:
    # same number and the same vertex sets (orientation normalised to the pattern normal).
    data = json.loads((shared_patterns / name).read_text())
    given = read_fold(data)
    del data["faces_vertices"]
    derived = read_fold(data)
    assert (
        derived.n_faces
        == given.n_faces
        == len(json.loads((shared_patterns / name).read_text())["faces_vertices"])
    )
    assert sorted(tuple(sorted(f)) for f in derived.faces) == sorted(
        tuple(sorted(f)) for f in given.faces
    )
    # counter-clockwise about the same normal: same cyclic order
    canon = lambda f: min(tuple(f[i:] + f[:i]) for i in range(len(f)))  # noqa: E731
    assert sorted(canon(list(f)) for f in derived.faces) == sorted(
        canon(list(f)) for f in given.faces
    )


def test_fold_counts_match_the_json(shared_patterns: Path) -> None:
    # counted with the json module alone, independent of the reader
    for name in FOLDS:
        raw = json.loads((shared_patterns / name).read_text())
        cp = read_fold(shared_patterns / name)
        assert cp.n_vertices == len(raw["vertices_coords"])
        assert cp.n_edges == len(raw["edges_vertices"])
        assert cp.n_faces == len(raw["faces_vertices"])
        np.testing.assert_array_equal(cp.assignment, raw["edges_assignment"])


@pytest.mark.parametrize("name", SVGS)
def test_svg_euler_characteristic(shared_patterns: Path, name: str) -> None:
    # Every shared SVG is made of sheets without holes (no "hole" finding): C discs, so
    # Euler's formula V - E + F = C holds (C = connected components of the edge graph).
    # squaretwistManyAngles holds 9 separate square twists (C = 9), all others one sheet.
    # FTpoly7's central spiral shrinks to a point; vertices there closer than the merge
    # tolerance (1e-3 of the size; its coordinates are rounded to integers) are merged, so
    # its counts depend on merge_tol, but the result is still a valid disc.
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    cp = read(shared_patterns / "origami-simulator" / name)
    assert not [f for f in findings(cp) if f.code == "hole"]
    n = cp.n_vertices
    g = coo_matrix((np.ones(cp.n_edges), (cp.edges[:, 0], cp.edges[:, 1])), shape=(n, n))
    C, _ = connected_components(g, directed=False)
    assert C == (9 if name == "squaretwistManyAngles.svg" else 1)
    assert cp.n_vertices - cp.n_edges + cp.n_faces == C
