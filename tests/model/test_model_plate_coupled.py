"""The coupled plate-consistent rule (barhinge.model.plate_hinges.coupled_bending).

References:
* the Kirchhoff plate energy of a uniform curvature, ``D/2 (k11^2 + k22^2 + 2 nu k11 k22 +
  2 (1 - nu) k12^2)`` per unit area, for every cell shape (the patch test of plate elements:
  Morley 1968; Irons & Razzaque 1972);
* Navier's series for the simply supported square plate (Timoshenko & Woinowsky-Krieger 1959,
  Sec. 30);
* the scikit-fem facet shell (barhinge.model.shell, Morley plate triangles) of a square plate
  free on two opposite edges, with the sheet's nu and with nu = 0: an independent model, the
  only one available where the Poisson ratio matters (free edges).
"""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.stiffness import linear_response
from barhinge.model.plate_hinges import cell_matrix, consistent_bending, coupled_bending
from barhinge.model.shell import shell_model
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.subdivide import subdivided

Q = 1000.0
SQUARE = CreasePattern(
    np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float),
    [[0, 1], [1, 2], [2, 3], [3, 0]],
    ["B"] * 4,
    faces=[[0, 1, 2, 3]],
)
CELLS = {
    "square": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "rectangle 2:1": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "rhombus 60": [[0, 0], [1, 0], [1.5, np.sqrt(3) / 2], [0.5, np.sqrt(3) / 2]],
    "skew parallelogram": [[0, 0], [1, 0], [1.3, 0.4], [0.3, 0.4]],
    "equilateral": [[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]],
    "right isosceles": [[0, 0], [1, 0], [0, 1]],
    "obtuse": [[0, 0], [1, 0], [1.4, 0.3]],
}


@pytest.mark.parametrize("nu", [0.0, 0.33, 0.45])
@pytest.mark.parametrize("name", list(CELLS))
def test_every_cell_stores_the_plate_energy_of_every_uniform_curvature(name, nu):
    from barhinge.model.plate_hinges import _cell_rows

    P = np.array(CELLS[name], float)
    K, residual = cell_matrix(P, nu)
    rows = _cell_rows(P)[0]
    area = 0.5 * abs(float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1])))
    rng = np.random.default_rng(1)
    for kappa in rng.standard_normal((5, 3)):
        k11, k22, k12 = kappa
        plate = 0.5 * area * (k11**2 + k22**2 + 2 * nu * k11 * k22 + 2 * (1 - nu) * k12**2)
        theta = rows[:, :3] @ kappa
        if rows.shape[1] == 4 and len(P) == 4:  # the centre offset relaxes (minimum over it)
            d = rows[:, 3]
            delta = -(d @ K @ theta) / (d @ K @ d)
            theta = theta + delta * d
        assert 0.5 * theta @ K @ theta == pytest.approx(plate, rel=1e-9)
    assert residual < 1e-9
    eig = np.linalg.eigvalsh(K)
    assert eig.min() > 1e-3 * eig.max()  # positive definite: no zero-energy angle pattern


@pytest.mark.parametrize("size", [3, 4])
def test_many_cells_at_once_are_each_cell_alone(size):
    """The batched cell matrices (one computation for every distinct cell shape of a graded
    grid) equal the matrices of the cells one by one, and each stores the plate energy."""
    from barhinge.model.plate_hinges import _cell_rows

    rng = np.random.default_rng(7)
    base = np.array(CELLS["square" if size == 4 else "obtuse"], float)
    P = base + 0.12 * rng.standard_normal((40, size, 2))
    # the neighbours' wing nodes across the sides (quads: centres; triangles: opposite
    # corners), off the point reflection, some sides without one (NaN)
    mid = 0.5 * (P + np.roll(P, -1, axis=1))
    own = P.mean(axis=1, keepdims=True) if size == 4 else np.roll(P, -2, axis=1)
    wings = 2 * mid - own + 0.05 * rng.standard_normal((40, size, 2))
    wings[::3, 1] = np.nan
    K, residual = cell_matrix(P, 0.3, wings)
    rows = _cell_rows(P, wings)[0]
    for i in range(len(P)):
        Ki, ri = cell_matrix(P[i], 0.3, wings[i])
        np.testing.assert_allclose(K[i], Ki, rtol=1e-12, atol=1e-12 * np.abs(Ki).max())
        np.testing.assert_allclose(rows[i], _cell_rows(P[i], wings[i])[0])
        assert residual[i] == pytest.approx(ri, abs=1e-12)
    assert residual.max() < 1e-9  # every cell passes the uniform-curvature patch test


