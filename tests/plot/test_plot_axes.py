"""Round colour-bar limits and the charts' x-axis (the control of the path)."""

from __future__ import annotations

import numpy as np
import pytest

from barhinge.plot.charts import control_axis
from barhinge.plot.render import nice_limits
from barhinge.results import FoldPath


@pytest.mark.parametrize(
    "lo, hi", [(-120.7, 120.7), (60.4, 121.0), (0.0, 2.295e-4), (-3.05e-8, 1e-8), (3.0, 3.5)]
)
def test_nice_limits_cover_the_data_with_round_ticks(lo, hi):
    a, b, n = nice_limits(lo, hi, 7)
    assert a <= lo and b >= hi and 2 <= n <= 7
    step = (b - a) / (n - 1)
    mant = step / 10 ** np.floor(np.log10(step))
    assert any(np.isclose(mant, k) for k in (1, 2, 2.5, 5))
    ticks = a + step * np.arange(n)
    np.testing.assert_allclose(ticks / step, np.round(ticks / step), atol=1e-6)
    assert (b - a) <= 2.5 * (hi - lo) + 2 * step  # not much wider than the data


def _path(angles, control, load=None):
    n = len(angles)
    fa = np.zeros((n, 3))
    fa[:, 1], fa[:, 2] = angles, -np.asarray(angles)
    return FoldPath(X=np.zeros((n, 4, 3)), fold_angles_deg=fa, actuator_edges=[1, 2],
                    load_factor=load, meta={"control": control})  # fmt: skip


def test_control_axis():
    x, label = control_axis(_path([0, 10, 20], "fold_angle"))
    np.testing.assert_array_equal(x, [0, 10, 20])
    assert label == "actuators' |fold angle| (deg)"
    x, label = control_axis(_path([0, 0, 0], "load", load=[0, 0.5, 1]))
    assert label == "load factor" and x[-1] == 1
    assert control_axis(_path([0, 0, 0], None))[1] == "step"


def test_supports_and_loads_are_drawn(tmp_path):
    """Black dots at supports and arrows at loads: the picture changes at those nodes only."""
    from PIL import Image

    from barhinge.families import miura
    from barhinge.plot import render

    if not render.can_render_offscreen():
        pytest.skip("no off-screen rendering")
    cp = miura(nx=2, ny=2, fold=30.0)
    X = cp.vertices3d
    fixed = np.zeros((len(X), 3), bool)
    fixed[0] = True
    loads = np.zeros((len(X), 3))
    loads[len(X) - 1, 2] = -1.0
    kw = {"pattern": cp, "window_size": (400, 300), "backend": "pyvista"}
    a = render.render_state(X, tmp_path / "a.png", **kw)
    b = render.render_state(X, tmp_path / "b.png", fixed=fixed, loads=loads, **kw)
    A = np.asarray(Image.open(a).convert("RGB"), float)
    B = np.asarray(Image.open(b).convert("RGB"), float)
    changed = np.abs(A - B).sum(axis=2) > 30
    assert 0 < changed.mean() < 0.1
    assert (B[changed].sum(axis=1) < A[changed].sum(axis=1)).mean() > 0.5  # dark marks
