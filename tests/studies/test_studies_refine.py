"""The roofs' refinement study in its quick mode (studies/roofs/refine.py): levels stop at the
2 % criterion or the DOF budget, every solve balances its load, an interrupted run resumes
from its cache, and the ranking states every roof's stability once."""

from __future__ import annotations

import json

import pytest


@pytest.fixture(scope="module")
def study(load_study):
    mod = load_study("roofs/refine.py", "roofs_refine")  # runs the quick mode
    assert mod.CACHE is None  # the quick mode writes nothing
    return mod


def test_levels_stop_at_the_criterion_or_the_budget(study) -> None:
    from barhinge.pattern.subdivide import subdivided_size

    for r in study.RESULTS:
        ms = [x["m"] for x in r["rows"]]
        assert ms == list(study.LEVELS[: len(ms)])
        assert max(x["n_dof"] for x in r["rows"]) <= study.DOF_BUDGET
        k = [x["stiffness"] for x in r["rows"]]
        if r["refined"]:
            assert abs(r["change"]) < study.TOL and study.roofs.settled(k, study.TOL)
            assert not study.roofs.settled(k[:-1], study.TOL)  # it stopped at the first one
        else:  # the next level would not fit
            cp, _, _ = study.roofs.folded(r["family"], r["state"])
            assert 3 * sum(subdivided_size(cp, 2 * ms[-1])) > study.DOF_BUDGET
            assert not study.roofs.settled(k, study.TOL)


def test_every_level_balances_its_load(study) -> None:
    for r in study.RESULTS:
        assert r["equilibrium_error"] < 1e-8
        plan = {round(x["plan_area"], 9) for x in r["rows"]}
        assert len(plan) == 1  # every level carries the same load


def test_loose_tolerance_stops_at_the_first_settled_level(study, monkeypatch) -> None:
    """With a loose tolerance the pleats (whose stiffness rises by shrinking changes) settle
    as soon as two changes exist."""
    monkeypatch.setattr(study, "TOL", 10.0)
    rows = study.refine("pleats", 90.0, [])
    assert [x["m"] for x in rows] == [1, 2, 4]
    assert study.summary("pleats", 90.0, rows)["refined"]


@pytest.mark.parametrize(
    ("k", "expect"),
    [
        ([100.0, 90.0, 89.0], True),  # -10 %, -1.1 %: settled
        ([503.1, 549.2, 547.1], False),  # +9.2 %, -0.4 %: turned, small by chance
        ([100.0, 99.0, 97.0], False),  # -1 %, -2 %: the changes grow
        ([100.0, 99.0, 98.9], True),
        ([100.0, 99.9], False),  # one change says nothing about the trend
    ],
)
def test_settled_needs_a_small_change_in_the_asymptotic_range(study, k, expect) -> None:
    assert study.roofs.settled(k, 0.02) is expect


def test_interrupted_run_resumes_from_its_cache(study, tmp_path, monkeypatch) -> None:
    cache = tmp_path / "levels.json"
    first = study.run([("pleats", 90.0)], cache)
    stored = json.loads(cache.read_text())
    assert [x["m"] for x in stored["pleats|90"]] == [x["m"] for x in first[0]["rows"]]

    def no_new_level(*args, **kwargs):
        raise AssertionError("a cached level was computed again")

    monkeypatch.setattr(study, "level", no_new_level)
    again = study.run([("pleats", 90.0)], cache)
    assert again[0]["stiffness"] == first[0]["stiffness"]


def test_ranking_states_every_roof_once(study) -> None:
    text = study.ranking(study.RESULTS, {})
    for r in study.RESULTS:  # the quick roofs are no baselines
        label = f"{r['family']} {r['state']:g}:"
        assert text.count(label) == 1
        assert "linear buckling factor" in text.split(label)[1].splitlines()[0]
        ok, why = study.stable(r, None)
        inst, row = study.nonlinear_verdict(r)
        assert row is not None and row["m"] == study.NONLINEAR_LEVELS[-1]
        assert ok == (inst is None)
        assert ok or f"unstable at load factor {inst:.3f} on the nonlinear path" in why
        # carried by the perfect roof, but the linear estimate below 1: marked
        line = text.split(label)[1].splitlines()[0]
        assert ("imperfection-sensitive" in line) == (ok and not r["buckling_factor"] > 1.0)
    pleats = next(r for r in study.RESULTS if r["family"] == "pleats")
    assert "imperfection-sensitive" in text.split("pleats 90:")[1].splitlines()[0]
    assert pleats["buckling_factor"] < 1.0


