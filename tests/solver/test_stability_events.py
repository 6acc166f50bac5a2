"""Stability monitored in every control, and "converged" means the target was reached.

* The inertia of the free-DOF tangent (actuators released) that the solver reads from its
  factorisations is checked against dense eigenvalues, on a bordered Miura system made
  indefinite and along an arc-length path of a Yoshimura roof.
* The von Mises two-bar truss (half span 1, rise h = 0.3, EA = 1000, Green-strain bars) has
  the closed-form limit load ``P_max = 2 EA h^3 / (3 sqrt(3) L0^3)`` at apex height
  ``h / sqrt(3)`` (Krenk 2009, "Non-linear Modeling and Analysis of Solids and Structures",
  ch. 1); by symmetry of the curve the load minimum is ``-P_max`` at ``-h / sqrt(3)``, and the
  tangent is negative exactly between the two.
* Arc length that stops at its step cap, or whose final correction onto load factor 1 fails,
  raises ConvergenceError with the partial path (``barhinge fold`` exits 3).
* External work and stored energy agree at the end of a run; the mismatch of the
  (third-order) work integration falls with the step size at a rate near 3.
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp

import barhinge as bh
from barhinge.errors import ConfigError, ConvergenceError
from barhinge.families import miura_line_creases
from barhinge.linalg.backends import available_backends, get_backend
from barhinge.model.model import BarHingeModel
from barhinge.output.table import step_table
from barhinge.scene import Scene
from barhinge.solver import newton
from barhinge.solver.bordered import BorderedSystem, Timer, actuator_terms
from barhinge.solver_options import SolverOptions
from barhinge.verify import rigid_link_strut, von_mises_limit_load, von_mises_model

H_VM = 0.3  # rise of barhinge.verify's von Mises truss
P_MAX = von_mises_limit_load()


def _vm_scene(steps: int = 20, factor: float = 1.5, **opts) -> Scene:
    model, S, apex = von_mises_model()
    P = np.zeros((model.n_nodes, 3))
    P[apex, 2] = -factor * P_MAX
    options = {"max_arc_steps": 200, **opts}
    return Scene(model, supports=S, loads=P, control="arc_length", steps=steps, options=options)


# ------------------------------------------------------------------ inertia
@pytest.mark.parametrize("route", ["schur complement", "haynsworth", "released factor"])
@pytest.mark.parametrize("name", available_backends())
def test_released_inertia_from_the_bordered_factorisation_matches_dense(name, route, monkeypatch):
    """neg(K_t) = neg([K_t G^T; G 0]) - neg(Y), Y the multiplier block of the inverse
    (Haynsworth), or the Schur complement ``-G K_t^-1 G^T`` the bordered factorisation
    computes beside its factor (PARDISO), or (many actuators, no such complement) the
    pivots of a factorisation of K_t itself: each checked on a Miura tangent shifted to 0,
    3, 7 and 11 negative eigenvalues; and the held count neg([K_t G^T; G 0]) - n_act
    against the eigenvalues of ``Z^T K_t Z`` (G Z = 0)."""
    from barhinge.solver import bordered

    min_act = 1 if route == "released factor" else 10**9
    monkeypatch.setattr(bordered, "RELEASED_FACTOR_MIN_ACT", min_act)
    cp = bh.families.miura(2, 2, alpha=60.0, fold=30.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=0.1, bar_EA=1e3)
    edges = miura_line_creases(cp)
    scene = Scene(model, actuators=bh.Actuators(edges=edges, targets_deg=[30.0] * len(edges)))
    X = model.X0 + 1e-3 * np.random.default_rng(0).standard_normal(model.X0.shape)
    K = model.evaluate(X).K
    terms = actuator_terms(model, X, scene.actuator_hinges())
    free = ~scene.fixed.ravel()
    mu = 0.01 * np.arange(1, len(edges) + 1)
    Kt = K.toarray()
    for a, dofs in enumerate(terms.dofs):
        Kt[np.ix_(dofs, dofs)] += mu[a] * terms.hess[a]
    w = np.linalg.eigvalsh(Kt[np.ix_(free, free)])
    n0 = int(np.sum(w < 0))  # the perturbed tangent is indefinite already (7)
    # held actuators: the tangent on the motions that keep every actuator angle
    Z = scipy.linalg.null_space(terms.G[:, free].toarray())
    Ktf = Kt[np.ix_(free, free)]
    for n_neg in (0, 3, n0, n0 + 4):
        shift = w[0] - 1.0 if n_neg == 0 else 0.5 * (w[n_neg - 1] + w[n_neg])
        sysm = BorderedSystem(get_backend(name), free, terms.dofs, Timer())
        schur = sysm._schur_counts and route == "schur complement"
        sysm._schur_counts = schur
        sysm.factorize((K - shift * sp.identity(K.shape[0])).tocsr(), terms, mu, penalty=50.0)
        assert (sysm.factor.schur_complement() is not None) if schur else True
        held = np.linalg.eigvalsh(Z.T @ (Ktf - shift * np.eye(len(Ktf))) @ Z)
        assert sysm.held_negative_eigenvalues() == int(np.sum(held < 0)), (name, n_neg)
        got = sysm.tangent_negative_eigenvalues()
        assert got == int(np.sum(w < shift)) == n_neg, (name, n_neg, got)
        # the bordered (saddle-point) factorisation takes the released factor's route
        took = sysm._released_counter is not None
        saddle = getattr(sysm.backend, "saddle_point", False)
        assert took == (route == "released factor" and saddle), name
        if route == "schur complement":
            assert schur == (name == "pardiso"), name


@pytest.mark.parametrize("name", available_backends())
def test_held_and_released_counts_of_a_driven_strut_follow_the_closed_forms(name):
    """A pinned-pinned chain of three rigid links (length l = 1, rotational springs k = 2 at
    the two inner creases) under an axial load ramped to 4.4 over 10 steps, its first
    inner crease driven (held at 0 deg). Released, it is the three-link strut: critical
    load ``4 k / l sin^2(pi / 6) = 2`` (Bazant & Cedolin 1991, ch. 1); held, the driven
    crease joins the first two links into one of length 2 l, and the two-link strut with
    one spring buckles at ``k (1 / (2 l) + 1 / l) = 3`` (its energy
    ``k/2 (w/a + w/b)^2 - P/2 (w^2/a + w^2/b)``). Both counts change at the first step past
    their critical load (2.2 and 3.08), and the held change is an event."""
    model, S, P = rigid_link_strut(3, ell=1.0, k=2.0)
    crease = next(i for i, e in enumerate(model.pattern.edges) if set(e) == {1, 5})
    scene = Scene(
        model,
        supports=S,
        loads=4.4 * P,
        actuators=bh.Actuators(edges=[crease], targets_deg=[0.0]),
        steps=10,
        control="fold_angle",
        options={"linear_solver": name},
    )
    path = bh.solve(scene)
    load = 4.4 * path.load_factor
    released, held = path.meta["negative_eigenvalues"], path.meta["negative_eigenvalues_held"]
    assert released == [int(p > 2.0) for p in load]
    assert held == [int(p > 3.0) for p in load]
    unstable = [e for e in path.meta["events"] if e.startswith("unstable equilibrium")]
    assert len(unstable) == 1 and "at step 7" in unstable[0], path.meta["events"]
    rows = step_table(path)  # states.csv has both counts per state
    assert [r["negative_eigenvalues"] for r in rows] == released
    assert [r["negative_eigenvalues_held"] for r in rows] == held


def test_failed_fold_increment_names_the_instability_its_iterates_met():
    """A fold-angle increment that fails from a stable state after iterates whose tangent
    is unstable with the actuators held says so in its reason (the counts come with every
    factorisation); with no such iterate the reason stays as it was."""
    model, S, P = rigid_link_strut(3)
    crease = next(i for i, e in enumerate(model.pattern.edges) if set(e) == {1, 5})
    acts = bh.Actuators(edges=[crease], targets_deg=[0.0])
    scene = Scene(model, supports=S, loads=P, actuators=acts)
    d = newton._Driver(scene)
    d.system.inertia_seen = [0, 2, 1]
    text = d.inertia.failure_text("residual diverged", held_before=0)
    assert text.startswith("residual diverged; the iterates' tangent was unstable with the")
    assert "up to 2 negative eigenvalues" in text
    assert d.inertia.failure_text("residual diverged", held_before=1) == ""
    d.system.inertia_seen = [0, 0]
    assert d.inertia.failure_text("residual diverged", held_before=0) == ""


def _miura_line_fold(fold_stiffness: float) -> Scene:
    """A 3 x 3 Miura with its 6 line creases driven from 50 to 20 deg in 8 steps."""
    cp = bh.families.miura(3, 3, alpha=60.0, fold=50.0)
    model = BarHingeModel.from_pattern(cp, "N5B8", fold_stiffness=fold_stiffness, bar_EA=1e3)
    edges = miura_line_creases(cp)
    targets = np.asarray(bh.families.miura(3, 3, alpha=60.0, fold=20.0).fold_angles)[edges]
    return Scene(
        model,
        actuators=bh.Actuators(edges=edges, targets_deg=targets),
        steps=8,
        options={"linear_solver": "pardiso"},
    )


@pytest.mark.skipif("pardiso" not in available_backends(), reason="PARDISO Schur complement")
def test_schur_complement_counts_give_the_same_fold_without_count_factorisations(monkeypatch):
    """The released count from the Schur complement of Newton's bordered factorisation
    (PARDISO, the default) against the released tangent factorised at every state (the
    route of other backends with many actuators): the same states, the same counts of both
    kinds, and the count factorisations gone (every state's released count was one)."""
    from barhinge.solver import bordered

    monkeypatch.setattr(bordered, "RELEASED_FACTOR_MIN_ACT", 1)
    scene = _miura_line_fold(0.1)
    schur = bh.solve(scene)
    monkeypatch.setattr(bordered, "SCHUR_COUNTS", False)
    factored = bh.solve(scene)
    scale = float(np.abs(factored.X[0]).max())
    assert np.abs(schur.X - factored.X).max() <= 1e-9 * scale
    assert np.abs(factored.X[-1] - factored.X[0]).max() > 0.05 * scale  # it folded
    for key in ("negative_eigenvalues", "negative_eigenvalues_held"):
        assert schur.meta[key] == factored.meta[key], key
    n_states = scene.steps + 1
    fewer = sum(factored.meta["newton"]["factorizations"]) - sum(
        schur.meta["newton"]["factorizations"]
    )
    assert fewer >= n_states - 1  # the states after the first, each counted by its own


@pytest.mark.skipif("pardiso" not in available_backends(), reason="PARDISO Schur complement")
def test_a_tangent_singular_with_the_actuators_released_takes_the_augmented_matrix(
    monkeypatch, caplog
):
    """No fold springs: the Miura's rigid-folding mode makes ``K_t`` singular, which the
    Schur-complement factorisation (``K_t`` eliminated first) meets as perturbed pivots.
    The solve switches to the augmented bordered matrix ``K_t + p G^T G`` (and the released
    tangent's own factorisation for its count) and gives exactly the fold of that route."""
    from barhinge.solver import bordered

    scene = _miura_line_fold(0.0)
    with caplog.at_level(logging.DEBUG, logger="barhinge.solver.bordered"):
        switched = bh.solve(scene)
    assert "augmented from here on" in caplog.text
    monkeypatch.setattr(bordered, "SCHUR_COUNTS", False)
    augmented = bh.solve(scene)
    np.testing.assert_array_equal(switched.X, augmented.X)
    for key in ("negative_eigenvalues", "negative_eigenvalues_held"):
        assert switched.meta[key] == augmented.meta[key], key


@pytest.mark.skipif("pardiso" not in available_backends(), reason="PARDISO releases factors")
def test_released_bordered_factor_gives_the_same_fold(monkeypatch):
    """Above ``InertiaCounter.RELEASE_ABOVE`` the bordered factor is released before the
    released tangent is factorised for the stability count (never two factors at once):
    the fold (:func:`_miura_line_fold` on the released-factor route) is the same state for
    state, with the same counts, as with every factor kept; the released factors are really
    released, and arc length keeps its factor."""
    from barhinge.linalg import inertia
    from barhinge.linalg.backends import PardisoBackend
    from barhinge.solver import bordered

    monkeypatch.setattr(bordered, "RELEASED_FACTOR_MIN_ACT", 1)
    monkeypatch.setattr(bordered, "SCHUR_COUNTS", False)
    scene = _miura_line_fold(0.1)
    released = []
    real_release = PardisoBackend.release
    monkeypatch.setattr(
        PardisoBackend, "release", lambda self: (released.append(self), real_release(self))[1]
    )
    kept = bh.solve(scene)
    assert not released
    monkeypatch.setattr(inertia.InertiaCounter, "RELEASE_ABOVE", 0)
    freed = bh.solve(scene)
    assert len(released) >= 2 * scene.steps  # the count's factors and the bordered ones
    assert freed.meta["negative_eigenvalues"] == kept.meta["negative_eigenvalues"]
    scale = float(np.abs(kept.X[0]).max())
    assert np.abs(freed.X - kept.X).max() <= 1e-9 * scale
    assert np.abs(kept.X[-1] - kept.X[0]).max() > 0.05 * scale  # it folded
    ctx_arc = newton._Driver(_vm_scene(steps=2)).ctx
    assert not ctx_arc.system.release_before_count


def test_stability_check_option_is_validated():
    with pytest.raises(ConfigError, match="stability_check"):
        SolverOptions(stability_check="yes")
    assert SolverOptions().exact_inertia("arc_length") and SolverOptions().exact_inertia("load")
    assert not SolverOptions().exact_inertia("fold_angle")
    assert SolverOptions(stability_check=True).exact_inertia("displacement")


# ------------------------------------------------------------------ von Mises truss
@pytest.fixture(scope="module")
def vm_path():
    return bh.solve(_vm_scene())


def test_von_mises_arc_length_reports_the_limit_points(vm_path):
    p = vm_path
    lam = 1.5 * p.load_factor  # in units of P_max
    maxima = [e for e in p.meta["events"] if e.startswith("limit point (load maximum)")]
    minima = [e for e in p.meta["events"] if e.startswith("limit point (load minimum)")]
    assert len(maxima) == 1 and len(minima) == 1, p.meta["events"]
    assert len(p.meta["events"]) == 2  # and nothing else (no work-balance event)
    at = float(maxima[0].split("load factor ")[1].split()[0]) * 1.5
    assert at == pytest.approx(1.0, rel=0.01)  # 0.9995 P_max at 20 steps
    assert at <= lam.max() + 1e-12
    at_min = float(minima[0].split("load factor ")[1].split()[0]) * 1.5
    assert at_min == pytest.approx(-1.0, rel=0.01)
    # the recorded inertia against the closed form: the one free DOF (apex height z) has
    # negative stiffness exactly for |z| < h / sqrt(3)
    z = p.X[:, 2, 2]
    neg = np.array(p.meta["negative_eigenvalues"])
    clear = np.abs(np.abs(z) - H_VM / math.sqrt(3)) > 1e-3
    np.testing.assert_array_equal(neg[clear], (np.abs(z[clear]) < H_VM / math.sqrt(3)) * 1)


def test_converged_arc_length_ends_exactly_at_load_factor_one(vm_path):
    p = vm_path
    assert p.converged and p.load_factor[-1] == pytest.approx(1.0, abs=1e-9)
    assert np.all(p.load_factor <= 1.0)  # no overshooting state in a converged path
    wb = p.meta["work_balance"]
    assert wb["work"] == pytest.approx(p.external_work[-1], rel=1e-15)
    assert wb["energy"] == pytest.approx(p.energy[-1] - p.energy[0], rel=1e-15)
    assert wb["rel_mismatch"] < wb["tolerance"] == newton.WORK_TOLERANCE
    # equilibrium at the final state, from the path alone: reactions balance the load
    scene = _vm_scene()
    total = (p.load_factor[-1] * scene.loads + p.reactions[-1]).sum(0)
    np.testing.assert_allclose(total, 0.0, atol=1e-8 * P_MAX)


def test_work_balance_converges_at_third_order():
    """The mismatch between work and energy is the error of the Simpson work integration
    (the states are in equilibrium): it falls like h^3 (measured 1.1e-4, 9.4e-6, 5.1e-6,
    5.7e-8 at 10, 20, 40, 80 steps: fitted slope 3.4, not monotone in between); at 10 arc
    steps through the whole snap-through it is 1.1e-4, a tenth of the event tolerance."""
    steps = np.array([10, 20, 40, 80])
    mis = [bh.solve(_vm_scene(int(s), max_arc_steps=800)).meta["work_balance"] for s in steps]
    rel = np.array([m["rel_mismatch"] for m in mis])
    slope = np.polyfit(np.log(1.0 / steps), np.log(rel), 1)[0]
    assert slope > 2.5, rel
    assert rel[0] < 0.2 * newton.WORK_TOLERANCE


# ------------------------------------------------------------------ failures
def test_arc_length_step_cap_raises_with_the_partial_path():
    with pytest.raises(ConvergenceError, match=r"step cap \(max_arc_steps = 10\)") as ei:
        bh.solve(_vm_scene(max_arc_steps=10))
    part = ei.value.last_state
    assert not part.converged and part.n_states == 11
    assert part.load_factor[-1] < 1.0 and ei.value.load_factor == part.load_factor[-1]
    assert "of 1" in str(ei.value) and len(part.meta["negative_eigenvalues"]) == 11


def test_failed_landing_on_load_factor_one_raises(monkeypatch):
    def fail(self, st, t1, lam1):
        raise newton._Failed("residual diverged", [1.0])

    monkeypatch.setattr(newton._Driver, "increment", fail)
    with pytest.raises(ConvergenceError, match="correction onto 1 failed") as ei:
        bh.solve(_vm_scene())
    part = ei.value.last_state
    assert not part.converged and np.all(part.load_factor < 1.0)


def test_cli_fold_exits_3_when_arc_length_stops_at_its_cap(tmp_path, monkeypatch, capsys):
    from barhinge.cli import main
    from barhinge.output.summary import run_summary

    scene = (
        "name = 'roof-arc'\n"
        "[pattern]\nfamily = 'yoshimura'\nparams = { nx = 3, ny = 2, fold = 30.0 }\n"
        "[model]\nscheme = 'N5B8'\nmaterial = { E = 1.0e6, nu = 0.3, t = 0.01 }\n"
        "fold_stiffness = 1.0\n"
        "[[supports]]\nwhere = 'bottom'\ndofs = 'xyz'\n"
        "[[supports]]\nwhere = 'top'\ndofs = 'xyz'\n"
        "[[loads]]\nself_weight = { area_density = 3.0, g = [0.0, 0.0, -9.81] }\n"
        "[solve]\nsteps = 10\ncontrol = 'arc_length'\noptions = { max_arc_steps = 15 }\n"
    )  # the roof of data/scenes at 30 times its weight: a limit point at state 13
    f = tmp_path / "roof.toml"
    f.write_text(scene)
    out = tmp_path / "o"
    monkeypatch.setenv("BARHINGE_PICTURES", "0")  # the result files only: seconds saved
    monkeypatch.setattr("sys.argv", ["barhinge", "fold", str(f), "--out", str(out)])
    with pytest.raises(SystemExit) as ex:
        main()
    err = capsys.readouterr().err
    assert ex.value.code == 3, err
    assert "step cap" in err and "event: limit point (load maximum)" in err
    part = bh.FoldPath.load(out / "fold_path.npz")
    assert not part.converged and part.load_factor[-1] < 1.0 and part.n_states == 16
    info = json.loads((out / "summary.json").read_text())
    results = info.pop("results")  # the final-state analysis, under its own key
    assert info == json.loads(json.dumps(run_summary(part)))  # written from the partial path
    assert results["converged"] is False and results["n_states"] == part.n_states
    assert not info["converged"] and any("limit point" in e for e in info["events"])


# ------------------------------------------------------------------ Yoshimura roof
def test_yoshimura_roof_going_indefinite_under_arc_length_gets_events():
    """The roof of data/scenes at 30 times its weight: load control stops at a limit point
    near load factor 0.70; arc length passes it (and a bifurcation on the way down), records
    them as events and ends at 1. The recorded inertia is checked against dense eigenvalues
    of the free-DOF tangent at every state."""
    base = bh.load_scene(Path(__file__).resolve().parents[2] / "data/scenes/yoshimura_roof.toml")
    arc = base.with_(loads=30 * base.loads, control="arc_length", steps=10,
                     options=SolverOptions(max_arc_steps=80))  # fmt: skip
    p = bh.solve(arc)
    assert p.converged and p.load_factor[-1] == 1.0
    ev = p.meta["events"]
    limit = [e for e in ev if e.startswith("limit point (load maximum)")]
    assert len(limit) == 1 and any(e.startswith("bifurcation") for e in ev), ev
    lam_limit = float(limit[0].split("load factor ")[1].split()[0])
    free = ~arc.fixed.ravel()
    for i in range(p.n_states):
        w = np.linalg.eigvalsh(arc.model.evaluate(p.X[i]).K.toarray()[np.ix_(free, free)])
        assert p.meta["negative_eigenvalues"][i] == int(np.sum(w < 0)), i
    with pytest.raises(ConvergenceError, match="limit point") as ei:
        bh.solve(arc.with_(control="load", options=SolverOptions()))
    assert ei.value.load_factor == pytest.approx(lam_limit, rel=0.01)
