"""``barhinge render RESULT.npz`` re-renders the pictures of a saved path."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from barhinge import FoldPath
from barhinge.cli import app
from barhinge.output.run import write_results

patterns = pytest.importorskip("barhinge.families")
pytest.importorskip("barhinge.pattern.fold")


def test_render_command_from_saved_path(tmp_path):
    theta = [10.0, 30.0, 50.0]
    cps = [patterns.miura(2, 2, fold=t) for t in theta]
    path = FoldPath(
        X=np.array([c.vertices3d for c in cps]),
        fold_angles_deg=np.array([c.state_fold_angles() for c in cps]),
        actuator_edges=[int(cps[0].crease_edges[0])],
        kind="rigid",
    )
    write_results(path, None, tmp_path, pattern=cps[0], vtu="none")
    out = tmp_path / "pics"
    r = CliRunner().invoke(
        app,
        ["render", str(tmp_path / "result.npz"), "--out", str(out), "--json", "--no-gif",
         "--backend", "matplotlib"],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    files = json.loads(r.output)
    for key in ("png", "charts"):
        img = np.asarray(Image.open(files[key]).convert("RGB"), float)
        assert img.std() > 10
    r = CliRunner().invoke(app, ["render", str(tmp_path / "missing.npz")])
    assert r.exit_code != 0