def test_without_the_refined_check_the_one_facet_path_and_buckling_decide(study) -> None:
    r = dict(study.RESULTS[0], nonlinear=[], buckling_factor=1.5)
    assert study.stable(r, {"instability_load_factor": ""}) == (True, "")
    ok, why = study.stable(r, {"instability_load_factor": "0.4"})
    assert not ok and "0.400 on the one-facet nonlinear path" in why
    ok, why = study.stable(dict(r, buckling_factor=0.5), None)
    assert not ok and why == "linear buckling factor 0.500"


def test_nonlinear_check_runs_at_its_levels_and_ends_on_a_criterion(study) -> None:
    """Every quick roof is checked at ``NONLINEAR_LEVELS``; a path that keeps its stability
    ends at load factor 1, one that loses it ends there (``arc_stop_instability``)."""
    for r in study.RESULTS:
        rows = r["nonlinear"]
        assert [x["m"] for x in rows] == list(study.NONLINEAR_LEVELS)
        for x in rows:
            assert not x["error"]
            if x["instability_load_factor"] is None:
                assert x["stop"] == "load_factor" and x["load_factor_reached"] == 1.0
            else:
                assert x["stop"] in ("instability", "limit_points")
                assert 0.0 < x["instability_load_factor"] <= x["load_factor_reached"] < 1.0
    table = study.nonlinear_table(study.RESULTS, {})
    assert table.count("\n") == len(study.RESULTS) + 1
    assert "7. **Nonlinear check on refined panels.**" in study.nonlinear_finding(study.RESULTS, {})


@pytest.mark.parametrize(("family", "state"), [("pleats", 90.0), ("yoshimura", 20.0)])
def test_nonlinear_verdict_against_a_dense_eigensolver(study, family, state) -> None:
    """The solver's verdict (the inertia of its sparse LDL^T factor) against the lowest
    eigenvalue of the free tangent from a dense symmetric eigensolver (LAPACK, scipy.linalg.eigh)
    at every state of the path, m = 2: positive at every state the path calls stable, negative
    at the state where it stops for a loss of stability. The pleats carry the design load
    although their linear buckling factor is below 1: their linear response deflects several
    times the nonlinear one (a soft mode that stiffens as it deflects), which the linear
    estimate extrapolates from."""
    import numpy as np
    import scipy.linalg

    roofs = study.roofs
    cp, flat_xy, _ = roofs.folded(family, state)
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[family]["axis"])
    row = study.nonlinear_level(cp, sv, se, 2, keep_path=True)
    path = row["path"]
    model, S, _ = roofs.subdivided_roof(cp, sv, se, 2, study.RULE)
    free = ~S.ravel()

    def lowest(X) -> float:
        K = model.tangent(np.asarray(X)).toarray()[np.ix_(free, free)]
        return float(scipy.linalg.eigh(K, eigvals_only=True, subset_by_index=[0, 0])[0])

    low = [lowest(X) for X in path.X]
    if row["instability_load_factor"] is None:
        assert all(v > 0 for v in low)
        assert low[-1] > 2 * low[0]  # it stiffens along the path
        assert path.load_factor[-1] == pytest.approx(1.0, abs=1e-12)
        lb = study.level(cp, sv, se, 2)["buckling_factor"]
        assert lb < 1.0  # the linear estimate says otherwise
        assert row["deflection_linear"] > 3 * row["deflection_nonlinear"]
    else:
        assert all(v > 0 for v in low[:-1]) and low[-1] < 0
        assert path.load_factor[-1] == pytest.approx(row["instability_load_factor"])
        # the interpolated critical load factor: the dense tangent interpolated just below
        # it is positive definite, just above it is not
        lo, hi = row["instability_bracket"]
        assert lo < row["instability_estimate"] <= hi
        alpha = (row["instability_estimate"] - lo) / (hi - lo)
        Ka = model.tangent(np.asarray(path.X[-2])).toarray()[np.ix_(free, free)]
        Kb = model.tangent(np.asarray(path.X[-1])).toarray()[np.ix_(free, free)]
        for a, sign in ((alpha - 1e-4, 1.0), (alpha + 1e-4, -1.0)):
            ev = scipy.linalg.eigh(Ka + a * (Kb - Ka), eigvals_only=True, subset_by_index=[0, 0])
            assert sign * ev[0] > 0


