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
        ok, why = study.stable(r, None)
        assert ok == (r["buckling_factor"] > 1.0)
        assert ok or "linear buckling factor" in why


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