def _navier(D: float) -> float:
    k = np.arange(1, 200, 2, dtype=float)
    M, N = np.meshgrid(k, k)
    terms = 1.0 / (M * N * (M**2 + N**2) ** 2) * (2 / (M * np.pi)) * (2 / (N * np.pi))
    return Q / (16 * Q / (np.pi**6 * D) * float(terms.sum()))


def _stiffness(model, S) -> float:
    F = np.zeros((model.n_nodes, 3))
    for f in model.pattern.faces:
        X = np.asarray(model.pattern.vertices3d)[list(f)]
        F[list(f), 2] -= Q * 0.5 * abs(float(np.cross(X, np.roll(X, -1, 0)).sum(0)[2])) / len(f)
    U, R = linear_response(model, F, S)
    assert abs(R.sum() + F.sum()) < 1e-8 * abs(F.sum())
    return float(F[:, 2].sum() ** 2 / np.sum(F * U))


def _navier_error(mat, m: int, grading: float = 1.0) -> float:
    """|stiffness / Navier's - 1| of the simply supported unit square cut into m x m coupled
    cells (``grading``: :func:`barhinge.pattern.subdivide.subdivided`)."""
    cpm, parent = subdivided(SQUARE, m, grading)
    model = coupled_bending(bh.BarHingeModel.from_pattern(cpm, "N5B8", mat))
    S = np.zeros((model.n_nodes, 3), bool)
    S[np.union1d(np.arange(4), np.flatnonzero(parent >= 0))] = True
    return abs(_stiffness(model, S) / _navier(mat.bending_rigidity) - 1.0)


def test_simply_supported_plate_converges_to_navier_at_order_two():
    mat = bh.Material(E=70e9, nu=0.33, t=2e-3)
    levels = [4, 8, 16]
    err = [_navier_error(mat, m) for m in levels]
    rate = -np.polyfit(np.log(levels), np.log(err), 1)[0]
    assert rate == pytest.approx(2.0, abs=0.3)
    assert err[-1] < 2e-3


def test_graded_cells_converge_to_navier_at_order_two_with_a_larger_constant():
    """Cells graded towards the panel's corners (p = 2, as the roof study cuts its Miura
    roofs' panels, :func:`barhinge.pattern.subdivide.subdivided`) keep the coupled rule's
    second order on Navier's simply supported plate, but its constant grows: measured +10.1,
    +2.6, +0.66 % at m = 8, 16, 32 against +0.28, +0.073, +0.018 % for equal cells. Grading
    pays where the membrane's corner stresses dominate (the Miura roofs), not for smooth
    bending."""
    mat = bh.Material(E=70e9, nu=0.33, t=2e-3)
    levels = [8, 16, 32]
    err = {g: [_navier_error(mat, m, g) for m in levels] for g in (1.0, 2.0)}
    rate = -np.polyfit(np.log(levels), np.log(err[2.0]), 1)[0]
    assert rate == pytest.approx(2.0, abs=0.2)
    assert err[2.0][-1] < 1e-2
    assert all(g > 10 * e for g, e in zip(err[2.0], err[1.0], strict=True))


TRIANGLES = CreasePattern(
    np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float),
    [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
    ["B"] * 4 + ["F"],
    faces=[[0, 1, 2], [0, 2, 3]],
)


def _simply_supported(cp: CreasePattern) -> np.ndarray:
    """Every node on the unit square's edges held (w = 0 there, rotations free)."""
    X = np.asarray(cp.vertices3d)
    on = (np.abs(X[:, :2]) < 1e-12).any(axis=1) | (np.abs(X[:, :2] - 1.0) < 1e-12).any(axis=1)
    return np.repeat(on[:, None], 3, axis=1)


