"""Tangent, effective stiffness and soft modes, against beam theory and independent algorithms.

Material: nu = 1/3 throughout. A square-celled X-braced bar lattice (N5B8) has the in-plane
Poisson's ratio 1/3 built in (Hrennikoff 1941), so only with nu = 1/3 does the membrane match an
isotropic sheet; with nu = 0 its uniaxial modulus is 8/9 E (measured: 0.889 E).
"""

from __future__ import annotations

import numpy as np
import pytest

bh = pytest.importorskip("barhinge")
pytest.importorskip("barhinge.model.model")

from barhinge import CreasePattern  # noqa: E402
from barhinge.analysis.stiffness import (  # noqa: E402
    effective_stiffness,
    stiffness_modes,
    tangent_stiffness,
)
from barhinge.errors import ConfigError  # noqa: E402
from barhinge.scene import self_weight  # noqa: E402

NU = 1.0 / 3.0


def grid_sheet(nx: int, ny: int, to_xyz, valley_row: int | None = None) -> CreasePattern:
    """(nx x ny) quads on the unit square mapped by ``to_xyz(u, v) -> (n, 3)``; interior lines
    are flat creases F (row ``valley_row`` a valley V), the outline B."""
    ni, nj = nx + 1, ny + 1

    def vid(i, j):
        return j * ni + i

    s = np.array([(i / nx, j / ny) for j in range(nj) for i in range(ni)])
    faces = [
        (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1))
        for j in range(ny)
        for i in range(nx)
    ]
    E, A = [], []
    for j in range(nj):
        for i in range(ni):
            if i < nx:
                E.append((vid(i, j), vid(i + 1, j)))
                A.append("B" if j in (0, ny) else ("V" if j == valley_row else "F"))
            if j < ny:
                E.append((vid(i, j), vid(i, j + 1)))
                A.append("B" if i in (0, nx) else "F")
    return CreasePattern(to_xyz(s[:, 0], s[:, 1]), np.array(E), A, faces=faces)


def _plate_hinges(model, span: float, nx: int, width: float, ny: int, stiff: float = 1.0):
    """Fold hinges as a continuous plate's rotational stiffness D * length / spacing (transverse
    creases: spacing span/nx; longitudinal: width/ny), times ``stiff`` for longitudinal ones."""
    D = model.material.bending_rigidity
    X0 = model.X0
    axis = X0[model.hinges[:, 1]] - X0[model.hinges[:, 0]]
    length = np.linalg.norm(axis, axis=1)
    fold = model.hinge_kind == "fold"
    trans = fold & (np.abs(axis[:, 0]) < 1e-9 * span)
    longi = fold & ~trans
    k = np.array(model.hinge_k, float)
    k[trans] = D * length[trans] / (span / nx)
    k[longi] = stiff * D * length[longi] / (width / ny)
    return k


def _simply_supported(model, span: float, diaphragm: bool):
    """Ends x = 0 and x = span: z fixed (and y too with a rigid end diaphragm); x fixed at one
    end (one node with a diaphragm, all end nodes without); y fixed at one node."""
    V = model.X0[: model.pattern.n_vertices]
    left = np.flatnonzero(np.abs(V[:, 0]) < 1e-9)
    right = np.flatnonzero(np.abs(V[:, 0] - span) < 1e-9)
    fixed = np.zeros((model.n_nodes, 3), bool)
    fixed[left, 2] = fixed[right, 2] = True
    if diaphragm:
        fixed[left, 1] = fixed[right, 1] = True
        fixed[left[np.argmin(V[left, 2])], 0] = True
    else:
        fixed[left, 0] = True
        fixed[left[0], 1] = True
    mid = np.flatnonzero(np.abs(V[:, 0] - span / 2) < 1e-9)
    return fixed, mid


def test_plate_strip_of_rigid_panels_converges_to_euler_bernoulli():
    """Simply supported strip (span L, width b) under a uniform load q per area, panels made
    rigid so the transverse creases carry the bending with k = D b / h: mid-span deflection
    -> 5 q b L^4 / (384 D b) (Euler-Bernoulli with EI = D b, cylindrical bending; e.g. Timoshenko
    & Woinowsky-Krieger 1959, Sec. 1-2). The hinge chain is a central difference of w'' = -M/EI
    with exact nodal moments, so the error is O(h^2)."""
    L, b, q = 10.0, 1.0, 2.0
    mat = bh.Material(E=1e6, nu=NU, t=0.01)
    exact = 5 * q * b * L**4 / (384 * mat.bending_rigidity * b)
    ns, err = [4, 8, 16], []
    for nx in ns:
        cp = grid_sheet(nx, 1, lambda u, v: np.column_stack([u * L, v * b, 0 * u]))
        model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat)
        k = _plate_hinges(model, L, nx, b, 1)
        k[model.hinge_kind == "bend"] *= 1e4  # rigid panels
        model = model.with_(hinge_k=k)
        fixed, mid = _simply_supported(model, L, diaphragm=False)
        F = self_weight(model, q, g=(0.0, 0.0, -1.0))
        r = effective_stiffness(model, F, fixed, at=mid)
        assert r.direction == pytest.approx([0, 0, -1])
        # equilibrium to the round-off of a stiff system (panels 1e4 x stiffer than the hinges)
        np.testing.assert_allclose(r.reactions.sum(0), -F.sum(0), rtol=1e-7, atol=1e-7)
        assert r.stiffness == pytest.approx(q * b * L / r.deflection)
        err.append(abs(r.deflection / exact - 1))
    slope = np.polyfit(np.log(ns), np.log(err), 1)[0]
    assert slope == pytest.approx(-2.0, abs=0.1)
    assert err[-1] < 0.005


