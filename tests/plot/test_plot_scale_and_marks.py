"""Every state picture states its scale, and the matplotlib fallback draws supports and
loads as the pyvista pictures do."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.plot import render


def test_extent_text_is_the_state_extent():
    X = np.array([[0.0, 0.0, 0.0], [12.0, 1.0, -3.1], [4.0, 8.5, 0.0]])
    assert render.extent_text(X) == "extent x 12 × y 8.5 × z 3.1"


def test_support_and_load_marks_are_scaled_to_the_state():
    X = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]])
    fixed = np.zeros((3, 3), bool)
    fixed[1, 2] = True
    loads = np.zeros((3, 3))
    loads[2] = [0.0, 0.0, -10.0]
    loads[0] = [0.0, 0.0, -5.0]
    sup, at, vec = render._supports_and_loads(X, fixed, loads)
    np.testing.assert_array_equal(sup, X[[1]])
    np.testing.assert_array_equal(at, X[[0, 2]])
    size = np.linalg.norm([3.0, 4.0, 0.0])  # diagonal of the bounding box
    np.testing.assert_allclose(np.linalg.norm(vec, axis=1), [0.04 * size, 0.08 * size])


def test_matplotlib_fallback_draws_supports_and_loads(tmp_path):
    from PIL import Image

    cp = bh.families.miura(nx=2, ny=2, fold=30.0)
    X = cp.vertices3d
    fixed = np.zeros((len(X), 3), bool)
    fixed[0] = True
    loads = np.zeros((len(X), 3))
    loads[len(X) // 2, 2] = 1.0
    kw = {"pattern": cp, "window_size": (400, 300), "backend": "matplotlib"}
    a = np.asarray(Image.open(render.render_state(X, tmp_path / "a.png", **kw)).convert("L"))
    b = np.asarray(
        Image.open(
            render.render_state(X, tmp_path / "b.png", fixed=fixed, loads=loads, **kw)
        ).convert("L")
    )
    if a.shape != b.shape:
        pytest.fail(f"the marks changed the picture's size: {a.shape} -> {b.shape}")
    changed = np.abs(a.astype(int) - b.astype(int)) > 30
    assert changed.any()  # the marks are drawn
    assert changed.mean() < 0.02  # and only the marks