def test_simply_supported_plate_of_triangles_converges_to_navier_at_order_one():
    """The square cut into two triangles along a flat diagonal, each cut into its barycentric
    grid: the triangle rule converges to Navier's plate, at first order (the quadrilaterals'
    rule at second, above)."""
    mat = bh.Material(E=70e9, nu=0.33, t=2e-3)
    levels, err = [8, 16, 32], []
    for m in levels:
        cpm, _ = subdivided(TRIANGLES, m)
        model = coupled_bending(bh.BarHingeModel.from_pattern(cpm, "N5B8", mat))
        assert model.meta["cell_residual"] < 1e-9
        S = _simply_supported(cpm)
        err.append(abs(_stiffness(model, S) / _navier(mat.bending_rigidity) - 1.0))
    rate = -np.polyfit(np.log(levels), np.log(err), 1)[0]
    assert rate == pytest.approx(1.0, abs=0.2)
    assert err[-1] < 0.05


def test_triangles_read_their_neighbours_where_they_are(caplog):
    """On a triangle grid that is not point-symmetric (inner nodes moved in the plane) every
    cell takes its neighbours' opposite corners where they are: the cells' angle rows agree
    with the model's hinges (no mismatch warning) and every cell still stores the plate
    energy of every uniform curvature."""
    cpm, parent = subdivided(TRIANGLES, 6)
    X = np.asarray(cpm.vertices3d, float).copy()
    inner = np.flatnonzero((parent < 0) & (np.arange(len(X)) >= TRIANGLES.n_vertices))
    X[inner, :2] += 0.02 * np.random.default_rng(3).uniform(-1.0, 1.0, (len(inner), 2))
    moved = cpm.replaced(vertices=X)
    mat = bh.Material(E=70e9, nu=0.33, t=2e-3)
    with caplog.at_level("WARNING", logger="barhinge.model.plate_hinges"):
        model = coupled_bending(bh.BarHingeModel.from_pattern(moved, "N5B8", mat))
    assert not [r for r in caplog.records if "differ" in r.getMessage()]
    assert model.meta["cell_residual"] < 1e-9


def _free_edge(mat, rule, m: int) -> float:
    cpm, _ = subdivided(SQUARE, m)
    model = rule(bh.BarHingeModel.from_pattern(cpm, "N5B8", mat, bend_calibration="kirchhoff"))
    X = np.asarray(model.X0)
    on = (np.abs(X[:, 0]) < 1e-9) | (np.abs(X[:, 0] - 1.0) < 1e-9)
    on[cpm.n_vertices :] = False
    S = np.zeros((model.n_nodes, 3), bool)
    S[on] = True
    return _stiffness(model, S)


def _richardson(k: list[float]) -> float:
    a, b, c = k[-3:]
    q = (b - a) / (c - b)
    return c + (c - b) / (q - 1.0)


@pytest.mark.parametrize("nu", [0.33, 0.0])
def test_plate_free_on_two_edges_converges_to_the_shell_with_the_sheets_nu(nu):
    # same D for both nu (E adjusted), so only the Poisson ratio differs
    D, t = 52.4, 2e-3
    mat = bh.Material(E=D * 12 * (1 - nu**2) / t**3, nu=nu, t=t)
    shell = []
    for r in (3, 4, 5):
        sh = shell_model(SQUARE, mat, r)
        f = sh.surface_load((0.0, 0.0, -Q))
        u = sh.solve(f, sh.nodes_on_edges(np.array([1, 3])))
        shell.append(float(sh.translations(f)[:, 2].sum()) ** 2 / float(f @ u))
    ref = _richardson(shell)
    coupled = _richardson([_free_edge(mat, coupled_bending, m) for m in (8, 16, 32)])
    assert coupled / ref - 1.0 == pytest.approx(0.0, abs=0.01)
    if nu > 0:  # the uncoupled rule carries nu = -1/3: it misses the sheet's plate
        plain = _free_edge(mat, consistent_bending, 32)
        assert abs(plain / ref - 1.0) > 0.015