def test_v_folded_plate_approaches_the_folded_plate_beam_estimate():
    """Simply supported V-shaped folded plate (two plates of width w at 45 deg from the valley
    fold, span L = 20 w) with rigid end diaphragms under a uniform area load q: the beam method
    for folded plates (Winter & Pei 1947; Billington, Thin Shell Concrete Structures, 1982,
    Ch. 8) treats the cross-section as rigid: I = t w^3 sin^2(phi) / 6 about the centroid,
    delta = 5 (2 q w) L^4 / (384 E I); shear adds (4/10) w^2/L^2 (0.1 %). With the section kept
    rigid (longitudinal hinges 1000x the plate value) the model converges to it: within 3 % on
    the finest mesh, the error falling with refinement. The bar lattice is stiff in in-plane
    bending on coarse meshes (one panel across a plate: 0.45 of the beam deflection)."""
    L, w, phi, q, t = 20.0, 1.0, np.radians(45.0), 1.0, 0.01
    mat = bh.Material(E=1e6, nu=NU, t=t)
    I = t * w**3 * np.sin(phi) ** 2 / 6
    beam = 5 * q * 2 * w * L**4 / (384 * mat.E * I)
    ratios = []
    for nx, m in [(40, 2), (80, 4), (160, 8)]:

        def to_xyz(u, v):
            y = (v - 0.5) * 2 * w
            return np.column_stack([u * L, y * np.cos(phi), np.abs(y) * np.sin(phi)])

        cp = grid_sheet(nx, 2 * m, to_xyz, valley_row=m)
        model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat)
        k = _plate_hinges(model, L, nx, w, m, stiff=1e3)
        k[model.hinge_kind == "bend"] *= 1e3
        model = model.with_(hinge_k=k)
        fixed, mid = _simply_supported(model, L, diaphragm=True)
        r = effective_stiffness(model, self_weight(model, q, g=(0.0, 0.0, -1.0)), fixed, at=mid)
        ratios.append(r.deflection / beam)
    err = np.abs(np.array(ratios) - 1)
    assert np.all(np.diff(err) < 0)
    assert err[-1] < 0.03


def test_soft_modes_count_the_bar_frameworks_mechanisms():
    """Soft modes (no bar stretching) = dimension of the null space of the bar framework's
    rigidity matrix, computed independently by SVD."""
    cp = bh.families.miura(2, 2, fold=40.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e6, nu=NU, t=0.01))
    X = model.X0
    B = model.bars
    d = X[B[:, 1]] - X[B[:, 0]]
    C = np.zeros((len(B), model.n_dof))
    for e, (i, j) in enumerate(B):
        C[e, 3 * i : 3 * i + 3] = -d[e]
        C[e, 3 * j : 3 * j + 3] = d[e]
    sv = np.linalg.svd(C, compute_uv=False)
    n_null = model.n_dof - int((sv > 1e-9 * sv[0]).sum())
    modes = stiffness_modes(model, k=n_null + 3)
    assert modes.n_soft == n_null
    assert modes.eigenvalues[:6] == pytest.approx(np.zeros(6), abs=1e-8)  # rigid-body modes
    # the mode shapes are eigenvectors of the tangent
    K = tangent_stiffness(model, X)
    v = modes.shapes[7].ravel()
    np.testing.assert_allclose(K @ v, modes.eigenvalues[7] * v, atol=1e-8 * abs(K).max())


def test_shift_invert_agrees_with_dense_eigensolver():
    cp = bh.families.miura(6, 5, fold=50.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e6, nu=NU, t=0.01))
    from barhinge.scene import restraint_321

    fixed = restraint_321(model)
    modes = stiffness_modes(model, fixed=fixed, k=5)
    assert modes.n_free > 600  # the sparse path
    free = np.flatnonzero(~fixed.ravel())
    Kd = tangent_stiffness(model).toarray()[np.ix_(free, free)]
    lam = np.linalg.eigvalsh(0.5 * (Kd + Kd.T))
    ref = lam[:5]
    # the dense reference is backward stable: its eigenvalues are exact to O(eps |K|_2)
    # (Weyl), 1.3e-11 here, 7e-8 of the softest mode with the plate-calibrated panels
    eps_ref = np.finfo(float).eps * lam[-1]
    np.testing.assert_allclose(modes.eigenvalues, ref, rtol=1e-8, atol=eps_ref)


