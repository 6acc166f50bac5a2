"""The facet shell reference against textbook plates, and its crease coupling."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.model.continuum import polygon_mesh
from barhinge.model.shell import shell_model
from barhinge.pattern.crease import CreasePattern

MAT = bh.Material(E=70e9, nu=0.3, t=0.01)


def _plate(a: float = 1.0, n: int = 2, tilt: float = 0.0):
    """Square plate a x a cut into n x n facets by flat F lines, rotated by ``tilt`` (rad)
    about the x axis. Returns (cp, boundary edge ids, unit normal, centre vertex)."""
    g = np.linspace(0.0, a, n + 1)
    xs, ys = np.meshgrid(g, g)
    P = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    c, s = np.cos(tilt), np.sin(tilt)
    Rx = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    X = P @ Rx.T
    vid = lambda i, j: (n + 1) * j + i  # noqa: E731
    faces = [
        [vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
        for j in range(n)
        for i in range(n)
    ]
    edges = sorted({tuple(sorted((f[k], f[(k + 1) % 4]))) for f in faces for k in range(4)})
    on_b = lambda v: P[v, 0] in (0.0, a) or P[v, 1] in (0.0, a)  # noqa: E731
    bnd = [
        e
        for e, (u, v) in enumerate(edges)
        if on_b(u)
        and on_b(v)
        and (P[u, 0] == P[v, 0] or P[u, 1] == P[v, 1])
        and (
            P[u, 0] in (0.0, a) and P[u, 0] == P[v, 0] or P[u, 1] in (0.0, a) and P[u, 1] == P[v, 1]
        )
    ]
    asg = ["B" if e in bnd else "F" for e in range(len(edges))]
    cp = CreasePattern(X, edges, asg, faces=faces)
    centre = int(np.argmin(np.linalg.norm(P - [a / 2, a / 2, 0], axis=1)))
    return cp, np.array(bnd), Rx @ [0.0, 0.0, 1.0], centre


def _centre_deflection(
    refine: int, clamped: bool, tilt: float = 0.3, grading: float = 1.0
) -> float:
    cp, bnd, N, centre = _plate(tilt=tilt)
    sh = shell_model(cp, MAT, refine, grading=grading)
    q = 1e3
    f = sh.surface_load(q * N)
    fixed_dofs = np.flatnonzero(np.isin(sh.dof_edge, bnd)) if clamped else None
    u = sh.solve(f, sh.nodes_on_edges(bnd), fixed_dofs)
    return float(sh.translations(u)[centre] @ N) * MAT.bending_rigidity / (q * 1.0**4)


# Timoshenko & Woinowsky-Krieger (1959), Theory of Plates and Shells: square plate under a
# uniform load q, w_max = alpha q a^4 / D; simply supported alpha = 0.00406 (Table 8,
# Navier series 0.0040624), clamped alpha = 0.00126 (Table 35, 0.0012653).
ALPHA_SS, ALPHA_CL = 0.0040624, 0.0012653


def test_simply_supported_square_plate_converges_at_order_two():
    """Four tilted facets joined by flat lines (the coupling across the joins and the rotation
    into 3-D are exercised): the error against the Navier solution falls as h^2 (CST +
    Morley) and is below 2 % at 16 elements per facet edge."""
    levels = np.array([2, 3, 4])
    err = np.array([abs(_centre_deflection(int(r), False) - ALPHA_SS) for r in levels])
    rate = np.polyfit(np.log(2.0**-levels), np.log(err), 1)[0]
    assert rate == pytest.approx(2.0, abs=0.3)
    assert err[-1] / ALPHA_SS < 0.02


def test_clamped_square_plate_within_two_percent():
    assert _centre_deflection(4, True) == pytest.approx(ALPHA_CL, rel=0.02)


def _null_dim(K) -> int:
    w = np.linalg.eigvalsh(K.toarray())
    return int((w < 1e-9 * w.max()).sum())


def test_folded_shell_has_exactly_the_rigid_body_modes():
    """A folded Miura cell, monolithic creases: the free shell's stiffness has the six
    rigid-body motions as its only null space (the rotations into 3-D and the crease
    coupling are consistent); with crease springs of zero stiffness it gains the cell's
    one-DOF folding mechanism of rigid origami... and the facets' own bending modes stay
    stiff (7 = 6 + 1)."""
    cp = bh.families.miura(1, 1, fold=60.0)
    assert _null_dim(shell_model(cp, MAT, 1).K) == 6
    assert _null_dim(shell_model(cp, MAT, 1, crease_stiffness=MAT.bending_rigidity).K) == 6
    assert _null_dim(shell_model(cp, MAT, 1, crease_stiffness=0.0).K) == 7


def test_non_planar_face_is_a_named_error():
    cp, *_ = _plate(n=1)
    X = np.asarray(cp.vertices3d).copy()
    X[2, 2] += 0.1

    with pytest.raises(ConfigError, match="not planar"):
        bent = CreasePattern(X, cp.edges, cp.assignment, faces=cp.faces, validate=False)
        shell_model(bent, MAT, 1)


def _scordelis_lo(nt: int, nl: int):
    """Scordelis-Lo roof: cylinder R = 25, length 50, 80 deg arc, x axial, z up, faceted into
    nt strips around and nl along (flat rectangular facets joined by F lines). Returns
    (cp, end edges, node at the middle of a free edge)."""
    R, L, phi = 25.0, 50.0, np.radians(40.0)
    th = np.linspace(-phi, phi, nt + 1)
    xs = np.linspace(0.0, L, nl + 1)
    X = np.array([[x, R * np.sin(t), R * np.cos(t)] for x in xs for t in th])
    vid = lambda i, j: j * (nt + 1) + i  # noqa: E731
    faces = [
        [vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
        for j in range(nl)
        for i in range(nt)
    ]
    edges = sorted({tuple(sorted((f[k], f[(k + 1) % 4]))) for f in faces for k in range(4)})
    row = lambda a: a // (nt + 1)  # noqa: E731
    col = lambda a: a % (nt + 1)  # noqa: E731
    end = [row(a) == row(b) and row(a) in (0, nl) for a, b in edges]
    side = [col(a) == col(b) and col(a) in (0, nt) for a, b in edges]
    asg = ["B" if e or s else "F" for e, s in zip(end, side, strict=True)]
    cp = CreasePattern(X, edges, asg, faces=faces, validate=False)
    return cp, np.flatnonzero(end), vid(0, nl // 2)


def _scordelis_lo_deflection(nt: int, nl: int, refine: int) -> float:
    """Vertical deflection at the middle of a free edge under the self-weight 90 per unit
    area; E = 4.32e8, nu = 0, t = 0.25; rigid diaphragms at the ends (y, z held, x free);
    the axial translation is stopped at the free-edge midpoint (zero there by symmetry)."""
    cp, ends, mid = _scordelis_lo(nt, nl)
    sh = shell_model(cp, bh.Material(E=4.32e8, nu=0.0, t=0.25), refine)
    f = sh.surface_load((0.0, 0.0, -90.0), per="area")
    nodes = sh.nodes_on_edges(ends)
    held = np.concatenate([3 * nodes + 1, 3 * nodes + 2, [3 * mid]])
    u = sh.solve(f, np.zeros(0, np.int64), held)
    return float(-sh.translations(u)[mid, 2])


def test_scordelis_lo_roof_within_two_percent():
    """MacNeal & Harder (1985), Finite Elements in Analysis and Design 1, 3-20: the
    Scordelis-Lo roof's free-edge midpoint deflects 0.3024 (the shallow-shell value used for
    element tests). A faceted shell also approximates the geometry; 16 x 16 facets with 4
    elements per facet edge is within 2 %, and closer than 8 x 8 facets with 2."""
    ref = 0.3024
    coarse = _scordelis_lo_deflection(8, 8, 1)
    fine = _scordelis_lo_deflection(16, 16, 2)
    assert fine == pytest.approx(ref, rel=0.02)
    assert abs(fine - ref) < abs(coarse - ref)


# ---- corner-graded facet meshes (grading of polygon_mesh and shell_model)

PENTAGON = np.array([[0.0, 0.0], [2.0, 0.0], [2.5, 1.2], [1.0, 2.0], [-0.3, 1.0]])
# a chevron: its centroid lies outside, so it is cut into ears (no fan centre)
CHEVRON = np.array([[0.0, 0.0], [1.0, 0.8], [2.0, 0.0], [2.0, 0.4], [1.0, 1.2], [0.0, 0.4]])


def _g(s: np.ndarray, p: float) -> np.ndarray:
    return s**p / (s**p + (1 - s) ** p)


def _area(P: np.ndarray) -> float:
    return 0.5 * float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))


def _tri_areas(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Signed areas of the triangles ``t`` (3, n) of the points ``x`` (m, 2)."""
    a = x[t]
    return 0.5 * (
        (a[1, :, 0] - a[0, :, 0]) * (a[2, :, 1] - a[0, :, 1])
        - (a[2, :, 0] - a[0, :, 0]) * (a[1, :, 1] - a[0, :, 1])
    )


