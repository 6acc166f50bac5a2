"""The constant-strain-triangle membrane written in the bars' strains
(barhinge.model.membrane, ``bar_calibration="cst"``).

Independent checks: the Cauchy relations of the equilateral bar lattice (Ostoja-Starzewski
2002, Appl. Mech. Rev. 55, 35-60: a triangular lattice of central-force bars is isotropic with
nu = 1/3, 2D modulus ``2 k / sqrt(3)``); scikit-fem's plane-stress P1 elasticity on the same
triangles; the homogeneous plane-stress energy (patch test); finite differences and the
element-by-element reference kernel.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.errors import ConfigError
from barhinge.kernels.reference import assemble_reference
from barhinge.model.compare import panel_errors, subdivided_membrane_errors
from barhinge.model.material import Material
from barhinge.model.membrane import cst_bar_matrix, triangle_side_matrices
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.subdivide import subdivided

MAT = Material(E=2.0e6, nu=0.3, t=0.02)
SHAPES = {
    "right isosceles": [[0, 0], [1, 0], [0, 1]],
    "square": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "skew quad": [[0, 0], [2, 0], [2.6, 1.3], [0.3, 0.9]],
    "long strip": [[0, 0], [5, 0], [5, 0.5], [0, 0.5]],
    "pentagon": [[0, 0], [2, 0], [2.5, 1.2], [1, 2.1], [-0.4, 1]],
}


def panel(P) -> CreasePattern:
    P = np.asarray(P, float)
    k = len(P)
    return CreasePattern(P, [[i, (i + 1) % k] for i in range(k)], ["B"] * k, faces=[list(range(k))])


def test_equilateral_triangle_is_the_cauchy_lattice_at_nu_one_third():
    L, mat = 1.7, Material(E=3.0e5, nu=1.0 / 3.0, t=0.05)
    P = np.array([[0, 0, 0], [L, 0, 0], [L / 2, L * np.sqrt(3) / 2, 0]])
    C = triangle_side_matrices(P[None], mat)[0]
    # each side of one triangle carries half of the lattice bar: EA / L = sqrt(3) E t / 4
    expected = np.sqrt(3.0) / 4.0 * mat.E * mat.t * L**2
    np.testing.assert_allclose(np.diag(C), expected, rtol=1e-12)
    np.testing.assert_allclose(C - np.diag(np.diag(C)), 0.0, atol=1e-10 * expected)


def test_other_nu_couples_the_sides_of_the_equilateral_triangle():
    P = np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    C = triangle_side_matrices(P[None], Material(nu=0.0))[0]
    assert np.abs(C[0, 1]) > 0.1 * C[0, 0]


@pytest.mark.parametrize("name", SHAPES)
@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_patch_test_is_exact_for_every_panel_shape(name, nu):
    mat = Material(E=1.0e6, nu=nu, t=0.01)
    errors = panel_errors(np.array(SHAPES[name], float), mat, "N5B8", "cst")
    membrane = {k: v for k, v in errors.items() if k != "warp"}
    np.testing.assert_allclose(list(membrane.values()), 0.0, atol=1e-10)


def test_refined_skew_panel_keeps_the_exact_membrane():
    errors = subdivided_membrane_errors(np.array(SHAPES["skew quad"], float), MAT, 4, "N5B8", "cst")
    np.testing.assert_allclose(list(errors.values()), 0.0, atol=1e-10)
    bars = subdivided_membrane_errors(np.array(SHAPES["skew quad"], float), MAT, 4, "N5B8", "fit")
    assert max(abs(v) for v in bars.values()) > 0.01  # the bar lattice does not


def _skfem_plane_stress(points: np.ndarray, triangles: np.ndarray, mat: Material):
    from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    mesh = MeshTri(points.T.copy(), triangles.T.copy())
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    lam, mu = lame_parameters(mat.E, mat.nu)
    lam_ps = 2.0 * lam * mu / (lam + 2.0 * mu)  # plane stress
    K = asm(linear_elasticity(lam_ps, mu), basis) * mat.t
    # skfem's vector dofs: node-major (u_x, u_y of node 0, then node 1, ...)
    return sp.csr_matrix(K), basis


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_in_plane_tangent_equals_scikit_fem_plane_stress(scheme):
    cp, _ = subdivided(panel(SHAPES["skew quad"]), 3)
    model = BarHingeModel.from_pattern(cp, scheme, MAT, bar_calibration="cst")
    from barhinge.model.triangulate import triangulate

    tri = triangulate(cp, scheme)
    K_ref, basis = _skfem_plane_stress(np.asarray(model.X0)[:, :2], tri.triangles, MAT)
    inplane = np.sort(np.r_[3 * np.arange(model.n_nodes), 3 * np.arange(model.n_nodes) + 1])
    K = model.tangent(model.X0)[inplane][:, inplane]
    order = basis.nodal_dofs.T.ravel()  # skfem dof of (node, x), (node, y) in node order
    K_ref = K_ref[order][:, order]
    scale = abs(K_ref).max()
    assert abs(K - K_ref).max() <= 1e-10 * scale


def test_force_and_tangent_match_finite_differences_and_the_reference_kernel():
    model = BarHingeModel.from_pattern(
        panel(SHAPES["pentagon"]), "N5B8", MAT, bar_calibration="cst"
    )
    rng = np.random.default_rng(3)
    X = np.asarray(model.X0) + 0.1 * rng.standard_normal(model.X0.shape)
    ev = model.evaluate(X)
    assert ev.K is not None
    E_ref, f_ref, K_ref = assemble_reference(model, X)
    assert ev.energy == pytest.approx(E_ref, rel=1e-12)
    np.testing.assert_allclose(ev.force, f_ref, atol=1e-9 * np.abs(f_ref).max())
    np.testing.assert_allclose(ev.K.toarray(), K_ref, atol=1e-9 * np.abs(K_ref).max())
    h, x = 1e-6, X.ravel()
    for i in rng.choice(model.n_dof, 6, replace=False):
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        fd = (model.energy(xp) - model.energy(xm)) / (2 * h)
        assert fd == pytest.approx(ev.force[i], rel=1e-6, abs=1e-8 * np.abs(ev.force).max())
        col = (model.internal_force(xp) - model.internal_force(xm)) / (2 * h)
        np.testing.assert_allclose(col, ev.K[:, i].toarray().ravel(), atol=1e-6 * abs(ev.K).max())


def test_rigid_rotation_stores_no_energy():
    model = BarHingeModel.from_pattern(
        panel(SHAPES["skew quad"]), "N5B8", MAT, bar_calibration="cst"
    )
    a = 1.1
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    X = np.asarray(model.X0) @ R.T + [0.3, -2.0, 5.0]
    assert model.energy(X) <= 1e-20 * MAT.E * MAT.t
    np.testing.assert_allclose(model.internal_force(X), 0.0, atol=1e-9 * MAT.E * MAT.t)


def test_bar_forces_resolve_the_membrane_force_at_every_node():
    from barhinge.analysis.forces import bar_axial_forces

    model = BarHingeModel.from_pattern(
        panel(SHAPES["skew quad"]), "N5B8", MAT, bar_calibration="cst", fold_k=0.0, bend_k=0.0
    )
    rng = np.random.default_rng(5)
    X = np.asarray(model.X0) + 0.02 * rng.standard_normal(model.X0.shape)
    N = bar_axial_forces(model, X)
    B = np.asarray(model.bars)
    e = X[B[:, 1]] - X[B[:, 0]]
    e /= np.linalg.norm(e, axis=1)[:, None]
    f = np.zeros_like(X)
    np.add.at(f, B[:, 1], N[:, None] * e)  # a bar in tension pulls its end nodes together
    np.add.at(f, B[:, 0], -N[:, None] * e)
    np.testing.assert_allclose(f.ravel(), model.internal_force(X), atol=1e-9 * np.abs(N).max())


def test_stiffness_parts_sum_to_the_tangent():
    from barhinge.analysis.buckling import stiffness_parts

    model = BarHingeModel.from_pattern(
        panel(SHAPES["skew quad"]), "N5B8", MAT, bar_calibration="cst"
    )
    X = np.asarray(model.X0) * [1.01, 0.99, 1.0]
    Km, Kg = stiffness_parts(model, X)
    assert abs(Km + Kg - model.tangent(X)).max() <= 1e-10 * abs(model.tangent(X)).max()


def test_stiffened_scales_the_couplings():
    model = BarHingeModel.from_pattern(
        panel(SHAPES["skew quad"]), "N5B8", MAT, bar_calibration="cst"
    )
    X = np.asarray(model.X0) * [1.01, 0.98, 1.0]
    Wb = model.evaluate(X).energy_bars
    assert model.stiffened(7.0).evaluate(X).energy_bars == pytest.approx(7.0 * Wb, rel=1e-12)
    ratio = BarHingeModel.from_pattern(
        panel(SHAPES["skew quad"]), "N5B8", MAT, bar_calibration="cst", stiffness_ratio=7.0
    )
    assert ratio.evaluate(X).energy_bars == pytest.approx(7.0 * Wb, rel=1e-12)


def test_bad_input_is_named():
    with pytest.raises(ConfigError, match="no bar areas"):
        BarHingeModel.from_pattern(panel(SHAPES["square"]), bar_calibration="cst", bar_EA=1.0)
    with pytest.raises(ConfigError, match="bar_calibration"):
        BarHingeModel.from_pattern(panel(SHAPES["square"]), bar_calibration="triangles")
    with pytest.raises(ConfigError, match="degenerate"):
        triangle_side_matrices(np.array([[[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]]), MAT)
    with pytest.raises(ConfigError, match="not a bar"):
        cst_bar_matrix(np.eye(3), np.array([[0, 1, 2]]), np.array([[0, 1], [1, 2]]), MAT)


def test_with_checks_the_bar_couplings():
    model = BarHingeModel.from_pattern(panel(SHAPES["square"]), bar_calibration="cst")
    with pytest.raises(ConfigError, match="bar_pairs refers to bars the model does not have"):
        model.with_(bar_pairs=[[0, model.n_bars]], bar_pair_c=[1.0])
    with pytest.raises(ConfigError, match=r"bar_pairs must have shape \(n, 2\)"):
        model.with_(bar_pairs=[[0, 1]], bar_pair_c=[1.0, 2.0])
    plain = model.with_(bar_pairs=np.zeros((0, 2), int), bar_pair_c=[])
    X = np.asarray(model.X0) * [1.02, 0.99, 1.0]
    eps = 0.5 * (np.sum((X[plain.bars[:, 1]] - X[plain.bars[:, 0]]) ** 2, 1) / plain.bar_L0**2 - 1)
    bars_alone = 0.5 * np.sum(plain.bar_EA * plain.bar_L0 * eps**2)
    assert plain.evaluate(X).energy_bars == pytest.approx(bars_alone, rel=1e-12)
