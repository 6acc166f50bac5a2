"""Per-hinge stiffness of the default (``"plate"``) bending rule on rectangles, from a closed
form that uses none of barhinge's plate code.

A free Kirchhoff plate W x H loaded at its corners deforms in pure twist ``w = c x y``
(Timoshenko & Woinowsky-Krieger 1959, Sec. 11), energy ``D (1 - nu) c^2 W H``. Its corner
deflections ``+-delta`` (``delta = c W H / 4``) give ``U = 16 D (1 - nu) delta^2 / (W H)``.
The same corner deflections fold an N4B5 panel about its diagonal (length L) by
``4 delta / h`` (h = W H / L, the corners' distance from it), and fold each of the four
half-diagonal hinges of an N5B8 panel by ``2 delta L / (W H)``; both give
``U = 8 k delta^2 L^2 / (W H)^2``. Equal energies: ``k = 2 D (1 - nu) W H / (W^2 + H^2)``
for every bending hinge of a rectangular panel, whatever its size or thickness ratio.
"""

from __future__ import annotations

import numpy as np
import pytest

import barhinge.model.continuum as cont
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern


def _rect(W: float, H: float) -> CreasePattern:
    P = np.array([[0, 0], [W, 0], [W, H], [0, H]], float)
    return CreasePattern(P, [[i, (i + 1) % 4] for i in range(4)], ["B"] * 4, faces=[[0, 1, 2, 3]])


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
@pytest.mark.parametrize("W,H", [(1.0, 1.0), (2.0, 1.0), (0.3, 1.2), (5.0, 0.5)])
@pytest.mark.parametrize("nu,t", [(0.3, 0.01), (0.0, 1e-3), (0.45, 0.05)])
def test_rectangle_hinge_closed_form(scheme: str, W: float, H: float, nu: float, t: float):
    mat = Material(E=2.0e9, nu=nu, t=t)
    m = BarHingeModel.from_pattern(_rect(W, H), scheme, mat)  # default bend_calibration
    k = m.hinge_k[m.hinge_kind == "bend"]
    D = mat.E * t**3 / (12.0 * (1.0 - nu**2))
    assert len(k) == (1 if scheme == "N4B5" else 4)
    np.testing.assert_allclose(k, 2.0 * D * (1.0 - nu) * W * H / (W**2 + H**2), rtol=1e-8)


def _quad_plate_energy(P: np.ndarray, mat: Material, corner_w: np.ndarray) -> float:
    """Closed-form minimum Kirchhoff energy of the free parallelogram ``P`` with the corner
    deflections ``corner_w`` (warping pattern ``+d, -d, +d, -d``): under corner forces only,
    a constant moment field with zero normal moment on both edge directions is in
    equilibrium and meets the free-edge conditions, so the deflection is the quadratic
    ``d xi eta + p (xi^2 - 1) + q (eta^2 - 1)`` in the parallelogram's affine coordinates
    (T&W 1959, Sec. 11, generalised); energy = area x density, minimised over p, q."""
    d = corner_w[0]
    A = np.column_stack([(P[1] - P[0]) / 2.0, (P[3] - P[0]) / 2.0])  # x = c + A (xi, eta)
    Ai = np.linalg.inv(A)
    Hs = [
        Ai.T @ h @ Ai
        for h in (np.array([[0, 1], [1, 0.0]]) * d, np.diag([2.0, 0]), np.diag([0, 2.0]))
    ]
    D = mat.E * mat.t**3 / (12.0 * (1.0 - mat.nu**2))

    def b(H1, H2):  # bilinear form of the energy density 1/2 D [(tr H)^2 - 2 (1 - nu) det H]
        det = H1[0, 0] * H2[1, 1] + H2[0, 0] * H1[1, 1] - 2 * H1[0, 1] * H2[0, 1]
        return 0.5 * D * (np.trace(H1) * np.trace(H2) - (1.0 - mat.nu) * det)

    G = np.array([[b(Hi, Hj) for Hj in Hs] for Hi in Hs])
    pq = np.linalg.solve(G[1:, 1:], -G[1:, 0])
    c = np.concatenate([[1.0], pq])
    return float(c @ G @ c) * abs(np.linalg.det(A)) * 4.0


PARALLELOGRAM = np.array([[0, 0], [1, 0], [1.5, np.sqrt(0.75)], [0.5, np.sqrt(0.75)]])
WARP = np.array([1.0, -1.0, 1.0, -1.0]) * 1e-3


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
@pytest.mark.parametrize(
    "P",
    [
        PARALLELOGRAM,
        np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]]),
        np.array([[0, 0], [1, 0], [1.2, 0.4], [0.2, 0.4]]),
    ],
)
def test_default_panel_warping_energy_closed_form(scheme: str, P: np.ndarray) -> None:
    """The default panel's corner-warping energy equals the free plate's closed form
    (parallelograms, where the plate solution is quadratic)."""
    mat = Material(E=1.0, nu=0.3, t=0.01)
    cp = CreasePattern(P, [[i, (i + 1) % 4] for i in range(4)], ["B"] * 4, faces=[[0, 1, 2, 3]])
    m = BarHingeModel.from_pattern(cp, scheme, mat)
    S = cont.panel_corner_stiffness(m, np.arange(4))
    want = _quad_plate_energy(P, mat, WARP)
    assert 0.5 * WARP @ S @ WARP == pytest.approx(want, rel=1e-8)