@pytest.mark.parametrize("P", [PENTAGON, CHEVRON], ids=["fan", "ears"])
@pytest.mark.parametrize("p", [1.5, 2.0, 3.0])
def test_graded_mesh_keeps_the_polygon_and_grades_its_edges(P: np.ndarray, p: float) -> None:
    """The corners stay the first mesh vertices, the triangles tile the polygon (areas add
    up, none inverted), and the nodes on every polygon edge sit at the fractions
    ``g(i / n) = s^p / (s^p + (1 - s)^p)`` of the edge (n = 2^refine): the closed form of
    the grading."""
    refine = 3
    n = 2**refine
    m = polygon_mesh(P, refine, grading=p)
    x = m.p.T
    np.testing.assert_array_equal(x[: len(P)], P)
    uniform = polygon_mesh(P, refine)
    np.testing.assert_array_equal(m.t, uniform.t)
    area, area_uniform = _tri_areas(x, m.t), _tri_areas(uniform.p.T, m.t)
    assert np.all(area * area_uniform > 0)  # no triangle turned over
    assert np.abs(area).sum() == pytest.approx(abs(_area(P)), rel=1e-12)
    expected = _g(np.arange(n + 1) / n, p)
    for i in range(len(P)):
        A, B = P[i], P[(i + 1) % len(P)]
        d = B - A
        s = (x - A) @ d / (d @ d)
        off = np.abs((x - A) @ np.array([-d[1], d[0]])) / np.linalg.norm(d)
        on = (off < 1e-12) & (s > -1e-12) & (s < 1 + 1e-12)
        np.testing.assert_allclose(np.sort(s[on]), expected, atol=1e-12)


