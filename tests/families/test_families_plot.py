"""Crease-pattern drawings (matplotlib, headless)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

import barhinge as bh  # noqa: E402
from barhinge.plot.pattern import COLOURS, draw_folded, draw_pattern  # noqa: E402


def test_draw_pattern_colours_by_assignment(tmp_path):
    cp = bh.families.miura(2, 2)
    ax = draw_pattern(cp)
    by_label = {c.get_label(): c for c in ax.collections}
    assert set(by_label) == {"M", "V", "B"}
    for a, coll in by_label.items():
        assert np.allclose(coll.get_colors()[0], to_rgba(COLOURS[a]))
        assert len(coll.get_segments()) == int((cp.assignment == a).sum())
    assert COLOURS["M"].lower() != COLOURS["V"].lower()
    path = tmp_path / "cp.png"
    draw_pattern(cp, path=path)
    assert path.stat().st_size > 1000


def test_draw_folded_writes_png(tmp_path):
    path = tmp_path / "folded.png"
    draw_folded(bh.families.yoshimura(4, 2, fold=40.0), path=path)
    assert path.stat().st_size > 1000