def test_cell_membrane_error_is_the_worst_face_of_the_roof(study) -> None:
    """``roofs.cell_membrane_error`` against every face computed on its own (no shape
    grouping): the worst homogeneous-mode error of panel_errors, whose reference is the
    closed-form plane-stress energy. Square pleat panels are near exact (the lattice is exact
    at nu = 1/3; the sheet has 0.33), the Yoshimura's right-isosceles triangles are not."""
    import numpy as np

    from barhinge.model.compare import panel_errors

    roofs = study.roofs
    for fam, state, low, high in (("pleats", 90.0, 0.0, 0.01), ("yoshimura", 20.0, 0.5, 0.9)):
        cp, _, _ = roofs.folded(fam, state)
        X = np.asarray(cp.vertices3d)
        worst = 0.0
        for f in cp.faces:
            P = X[list(f)]
            e1 = (P[1] - P[0]) / np.linalg.norm(P[1] - P[0])
            n = np.cross(P[1] - P[0], P[2] - P[0])
            e2 = np.cross(n / np.linalg.norm(n), e1)
            Q = np.column_stack([(P - P[0]) @ e1, (P - P[0]) @ e2])
            e = panel_errors(Q, roofs.material(), "N5B8", "fit", plate_refine=1)
            worst = max(worst, *(abs(v) for k, v in e.items() if k != "warp"))
        got = roofs.cell_membrane_error(cp)
        assert got == pytest.approx(worst, rel=1e-6)
        assert low <= got <= high


def test_ranking_marks_roofs_whose_cells_miss_the_membrane(study) -> None:
    rows = [dict(r, membrane_error=0.7) for r in study.RESULTS]
    text = study.ranking(rows, {})
    assert text.count("indicative: cells' membrane error 0.70") == len(rows)
    assert "bar lattice's own limit" in study.membrane_finding(rows)


def test_refined_models_have_the_exact_cst_membrane(study) -> None:
    """The refinement's models couple the sides of each triangle (``cst``): every roof's cells
    store a uniform membrane strain exactly, where bars (``fit``) miss the Yoshimura's by
    more than half; the finding says both, and every cached level records its membrane."""
    assert study.MEMBRANE == "cst"
    for r in study.RESULTS:
        assert r["membrane_error"] < 1e-9
        assert {x["membrane"] for x in r["rows"]} == {"cst"}
    yosh = next(r for r in study.RESULTS if r["family"] == "yoshimura")
    assert yosh["bar_membrane_error"] > 0.5
    text = study.membrane_finding(study.RESULTS)
    assert "`cst` membrane" in text and f"yoshimura up to {yosh['bar_membrane_error']:.2f}" in text


def test_levels_of_another_membrane_are_recomputed(study) -> None:
    """A cache written with bars (levels without ``membrane: cst``) is not reused."""
    stale = [dict(x, membrane="fit") for x in study.RESULTS[0]["rows"][:2]]
    fam, state = study.RESULTS[0]["family"], study.RESULTS[0]["state"]
    rows = study.refine(fam, state, stale)
    assert {x["membrane"] for x in rows} == {"cst"}
    assert [x["stiffness"] for x in rows] == [x["stiffness"] for x in study.RESULTS[0]["rows"]]


def test_every_roof_has_its_shell_gap(study) -> None:
    """The shell reference of each roof is the Richardson estimate of its graded shell levels
    (``roofs.shell_level``, at least ``SHELL_LEVELS``), and the gap is the refined limit over
    it, both per width; the table and the findings report them."""
    import math

    from barhinge.analysis.accuracy import richardson

    for r in study.RESULTS:
        rs = [s["r"] for s in r["shell"]]
        assert rs[: len(study.SHELL_LEVELS)] == list(study.SHELL_LEVELS)
        ref, _, corr = richardson([s["stiffness"] for s in r["shell"]])
        width = r["rows"][-1]["plan_area"] / study.roofs.SPAN
        assert r["shell_reference_per_width"] == pytest.approx(ref / width, rel=1e-12)
        limit = r["limit_per_width"] * width
        assert r["shell_gap"] == pytest.approx(limit / ref - 1.0, rel=1e-9)
        if math.isfinite(corr):
            assert r["shell_uncertainty"] == pytest.approx(abs(corr / ref), rel=1e-9)
    text = study.table(study.RESULTS, {})
    assert "limit / shell − 1" in text
    assert "6. **Against the shell.**" in study.shell_finding(study.RESULTS)


