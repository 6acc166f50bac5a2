"""Plate-consistent hinge stiffnesses of subdivided panels (barhinge.model.plate_hinges).

Reference: the simply supported rectangular plate under a uniform load q, Navier's series
(Timoshenko & Woinowsky-Krieger 1959, Sec. 30):
``w = 16 q / (pi^6 D) sum_(m,n odd) sin(m pi x/a) sin(n pi y/b) / (m n ((m/a)^2 + (n/b)^2)^2)``;
its mean over the plate (each sine averages 2 / (m pi)) gives the compliance stiffness
``q a b / mean(w)``, which does not depend on nu for a given D.
"""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.stiffness import linear_response
from barhinge.errors import ConfigError
from barhinge.model.plate_hinges import cell_fit, consistent_hinge_stiffness
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.subdivide import subdivided

MAT = bh.Material(E=70e9, nu=0.33, t=2e-3)
Q = 1000.0


def _navier_stiffness(a: float, b: float, D: float) -> float:
    k = np.arange(1, 200, 2, dtype=float)
    M, N = np.meshgrid(k, k)
    terms = (
        1.0 / (M * N * ((M / a) ** 2 + (N / b) ** 2) ** 2) * (2 / (M * np.pi)) * (2 / (N * np.pi))
    )
    mean_w = 16 * Q / (np.pi**6 * D) * float(terms.sum())
    return Q * a * b / mean_w


def _plate_stiffness(a: float, b: float, m: int) -> tuple[float, float]:
    """(stiffness / Navier, largest cell residual) of the m x m subdivided plate."""
    P = np.array([[0, 0], [a, 0], [a, b], [0, b]], float)
    cp = CreasePattern(P, [[0, 1], [1, 2], [2, 3], [3, 0]], ["B"] * 4, faces=[[0, 1, 2, 3]])
    cpm, parent = subdivided(cp, m)
    model = bh.BarHingeModel.from_pattern(cpm, "N5B8", MAT)
    ph = consistent_hinge_stiffness(model)
    model = model.with_(hinge_k=ph.hinge_k)
    S = np.zeros((model.n_nodes, 3), bool)
    S[np.union1d(np.arange(4), np.flatnonzero(parent >= 0))] = True
    F = np.zeros((model.n_nodes, 3))
    for f in cpm.faces:  # uniform load, each cell's share to its corners
        X = np.asarray(cpm.vertices3d)[list(f)]
        area = 0.5 * abs(float(np.cross(X, np.roll(X, -1, axis=0)).sum(axis=0)[2]))
        F[list(f), 2] -= Q * area / len(f)
    U, _ = linear_response(model, F, S)
    k = float(F[:, 2].sum() ** 2 / np.sum(F * U))
    return k / _navier_stiffness(a, b, MAT.bending_rigidity), float(ph.residual.max())


def test_square_cell_closed_form():
    # hand derivation (module docstring): anticlastic k_s, twist k_d, spherical
    # k_s k_d / (k_s + k_d) against D(1-nu) - lam, D(1-nu) - lam, D(1+nu) + lam
    # -> k_s = k_d = 4 D / 3, lam = -(1/3 + nu) D
    k, lam, res = cell_fit(np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), 0.33)
    np.testing.assert_allclose(k, 4.0 / 3.0, rtol=1e-8)
    assert lam == pytest.approx(-(1.0 / 3.0 + 0.33), rel=1e-8)
    assert res < 1e-10
    # equilateral triangle: the three-direction lattice, every side 2 / sqrt(3) D
    kt, _, rt = cell_fit(np.array([[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]]), 0.33)
    np.testing.assert_allclose(kt, 2 / np.sqrt(3), rtol=1e-8)
    assert rt < 1e-10


@pytest.mark.parametrize("b", [1.0, 0.8])
def test_subdivided_plate_converges_to_navier_at_order_two(b):
    levels = [4, 8, 16]
    out = [_plate_stiffness(1.0, b, m) for m in levels]
    err = np.array([abs(r - 1.0) for r, _ in out])
    assert max(res for _, res in out) < 1e-8
    rate = -np.polyfit(np.log(levels), np.log(err), 1)[0]
    assert rate == pytest.approx(2.0, abs=0.3)
    assert err[-1] < 0.01


def test_elongated_cells_fail_the_patch_test_and_converge_elsewhere():
    # 2:1 cells: the fit leaves a residual, and the plate converges to a wrong value
    r8, res = _plate_stiffness(2.0, 1.0, 8)
    r16, _ = _plate_stiffness(2.0, 1.0, 16)
    assert res > 0.1
    assert abs(r16 - r8) < 0.03
    assert abs(r16 - 1.0) > 0.05


def test_creases_in_series_with_the_plate_strip_and_n4b5_is_refused():
    cp = bh.families.miura(nx=2, ny=2, fold=40.0)
    model = bh.BarHingeModel.from_pattern(subdivided(cp, 2)[0], "N5B8", MAT)
    ph = consistent_hinge_stiffness(model)
    asg = np.asarray(model.pattern.assignment)[np.maximum(model.hinge_edge, 0)]
    crease = (model.hinge_kind == "fold") & np.isin(asg, ["M", "V"])
    kc = model.hinge_k[crease]
    # 1/k = 1/k_crease + 1/k_strip with a positive strip stiffness: softer than the crease
    k_strip = 1.0 / (1.0 / ph.hinge_k[crease] - 1.0 / kc)
    assert (ph.hinge_k[crease] < kc).all() and (k_strip > 0).all()
    assert ph.changed.all() and (ph.hinge_k > 0).all()
    with pytest.raises(ConfigError, match="N5B8"):
        consistent_hinge_stiffness(bh.BarHingeModel.from_pattern(cp, "N4B5", MAT))
