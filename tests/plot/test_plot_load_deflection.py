"""The load-deflection chart of a load- or arc-length-controlled path.

Its data are checked against the closed-form curve of the Green-strain two-bar truss
(``P(z) = EA z (h^2 - z^2) / L0^3``, Krenk 2009, ch. 1): the apex is the node that moves
most, so the x values are ``h - z`` and the y values ``P(z) / P_ref``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.plot import charts
from barhinge.scene import Scene
from barhinge.verify import von_mises_limit_load, von_mises_model

A, H, EA = 1.0, 0.3, 1000.0


@pytest.fixture(scope="module")
def truss_path():
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -1.5 * von_mises_limit_load()
    scene = Scene(model, supports=S, loads=P, control="arc_length", steps=20,
                  options={"max_arc_steps": 200})  # fmt: skip
    return bh.solve(scene), apex


def test_chart_data_follow_the_closed_form_curve(truss_path):
    path, apex = truss_path
    ax = charts.plot_load_deflection(path)
    x, y = ax.lines[0].get_data()
    z = H - np.asarray(x)
    L0 = math.hypot(A, H)
    np.testing.assert_allclose(
        np.asarray(y) * 1.5 * von_mises_limit_load(), EA * z * (H**2 - z**2) / L0**3, atol=1e-8
    )
    u, node = charts.max_displacement(path)
    apex_u = np.linalg.norm(path.X[:, apex] - path.X[0, apex], axis=1)
    assert node == apex and np.allclose(u, apex_u)


def test_summary_figure_shows_load_deflection_and_no_empty_actuator_panel(truss_path):
    path, _ = truss_path
    fig = charts.summary_figure(path)
    titles = [ax.get_title() for ax in fig.axes]
    assert "Load-deflection" in titles
    assert not any("ctuator" in t for t in titles), titles