def test_shift_invert_of_a_free_sheet_finds_its_rigid_body_modes(monkeypatch):
    """Unsupported (the six rigid-body modes make the tangent singular; the shift keeps the
    factorised matrix regular): the sparse path, its shifted matrix factorised once by the
    solver's backend, agrees with the dense eigensolver (Weyl bound as above)."""
    import barhinge.analysis.stiffness as stiffness

    calls = []
    real = stiffness.factorize_symmetric
    monkeypatch.setattr(
        stiffness, "factorize_symmetric", lambda b, A: calls.append(b.name) or real(b, A)
    )
    cp = bh.families.miura(6, 5, fold=50.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e6, nu=NU, t=0.01))
    modes = stiffness_modes(model, k=8)
    assert modes.n_free > 600  # the sparse path
    assert len(calls) == 1
    lam = np.linalg.eigvalsh(tangent_stiffness(model).toarray())
    eps_ref = np.finfo(float).eps * lam[-1]
    np.testing.assert_allclose(modes.eigenvalues[:6], 0.0, atol=10 * eps_ref)
    np.testing.assert_allclose(modes.eigenvalues[6:], lam[6:8], rtol=1e-8, atol=eps_ref)
    assert modes.n_soft >= 6


def test_mechanism_is_reported():
    cp = bh.families.miura(1, 1, fold=40.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e6, nu=NU, t=0.01))
    model = model.with_(hinge_k=np.zeros(model.n_hinges))
    fixed = np.zeros((model.n_nodes, 3), bool)
    fixed[:3] = True
    F = np.zeros((model.n_nodes, 3))
    F[-1, 2] = -1.0
    with pytest.raises(ConfigError, match="mechanism"):
        effective_stiffness(model, F, fixed)


def test_a_linear_analysis_that_drops_the_assembler_returns_the_same_response(monkeypatch):
    """With the release threshold at zero, ``linear_response`` frees the model's assembler
    before it factorises: the displacements and reactions are those computed with it kept
    (bit for bit: the same tangent, the same factorisation), the next evaluation builds the
    assembler again and gives the same tangent."""
    import barhinge.analysis.stiffness as stiffness

    L, b, q = 10.0, 1.0, 2.0
    mat = bh.Material(E=1e6, nu=NU, t=0.01)
    cp = grid_sheet(6, 2, lambda u, v: np.column_stack([u * L, v * b, 0.3 * np.sin(np.pi * u)]))
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat)
    fixed, _ = _simply_supported(model, L, diaphragm=True)
    F = self_weight(model, q, g=(0.0, 0.0, -1.0))
    K0 = tangent_stiffness(model)
    U0, R0 = stiffness.linear_response(model, F, fixed)
    assert "assembler" in model.__dict__  # small: kept
    monkeypatch.setattr(stiffness, "RELEASE_ASSEMBLER_ABOVE", 0)
    U1, R1 = stiffness.linear_response(model, F, fixed)
    assert "assembler" not in model.__dict__
    np.testing.assert_array_equal(U1, U0)
    np.testing.assert_array_equal(R1, R0)
    assert abs(tangent_stiffness(model) - K0).max() == 0.0
    assert model.release_assembler() > 0 and model.release_assembler() == 0


def test_linear_buckling_that_drops_the_assembler_finds_the_same_factor(monkeypatch):
    """The buckling factor of a shallow arch is the same whether the assembler is kept or
    freed before each factorisation (and rebuilt for the geometric stiffness, with the factor
    released meanwhile as for a large model)."""
    import barhinge.analysis.buckling as buckling
    import barhinge.analysis.stiffness as stiffness
    from barhinge.analysis.buckling import linear_buckling

    L, b = 10.0, 1.0
    mat = bh.Material(E=1e6, nu=NU, t=0.01)
    cp = grid_sheet(8, 1, lambda u, v: np.column_stack([u * L, v * b, 1.0 * np.sin(np.pi * u)]))
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=mat)
    fixed, _ = _simply_supported(model, L, diaphragm=True)
    fixed[np.abs(model.X0[:, 0] - L) < 1e-9, 0] = True  # pinned ends: the arch thrusts
    F = self_weight(model, 1.0, g=(0.0, 0.0, -1.0))
    kept = linear_buckling(model, F, fixed, n_modes=2).factors
    monkeypatch.setattr(stiffness, "RELEASE_ASSEMBLER_ABOVE", 0)
    monkeypatch.setattr(buckling, "RELEASE_FACTOR_ABOVE", 0)
    freed = linear_buckling(model, F, fixed, n_modes=2).factors
    assert "assembler" not in model.__dict__
    np.testing.assert_allclose(freed, kept, rtol=1e-9)