def test_graded_facets_still_share_their_edge_nodes() -> None:
    """Four facets meeting along flat lines: graded meshes have exactly as many nodes as
    uniform ones (the nodes along shared edges coincide and merge)."""
    cp, *_ = _plate()
    for refine in (1, 2, 3):
        uniform = shell_model(cp, MAT, refine).n_nodes
        assert shell_model(cp, MAT, refine, grading=2.0).n_nodes == uniform


def test_graded_shell_converges_to_navier_at_order_two() -> None:
    """The simply supported square plate (Timoshenko & Woinowsky-Krieger 1959, Table 8;
    Navier series) on graded meshes: the same limit at the same order 2 (the plate has no
    corner singularity, so grading costs a constant factor), within 1 % at r = 4."""
    levels = np.array([2, 3, 4])
    err = np.array([abs(_centre_deflection(int(r), False, grading=2.0) - ALPHA_SS) for r in levels])
    rate = np.polyfit(np.log(2.0**-levels), np.log(err), 1)[0]
    assert rate == pytest.approx(2.0, abs=0.3)
    assert err[-1] / ALPHA_SS < 0.01


@pytest.mark.parametrize("bad", [0.5, 0.0, float("nan")])
def test_grading_below_one_is_a_named_error(bad: float) -> None:
    cp, *_ = _plate()
    with pytest.raises(ConfigError, match="grading"):
        shell_model(cp, MAT, 1, grading=bad)
