"""The one writer of a path writes the result files, pictures and the summary rows."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

import barhinge as bh
from barhinge.output.run import write_results
from barhinge.output.summary import summary_rows

pytest.importorskip("barhinge.model.model")
patterns = pytest.importorskip("barhinge.families")


def test_write_results_writes_files_pictures_and_rows(tmp_path, monkeypatch):
    monkeypatch.setenv("BARHINGE_OFFSCREEN", "0")  # matplotlib pictures: fast and GL-free
    cp = patterns.miura(2, 2, fold=30.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e3, nu=0.3, t=0.01))
    from barhinge.plot import render

    render.can_render_offscreen.cache_clear()
    X = np.array([model.X0, model.X0 + 1e-3 * np.random.default_rng(0).normal(size=model.X0.shape)])
    path = bh.FoldPath(
        X=X,
        fold_angles_deg=np.array([model.crease_fold_angles_deg(x) for x in X]),
        actuator_edges=[int(cp.crease_edges[0])],
    )
    from barhinge.scene import restraint_321, self_weight

    scene = SimpleNamespace(model=model, fixed=restraint_321(model), loads=self_weight(model, 1.0))
    files = write_results(path, model, tmp_path, name="fold_path", fixed=scene.fixed,
                          loads=scene.loads, npz=False, pictures=True).values()  # fmt: skip
    names = {f.name for f in files}
    for n in ("fold_path.xdmf", "states.csv", "summary.json",
              "fold_path.png", "fold_path_charts.png", "fold_path_0001.vtu"):  # fmt: skip
        assert n in names and (tmp_path / n).is_file()
    written = json.loads((tmp_path / "summary.json").read_text())
    summary = written["results"]
    assert summary["n_free_dofs"] == model.n_dof - 6
    assert summary["effective_stiffness"] > 0
    rows = dict(summary_rows(written))
    assert "max |bar strain|" in rows and "Gaussian curvature K (global form)" in rows
    render.can_render_offscreen.cache_clear()