def test_critical_load_factor_of_a_check(study) -> None:
    """Past a limit point the load maximum is where stability is lost (the first unstable
    state lies below it, on the descending branch); at a bifurcation the interpolated
    estimate inside the bracket; a path that carries the design load has none."""
    base = {"limit_load_factor": None, "instability_load_factor": None, "stop": "load_factor",
            "instability_estimate": None, "instability_bracket": None}  # fmt: skip
    assert study.critical(base) is None
    limit = dict(base, stop="limit_points", limit_load_factor=0.56, instability_load_factor=0.54,
                 instability_bracket=[0.56, 0.54], instability_estimate=0.541)  # fmt: skip
    assert study.critical(limit) == 0.56
    assert study._inst(limit) == "0.560 (limit point)"
    bif = dict(base, stop="instability", instability_load_factor=0.30,
               instability_bracket=[0.28, 0.30], instability_estimate=0.295)  # fmt: skip
    assert study.critical(bif) == 0.295
    assert study._inst(bif) == "0.295 (0.280–0.300)"


def test_nonlinear_csv_has_every_level(study, tmp_path) -> None:
    import csv

    out = tmp_path / "nl.csv"
    study.write_nonlinear_csv(study.RESULTS, out)
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == sum(len(r["nonlinear"]) for r in study.RESULTS)
    for row, x in zip(rows, (x for r in study.RESULTS for x in r["nonlinear"]), strict=True):
        assert int(row["m"]) == x["m"] and row["stop"] == x["stop"]
        crit = study.critical(x)
        assert (row["critical_load_factor"] == "") == (crit is None)


def test_a_check_that_loses_stability_gets_a_second_look(study, monkeypatch) -> None:
    """A nonlinear check that loses stability from the first increment 1/10 is run again from
    1/40 and that path is kept, with the coarse one's critical load factor; a check that
    carries the load, or one already from 1/40, is not run again."""
    calls = []

    def fake(cp, sv, se, m, keep_path=False, steps=study.NONLINEAR_STEPS):
        calls.append((m, steps))
        lost = steps == study.NONLINEAR_STEPS and m == study.NONLINEAR_LEVELS[-1]
        return {"m": m, "membrane": study.MEMBRANE, "n_dof": 10, "first_increment": 1.0 / steps,
                "instability_load_factor": 0.6 if lost else None, "instability_estimate": 0.55
                if lost else None, "instability_bracket": [0.5, 0.6] if lost else None,
                "limit_load_factor": None, "stop": "instability" if lost else "load_factor",
                "load_factor_reached": 0.6 if lost else 1.0, "error": "", "events": [],
                "time_s": 1.0}  # fmt: skip

    monkeypatch.setattr(study, "nonlinear_level", fake)
    saved = []
    rows = study.nonlinear("pleats", 90.0, [], saved.append)
    lo, hi = study.NONLINEAR_LEVELS
    assert calls == [(lo, study.NONLINEAR_STEPS), (hi, study.NONLINEAR_STEPS),
                     (hi, study.FINE_STEPS)]  # fmt: skip
    fine = rows[-1]
    assert fine["m"] == hi and fine["coarse_critical"] == 0.55 and study.critical(fine) is None
    assert fine["time_s"] == 2.0  # both paths' cost
    assert study._inst(fine) == f"stable to 1 (1/{study.NONLINEAR_STEPS}: 0.550)"
    calls.clear()
    assert study.nonlinear("pleats", 90.0, rows, saved.append) == rows
    assert calls == []  # nothing to look at again
    # a cached coarse check without ``first_increment`` (written before it was recorded)
    old = {k: v for k, v in fake(None, None, None, hi).items() if k != "first_increment"}
    calls.clear()
    study.nonlinear("pleats", 90.0, [rows[0], old], saved.append)
    assert calls == [(hi, study.FINE_STEPS)]


