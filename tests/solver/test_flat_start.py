"""Fold from flat: the bar-and-hinge solver leaves the flat state on the branch the crease
pattern asks for, and approaches the energy-minimising rigid fold as panels stiffen."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh

MAT = bh.Material(E=1e6, nu=0.3, t=0.01)


def _against(cp, fold_deg, min_deg=1e-6):
    asg = cp.assignment
    want = np.where(asg == "V", 1.0, np.where(asg == "M", -1.0, 0.0))
    return np.flatnonzero(want * fold_deg < -min_deg)


def test_readme_example_folds_with_the_assignment():
    """The README's Python example, started flat exactly as written: every crease folds with
    its assignment's sign, nearly all the energy is in the folds (panels + bars < 1 % at
    stiffness ratio 1e5; ~1/r, 2.9 % at 1e4 with the plate-calibrated panel bending), and the
    actuator reaches its target."""
    cp = bh.families.miura(nx=4, ny=4, a=1.0, b=1.0, alpha=60.0)
    a = bh.dof(cp).mechanism.actuators
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=1e5)
    scene = bh.Scene(
        model, actuators=bh.Actuators(edges=a, targets_deg=cp.fold_angles[a] / 2), steps=10
    )
    fp = bh.solve(scene)
    assert fp.converged
    assert len(_against(cp, fp.fold_angles_deg[-1])) == 0
    share = 1.0 - fp.energy_fold[-1] / fp.energy[-1]
    assert share < 0.01
    np.testing.assert_allclose(fp.fold_angles_deg[-1, a], cp.fold_angles[a] / 2, atol=1e-6)
    assert fp.meta["flat_start"]["predictor"] == "rigid panels"
    assert fp.meta["branch_events"] == []


def _rigid_gap(n, scheme, ratios, steps=6):
    cp = bh.families.miura(nx=n, ny=n, a=1.0, b=1.0, alpha=60.0)
    z = int(bh.families.miura_layout(n, n).interior_zigzag_edges[0])
    target = 0.5 * cp.fold_angles[z]
    rigid = bh.rigid_fold(cp, [z], targets_deg=[target], steps=steps).fold_angles_deg[-1]
    errs = []
    for ratio in ratios:
        model = bh.BarHingeModel.from_pattern(
            cp, scheme=scheme, material=MAT, stiffness_ratio=ratio
        )
        fp = bh.solve(
            bh.Scene(model, actuators=bh.Actuators(edges=[z], targets_deg=[target]), steps=steps)
        )
        assert len(_against(cp, fp.fold_angles_deg[-1])) == 0
        errs.append(float(np.abs(fp.fold_angles_deg[-1] - rigid).max()))
    return np.asarray(errs)


@pytest.mark.parametrize("n, scheme", [(2, "N5B8"), (3, "N5B8"), (3, "N4B5")])
def test_bar_hinge_converges_to_the_rigid_fold_as_one_over_the_ratio(n, scheme):
    """Rigid limit: with bars and panels `ratio` times stiffer, the fold angles differ from
    the rigid kinematics (an independent solver in the crease angles) by O(1/ratio):
    log-log slope -1 +- 0.15 over three decades."""
    ratios = np.array([1e3, 1e4, 1e5])
    errs = _rigid_gap(n, scheme, ratios)
    slope = np.polyfit(np.log(ratios), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 0.15, (errs, slope)


@pytest.mark.slow
def test_ten_by_ten_miura_from_flat_approaches_the_rigid_fold():
    ratios = np.array([1e4, 1e5, 1e6])
    errs = _rigid_gap(10, "N5B8", ratios, steps=5)
    slope = np.polyfit(np.log(ratios), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 0.15, (errs, slope)


def test_flat_start_option_tangent_keeps_the_old_predictor():
    cp = bh.families.miura(2, 2)
    z = int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=1e5)
    acts = bh.Actuators(edges=[z], targets_deg=[0.5 * cp.fold_angles[z]])
    fp = bh.solve(bh.Scene(model, actuators=acts, steps=4, options={"flat_start": "tangent"}))
    assert fp.meta["flat_start"] is None
    # the plain tangent takes another branch here; the sign check still names it
    bad = _against(cp, fp.fold_angles_deg[-1], min_deg=1.0)
    assert len(bad) > 0
    assert any(ev.startswith(f"{len(bad)} crease(s) fold against") for ev in fp.meta["events"])
    with pytest.raises(bh.ConfigError, match="flat_start"):
        bh.Scene(model, actuators=acts, steps=4, options={"flat_start": "bogus"})


def test_creases_against_the_assignment_are_an_event():
    """A 6 x 6 Miura sheet with panels only 100 x stiffer than the default, driven by one
    actuator: the panels bend and creases far from the actuator fold the other way; the run
    names them (the count is checked against the assignment independently)."""
    cp = bh.families.miura(6, 6)
    z = int(bh.families.miura_layout(6, 6).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=100.0)
    acts = bh.Actuators(edges=[z], targets_deg=[0.5 * cp.fold_angles[z]])
    fp = bh.solve(bh.Scene(model, actuators=acts, steps=6))
    bad = _against(cp, fp.fold_angles_deg[-1], min_deg=1.0)
    assert len(bad) > 0
    (ev,) = fp.meta["branch_events"]
    assert ev.startswith(f"{len(bad)} crease(s) fold against their M/V assignment")


@pytest.mark.parametrize(
    "cp", [bh.families.resch(3, 3), bh.families.waterbomb(3, 3)], ids=["resch", "waterbomb"]
)
def test_resch_and_waterbomb_fold_from_flat_and_name_what_they_do(cp):
    """Resch and waterbomb sheets driven from flat by 1-3 of their suggested actuators:
    the solve reaches the targets (or raises the package's ConvergenceError), and every
    crease that folds against its assignment by more than 1 deg is named in an event."""
    a_all = [int(e) for e in bh.dof(cp).mechanism.actuators]
    for k in (1, 3):
        a = a_all[:k]
        model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=1e5)
        acts = bh.Actuators(edges=a, targets_deg=0.5 * cp.fold_angles[a])
        try:
            fp = bh.solve(bh.Scene(model, actuators=acts, steps=5))
        except bh.ConvergenceError as exc:
            assert str(exc) and exc.last_state is not None
            continue
        np.testing.assert_allclose(fp.fold_angles_deg[-1, a], 0.5 * cp.fold_angles[a], atol=1e-6)
        bad = _against(cp, fp.fold_angles_deg[-1], min_deg=1.0)
        named = [ev for ev in fp.meta["events"] if "fold against their M/V" in ev]
        assert (len(bad) > 0) == (len(named) > 0)
        if bad.size:
            assert named[0].startswith(f"{len(bad)} crease(s)")


@pytest.mark.parametrize("n, k", [(3, 1), (3, 2), (6, 2)])
def test_underactuated_resch_converges_to_the_energy_minimising_rigid_fold(n, k):
    """Ron Resch sheets driven from flat by fewer actuators than their DOF: the free motions
    are resolved by the fold springs in both solvers, and the bar-and-hinge fold angles
    approach the energy-minimising rigid fold (bh.rigid_fold with the model's fold
    stiffnesses) as 1/ratio: log-log slope -1 +- 0.15. Tight force tolerances: the gap is
    below 1e-5 deg at ratio 1e5, where the default tolerance's error on the soft modes would
    dominate it."""
    from barhinge.solver.branch import fold_weights

    cp = bh.families.resch(n, n)
    a = [int(e) for e in bh.dof(cp).mechanism.actuators][:k]
    targets = 0.5 * cp.fold_angles[a]
    ratios = np.array([1e3, 1e4, 1e5])
    errs = []
    for ratio in ratios:
        model = bh.BarHingeModel.from_pattern(
            cp, scheme="N5B8", material=MAT, stiffness_ratio=ratio
        )
        w, _ = fold_weights(model)
        rigid = bh.rigid_fold(cp, a, targets_deg=targets, steps=5, fold_stiffness=w)
        assert rigid.meta["free_dof"] > 0
        acts = bh.Actuators(edges=a, targets_deg=targets)
        opts = {"tol_force": 1e-13, "tol_disp": 1e-13}
        fp = bh.solve(bh.Scene(model, actuators=acts, steps=5, options=opts))
        errs.append(np.abs(fp.fold_angles_deg[-1] - rigid.fold_angles_deg[-1]).max())
    slope = np.polyfit(np.log(ratios), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 0.15, (errs, slope)


def _readme_gap(cp, k, ratios, steps=5):
    """The README workflow from the flat state: the first ``k`` actuators bh.dof suggests,
    driven to half the pattern's target fold angles, default solver options. Checks that
    the rigid fold (bh.rigid_fold with the model's fold stiffnesses) and the bar-and-hinge
    fold both fold every crease with its assignment; returns the largest fold-angle gap
    (deg) between them per stiffness ratio."""
    from barhinge.solver.branch import fold_weights

    a = [int(e) for e in bh.dof(cp).mechanism.actuators][:k]
    targets = 0.5 * cp.fold_angles[a]
    errs = []
    for ratio in ratios:
        model = bh.BarHingeModel.from_pattern(
            cp, scheme="N5B8", material=MAT, stiffness_ratio=ratio
        )
        w, _ = fold_weights(model)
        rigid = bh.rigid_fold(cp, a, targets_deg=targets, steps=steps, fold_stiffness=w)
        assert len(_against(cp, rigid.fold_angles_deg[-1])) == 0
        acts = bh.Actuators(edges=a, targets_deg=targets)
        fp = bh.solve(bh.Scene(model, actuators=acts, steps=steps))
        assert fp.converged
        assert len(_against(cp, fp.fold_angles_deg[-1])) == 0
        assert fp.meta["branch_events"] == []
        errs.append(np.abs(fp.fold_angles_deg[-1] - rigid.fold_angles_deg[-1]).max())
    return np.asarray(errs), rigid


@pytest.mark.parametrize(
    "name, cp, k, ratios",
    [
        ("miura 4x4", bh.families.miura(nx=4, ny=4, a=1.0, b=1.0, alpha=60.0), 1, (1e3, 1e4, 1e5)),
        ("yoshimura 1x2", bh.families.yoshimura(1, 2), 2, (1e3, 1e4, 1e5)),
        ("yoshimura 1x2", bh.families.yoshimura(1, 2), 3, (1e4, 1e5, 1e6)),
        ("resch 3x3", bh.families.resch(3, 3), 3, (1e3, 1e4, 1e5)),
        ("waterbomb 1x1", bh.families.waterbomb(1, 1), 3, (1e3, 1e4, 1e5)),
    ],
    ids=["miura4-1", "yoshimura-2", "yoshimura-3", "resch-3", "waterbomb-3"],
)
def test_readme_workflow_from_flat_reaches_the_rigid_fold(name, cp, k, ratios):
    """From the flat state with the README workflow (bh.dof's actuators, default options):
    every crease folds with its assignment's sign and the fold angles approach the
    energy-minimising rigid fold as 1/ratio, log-log slope -1 +- 0.15 over three decades.
    The Yoshimura sheet (one cell wide, two rows: 3 rigid DOF) with 2 actuators leaves one
    free motion to the fold springs in both solvers. Larger under-actuated Yoshimura sheets
    have several strict energy minima (tests/kinematics/test_kin_energy.py), so their
    rigid limit is not unique (docs/solver.md). With its free motion the 2-actuator sheet
    is taken to 1e5 only: at 1e6 its gap (5.6e-7 deg) is below what the default displacement
    tolerance resolves on that soft motion (the fold then ends 2.5e-6 deg off)."""
    ratios = np.asarray(ratios)
    errs, rigid = _readme_gap(cp, k, ratios)
    if name.startswith("yoshimura"):
        assert bh.dof(cp).mechanism.global_dof == 3 and rigid.meta["free_dof"] == 3 - k
    slope = np.polyfit(np.log(ratios), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 0.15, (errs, slope)


def test_conflicting_actuators_of_a_folded_start_are_named_before_solving(caplog):
    """A folded Miura 3 x 3 (one rigid DOF, checked by a dense SVD of the loop-closure
    Jacobian) driven by two zig-zag creases: targets taken from the rigid fold of one of
    them are compatible (no event); moving the second the other way conflicts, and the run
    names the dependent actuator in a warning logged before the first increment and in its
    events."""
    import logging

    from barhinge.kinematics.constraints import RigidConstraints

    cp = bh.families.miura(3, 3, alpha=60.0, fold=30.0)
    rc = RigidConstraints.from_pattern(cp)
    sv = np.linalg.svd(rc.jacobian(rc.rho0).toarray(), compute_uv=False)
    assert rc.n_var - np.sum(sv > 1e-9 * sv[0]) == 1
    z1, z2 = (int(e) for e in bh.families.miura_layout(3, 3).interior_zigzag_edges[:2])
    ref = bh.rigid_fold(cp, [z1], targets_deg=[cp.fold_angles[z1] * 1.2], steps=4)
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=1e5)

    good = bh.Actuators(edges=[z1, z2], targets_deg=ref.fold_angles_deg[-1, [z1, z2]])
    fp = bh.solve(bh.Scene(model, actuators=good, steps=4))
    assert fp.converged and not any("conflict" in ev for ev in fp.meta["events"])

    bad_t = [ref.fold_angles_deg[-1, z1], cp.fold_angles[z2] * 0.8]
    bad = bh.Actuators(edges=[z1, z2], targets_deg=bad_t)
    with caplog.at_level(logging.WARNING):
        fp = bh.solve(bh.Scene(model, actuators=bad, steps=4))
    named = [ev for ev in fp.meta["events"] if "actuator targets conflict" in ev]
    assert len(named) == 1
    assert f"edges [{z2}] follow from edges [{z1}]" in named[0] or (
        f"edges [{z1}] follow from edges [{z2}]" in named[0]
    )
    first = next(i for i, r in enumerate(caplog.records) if "conflict" in r.getMessage())
    assert first == 0  # before anything the solve logs about its increments


def test_rigid_guide_between_steps_is_the_cubic_through_the_rigid_fold():
    """The rigid-fold predictor of increments shorter than a requested step (a cut-back first
    step) lies on the rigid fold to fourth order in the step: against the rigid fold solved
    at the off-step parameter itself (an independent rigid solve), halving the requested
    step divides the error about 2**4 = 16 times (a straight line between steps, which
    shortens the panels like the square of the fold angle, would divide it 4 times), and
    the guide is exact at the requested steps."""
    from barhinge.solver.branch import rigid_guide

    cp = bh.families.miura(nx=3, ny=3, a=1.0, b=1.0, alpha=60.0)
    z = int(bh.families.miura_layout(3, 3).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT)
    fixed = np.zeros((model.n_nodes, 3), bool)
    X0 = np.asarray(model.X0)
    final = 40.0  # degrees at t = 1
    t_probe = 0.0375  # inside the first step of both guides below (steps 8 and 16)
    exact = rigid_guide(
        model, bh.Actuators(edges=[z], targets_deg=[final * t_probe]), 1, fixed, X0
    ).X[-1]
    errors = []
    for steps in (8, 16):
        g = rigid_guide(model, bh.Actuators(edges=[z], targets_deg=[final]), steps, fixed, X0)
        assert g is not None
        np.testing.assert_allclose(g.at(2 / steps), g.X[2], atol=1e-14)
        errors.append(float(np.abs(g.at(t_probe) - exact).max()))
    assert errors[1] > 0.0
    assert errors[0] / errors[1] > 10.0


def test_rigid_guide_head_folds_the_first_steps_as_the_whole_schedule():
    """Where the actuators leave no free motion the solver predicts only its first increment
    from the rigid fold, so the guide folds only the first ``GUIDE_HEAD`` requested steps:
    the same states as the whole schedule's (each step starts from the last) and the same
    cubic over the first step. Where the actuators leave free motions (an under-actuated
    Ron Resch sheet, whose later increments follow the guide) the whole schedule is folded."""
    from barhinge.solver.branch import GUIDE_HEAD, rigid_guide

    cp = bh.families.miura(nx=3, ny=3, a=1.0, b=1.0, alpha=60.0)
    z = int(bh.families.miura_layout(3, 3).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT)
    fixed = np.zeros((model.n_nodes, 3), bool)
    X0 = np.asarray(model.X0)
    acts = bh.Actuators(edges=[z], targets_deg=[40.0])
    whole = rigid_guide(model, acts, 20, fixed, X0)
    head = rigid_guide(model, acts, 20, fixed, X0, head=GUIDE_HEAD)
    assert whole is not None and head is not None
    assert whole.record["free_dof"] == 0 and whole.t_max == 1.0
    assert len(head.X) == GUIDE_HEAD + 1 and head.t_max == GUIDE_HEAD / 20
    np.testing.assert_allclose(head.X, whole.X[: GUIDE_HEAD + 1], atol=1e-12)
    for t in (0.01, 0.025, 0.05):
        np.testing.assert_allclose(head.at(t), whole.at(t), atol=1e-12)

    resch = bh.families.resch(3, 3)
    a = [int(e) for e in bh.dof(resch).mechanism.actuators][:1]
    under = bh.Actuators(edges=a, targets_deg=0.5 * resch.fold_angles[a])
    m = bh.BarHingeModel.from_pattern(resch, scheme="N5B8", material=MAT)
    g = rigid_guide(m, under, 10, np.zeros((m.n_nodes, 3), bool), np.asarray(m.X0), head=2)
    assert g is not None and g.record["free_dof"] > 0
    assert g.t_max == 1.0 and len(g.X) == 11
