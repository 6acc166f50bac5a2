"""Every pattern family: exact geometry, vertex conditions, exact folded states.

Sources of the conditions checked:
* developability: sector angles sum to 2 pi at every interior vertex of a flat pattern;
* Maekawa |M - V| = 2 and Kawasaki (alternate sector angles sum to pi) at every interior vertex
  of a flat-foldable pattern (Demaine & O'Rourke, *Geometric Folding Algorithms*, 2007,
  Thm 12.2.2 and 12.2.4);
* a rigidly folded state keeps every edge length and every sector angle of the flat pattern.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import PatternError
from barhinge.families import FAMILIES
from barhinge.families.eggbox import eggbox, eggbox_symmetric_fold
from barhinge.families.miura_arc import miura_arc
from barhinge.families.miura_nonuniform import miura_nonuniform
from barhinge.families.miura_tachi import default_arch_curve, miura_tachi, tachi_section
from barhinge.families.pleats import pleats
from barhinge.families.properties import kawasaki_error, maekawa_count, sector_sum_error
from barhinge.families.russo import russo_pleat
from barhinge.families.yoshimura import yoshimura, yoshimura_arch_rows
from barhinge.pattern.crease import CreasePattern

FLAT_FOLDABLE = [
    "miura",
    "miura_arc",
    "miura_nonuniform",
    "miura_tachi",
    "yoshimura",
    "waterbomb",
    "square_twist",
    "kresling",
    "diagonal",
    "russo_pleat",
]


def _default(name: str) -> CreasePattern:
    fn = FAMILIES[name]
    return fn(3, 3) if name in ("miura", "yoshimura", "eggbox") else fn()


def _lengths(cp: CreasePattern) -> np.ndarray:
    X = cp.vertices3d
    return np.linalg.norm(X[cp.edges[:, 1]] - X[cp.edges[:, 0]], axis=1)


def _assert_isometric(flat: CreasePattern, folded: CreasePattern) -> None:
    """Same topology, same edge lengths, same sector angles, planar faces."""
    assert np.array_equal(flat.edges, folded.edges)
    assert flat.faces == folded.faces
    np.testing.assert_allclose(_lengths(folded), _lengths(flat), rtol=0, atol=1e-12)
    for f0, f1 in zip(flat.face_corner_angles, folded.face_corner_angles, strict=True):
        np.testing.assert_allclose(f1, f0, atol=1e-10)
    X = folded.vertices3d
    for f in folded.faces:
        if len(f) > 3:
            P = X[list(f)] - X[f[0]]
            assert np.linalg.svd(P, compute_uv=False)[2] < 1e-11


def _assert_state_matches_assignment(cp: CreasePattern) -> None:
    rho = cp.state_fold_angles()
    np.testing.assert_allclose(rho, cp.fold_angles, atol=1e-9)
    cr = cp.crease_edges[np.isin(cp.assignment[cp.crease_edges], ("M", "V"))]
    moving = cr[np.abs(rho[cr]) > 1e-9]
    assert np.all(np.sign(rho[moving]) == np.where(cp.assignment[moving] == "V", 1, -1))


# ------------------------------------------------------------------ every family
@pytest.mark.parametrize("name", list(FAMILIES))
def test_family_builds_a_valid_pattern(name):
    cp = _default(name)
    assert cp.meta["barhinge:family"] == name
    assert cp.n_faces > 0 and len(cp.crease_edges) > 0
    # assignment and target angles agree in sign (valley > 0)
    F = cp.fold_angles
    assert np.all(F[cp.assignment == "V"] > 0)
    assert np.all(F[cp.assignment == "M"] < 0)
    assert np.all(F[np.isin(cp.assignment, ("B", "F"))] == 0)
    if cp.developable:
        assert cp.vertices.shape[1] == 2
        # counter-clockwise faces seen from +z
        assert np.all(cp.face_normals[:, 2] > 0.999)


@pytest.mark.parametrize("name", [n for n in FAMILIES if n != "eggbox"])
def test_developable_at_every_interior_vertex(name):
    cp = _default(name)
    iv = cp.interior_vertices
    assert len(iv) > 0 or name == "pleats"  # straight pleats have no interior vertex
    np.testing.assert_allclose(sector_sum_error(cp)[iv], 0.0, atol=1e-12)


@pytest.mark.parametrize("name", FLAT_FOLDABLE)
def test_maekawa_and_kawasaki(name):
    cp = _default(name)
    iv = cp.interior_vertices
    assert np.all(np.abs(maekawa_count(cp)[iv]) == 2)
    assert np.all(cp.vertex_degree[iv] % 2 == 0)
    np.testing.assert_allclose(kawasaki_error(cp)[iv], 0.0, atol=1e-12)


# ------------------------------------------------------------------ Yoshimura
def test_yoshimura_flat_edge_lengths_and_sector_angles():
    w, h = 1.2, 0.7
    cp = yoshimura(4, 3, w=w, h=h)
    X = cp.vertices
    L = _lengths(cp)
    d = X[cp.edges[:, 1]] - X[cp.edges[:, 0]]
    horiz = np.abs(d[:, 1]) < 1e-12
    vert = np.abs(d[:, 0]) < 1e-12
    diag = ~horiz & ~vert
    assert set(np.round(L[horiz], 12)) <= {round(w, 12), round(w / 2, 12)}
    np.testing.assert_allclose(L[diag], math.hypot(w / 2, h), atol=1e-13)
    np.testing.assert_allclose(L[vert], h, atol=1e-13)  # the side boundary
    beta = math.degrees(math.atan2(h, w / 2))  # base angle of the isosceles triangles
    for v in cp.interior_vertices:
        sec = np.sort(np.degrees(cp.sector_angles[v]))
        np.testing.assert_allclose(sec, sorted([beta] * 4 + [180 - 2 * beta] * 2), atol=1e-10)
    assert np.all(cp.vertex_degree[cp.interior_vertices] == 6)


@pytest.mark.parametrize("fold", [5.0, 30.0, 60.0, 85.0])
def test_yoshimura_arch_is_exact(fold):
    """Closed-form arch: rows on polygons of circumradius R = w / (2 sin beta), spacing
    d = sqrt(h^2 - (w/2)^2 tan^2(beta/2)); all triangles keep their shape."""
    w, h, nx, ny = 1.0, 0.6, 4, 3
    flat = yoshimura(nx, ny, w=w, h=h)
    cp = yoshimura(nx, ny, w=w, h=h, fold=fold)
    _assert_isometric(flat, cp)
    _assert_state_matches_assignment(cp)
    R, d = yoshimura_arch_rows(w, h, fold)
    beta = math.radians(fold) / 2
    assert R == pytest.approx(w / (2 * math.sin(beta)), rel=1e-14)
    X = cp.vertices
    rows = cp.meta["barhinge:rows"]
    first, count = rows[0]
    P = X[first : first + count]
    # even row: all points on one circle about an axis parallel to y; measure its radius
    centre_z = P[:, 2].max() - R
    centre_x = P[:, 0].mean() if count % 2 else P[count // 2, 0]
    r_meas = np.hypot(P[:, 0] - centre_x, P[:, 2] - centre_z)
    np.testing.assert_allclose(r_meas, R, rtol=1e-12)
    y_rows = [X[r0, 1] for r0, _ in rows]
    np.testing.assert_allclose(np.diff(y_rows), d, atol=1e-13)


def test_yoshimura_fold_range():
    with pytest.raises(PatternError, match="fold"):
        yoshimura(2, 2, w=1.0, h=0.2, fold=170.0)  # beyond 4 arctan(2h/w)
    with pytest.raises(PatternError, match="nx"):
        yoshimura(8, 2, fold=60.0)  # 480 deg > 360


# ------------------------------------------------------------------ pleats, egg-box
@pytest.mark.parametrize("fold", [0.0, 45.0, 120.0, 179.0])
def test_pleats_fold_exact(fold):
    flat = pleats(5, w=0.7, length=2.0)
    cp = pleats(5, w=0.7, length=2.0, fold=fold)
    _assert_isometric(flat, cp)
    _assert_state_matches_assignment(cp)
    cr = cp.crease_edges
    np.testing.assert_allclose(np.abs(cp.state_fold_angles()[cr]), fold, atol=1e-9)
    # the pleated width is n w cos(fold / 2)
    assert np.ptp(cp.vertices[:, 0]) == pytest.approx(5 * 0.7 * math.cos(math.radians(fold / 2)))


@pytest.mark.parametrize("alpha,fold", [(60.0, None), (70.0, 40.0), (45.0, 80.0)])
def test_eggbox_geometry_and_non_developability(alpha, fold):
    a, b = 1.0, 1.3
    cp = eggbox(2, 2, a=a, b=b, alpha=alpha, fold=fold)
    assert cp.developable is False
    L = _lengths(cp)
    X = cp.vertices
    d = X[cp.edges[:, 1]] - X[cp.edges[:, 0]]
    along_x = np.abs(d[:, 1]) < 1e-12
    np.testing.assert_allclose(L[along_x], a, atol=1e-13)
    np.testing.assert_allclose(L[~along_x], b, atol=1e-13)
    # pits/peaks: four sectors gamma (defect 2 pi - 4 gamma); saddles: four pi - gamma
    defect = np.degrees(cp.angle_defect[cp.interior_vertices])
    np.testing.assert_allclose(np.abs(defect), abs(360 - 4 * alpha), atol=1e-9)
    assert (defect > 0).any() and (defect < 0).any()
    _assert_state_matches_assignment(cp)
    # the validator rejects it when declared developable
    with pytest.raises(PatternError, match="360"):
        CreasePattern(cp.vertices, cp.edges, cp.assignment, cp.fold_angles, cp.faces)
    assert eggbox_symmetric_fold(alpha) > 90 - alpha


# ------------------------------------------------------------------ Miura variations
@pytest.mark.parametrize("fold", [10.0, 60.0, 120.0, 175.0])
def test_miura_arc_folds_exactly(fold):
    kw = {"nx": 3, "ny": 2, "a": 1.0, "h": 0.8, "alpha": 55.0, "delta": 12.0, "grade": 4.0}
    flat = miura_arc(**kw)
    cp = miura_arc(**kw, fold=fold)
    _assert_isometric(flat, cp)
    _assert_state_matches_assignment(cp)
    st = np.asarray(bh.families.grid_layout(cp).row_edges)
    st = st[np.isin(st, cp.crease_edges)]
    np.testing.assert_allclose(np.abs(cp.state_fold_angles()[st]), fold, atol=1e-9)
    # the section bends into an arch: its two ends are level and its middle is higher
    lay = bh.families.grid_layout(cp)
    z = cp.vertices[lay.bottom, 2]
    assert z[0] == pytest.approx(z[-1], abs=1e-12)
    assert z[len(z) // 2] > z[0] + 0.05


def test_miura_arc_without_delta_is_the_miura():
    gamma = 60.0
    arc = miura_arc(2, 2, a=1.0, h=math.sin(math.radians(gamma)), alpha=gamma, delta=0.0)
    ref = bh.families.miura(2, 2, a=1.0, b=1.0, alpha=gamma)
    np.testing.assert_allclose(arc.vertices, ref.vertices, atol=1e-12)
    assert np.array_equal(arc.assignment, ref.assignment)


def test_miura_nonuniform_folds_exactly():
    a, b = [1.0, 0.4, 1.5, 0.7], [0.8, 1.2, 0.5]
    flat = miura_nonuniform(a, b, alpha=58.0)
    cp = miura_nonuniform(a, b, alpha=58.0, fold=35.0)
    _assert_isometric(flat, cp)
    _assert_state_matches_assignment(cp)


def test_miura_tachi_follows_the_section_and_unfolds():
    curve = default_arch_curve(radius=3.0, angle=100.0, n=6)
    folded = miura_tachi(curve, ny=2, depth=0.3, offset=0.25, spacing=0.5, folded=True)
    flat = miura_tachi(curve, ny=2, depth=0.3, offset=0.25, spacing=0.5)
    _assert_isometric(flat, folded)
    _assert_state_matches_assignment(folded.replaced(fold_angles=folded.state_fold_angles()))
    lay = bh.families.grid_layout(folded)
    P = folded.vertices[lay.bottom]
    np.testing.assert_allclose(P[:, [0, 2]], tachi_section(curve, 0.3), atol=1e-12)
    # rows are straight in the flat pattern (Miura-like), y constant per row
    Y = flat.vertices[:, 1].reshape(lay.nj, lay.ni)
    np.testing.assert_allclose(Y - Y[:, :1], 0.0, atol=1e-12)


def test_miura_tachi_rejects_a_smooth_section_without_depth():
    with pytest.raises(PatternError, match="zig-zag"):
        miura_tachi(default_arch_curve(), depth=0.0)


def test_russo_pleat_is_a_miura_with_narrow_panels():
    cp = russo_pleat(pleats=3, strips=3, pitch=1.0, width=0.25, height=0.8, angle=20.0)
    lay = bh.families.grid_layout(cp)
    X = cp.vertices
    widths = np.diff(X[lay.bottom, 0])
    np.testing.assert_allclose(widths, [0.75, 0.25] * 3 + [0.75], atol=1e-12)
    # pleat lines lean +20 deg in even strips and -20 deg in odd strips
    for j in range(3):
        v0, v1 = lay.vertex(1, j), lay.vertex(1, j + 1)
        lean = math.degrees(math.atan2(X[v1, 0] - X[v0, 0], X[v1, 1] - X[v0, 1]))
        assert lean == pytest.approx(20.0 if j % 2 == 0 else -20.0)
    # each pleat is one mountain and one valley line
    A = cp.assignment
    for i in (1, 2):
        assert A[lay.column_edge(i, 0)] != A[lay.column_edge(i + 1, 0)]
    folded = russo_pleat(pleats=3, strips=3, pitch=1.0, width=0.25, height=0.8, angle=20.0, fold=50)
    _assert_isometric(cp, folded)


# ------------------------------------------------------------------ real patterns
def test_resch_proportions_match_origami_simulator(shared_patterns):
    """Spokes : tile sides : long valleys = 1 : sqrt 3 : 2, as in reschTriTessellation.svg."""
    cp = bh.families.resch(9, 7, t=2.0)
    L = _lengths(cp)
    spokes = L[cp.assignment == "V"]
    np.testing.assert_allclose(spokes, 4.0 / math.sqrt(3), atol=1e-12)
    m = np.unique(np.round(L[cp.assignment == "M"], 9))
    np.testing.assert_allclose(m, [2.0 / math.sqrt(3), 2.0], atol=1e-9)
    ref = bh.read_svg(shared_patterns / "origami-simulator" / "reschTriTessellation.svg")
    Lr = _lengths(ref)
    inner = np.isin(ref.assignment, ("M", "V")) & ~np.isin(ref.edges, ref.boundary_vertices).any(1)
    short = Lr[inner].min()
    ratios = np.unique(np.round(Lr[inner] / short, 2))
    np.testing.assert_allclose(ratios, [1.0, math.sqrt(3), 2.0], atol=0.01)
    assert set(np.unique(cp.vertex_degree[cp.interior_vertices])) == {6}
    assert set(np.unique(ref.vertex_degree[ref.interior_vertices])) == {6}


def test_waterbomb_matches_origami_simulator(shared_patterns):
    cp = bh.families.waterbomb(6, 4, s=1.0)
    ref = bh.read_svg(shared_patterns / "origami-simulator" / "waterbomb.svg")
    for c in (cp, ref):
        L = _lengths(c)
        unit = L[c.assignment == "V"].min()
        # valleys: half diagonals; mountains: s/2 (row lines, split centre lines) and s
        np.testing.assert_allclose(L[c.assignment == "V"] / unit, 1.0, atol=1e-3)
        m = np.unique(np.round(L[c.assignment == "M"] / unit, 3))
        np.testing.assert_allclose(m, [1 / math.sqrt(2), math.sqrt(2)], atol=1e-3)
        assert set(np.unique(c.vertex_degree[c.interior_vertices])) == {6}