def test_a_failed_check_gets_a_second_look_once(study, monkeypatch) -> None:
    """A check that fails from 1/10 is run again from 1/40; the coarse failure is kept as
    ``coarse_error`` and named in the cell; a second failure is not run a third time."""
    calls = []
    hi = study.NONLINEAR_LEVELS[-1]

    def fake(cp, sv, se, m, keep_path=False, steps=study.NONLINEAR_STEPS):
        calls.append((m, steps))
        failed = m == hi and steps == study.NONLINEAR_STEPS
        return {"m": m, "membrane": study.MEMBRANE, "n_dof": 10, "first_increment": 1.0 / steps,
                "instability_load_factor": None, "instability_estimate": None,
                "instability_bracket": None, "limit_load_factor": None, "stop": "load_factor",
                "load_factor_reached": 1.0, "events": [], "time_s": 1.0,
                "error": "arc-length increment 14 did not converge at load factor 0.769834"
                if failed else ""}  # fmt: skip

    monkeypatch.setattr(study, "nonlinear_level", fake)
    rows = study.nonlinear("pleats", 90.0, [], lambda rows: None)
    assert calls[-1] == (hi, study.FINE_STEPS)
    fine = rows[-1]
    assert fine["coarse_error"].startswith("arc-length") and fine["error"] == ""
    assert study._inst(fine) == f"stable to 1 (1/{study.NONLINEAR_STEPS}: failed at 0.770)"
    again = dict(fine, error="no convergence")
    assert not study.needs_second_look(again)  # already from 1/40


def test_finding_names_checks_the_finer_increment_moved(study) -> None:
    """Finding 7 names the checks whose finer path loses stability more than 5 % earlier
    (the coarse increment stepped past the critical point) or later (it converged off the
    path), and the ones it turned."""
    base = {"membrane": study.MEMBRANE, "n_dof": 10, "limit_load_factor": None, "error": "",
            "stop": "instability", "instability_bracket": [0.1, 0.2], "time_s": 1.0,
            "deflection_linear": 1.0, "deflection_nonlinear": 1.0,
            "load_factor_reached": 0.2}  # fmt: skip

    def check(m, crit, was):
        return {**base, "m": m, "instability_load_factor": crit, "instability_estimate": crit,
                "coarse_critical": was}  # fmt: skip

    lo, hi = study.NONLINEAR_LEVELS
    results = [
        {"family": "a", "state": 1.0, "buckling_factor": 2.0,
         "nonlinear": [check(lo, 0.30, 0.40), check(hi, 0.30, 0.40)]},
        {"family": "b", "state": 2.0, "buckling_factor": 2.0,
         "nonlinear": [check(lo, 0.50, 0.20), check(hi, 0.60, 0.61)]},
        {"family": "c", "state": 3.0, "buckling_factor": 2.0,
         "nonlinear": [check(lo, None, 0.25) | {"instability_estimate": None,
                                                "stop": "load_factor"}, check(hi, 0.9, 0.9)]},
    ]  # fmt: skip
    text = study.nonlinear_finding(results, {})
    assert f"a 1 at m = {hi} (0.300, was 0.400)" in text.split("earlier for")[1]
    assert f"b 2 at m = {lo} (0.500, was 0.200)" in text.split("later for")[1]
    assert f"b 2 at m = {hi} (" not in text  # 0.60 against 0.61: within 5 %
    assert f"c 3 at m = {lo} (was 0.250) carry the design load" in text


@pytest.mark.parametrize(
    ("family", "graded"),
    [("miura60", True), ("miura75", True), ("pleats", False), ("flat", False),
     ("miura_arc", False), ("yoshimura", False)],
)  # fmt: skip
def test_grading_goes_where_creases_of_two_directions_meet(study, family, graded, monkeypatch):
    """Sub-panels are graded only on parallelogram panels whose creases meet at an angle
    (the Miura roofs); the pleats' parallel creases meet nowhere and keep equal sub-panels."""
    monkeypatch.setattr(study, "GRADING", 2.0)
    cp, _, _ = study.roofs.folded(family, study.roofs.FAMILIES[family]["states"][0])
    assert study.crease_corners(cp) == (family not in ("pleats", "flat"))
    assert study.grading_of(cp) == (2.0 if graded else 1.0)


def test_the_nonlinear_checks_cut_the_panels_as_the_linear_levels(
    study, monkeypatch, subdivision_gradings
):
    """The refined nonlinear checks are made on the linear levels' sub-panels: graded on the
    Miura roofs (they were once cut into equal ones), equal on the pleats."""
    monkeypatch.setattr(study, "GRADING", 2.0)
    seen = subdivision_gradings(study.roofs)
    for family, state in (("miura60", 30.0), ("pleats", 90.0)):
        cp, flat_xy, _ = study.roofs.folded(family, state)
        sv, se = study.roofs.support_lines(cp, flat_xy, study.roofs.FAMILIES[family]["axis"])
        with pytest.raises(subdivision_gradings.built):
            study.level(cp, sv, se, 4)
        with pytest.raises(subdivision_gradings.built):
            study.nonlinear_level(cp, sv, se, 4)
    assert seen == [2.0, 2.0, 1.0, 1.0]
