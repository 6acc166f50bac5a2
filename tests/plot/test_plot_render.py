"""Pictures are made headless and are not blank (image statistics)."""

from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from barhinge.errors import ConfigError

spec = importlib.util.spec_from_file_location(
    "_io_fixtures", Path(__file__).resolve().parents[1] / "output" / "test_output_fields.py"
)
_fx = importlib.util.module_from_spec(spec)
spec.loader.exec_module(_fx)
simple_fold_path = _fx.simple_fold_path


def _not_blank(path: Path, min_std: float = 10.0, min_ink: float = 0.03) -> np.ndarray:
    """Pixel statistics of a picture: contrast, and the fraction of non-background pixels
    (3-D renders fill panels: >= 3 %; line charts: >= 1 %)."""
    img = np.asarray(Image.open(path).convert("RGB"), float)
    assert img.std() > min_std, f"{path.name} looks blank (std {img.std():.1f})"
    assert (img.min(axis=2) < 200).mean() > min_ink
    return img


def test_offscreen_render_with_pyvista(tmp_path):
    render = pytest.importorskip("barhinge.plot.render")
    if not render.can_render_offscreen():
        pytest.skip("no off-screen GL on this machine (probe failed)")
    cp, path = simple_fold_path()
    out = render.render_state(
        path.X[-1],
        tmp_path / "s.png",
        pattern=cp,
        backend="pyvista",
        window_size=(400, 300),
        fold_angles_deg=path.fold_angles_deg[-1],
    )
    img = _not_blank(out)
    assert img.shape == (300, 400, 3)
    # the valley crease is drawn in blue (RdBu: valley > 0)
    blue = (img[..., 2] > img[..., 0] + 60).mean()
    assert blue > 1e-4


def test_matplotlib_fallback_and_named_arrays(tmp_path):
    from barhinge.plot import render

    cp, path = simple_fold_path()
    X = path.X[-1].copy()
    X[4, 2] += 0.2  # strain the sheet: non-zero angle defect at the interior vertex
    out = render.render_state(
        X,
        tmp_path / "d.png",
        pattern=cp,
        scalars="angle_defect",
        backend="matplotlib",
        window_size=(400, 300),
    )
    _not_blank(out)
    with pytest.raises(ConfigError, match="unknown array"):
        render.render_state(X, tmp_path / "x.png", pattern=cp, scalars="nope", backend="matplotlib")


def test_gif_animation_has_frames(tmp_path):
    from barhinge.plot import render

    cp, path = simple_fold_path(6)
    backend = "pyvista" if render.can_render_offscreen() else "matplotlib"
    gif = render.animate(
        path, tmp_path / "a.gif", pattern=cp, window_size=(240, 180), backend=backend
    )
    im = Image.open(gif)
    assert im.n_frames == 2 * 6 - 2  # boomerang
    im.seek(3)
    frame = np.asarray(im.convert("RGB"), float)
    assert frame.std() > 10


def test_charts_are_drawn(tmp_path):
    from barhinge.plot import charts

    cp, path = simple_fold_path(8)
    t = np.linspace(0, 1, path.n_states)
    path = dataclasses.replace(
        path,
        actuator_moments=(t**3)[:, None],
        energy_bars=0.01 * t,
        energy_bend=0.1 * t**2,
        energy_fold=t**2,
    )
    charts.summary_figure(path, tmp_path / "c.png")
    _not_blank(tmp_path / "c.png", min_ink=0.01)
    charts.plot_poisson(
        np.arange(5),
        -np.arange(5) / 4,
        path=tmp_path / "p.png",
        reference=(np.arange(5), -np.arange(5) / 4, "closed form"),
    )
    _not_blank(tmp_path / "p.png", min_std=5, min_ink=0.01)
