"""The transformation study (studies/transformations) against its published quick numbers.

docs/transformations-quick.json is written by ``python studies/transformations/run.py --quick
--publish``; these tests recompute a subset of its runs and check them against it, and check
the physics the doc states with independent references:

* a rigid Miura-ori sheet is a one-DOF mechanism whose folded form stays globally flat (K = 0)
  and whose bending under a curved control is a saddle (K < 0) once the panels may strain
  (Schenk & Guest 2013, PNAS 110:3276, out-of-plane Poisson's ratio positive);
* the bar-and-hinge model approaches the rigid limit as 1/r in the stiffness ratio r where
  the targets are compatible (log-log slope -1);
* the DOF analysis's actuators fix the form at their count (form error 0), section-line
  creases at the same count do not (Yoshimura: DOF 10);
* with compliant actuators the bar-and-hinge model converges to the rigid limit as 1/r
  even where the targets are incompatible (both minimise the same energy), and the
  chain-rule derivatives of the control-parameter design match central differences.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
HERE = ROOT / "studies" / "transformations"
PUBLISHED = json.loads((ROOT / "docs" / "transformations-quick.json").read_text())["runs"]


@pytest.fixture(scope="module")
def run_mod():
    sys.path.insert(0, str(HERE))
    try:
        spec = importlib.util.spec_from_file_location("transformations_run", HERE / "run.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)  # defines, runs nothing
        import transform

        yield mod, transform
    finally:
        sys.path.remove(str(HERE))


def _published(params: dict) -> dict:
    return PUBLISHED[json.dumps(params, sort_keys=True)]


def _form(pattern, kappa_L, model="rigid", curve="circle", ky_L=None, actuator_k=None) -> dict:
    out = {"kind": "form", "pattern": pattern, "spacing": 1, "curve": curve,
           "kappa_L": kappa_L, "ky_L": ky_L, "model": model}  # fmt: skip
    if actuator_k is not None:
        out["actuator_k"] = actuator_k
    return out


def _recompute(params: dict) -> dict:
    import cells  # the study's sweep function (studies/transformations is on the path)

    prm = {k: v for k, v in params.items() if k != "kind"}
    return cells.cell(params["kind"], quick=True, steps=6, **prm)


def _check(res: dict, pub: dict) -> None:
    assert res["model_label"] == pub["model_label"]
    for k in ("KL2", "actuator_misfit_deg", "form_error_deg"):
        if k in pub:
            np.testing.assert_allclose(res[k], pub[k], rtol=1e-5, atol=1e-7, err_msg=k)


def test_help_runs_nothing(run_mod, capsys) -> None:
    mod, _ = run_mod
    with pytest.raises(SystemExit) as exc:
        mod.main(["--help"])
    assert exc.value.code == 0
    assert "--quick" in capsys.readouterr().out


def test_quick_run_list_matches_the_published_numbers(run_mod) -> None:
    mod, _ = run_mod
    keys = {json.dumps(p, sort_keys=True) for p in mod.runs(quick=True)}
    assert keys == set(PUBLISHED), "rerun `run.py --quick --publish`"
    for p in mod.runs(quick=True):  # every cell says which model produced it
        assert PUBLISHED[json.dumps(p, sort_keys=True)]["model_label"]


def test_rerun_skips_finished_runs(run_mod, tmp_path, monkeypatch) -> None:
    mod, _ = run_mod
    monkeypatch.setattr(mod, "runs", lambda quick: [_form("miura", 0.0), _form("yoshimura", 1.0)])
    first, _ = mod.run(True, tmp_path, True, None, False)
    again, records = mod.run(True, tmp_path, True, None, False)
    assert (first.skipped, again.skipped, again.total) == (0, 2, 2)
    assert all(r["status"] == "ok" for r in records.values())


def test_bar_and_hinge_converges_to_the_rigid_limit_as_one_over_r(run_mod) -> None:
    """Compatible targets (yoshimura kappa L = 1, miura kappa L = 0): max fold-angle
    distance to the rigid limit falls like 1/r (solver.md, rigid limit)."""
    mod, transform = run_mod
    for pattern, kl, tol in (("yoshimura", 1.0, 0.05), ("miura", 0.0, 0.15)):
        rig = _recompute(_form(pattern, kl))
        _check(rig, _published(_form(pattern, kl)))
        assert rig["actuator_misfit_deg"] < 1e-6
        d = []
        for r in (100.0, 1000.0):
            bh = _recompute(_form(pattern, kl, r))
            _check(bh, _published(_form(pattern, kl, r)))
            d.append(np.max(np.abs(np.asarray(bh["rho_deg"]) - rig["rho_deg"])))
        assert mod.slope([100.0, 1000.0], d) == pytest.approx(-1.0, abs=tol)


def test_rigid_miura_stays_flat_and_bends_into_a_saddle_only_by_straining(run_mod) -> None:
    """Curved control of the one-DOF Miura: the rigid limit can only meet the targets in
    least squares (misfit > 0) and stays globally flat (K = 0); the bar-and-hinge model meets
    them by straining into a saddle (K < 0, Schenk & Guest 2013)."""
    _, transform = run_mod
    rig = _recompute(_form("miura", 1.0))
    _check(rig, _published(_form("miura", 1.0)))
    assert rig["actuator_misfit_deg"] > 1.0 and abs(rig["KL2"]) < 1e-9
    for r in (100.0, 1000.0):  # published only (6 s each)
        assert _published(_form("miura", 1.0, r))["KL2"] < -0.01
    for kx, ky in ((1.0, 1.0), (1.0, -1.0)):  # no control surface makes a rigid Miura curve
        assert abs(_published(_form("miura", kx, "rigid", "parabola", ky))["KL2"]) < 1e-9


def test_dof_placement_fixes_the_form_and_section_lines_do_not(run_mod) -> None:
    _, transform = run_mod
    for placement, fixed in (("dof", True), ("section", False)):
        p = {"kind": "placement", "pattern": "yoshimura", "count": 10, "placement": placement}
        res = _recompute(p)
        _check(res, _published(p))
        assert (res["form_error_deg"] < 1e-6) == fixed


def test_inverse_design_reaches_an_arch_and_says_why_a_miura_cannot_be_a_dome(run_mod) -> None:
    """miura_arc: the arch k2 L = -0.6 (k1 = 0) is reached by the one bh.dof actuator; a Miura
    sheet asked for a dome is not, with the reason (its rigid folds are globally flat)."""
    _, transform = run_mod
    for pattern, k1, k2, reached in (("miura_arc", 0.0, -0.6, True), ("miura", -0.5, -0.5, False)):
        p = {"kind": "design", "pattern": pattern, "target_k1L": k1, "target_k2L": k2}
        res = _recompute(p)
        _check(res, _published(p))
        assert res["reached"] is reached
        assert (res["relative_error"] <= 0.05) is reached
        if not reached:
            assert "does not respond to the actuators" in res["reason"]
    p = {"kind": "design", "pattern": "yoshimura", "target_k1L": 0.2, "target_k2L": -3.0}
    assert _published(p)["relative_error"] < 0.05  # published only (8 s)


def test_a_design_trial_that_cannot_be_folded_is_rejected_not_fatal(run_mod, monkeypatch):
    """A trial whose rigid limit fails (here the search's second evaluation, made to fail)
    gets a penalty residual: the trust region rejects the step and the design still reaches
    the arch, listing the failed trial. A start that cannot be folded fails the run."""
    import design

    from barhinge.errors import BarhingeError

    real, calls = design.forward, []

    def second_fails(cp, acts, steps, jac):
        calls.append(1)
        if len(calls) == 2:
            raise BarhingeError("step 2: locked (made to fail by the test)")
        return real(cp, acts, steps, jac)

    monkeypatch.setattr(design, "forward", second_fails)
    res = design.design("miura_arc", 0.0, -0.6, quick=True, steps=6)
    (failed,) = res["failed_trials"]  # where, and why
    assert failed.startswith(" at [") and failed.endswith(
        "]: step 2: locked (made to fail by the test)"
    )
    assert res["reached"] and res["relative_error"] <= 0.05

    calls.clear()
    calls.append(1)  # the start is now the second call
    with pytest.raises(BarhingeError, match="made to fail"):
        design.design("miura_arc", 0.0, -0.6, quick=True, steps=6)


def test_compliant_actuators_converge_to_the_rigid_limit_for_incompatible_targets(run_mod):
    """Miura, kappa L = 1: no rigid fold meets the curved targets. With compliant actuators
    the rigid limit and the bar-and-hinge model minimise the same energy, and the distance
    falls as 1/r (held actuators stall at the misfit instead: the table above); the strained
    saddle of held actuators (K < 0) vanishes with it, K -> 0 (Schenk & Guest 2013)."""
    mod, transform = run_mod
    k = transform.COMPLIANT_K
    rig = _recompute(_form("miura", 1.0, actuator_k=k))
    _check(rig, _published(_form("miura", 1.0, actuator_k=k)))
    assert rig["actuator_misfit_deg"] > 1.0 and abs(rig["KL2"]) < 1e-9
    d, kl2 = [], []
    ratios = [1e4, 1e5]
    for r in ratios:
        bh = _recompute(_form("miura", 1.0, r, actuator_k=k))
        _check(bh, _published(_form("miura", 1.0, r, actuator_k=k)))
        d.append(np.max(np.abs(np.asarray(bh["rho_deg"]) - rig["rho_deg"])))
        kl2.append(abs(bh["KL2"]))
    assert mod.slope(ratios, d) == pytest.approx(-1.0, abs=0.1)
    assert d[-1] < 0.05 and kl2[1] < 0.05 * kl2[0]


def test_control_design_derivatives_match_central_differences(run_mod) -> None:
    """d(k1 L, k2 L)/d(beta, kx L, ky L) by the chain rule (exact rigid-limit sensitivities x
    the control's target map) against central differences of re-solved rigid limits."""
    _, transform = run_mod
    import design

    cp = transform.make_pattern("yoshimura", True)
    x = np.array([26.0, 0.1, -0.8])
    _, J = design.forward_control(cp, x, 4, True)
    fd = np.zeros_like(J)
    for j, h in enumerate([1e-3, 1e-4, 1e-4]):
        e = np.zeros(3)
        e[j] = h
        kp = design.forward_control(cp, x + e, 4, False)[0]
        km = design.forward_control(cp, x - e, 4, False)[0]
        fd[:, j] = (kp - km) / (2 * h)
    assert np.abs(fd).max() > 0.1
    np.testing.assert_allclose(J, fd, atol=1e-5 * np.abs(fd).max())


def test_control_design_reaches_its_published_target(run_mod) -> None:
    """The published quick design of the control (Yoshimura saddle) is reached, and its
    control reproduces the published form in one rigid fold."""
    _, transform = run_mod
    import design

    p = {"kind": "design", "pattern": "yoshimura", "target_k1L": 0.2, "target_k2L": -2.0,
         "control": "surface"}  # fmt: skip
    pub = _published(p)
    assert pub["reached"] and pub["relative_error"] < 0.05
    v = pub["variables"]
    cp = transform.make_pattern("yoshimura", True)
    k, _ = design.forward_control(cp, np.array([v["beta_deg"], v["kx_L"], v["ky_L"]]), 4, False)
    np.testing.assert_allclose(k, pub["achieved"], rtol=1e-6, atol=1e-8)


def test_every_table_of_the_doc_is_written_and_stamped() -> None:
    import re

    text = (ROOT / "docs" / "transformations.md").read_text()
    blocks = re.findall(r"<!-- BEGIN (\w+) -->\n(.*?)<!-- END \1 -->", text, flags=re.S)
    want = {"stamp", "rigid", "convergence", "compliant", "placement", "design"}
    assert {b for b, _ in blocks} >= want
    assert all(body.strip() for _, body in blocks), "rerun `run.py --publish`"
    assert re.search(r"barhinge \d+\.\d+\.\d+, \d{4}-\d\d-\d\d", dict(blocks)["stamp"])