def test_ear_clipped_mesh_gives_the_fan_mesh_energy() -> None:
    """A convex parallelogram meshed by ear clipping instead of the centroid fan: both give
    the closed-form warping energy (Morley elements reproduce the quadratic solution
    exactly on either mesh)."""
    mat = Material(E=1.0, nu=0.3, t=0.01)
    P = PARALLELOGRAM
    fan = cont.plate_corner_energy(P, mat, WARP, 2)
    from skfem import MeshTri

    ears = cont._ear_clip(P, 1.0)
    mp = pytest.MonkeyPatch()
    used = []

    def ear_mesh(Q, refine=3):
        used.append(1)
        return MeshTri(Q.T, ears.T).refined(refine)

    mp.setattr(cont, "polygon_mesh", ear_mesh)
    try:
        ear = cont.plate_corner_energy(P, mat, WARP, 2)
    finally:
        mp.undo()
    assert used and ears.shape == (2, 3)
    want = _quad_plate_energy(P, mat, WARP)
    assert fan == pytest.approx(want, rel=1e-10)
    assert ear == pytest.approx(want, rel=1e-10)


@pytest.mark.parametrize(
    "P,tol",
    [
        ([[0, 0], [2, 0], [1.5, 1], [0.5, 1]], 1e-3),  # trapezoid: smooth, second order
        ([[0, 0], [1.3, 0.1], [1.1, 0.9], [0.2, 1.4]], 1e-3),  # generic convex quad
        ([[0, 0], [2, 0], [1, 0.3], [1, 2]], 3e-2),  # dart: reflex corner, first order
    ],
)
def test_plate_reference_at_the_default_refinement(P, tol: float) -> None:
    """Quadrilaterals other than parallelograms have no polynomial plate solution: the
    default rule matches the Morley plate at ``refine=4``, which is within ``tol`` of the
    refinement limit (Richardson extrapolation of refine 3, 4, 5 at the observed rate)."""
    mat = Material(E=1.0, nu=0.3, t=0.01)
    Q = np.array(P, float)
    tr = np.array([np.trace(cont.plate_corner_stiffness(Q, mat, r)) for r in (3, 4, 5)])
    d = np.diff(tr)
    assert d[0] > 0 and d[1] > 0  # monotone from below (Morley is soft here)
    rate = np.log2(d[0] / d[1])
    limit = tr[2] + d[1] / (2.0**rate - 1.0)
    assert abs(tr[1] / limit - 1.0) < tol


def test_a_sliver_panel_is_a_named_error_not_a_stiffness_of_nan() -> None:
    """A quadrilateral 1e-12 high: its plate with the corners held is singular (the solve
    with scipy warned and returned NaN). It is refused with a message naming the cause."""
    from barhinge.errors import ConfigError

    mat = Material(E=1e6, nu=0.3, t=0.01)
    sliver = np.array([[0, 0], [1, 0], [1, 1e-12], [0, 1e-12]], float)
    with pytest.raises(ConfigError, match="sliver"):
        cont.plate_corner_stiffness(sliver, mat)


@pytest.mark.parametrize(
    "height, singular",
    [(1e-2, False), (1e-4, False), (3e-5, False), (1e-6, True), (1e-12, True)],
)
def test_thin_panels_condense_symmetric_or_are_refused(height: float, singular: bool) -> None:
    """A condensed stiffness (a Schur complement of a symmetric matrix) is symmetric: its
    asymmetry measures the condensation's rounding error. A panel that is accepted keeps the
    digits the condensation promises (relative error at most ``CONDENSATION_ERROR_MAX``,
    1e-6), down to panels 3e-5 high, near the limit; the error grows like height^-3 (about
    1e-7 at 1e-4, its constant set by the CPU's rounding). At 1e-6 the condensation would
    keep three digits (asymmetric by ~1e-3) and the panel is refused as a sliver instead."""
    from barhinge.errors import ConfigError

    mat = Material(E=1e6, nu=0.3, t=0.01)
    P = np.array([[0, 0], [1, 0], [1, height], [0, height]], float)
    if singular:
        with pytest.raises(ConfigError, match="sliver"):
            cont.plate_corner_stiffness(P, mat)
        return
    S = cont.plate_corner_stiffness(P, mat)
    assert np.all(np.isfinite(S))
    assert np.abs(S - S.T).max() <= cont.CONDENSATION_ERROR_MAX * np.abs(S).max()
