"""``barhinge info``: counts, findings, bounding box, JSON output, one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

from barhinge.cli import app

runner = CliRunner()

SQUARE = {
    "vertices_coords": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
    "edges_assignment": ["B", "B", "B", "B", "M"],
    "edges_foldAngle": [0, 0, 0, 0, -90],
}


def test_info_json(tmp_path: Path) -> None:
    p = tmp_path / "sq.fold"
    p.write_text(json.dumps(SQUARE))
    res = runner.invoke(app, ["info", str(p), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert (d["n_vertices"], d["n_edges"], d["n_faces"]) == (4, 5, 2)
    assert d["edges_by_assignment"]["M"] == 1 and d["edges_by_assignment"]["B"] == 4
    assert d["bounding_box"] == {"min": [0.0, 0.0], "max": [2.0, 1.0]}
    assert d["degree_histogram"] == {"2": 2, "3": 2}
    assert d["n_interior_vertices"] == 0 and d["n_holes"] == 0
    assert d["findings"] == []


def test_info_table_and_findings(tmp_path: Path) -> None:
    bad = dict(SQUARE, edges_foldAngle=[0, 0, 0, 0, 90])  # mountain with a valley angle
    p = tmp_path / "bad.fold"
    p.write_text(json.dumps(bad))
    res = runner.invoke(app, ["info", str(p)])
    assert res.exit_code == 2
    assert "assignment-sign" in res.output and "edge 4 is a mountain" in res.output


def test_info_error_is_one_line(tmp_path: Path) -> None:
    p = tmp_path / "broken.fold"
    p.write_text("{")
    out = subprocess.run(
        [sys.executable, "-m", "barhinge.cli", "info", str(p)], capture_output=True, text=True
    )
    assert out.returncode == 2
    assert out.stderr.strip().count("\n") == 0 and "not valid JSON" in out.stderr
    assert "Traceback" not in out.stderr
