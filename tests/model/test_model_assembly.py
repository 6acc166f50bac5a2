"""Assembled energy, internal force and tangent of BarHingeModel: element-by-element oracle,
finite differences of the assembled energy, rigid-body invariance, zero-eigenvalue counts."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import barhinge as bh
from barhinge.kernels.reference import assemble_reference
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern

MAT = Material(E=1.0, nu=0.3, t=0.05)


def single_fold(fold_deg: float = 0.0) -> CreasePattern:
    """Two triangles sharing the valley crease 0 -> 1 (the y axis); the right wing (vertex 2)
    folded up by ``fold_deg`` (valley > 0)."""
    V = np.array([[0, 0, 0], [0, 1, 0], [1, 0.5, 0], [-1, 0.5, 0]], float)
    R = Rotation.from_rotvec([0.0, -np.radians(fold_deg), 0.0])
    V[2] = R.apply(V[2])
    return CreasePattern(
        V, [[0, 1], [0, 2], [2, 1], [1, 3], [3, 0]], ["V", "B", "B", "B", "B"],
        faces=[[0, 2, 1], [0, 1, 3]],
    )  # fmt: skip


def models():
    out = [BarHingeModel.from_pattern(single_fold(40.0), "N4B5", MAT)]
    cp = bh.families.miura(2, 1, fold=35.0)
    for s in ("N4B5", "N5B8"):
        out.append(BarHingeModel.from_pattern(cp, s, MAT))
    out.append(
        BarHingeModel.from_pattern(
            cp, "N5B8", MAT, fold_law="penetration", fold_limits_deg=(-60, 60), strain="engineering"
        )
    )
    return out


MODELS = models()


def perturbed(m: BarHingeModel, seed: int, amp: float = 0.05) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return m.X0 + amp * rng.normal(size=m.X0.shape)


@pytest.mark.parametrize("mi", range(len(MODELS)))
def test_assembly_equals_element_by_element_oracle(mi: int) -> None:
    m = MODELS[mi]
    X = perturbed(m, mi)
    ev = m.evaluate(X)
    E, f, K = assemble_reference(m, X)
    assert ev.energy == pytest.approx(E, rel=1e-12)
    assert np.abs(ev.force - f).max() <= 1e-12 * np.abs(f).max()
    Kd = ev.K.toarray()
    assert np.abs(Kd - K).max() <= 1e-12 * np.abs(K).max()
    assert np.array_equal(Kd, Kd.T)
    assert m.energy(X) == pytest.approx(ev.energy, rel=1e-13)
    # the force-only path uses the element-major gradient kernel: same to rounding
    assert np.abs(m.internal_force(X) - ev.force).max() <= 1e-13 * np.abs(ev.force).max()


@pytest.mark.parametrize("mi", range(len(MODELS) + 1))
def test_an_evaluation_in_chunks_of_three_elements_is_the_one_in_a_single_chunk(
    mi: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The evaluation writes its element values chunk by chunk (``ASSEMBLY_CHUNK``); with
    chunks of three elements the hinge laws that read their hinges' slice (per-hinge
    penetration limits) and the hinge couplings (the last case) still get their own hinges:
    the same energy, force and tangent as the oracle and as one chunk per group."""
    import barhinge.assembly as assembly

    def build() -> BarHingeModel:
        return models()[mi] if mi < len(MODELS) else _coupled_miura()

    whole = build()
    X = perturbed(whole, 20 + mi)
    ref = whole.evaluate(X)
    monkeypatch.setattr(assembly, "ASSEMBLY_CHUNK", 3)
    m = build()
    assert max(len(group) for group in m.assembler._chunks) > 1
    ev = m.evaluate(X)
    assert ev.energy == pytest.approx(ref.energy, rel=1e-13)
    assert np.abs(ev.force - ref.force).max() <= 1e-13 * np.abs(ref.force).max()
    assert np.abs(ev.K.toarray() - ref.K.toarray()).max() <= 1e-13 * abs(ref.K).max()
    if mi < len(MODELS):
        E, f, K = assemble_reference(m, X)
        assert ev.energy == pytest.approx(E, rel=1e-12)
        assert np.abs(ev.force - f).max() <= 1e-12 * np.abs(f).max()
        assert np.abs(ev.K.toarray() - K).max() <= 1e-12 * np.abs(K).max()
    else:
        assert len(m.hinge_pairs) > 10


