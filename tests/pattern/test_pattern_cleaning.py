"""Pattern cleaning in the right order (merge near-coincident vertices, then find the faces)
and patterns without faces flagged (issue 16, item 5)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app
from barhinge.pattern.validate import findings, merged

runner = CliRunner()

# a unit square with a valley diagonal 0-2; vertex 4 duplicates vertex 2 (1e-9 away) and
# closes the border instead of it, so before merging the diagonal dangles into one face
DUP = {
    "vertices_coords": [[0, 0], [1, 0], [1, 1], [0, 1], [1 + 1e-9, 1]],
    "edges_vertices": [[0, 1], [1, 4], [4, 3], [3, 0], [0, 2]],
    "edges_assignment": ["B", "B", "B", "B", "V"],
    "edges_foldAngle": [0, 0, 0, 0, 90],
}
SQUARE = {
    "vertices_coords": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
    "edges_assignment": ["B", "B", "B", "B", "V"],
    "edges_foldAngle": [0, 0, 0, 0, 90],
}


def _write(tmp_path: Path, data: dict, name: str = "p.fold") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(data))
    return p


def test_info_merge_tol_merges_before_finding_faces(tmp_path: Path) -> None:
    res = runner.invoke(app, ["info", str(_write(tmp_path, DUP)), "--merge-tol", "1e-6", "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert (d["n_vertices"], d["n_edges"], d["n_faces"]) == (4, 5, 2)  # the diagonal splits it
    assert d["findings"] == []


@pytest.mark.parametrize("reader", ["read", "read_fold"])
def test_reader_merge_tol_finds_faces_of_the_merged_graph(tmp_path: Path, reader: str) -> None:
    cp = getattr(bh, reader)(_write(tmp_path, DUP), merge_tol=1e-6)
    assert cp.n_vertices == 4 and cp.n_faces == 2 and findings(cp) == []


def test_replaced_and_merged_refind_faces_that_were_found() -> None:
    raw = bh.read_fold(DUP, validate=False)  # faces found before any merge: one face
    assert raw.n_faces == 1
    assert raw.replaced(merge_tol=1e-6, validate=False).n_faces == 2
    assert raw.replaced(developable=True, validate=False).replaced(merge_tol=1e-6).n_faces == 2
    assert merged(raw).n_faces == 2 and findings(merged(raw)) == []
    # faces given in the file are the user's: renumbered, not replaced
    given = bh.read_fold({**DUP, "faces_vertices": [[0, 1, 4, 3]]}, validate=False)
    assert merged(given).faces == ((0, 1, 2, 3),)
    assert merged(given, derive_faces=True).n_faces == 2


def test_empty_face_list_is_an_error(tmp_path: Path) -> None:
    p = _write(tmp_path, {**SQUARE, "faces_vertices": []})
    cp = bh.read_fold(p, validate=False)
    f = [x for x in findings(cp) if x.code == "no-faces"]
    assert len(f) == 1 and f[0].severity == "error" and "\n" not in f[0].message
    assert "5 edges but no faces" in f[0].message and "faces_vertices" in f[0].message
    with pytest.raises(bh.PatternError, match="no faces"):
        bh.read_fold(p)
    res = runner.invoke(app, ["info", str(p)])
    assert res.exit_code == 2 and "no-faces" in res.output and "no findings" not in res.output


def test_edges_that_enclose_nothing_are_an_error() -> None:
    # a path of creases: the planar graph has no bounded face
    tree = {
        "vertices_coords": [[0, 0], [1, 0], [2, 1]],
        "edges_vertices": [[0, 1], [1, 2]],
        "edges_assignment": ["B", "B"],
    }
    cp = bh.read_fold(tree, validate=False)
    assert cp.n_faces == 0
    assert [f.code for f in findings(cp) if f.severity == "error"] == ["no-faces"]
    assert "enclose no area" in next(f.message for f in findings(cp) if f.code == "no-faces")


def test_merge_in_the_constructor_keeps_working() -> None:
    V = np.array(DUP["vertices_coords"], float)
    cp = bh.CreasePattern(V, DUP["edges_vertices"], list("BBBBV"), [0, 0, 0, 0, 90], merge_tol=1e-6)
    assert cp.n_faces == 2 and findings(cp) == []
