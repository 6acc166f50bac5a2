"""The bordered actuator system: Schur-complement, saddle-point (KKT) and GMRES-with-reused-
factorisation paths all solve the same exact bordered system (checked against a dense solve
of [K_t G^T; G 0] on a real Miura tangent)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.linalg.backends import available_backends, get_backend
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene
from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms
from barhinge.solver_options import SolverOptions

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_solver import miura_scene  # noqa: E402


def _miura_system(fold: float = 30.0, nudge: float = 0.0):
    cp = bh.families.miura(2, 2, alpha=60.0, fold=fold)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    edges = miura_line_creases(cp)
    scene = Scene(model, actuators=bh.Actuators(edges=edges, targets_deg=[fold] * len(edges)))
    X = model.X0 + 1e-3 * np.random.default_rng(0).standard_normal(model.X0.shape)
    X = X + nudge * np.random.default_rng(9).standard_normal(model.X0.shape)
    K = model.evaluate(X).K
    terms = actuator_terms(model, X, scene.actuator_hinges())
    free = ~scene.fixed.ravel()
    mu = 0.01 * np.arange(1, len(edges) + 1)
    return K, terms, free, mu


def _dense_bordered(K, terms, free, mu):
    Kt = K.toarray()
    for a, dofs in enumerate(terms.dofs):
        Kt[np.ix_(dofs, dofs)] += mu[a] * terms.hess[a]
    f = np.flatnonzero(free)
    G = terms.G.toarray()[:, f]
    na = len(mu)
    return np.block([[Kt[np.ix_(f, f)], G.T], [G, np.zeros((na, na))]])


@pytest.mark.parametrize("name", available_backends())
def test_direct_paths_solve_the_exact_bordered_system(name):
    K, terms, free, mu = _miura_system()
    sysm = BorderedSystem(get_backend(name), free, terms.dofs, Timer())
    sysm.factorize(K, terms, mu, penalty=50.0)
    nf, na = int(free.sum()), len(mu)
    rng = np.random.default_rng(1)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    dx, dmu = sysm.solve(rx, rc)
    ref = np.linalg.solve(_dense_bordered(K, terms, free, mu), np.concatenate([rx, rc]))
    scale = np.abs(ref).max()
    np.testing.assert_allclose(np.concatenate([dx, dmu]), ref, rtol=0, atol=1e-8 * scale)


def test_reused_factorisation_with_gmres_solves_the_new_operator():
    """The operator changes (another state's tangent, other multipliers); the old
    factorisation preconditions GMRES, which must reach the requested tolerance on the
    *new* exact system — and a fresh factorisation is made when it cannot."""
    K, terms, free, mu = _miura_system()
    K2, terms2, _, _ = _miura_system(nudge=1e-5)  # a nearby state (the next iterate)
    sysm = BorderedSystem(get_backend("superlu"), free, terms.dofs, Timer(), reuse=True)
    sysm.set_operator(K, terms, mu, penalty=50.0)  # first: factorised
    assert sysm.current_factored
    sysm.set_operator(K2, terms2, 1.01 * mu, penalty=50.0)
    assert not sysm.current_factored  # reused
    nf, na = int(free.sum()), len(mu)
    rng = np.random.default_rng(2)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    dx, dmu = sysm.solve(rx, rc, rtol=1e-10)
    assert sysm.last_krylov_iters > 0 and not sysm.current_factored
    M = _dense_bordered(K2, terms2, free, 1.01 * mu)
    z = np.concatenate([dx, dmu])
    b = np.concatenate([rx, rc])
    s = sysm.row_scale
    # GMRES's test is on the scaled residual (constraint rows times s)
    r = M @ z - b
    r[nf:] *= s
    bs = b.copy()
    bs[nf:] *= s
    assert np.linalg.norm(r) <= 1e-9 * np.linalg.norm(bs)
    # no iterations allowed: the solve falls back to a factorisation of the new operator
    sysm.set_operator(K, terms, mu, penalty=50.0)
    sysm.krylov_max = 0
    dx0, dmu0 = sysm.solve(rx, rc, rtol=1e-12)
    assert sysm.current_factored
    ref = np.linalg.solve(_dense_bordered(K, terms, free, mu), b)
    np.testing.assert_allclose(np.concatenate([dx0, dmu0]), ref, atol=1e-8 * np.abs(ref).max())


def test_solver_with_reused_factorisations_reaches_the_same_states():
    """Inexact Newton (GMRES preconditioned by an old factorisation) converges to the same
    equilibrium path as exact Newton, with fewer factorisations. Two states that both meet
    the force tolerance differ by at most ``(|r_a| + |r_b|) / lambda_min`` where
    ``lambda_min`` is the smallest |eigenvalue| of the constrained tangent ``Z^T K_t Z``
    (Z spans the null space of the actuator rows): checked at every step, with that
    bound computed independently from a dense eigen-decomposition."""
    cp = bh.families.miura(3, 3, alpha=60.0, fold=20.0)
    cp1 = bh.families.miura(3, 3, alpha=60.0, fold=40.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e4)
    edges = miura_line_creases(cp)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    opts = {"tol_force": 1e-10, "tol_disp": 1e-10}
    scene = Scene(model, actuators=acts, steps=8, options=opts)
    a = bh.solve(scene)
    b = bh.solve(scene.with_(options={**opts, "reuse_factorization": True}))
    assert b.meta["timing"]["n_factorizations"] < a.meta["timing"]["n_factorizations"]
    assert b.meta["timing"]["n_krylov"] > 0
    free = ~scene.fixed.ravel()
    hinges = scene.actuator_hinges()
    for k in range(1, 9):
        X = a.X[k]
        terms = actuator_terms(model, X, hinges)
        M = _dense_bordered(model.evaluate(X).K, terms, free, -a.actuator_moments[k])
        nf = int(free.sum())
        G = M[nf:, :nf]
        Z = np.linalg.svd(G)[2][len(G) :].T  # null space of the actuator rows
        lam_min = np.abs(np.linalg.eigvalsh(Z.T @ M[:nf, :nf] @ Z)).min()
        assert lam_min > 0  # a regular constrained equilibrium: the bound applies
        bound = (a.residual_norms[k][-1] + b.residual_norms[k][-1]) / lam_min
        diff = np.linalg.norm((a.X[k] - b.X[k]).ravel()[free])
        assert diff <= 2 * bound + 1e-12, (k, diff, bound)
    np.testing.assert_allclose(b.energy, a.energy, rtol=1e-9, atol=1e-14)


def test_reuse_option_validation():
    with pytest.raises(bh.ConfigError, match="reuse_factorization"):
        SolverOptions(reuse_factorization="auto")
    with pytest.raises(bh.ConfigError, match="krylov_max"):
        SolverOptions(krylov_max=0)


def test_kkt_matrix_keeps_its_pattern_and_zero_diagonal():
    K, terms, free, mu = _miura_system()
    sysm = BorderedSystem(get_backend("superlu"), free, terms.dofs, Timer())
    sysm.set_operator(K, terms, mu, penalty=0.0)
    kkt = sysm._kkt_matrix()
    na = len(mu)
    assert np.all(kkt.diagonal()[-na:] == 0.0)
    ref = _dense_bordered(K, terms, free, mu)
    np.testing.assert_allclose(kkt.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    sysm.set_operator(K * 2.0, terms, mu, penalty=0.0)  # same pattern: gathered again
    kkt2 = sysm._kkt_matrix()
    assert kkt2.nnz == kkt.nnz and np.all(kkt2.indices == kkt.indices)
    assert sp.issparse(kkt2)


def test_force_only_evaluation_when_convergence_is_expected_changes_nothing(monkeypatch):
    """Iterates expected to converge are evaluated without the tangent (assembled later
    only if the guess was wrong). The path must be identical, bit for bit, to the one with
    the tangent assembled at every iterate."""
    from barhinge.solver import newton

    cp = bh.families.miura(3, 3, alpha=60.0, fold=10.0)
    cp1 = bh.families.miura(3, 3, alpha=60.0, fold=40.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e4)
    edges = miura_line_creases(cp)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
    scene = Scene(model, actuators=acts, steps=6)
    light = bh.solve(scene)
    assert light.meta["timing"]["n_force_only"] > 0
    monkeypatch.setattr(newton._Driver, "_expects_convergence", lambda self, res: False)
    full = bh.solve(scene)
    # the polynomial predictor's own force-only evaluations remain (two candidates compared)
    assert full.meta["timing"]["n_force_only"] < light.meta["timing"]["n_force_only"]
    np.testing.assert_array_equal(light.X, full.X)
    np.testing.assert_array_equal(light.actuator_moments, full.actuator_moments)
    assert light.residual_norms == full.residual_norms


@pytest.mark.parametrize("name", available_backends())
def test_redundant_actuators_are_named_by_every_backend(name):
    """Every crease of a flat waterbomb actuated: the actuator rows are dependent at the
    flat state (documented in docs/roofs.md). Each backend must stop with the cause named;
    PARDISO's bordered factorisation perturbs pivots there and falls back to the Schur
    complement, which identifies the redundancy."""
    cp = bh.families.waterbomb(2, 2)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e4)
    edges = np.flatnonzero(np.isin(np.asarray(cp.assignment), ["M", "V"]))
    targets = 0.2 * np.asarray(cp.fold_angles)[edges]
    scene = Scene(
        model,
        actuators=bh.Actuators(edges=edges, targets_deg=targets),
        steps=3,
        options={"linear_solver": name, "max_cutbacks": 1},
    )
    with pytest.raises(bh.ConvergenceError, match="actuators are redundant"):
        bh.solve(scene)


def test_no_gmres_iterations_allowed_factorises_without_calling_gmres():
    """``krylov_max = 0`` on a reused factorisation: scipy >= 1.12 fails inside ``gmres``
    with ``restart=0`` or ``maxiter=0`` (UnboundLocalError in scipy 1.17), so the solve must
    factorise the new operator instead of calling GMRES. The operator is reused (not stale)
    by construction, independent of timing."""
    K, terms, free, mu = _miura_system()
    K2, terms2, _, _ = _miura_system(nudge=1e-5)
    sysm = BorderedSystem(get_backend("superlu"), free, terms.dofs, Timer(), reuse=True)
    sysm.set_operator(K, terms, mu, penalty=50.0)
    sysm.krylov_max = 0
    sysm.set_operator(K2, terms2, 1.01 * mu, penalty=50.0)  # no GMRES time yet: reused
    assert not sysm.current_factored
    nf, na = int(free.sum()), len(mu)
    rng = np.random.default_rng(3)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    dx, dmu = sysm.solve(rx, rc, rtol=1e-12)
    assert sysm.current_factored and sysm.last_krylov_iters == 0
    ref = np.linalg.solve(_dense_bordered(K2, terms2, free, 1.01 * mu), np.concatenate([rx, rc]))
    np.testing.assert_allclose(
        np.concatenate([dx, dmu]), ref, rtol=0, atol=1e-8 * np.abs(ref).max()
    )


@pytest.mark.parametrize("name", available_backends())
def test_released_values_leave_solves_and_counts_to_the_factor(name):
    """``release_values``: once factorised, the operator's values are let go where the factor
    alone serves; solves and the stability counts are unchanged (dense reference), and the
    next operator is built and factorised as before."""
    K, terms, free, mu = _miura_system()
    keep = BorderedSystem(get_backend(name), free, terms.dofs, Timer())
    keep.set_operator(K, terms, mu, 50.0, factorize=True)
    drop = BorderedSystem(get_backend(name), free, terms.dofs, Timer())
    drop.set_operator(K, terms, mu, 50.0, factorize=True, release_values=True)
    assert keep.holds_values
    assert not drop.holds_values and drop.A is None
    nf, na = int(free.sum()), len(mu)
    rng = np.random.default_rng(4)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    ref = np.linalg.solve(_dense_bordered(K, terms, free, mu), np.concatenate([rx, rc]))
    dx, dmu = drop.solve(rx, rc)
    np.testing.assert_allclose(np.concatenate([dx, dmu]), ref, rtol=0, atol=1e-8 * abs(ref).max())
    assert drop.held_negative_eigenvalues() == keep.held_negative_eigenvalues()
    assert drop.tangent_negative_eigenvalues() == keep.tangent_negative_eigenvalues()
    # the next operator (another tangent) after a release: set, factorised and exact
    K2, terms2, _, _ = _miura_system(nudge=1e-3)
    drop.set_operator(K2, terms2, mu, 50.0, factorize=True, release_values=True)
    ref2 = np.linalg.solve(_dense_bordered(K2, terms2, free, mu), np.concatenate([rx, rc]))
    dx2, dmu2 = drop.solve(rx, rc)
    np.testing.assert_allclose(
        np.concatenate([dx2, dmu2]), ref2, rtol=0, atol=1e-8 * abs(ref2).max()
    )


def _miura_context(seed: int):
    """The solve context of a 2 x 2 Miura sheet driven by its line creases, and a state near
    its reference geometry (coordinates perturbed by 1e-3, small multipliers)."""
    from barhinge.solver.context import SolveContext
    from barhinge.solver.state import State

    cp = bh.families.miura(2, 2, alpha=60.0, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    edges = miura_line_creases(cp)
    scene = Scene(model, actuators=bh.Actuators(edges=edges, targets_deg=[40.0] * len(edges)))
    ctx = SolveContext(scene)
    ctx.make_system()
    x = model.X0.ravel() + 1e-3 * np.random.default_rng(seed).standard_normal(model.X0.size)
    st = State(x, 0.01 * np.arange(1, len(edges) + 1), 0.0, 0.5)
    return ctx, st, edges


def test_the_solver_lets_go_of_a_factorised_tangent_and_assembles_it_again_when_asked():
    """``SolveContext.factorize`` releases the iterate's tangent once it is factorised (the
    factor alone solves); factorising the same iterate again assembles it anew and solves
    the same system."""
    ctx, st, edges = _miura_context(seed=2)
    e = ctx.evaluate(st)
    K = e.ev.K.copy()
    ctx.factorize(e, st)
    assert e.ev.K is None and not ctx.system.holds_values
    nf, na = int(ctx.free.sum()), len(edges)
    rng = np.random.default_rng(5)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    first = np.concatenate(ctx.system.solve(rx, rc))
    ref = np.linalg.solve(_dense_bordered(K, e.terms, ctx.free, st.mu), np.concatenate([rx, rc]))
    np.testing.assert_allclose(first, ref, rtol=0, atol=1e-8 * np.abs(ref).max())
    ctx.factorize(e, st)  # the same iterate again: its tangent assembled anew
    np.testing.assert_allclose(np.concatenate(ctx.system.solve(rx, rc)), first, rtol=1e-12)


def test_a_residual_evaluation_skips_the_actuator_hessians_and_factorize_adds_them():
    """A residual needs no actuator Hessians: an evaluation without the tangent gives the
    same residual, constraint residual and constraint Jacobian as a full one (angles and
    gradients from the gradient kernel alone) and no Hessians. Factorising that iterate
    evaluates the tangent and the Hessians first: its solves are the dense bordered
    system's, which adds ``mu_a H_a`` from the full evaluation's Hessians."""
    ctx, st, edges = _miura_context(seed=3)
    full = ctx.evaluate(st)
    light = ctx.evaluate(st, tangent=False)
    assert light.ev.K is None and light.terms.hess is None and full.terms.hess is not None
    np.testing.assert_array_equal(light.r, full.r)
    np.testing.assert_array_equal(light.c, full.c)
    assert abs(light.terms.G - full.terms.G).max() == 0.0
    ctx.factorize(light, st)
    assert light.terms.hess is not None
    nf, na = int(ctx.free.sum()), len(edges)
    rng = np.random.default_rng(7)
    rx, rc = rng.standard_normal(nf), rng.standard_normal(na)
    got = np.concatenate(ctx.system.solve(rx, rc))
    dense = _dense_bordered(full.ev.K, full.terms, ctx.free, st.mu)
    ref = np.linalg.solve(dense, np.concatenate([rx, rc]))
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max())


def test_an_iterate_a_chord_step_follows_is_evaluated_without_its_tangent(monkeypatch):
    """After a Newton correction that is not accelerated, the next iterate is tested for
    convergence and, failing the test, chord-corrected: neither needs its tangent, so it is
    evaluated without one. The path must be identical, bit for bit, to the one with the
    tangent assembled there, and the tangents assembled fewer: an increment that converges
    in one correction assembles one tangent, for that correction."""
    from barhinge.solver import newton

    scene = miura_scene(5, 0.0, 20)  # flat -> 60 deg, quasi-rigid: mostly one correction
    tangents = [0]
    evaluate = BarHingeModel.evaluate

    def counted(self, X, tangent=True):
        tangents[0] += bool(tangent)
        return evaluate(self, X, tangent=tangent)

    monkeypatch.setattr(BarHingeModel, "evaluate", counted)
    light = bh.solve(scene)
    n_light = tangents[0]
    monkeypatch.setattr(newton._Driver, "_chord_next", lambda self, res: False)
    tangents[0] = 0
    full = bh.solve(scene)
    n_full = tangents[0]
    np.testing.assert_array_equal(light.X, full.X)
    np.testing.assert_array_equal(light.actuator_moments, full.actuator_moments)
    assert light.residual_norms == full.residual_norms
    # one tangent fewer for every increment that converged in one Newton correction
    stats = light.meta["newton"]
    one = sum(1 for k in stats["iterations"] if k == 1)
    assert one >= 10, one
    assert n_full - n_light >= one, (n_full, n_light, one)
    # each Newton factorisation needs one tangent; the first state and the stability
    # counts of the records add at most one each
    n_fact = light.meta["timing"]["n_factorizations"]
    assert n_light <= n_fact + 1 + len(light.X)