@pytest.mark.parametrize("mi", range(len(MODELS) + 1))
def test_an_evaluation_on_worker_threads_is_the_one_on_a_single_thread(
    mi: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The kernels' passes (two hinges each here) and the nine components of the block sums
    run side by side on the worker threads, the hinge laws called from them: energy, force
    and tangent are those of one thread to the last bit, and the oracle's."""
    import barhinge.assembly as assembly
    import barhinge.kernels.geometry as geometry
    from barhinge.linalg import threads

    m = MODELS[mi] if mi < len(MODELS) else _coupled_miura()
    X = perturbed(m, 40 + mi)
    monkeypatch.setattr(geometry, "HESSIAN_CHUNK", 2)
    monkeypatch.setattr(geometry, "GRADIENT_CHUNK", 2)
    monkeypatch.setattr(assembly, "PARALLEL_INSTANCES", 1)
    names: set[str] = set()
    kernel = geometry._hinge_hessian_packed_t

    def spy(*args, **kwargs):
        names.add(threading.current_thread().name)
        return kernel(*args, **kwargs)

    monkeypatch.setattr(geometry, "_hinge_hessian_packed_t", spy)
    runs = []
    for count in ("1", "3"):
        monkeypatch.setenv(threads.ENV, count)
        runs.append((m.evaluate(X), m.evaluate(X, tangent=False)))
    (one, one_f), (three, three_f) = runs
    if m.n_hinges > 2:  # more than one pass
        assert any(name.startswith("barhinge-worker") for name in names)
    assert three.energy == one.energy
    assert np.array_equal(three.force, one.force)
    assert np.array_equal(three_f.force, one_f.force)
    assert np.array_equal(three.K.data, one.K.data)
    if mi < len(MODELS):
        E, f, K = assemble_reference(m, X)
        assert three.energy == pytest.approx(E, rel=1e-12)
        assert np.abs(three.force - f).max() <= 1e-12 * np.abs(f).max()
        assert np.abs(three.K.toarray() - K).max() <= 1e-12 * np.abs(K).max()


def _coupled_miura() -> BarHingeModel:
    """A 2 x 2 Miura whose neighbouring hinges are coupled (the couplings' tangent reads the
    hinge gradients the kernels' passes write)."""
    m = BarHingeModel.from_pattern(bh.families.miura(2, 2, fold=30.0), "N5B8", MAT)
    h = [set(x) for x in np.asarray(m.hinges)]
    near = [(i, j) for i in range(len(h)) for j in range(i + 1, len(h)) if h[i] & h[j]]
    pairs = np.array(near[:: max(1, len(near) // 30)])
    k = np.random.default_rng(2).uniform(-0.5, 0.5, len(pairs))
    return m.with_(hinge_pairs=pairs, pair_k=k)


def test_a_miura_sheet_evaluated_on_worker_threads_is_the_one_on_a_single_thread(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """At the default pass sizes (a 20 x 20 sheet has two passes of the Hessian kernel and
    sums its hinges' components side by side): the same tangent and force to the last bit."""
    from barhinge.linalg import threads

    m = BarHingeModel.from_pattern(bh.families.miura(20, 20, fold=30.0), "N5B8", MAT)
    X = perturbed(m, 3, amp=1e-3)
    runs = []
    for count in ("1", "2"):
        monkeypatch.setenv(threads.ENV, count)
        runs.append(m.evaluate(X))
    assert np.array_equal(runs[0].K.data, runs[1].K.data)
    assert np.array_equal(runs[0].force, runs[1].force)


@pytest.mark.parametrize("mi", range(len(MODELS)))
def test_assembled_force_and_tangent_match_fd_of_energy(mi: int) -> None:
    """Central differences of the assembled energy / force along random directions; relative
    error <= 1e-6 (step 1e-6 gives truncation ~1e-12 and round-off ~1e-10)."""
    m = MODELS[mi]
    X = perturbed(m, 10 + mi)
    ev = m.evaluate(X)
    rng = np.random.default_rng(mi)
    h = 1e-6
    for _ in range(3):
        v = rng.normal(size=m.n_dof)
        v /= np.linalg.norm(v)
        dE = (m.energy(X.ravel() + h * v) - m.energy(X.ravel() - h * v)) / (2 * h)
        assert dE == pytest.approx(ev.force @ v, rel=1e-6, abs=1e-9 * np.abs(ev.force).max())
        df = (m.internal_force(X.ravel() + h * v) - m.internal_force(X.ravel() - h * v)) / (2 * h)
        Kv = ev.K @ v
        assert np.abs(df - Kv).max() <= 1e-6 * np.abs(Kv).max()


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), mi=st.integers(0, len(MODELS) - 1))
def test_rigid_body_motion_leaves_energy_and_rotates_force(seed: int, mi: int) -> None:
    m = MODELS[mi]
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=seed % 2**31)
    c = rng.normal(size=3) * 3
    # unstressed: the reference state moved rigidly has zero energy and zero force
    ev0 = m.evaluate(R.apply(np.array(m.X0)) + c, tangent=False)
    assert abs(ev0.energy) <= 1e-20
    assert np.abs(ev0.force).max() <= 1e-11 * max(m.bar_EA.max(), m.hinge_k.max())
    # stressed: energy invariant, force rotates with the body
    X = perturbed(m, seed % 1000)
    ev = m.evaluate(X, tangent=False)
    evr = m.evaluate(R.apply(X) + c, tangent=False)
    assert evr.energy == pytest.approx(ev.energy, rel=1e-10)
    fr = R.apply(ev.force.reshape(-1, 3)).ravel()
    assert np.abs(evr.force - fr).max() <= 1e-9 * np.abs(fr).max()


def n_zero_eigenvalues(m: BarHingeModel, X: np.ndarray | None = None) -> tuple[int, float]:
    """Number of eigenvalues below 1e-10 * the largest, and the gap ratio to the next one."""
    w = np.linalg.eigvalsh(m.tangent(m.X0 if X is None else X).toarray())
    tol = 1e-10 * w.max()
    nz = int((np.abs(w) < tol).sum())
    return nz, w[nz] / w.max()


def test_zero_eigenvalues_single_fold() -> None:
    """Two triangles and one crease: 12 dof, 5 bars. With fold stiffness 0 the free tangent
    has 6 rigid-body modes + 1 folding mechanism = 7 zero eigenvalues; with fold stiffness > 0
    exactly 6. Checked flat and folded."""
    for fold in (0.0, 50.0):
        m0 = BarHingeModel.from_pattern(single_fold(fold), "N4B5", MAT, fold_stiffness=0.0)
        nz, gap = n_zero_eigenvalues(m0)
        assert nz == 7 and gap > 1e-7
        m1 = BarHingeModel.from_pattern(single_fold(fold), "N4B5", MAT)
        nz, gap = n_zero_eigenvalues(m1)
        assert nz == 6 and gap > 1e-7


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_zero_eigenvalues_degree4_vertex(scheme: str) -> None:
    """Degree-4 vertex with four parallelogram panels (a 1x1-cell Miura), panels triangulated
    with stiff bending hinges.

    * folded (theta = 30 deg), fold stiffness 0: a degree-n vertex has n - 3 = 1 rigid-folding
      DOF, so 6 + 1 = 7 zero eigenvalues;
    * flat, fold stiffness 0: 8 -- at the flat state the linearised loop-closure constraints
      lose rank and the vertex has two first-order flexes (the tangents of its two folding
      branches, Tachi 2009 / Demaine & O'Rourke), so 6 + 2;
    * any state with fold stiffness > 0: exactly the 6 rigid-body modes.
    """
    for fold, expect in ((30.0, 7), (None, 8)):
        cp = bh.families.miura(1, 1, fold=fold)
        nz, gap = n_zero_eigenvalues(
            BarHingeModel.from_pattern(cp, scheme, MAT, fold_stiffness=0.0)
        )
        assert nz == expect and gap > 1e-7
        nz, gap = n_zero_eigenvalues(BarHingeModel.from_pattern(cp, scheme, MAT))
        assert nz == 6 and gap > 1e-7


def test_evaluate_split_and_moments() -> None:
    m = MODELS[2]
    X = perturbed(m, 7)
    ev = m.evaluate(X)
    fold = m.hinge_kind == "fold"
    d = ev.hinge_angle - m.rest_angle
    assert ev.energy_fold == pytest.approx(0.5 * np.sum(m.hinge_k[fold] * d[fold] ** 2))
    assert ev.energy_bend == pytest.approx(0.5 * np.sum(m.hinge_k[~fold] * d[~fold] ** 2))
    eps = ev.bar_strain
    assert ev.energy_bars == pytest.approx(0.5 * np.sum(m.bar_EA * m.bar_L0 * eps**2))
    assert np.allclose(ev.hinge_moment, m.hinge_k * d)
    assert np.allclose(m.hinge_angles(X), ev.hinge_angle)
    Wb, Wh = m.element_energies(X)
    assert Wb.sum() == pytest.approx(ev.energy_bars) and Wh[~fold].sum() == pytest.approx(
        ev.energy_bend
    )
    # flattened coordinates are accepted
    assert m.energy(X.ravel()) == pytest.approx(ev.energy)


@pytest.mark.parametrize("mi", range(len(MODELS)))
def test_element_states_are_the_derivatives_of_the_element_energies(mi: int) -> None:
    """Each bar's axial force is ``dW_b/dL`` (central difference of its energy as one end
    moves along the bar), each hinge's moment is the evaluation's ``dW/drho`` and the
    energies are :meth:`element_energies`; penetration law and engineering strain
    included."""
    m = MODELS[mi]
    X = perturbed(m, 3)
    el = m.element_states(X)
    Wb, Wh = m.element_energies(X)
    # the same strains by two kernels: equal to round-off of the largest energy
    np.testing.assert_allclose(el.bar_energy, Wb, rtol=0, atol=1e-13 * Wb.max())
    np.testing.assert_allclose(el.hinge_energy, Wh, rtol=0, atol=1e-13 * Wh.max())
    ev = m.evaluate(X, tangent=False)
    np.testing.assert_allclose(el.hinge_angle, ev.hinge_angle, rtol=0, atol=1e-13)
    np.testing.assert_allclose(el.hinge_moment, ev.hinge_moment, rtol=1e-12, atol=1e-15)
    h = 1e-6
    for b, (i, j) in enumerate(m.bars):
        e = (X[j] - X[i]) / np.linalg.norm(X[j] - X[i])
        Xp, Xm = X.copy(), X.copy()
        Xp[j] += h * e
        Xm[j] -= h * e
        dW = (m.element_energies(Xp)[0][b] - m.element_energies(Xm)[0][b]) / (2 * h)
        assert el.bar_axial_force[b] == pytest.approx(dW, rel=1e-6, abs=1e-10)


def test_assembly_scatter_pattern_is_reused() -> None:
    m = MODELS[1]
    K1 = m.tangent(perturbed(m, 1))
    K2 = m.tangent(perturbed(m, 2))
    assert np.shares_memory(K1.indices, K2.indices) and np.shares_memory(K1.indptr, K2.indptr)
    assert K1.data is not K2.data


def test_with_and_stiffened_share_the_scatter_maps_and_scale_the_tangent() -> None:
    m = MODELS[1]
    X = perturbed(m, 3)
    K = m.tangent(X)
    m2 = m.with_(hinge_k=2.0 * m.hinge_k, bar_EA=2.0 * m.bar_EA)
    assert m2.assembler is m.assembler
    assert np.allclose(m2.tangent(X).toarray(), 2.0 * K.toarray(), rtol=1e-13, atol=0)
    with pytest.raises(bh.ConfigError):
        m.with_(hinge_k=np.ones(3))


def test_model_pickles_and_evaluates_the_same() -> None:
    import pickle

    m = MODELS[2]
    X = perturbed(m, 5)
    ev = m.evaluate(X)
    m2 = pickle.loads(pickle.dumps(m))
    ev2 = m2.evaluate(X)
    assert ev2.energy == ev.energy and np.array_equal(ev2.K.toarray(), ev.K.toarray())


def test_pattern_groups_hold_entries_that_add_entries_fills_symmetrically() -> None:
    """Elements given as ``pattern_groups`` put their node-pair blocks in the pattern (zero
    until filled); ``add_entries`` adds a symmetric matrix there exactly as a dense sum
    would, keeps the result bitwise symmetric, and names entries outside the pattern."""
    import scipy.sparse as sp

    from barhinge.assembly import Assembler

    bars = np.array([[0, 1], [1, 2], [2, 3]])
    extra = np.array([[0, 3]])
    asm = Assembler(4, [bars], pattern_groups=[extra])
    rng = np.random.default_rng(0)
    Kb = rng.normal(size=(3, 6, 6))
    K = asm.matrix([Kb + Kb.transpose(0, 2, 1)])
    dense = K.toarray()
    assert asm.pattern().toarray()[0:3, 9:12].all()  # the extra block is in the pattern
    assert not dense[0:3, 9:12].any()  # and holds zeros
    M = np.zeros((12, 12))
    B = rng.normal(size=(3, 3))
    M[0:3, 9:12], M[9:12, 0:3] = B, B.T
    M[4, 4] = 2.5
    asm.add_entries(K, sp.csr_matrix(M))
    np.testing.assert_allclose(K.toarray(), dense + M, rtol=0, atol=1e-15)
    assert np.array_equal(K.toarray(), K.toarray().T)
    outside = np.zeros((12, 12))
    outside[0, 7] = outside[7, 0] = 1.0  # nodes 0 and 2 share no element
    with pytest.raises(ValueError, match="outside"):
        asm.add_entries(K, sp.csr_matrix(outside))


def test_add_entries_reuses_the_positions_of_a_structure_it_has_seen() -> None:
    """A matrix of the last call's structure is added through the kept positions, bitwise as
    the first (searched) add; a matrix of another structure, or one storing a position twice,
    is added by searching again, and still exactly."""
    import scipy.sparse as sp

    from barhinge.assembly import Assembler

    rng = np.random.default_rng(3)
    bars = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    asm = Assembler(4, [bars])
    Kb = rng.normal(size=(4, 6, 6))
    base = asm.matrix([Kb + Kb.transpose(0, 2, 1)])

    def sym(mask: np.ndarray) -> sp.csr_matrix:
        A = rng.normal(size=(12, 12)) * mask
        return sp.csr_matrix(A + A.T)

    mask = asm.pattern().toarray() * (rng.random((12, 12)) < 0.5)
    other = mask * (rng.random((12, 12)) < 0.7)
    for M in (sym(mask), sym(mask), sym(other), sym(mask), sym(mask).tocsc(), sym(mask).tocsc()):
        K = base.copy()
        asm.add_entries(K, M)
        expected = base.toarray() + np.triu(M.toarray()) + np.triu(M.toarray(), 1).T
        np.testing.assert_array_equal(K.toarray(), expected)
        assert np.array_equal(K.toarray(), K.toarray().T)
    # a CSR storing the entry (1, 1) twice: both parts are added
    dup = sp.csr_matrix(
        (np.array([1.0, 2.0]), np.array([1, 1]), np.array([0, 0, 2] + [2] * 10)), shape=(12, 12)
    )
    for _ in range(2):
        K = base.copy()
        asm.add_entries(K, dup)
        assert K[1, 1] == base[1, 1] + 3.0


def test_hinge_couplings_keep_the_scatter_maps_small() -> None:
    """Couplings of a refined panel's hinges (the coupled plate rule: several per hinge) add
    their entries to the pattern, not element matrices to the scatter maps: the maps hold no
    more than with the hinges uncoupled plus the pattern's own growth (an index and a gather
    entry per new entry, and the upper blocks' pointers: 10 bytes; a per-pair element over
    the 5 to 8 nodes of two hinges would add 120 to 231 packed values, 12 bytes each)."""
    from barhinge.model.plate_hinges import coupled_bending
    from barhinge.pattern.subdivide import subdivided

    cpm, _ = subdivided(bh.families.miura(1, 1, fold=30.0), 4)
    plain = BarHingeModel.from_pattern(cpm, "N5B8", MAT)
    coupled = coupled_bending(plain)
    assert len(coupled.hinge_pairs) > 2 * coupled.n_hinges
    a, b = plain.assembler, coupled.assembler
    assert b.nbytes <= a.nbytes + 12 * (b.nnz - a.nnz)


def _scattered_and_strip(
    n_nodes: int, n_el: int, rng: np.random.Generator
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Two sets of element groups (bars of 2 nodes, hinges of 4) on ``n_nodes`` nodes:
    ``n_el`` elements each on random nodes (their blocks of both orientations, addressed by
    index), and elements along a strip (blocks in a range)."""
    scattered = [
        rng.permuted(np.tile(np.arange(n_nodes), (n_el, 1)), axis=1)[:, :k] for k in (2, 4)
    ]
    strip = [np.arange(k)[None, :] + np.arange(n_nodes - 4)[:, None] for k in (2, 4)]
    return scattered, strip


def _random_element_matrices(
    groups: list[np.ndarray], n_nodes: int, rng: np.random.Generator
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Random symmetric element matrices on the groups' elements: their dense sum (written
    entry by entry) and their packed upper triangles, one ``(m (m + 1) / 2, n_el)`` array
    per group."""
    from barhinge.assembly import element_dofs

    dense = np.zeros((3 * n_nodes, 3 * n_nodes))
    packed = []
    for conn in groups:
        m = 3 * conn.shape[1]
        A = rng.normal(size=(len(conn), m, m))
        Ke = A + A.transpose(0, 2, 1)
        for dofs, k in zip(element_dofs(conn), Ke, strict=True):
            dense[np.ix_(dofs, dofs)] += k
        iu, ju = np.triu_indices(m)
        packed.append(Ke[:, iu, ju].T)
    return dense, packed


def test_block_layout_rows_and_packed_lists_assemble_the_same_dense_sum() -> None:
    """The assembler's block layout against a dense sum written here: random symmetric element
    matrices on elements whose node order is both ascending and descending (the swapped
    node pairs add their blocks transposed), given as packed lists and written row by row
    through ``value_buffers``; the maps hold one entry per node pair of an element."""
    from barhinge.assembly import Assembler

    rng = np.random.default_rng(7)
    n_nodes = 9
    groups = [rng.permuted(np.tile(np.arange(n_nodes), (6, 1)), axis=1)[:, :k] for k in (2, 4)]
    asm = Assembler(n_nodes, groups)
    dense, packed = _random_element_matrices(groups, n_nodes, rng)
    K_list = asm.matrix_packed(packed).toarray()
    flat, views = asm.value_buffers()
    for view, P in zip(views, packed, strict=True):
        for p in range(len(P)):
            view[p][...] = P[p]
    K_rows = asm.matrix_packed(flat).toarray()
    assert np.abs(K_list - dense).max() <= 1e-13 * np.abs(dense).max()
    assert np.array_equal(K_rows, K_list) and np.array_equal(K_list, K_list.T)
    pairs = sum(len(c) * c.shape[1] * (c.shape[1] + 1) // 2 for c in groups)
    chunks = [c for group in asm._chunks for c in group]
    assert sum(c.direct.nnz + c.swapped.nnz for c in chunks) == pairs
    # the summations' values are views of one array of ones (what ``nbytes`` counts once)
    matrices = [S for c in chunks for S in (c.direct, c.swapped) if S.nnz]
    assert all(np.shares_memory(S.data, asm._ones) for S in matrices)
    with pytest.raises(ValueError, match="flat value array"):
        asm.matrix_packed(np.zeros(5))


@pytest.mark.parametrize("chunk", [1, 4, 7, 65536])
def test_element_values_written_chunk_by_chunk_sum_to_the_dense_sum(
    chunk: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``block_sums_filled`` (an evaluation's path: one chunk of elements' values at a time)
    and ``block_sums`` of the whole value array give the dense sum written here, with chunks
    of one element, chunks whose last is shorter, and one chunk per group; the elements'
    nodes at random (their blocks addressed by index) and numbered along a strip (a range)."""
    import barhinge.assembly as assembly
    from barhinge.assembly import Assembler

    monkeypatch.setattr(assembly, "ASSEMBLY_CHUNK", chunk)
    rng = np.random.default_rng(5)
    n_nodes = 40
    scattered, strip = _scattered_and_strip(n_nodes, 30, rng)
    for groups in (scattered, strip):
        asm = Assembler(n_nodes, groups)
        kinds = {isinstance(c.out, slice) for group in asm._chunks for c in group}
        dense, packed = _random_element_matrices(groups, n_nodes, rng)
        calls = []

        def fill(g: int, sl: slice, rows, calls=calls, packed=packed) -> None:
            calls.append((g, sl.start, sl.stop))
            for p in range(len(packed[g])):
                rows[p][...] = packed[g][p, sl]

        K_filled = asm.matrix_from_sums(asm.block_sums_filled(fill)).toarray()
        assert calls == [
            (g, s0, min(s0 + chunk, len(c))) for g, c in enumerate(groups)
            for s0 in range(0, len(c), chunk)
        ]  # fmt: skip
        K_whole = asm.matrix_packed(packed).toarray()
        for K in (K_filled, K_whole):
            assert np.abs(K - dense).max() <= 1e-13 * np.abs(dense).max()
            assert np.array_equal(K, K.T)
        if groups is strip:
            assert kinds == {True}  # numbered along the strip: every chunk a range
        elif chunk <= 4:
            assert False in kinds  # scattered: some chunk addressed by index


def test_value_buffer_above_the_kept_size_is_new_at_every_evaluation(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A value buffer larger than ``KEEP_SCRATCH_BYTES`` is not kept between evaluations (so
    it is not held beside the factorisation) and gives the same tangent, twice in a row, as
    the kept one."""
    import barhinge.assembly as assembly

    cp = bh.families.miura(3, 3, alpha=60.0, fold=40.0)
    tangents = []
    for keep in (10**9, 0):
        monkeypatch.setattr(assembly, "KEEP_SCRATCH_BYTES", keep)
        model = bh.BarHingeModel.from_pattern(cp, "N5B8")
        X = model.X0 + 1e-3 * np.random.default_rng(3).standard_normal(model.X0.shape)
        first = model.evaluate(X).K
        flat_a, _ = model.assembler.value_buffers()
        flat_b, _ = model.assembler.value_buffers()
        assert (flat_a is flat_b) == (keep > 0)
        assert (getattr(model.assembler, "_flat", None) is None) == (keep == 0)
        tangents += [first, model.evaluate(X).K]
    ref = tangents[0].toarray()
    assert np.abs(ref).max() > 0
    for K in tangents[1:]:
        assert np.array_equal(K.toarray(), ref)


@pytest.mark.parametrize("fill_chunk", [1, 90, 1 << 20])
def test_the_matrix_filled_from_block_sums_in_parts_is_the_dense_sum(
    fill_chunk: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``matrix_from_sums`` gathers the matrix's values into the buffer its sums lie at the
    start of, whole node rows at a time, from the last rows to the first (``SUMS_FILL_CHUNK``
    entries: one row at a time, a few rows, everything): the dense sum of the element
    matrices, symmetric, with random nodes (blocks of both orientations) and along a strip;
    sums not made by the assembler (a copy here) give the same matrix and are left as they
    were."""
    import barhinge.assembly as assembly
    from barhinge.assembly import Assembler

    monkeypatch.setattr(assembly, "SUMS_FILL_CHUNK", fill_chunk)
    rng = np.random.default_rng(11)
    n_nodes = 30
    for groups in _scattered_and_strip(n_nodes, 25, rng):
        asm = Assembler(n_nodes, groups)
        dense, packed = _random_element_matrices(groups, n_nodes, rng)
        flat = np.zeros(9 * asm.n_instances)
        for view, arr in zip(asm._group_views(flat), packed, strict=True):
            view.buf[view.comp, view.pair] = arr
        sums = asm.block_sums(flat)
        own = np.array(sums)  # a plain (9, n_blocks) array: not the assembler's buffer
        K = asm.matrix_from_sums(sums)
        assert np.shares_memory(K.data, sums)  # filled in place of its sums
        np.testing.assert_allclose(K.toarray(), dense, rtol=0, atol=1e-12 * np.abs(dense).max())
        assert np.array_equal(K.toarray(), K.toarray().T)
        kept = own.copy()
        K2 = asm.matrix_from_sums(own)
        assert np.array_equal(K2.data, K.data) and np.array_equal(own, kept)
