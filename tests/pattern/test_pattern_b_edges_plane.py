"""A B edge between two faces is a crease (warning finding), and planarity is judged in any
plane (``barhinge info`` calls a sheet drawn in the xz plane flat)."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app
from barhinge.pattern.fold import write_fold
from barhinge.pattern.validate import findings


def _grid(middle: str) -> bh.CreasePattern:
    """2 x 2 squares; the two creases of the middle row line get ``middle``."""
    V = np.array([[x, y] for y in range(3) for x in range(3)], dtype=float)
    E, A = [], []
    for y in range(3):
        for x in range(2):
            E.append((3 * y + x, 3 * y + x + 1))
            A.append(middle if y == 1 else "B")
    for x in range(3):
        for y in range(2):
            E.append((3 * y + x, 3 * (y + 1) + x))
            A.append("V" if x == 1 else "B")
    return bh.CreasePattern(vertices=V, edges=np.array(E), assignment=np.array(A))


def test_b_edge_between_two_faces_is_a_crease_with_a_warning():
    b, v = _grid("B"), _grid("V")
    codes = [f.code for f in findings(b)]
    assert codes.count("interior-boundary-edge") == 2
    assert "interior-boundary-edge" not in [f.code for f in findings(v)]
    assert len(b.crease_edges) == len(v.crease_edges) == 4
    assert len(b.interior_vertices) == 1
    rb, rv = bh.dof(b, folded_check=False), bh.dof(v, folded_check=False)
    # generic count: 4 creases - 3 x 1 interior vertex = 1; flat first-order DOF 4 - 2 = 2
    assert rb.counted_dof == rv.counted_dof == 1
    assert rb.global_dof == rv.global_dof == 2


def test_info_calls_a_sheet_in_the_xz_plane_flat(tmp_path):
    cp = bh.families.miura(2, 2)
    V = cp.vertices
    V3 = np.column_stack([V[:, 0], np.zeros(len(V)), V[:, 1]])  # the xz plane
    tilted = cp.replaced(vertices=V3, validate=False)
    assert tilted.is_planar and not tilted.is_flat
    R = np.linalg.qr(np.random.default_rng(0).standard_normal((3, 3)))[0]
    assert cp.replaced(vertices=V3 @ R.T, validate=False).is_planar
    V3f = V3.copy()
    V3f[4, 1] += 1e-3  # one vertex off the plane
    assert not cp.replaced(vertices=V3f, validate=False).is_planar
    f = tmp_path / "xz.fold"
    write_fold(tilted, f)
    res = CliRunner().invoke(app, ["info", str(f), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.output)["flat"] is True
