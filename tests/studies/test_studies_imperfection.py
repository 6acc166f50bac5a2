"""The imperfect-roof study (studies/roofs/imperfection.py) in its quick mode: every roof at
both amplitudes, amplitudes from the code rules, the section and CSV carry every check, and
the refined ranking reads the verdicts back."""

from __future__ import annotations

import csv
import importlib.util
from pathlib import Path

import pytest

STUDY = Path(__file__).resolve().parents[2] / "studies" / "roofs" / "imperfection.py"


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("imperfection_study", STUDY)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def quick_rows(study):
    roofs = [("pleats", 90.0), ("waterbomb", 0.6)]
    return study.run(roofs, 2, None)


def test_every_roof_is_checked_at_every_amplitude(study, quick_rows) -> None:
    assert len(quick_rows) == 2 * len(study.AMPLITUDES)
    for r in quick_rows:
        assert r["error"] == ""
        assert r["stop"] in ("load_factor", "instability", "limit_points")
        assert r["deflection_nonlinear"] > 0.0
    # the amplitudes: b/200 of the pleats' 0.5 m panels (EN 1993-1-5), span/300 of 4 m
    pleats = {r["imperfection"]: r for r in quick_rows if r["family"] == "pleats"}
    assert pleats["b/200"]["panel_side"] == pytest.approx(0.5)
    assert pleats["b/200"]["amplitude"] == pytest.approx(0.5 / 200)
    assert pleats["span/300"]["amplitude"] == pytest.approx(4.0 / 300)


def test_section_and_csv_carry_every_check(study, quick_rows, tmp_path) -> None:
    perfect = study.perfect_rows()
    text = study.section(quick_rows, perfect)
    assert text.startswith(study.START) and text.endswith(study.END)
    for name in study.AMPLITUDES:
        assert f"**w0 = {name}**" in text
    assert "| pleats | 90 |" in text and "| waterbomb | 0.6 |" in text
    out = tmp_path / "imperfect.csv"
    study.write_csv(quick_rows, out)
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["family"], r["imperfection"]) for r in rows] == [
        (r["family"], r["imperfection"]) for r in quick_rows
    ]


def test_only_roofs_that_carry_the_load_perfect_are_seeded(study) -> None:
    perfect = study.perfect_rows()
    carried = [k for k, r in perfect.items() if study.carries(r)]
    assert carried, "the refined study's CSV names roofs that carry the load"
    for k in carried:
        assert perfect[k]["stop"] == "load_factor" and not perfect[k]["critical_load_factor"]
    # yoshimura 10 loses stability on the perfect path (docs/roofs.md): not seeded
    assert ("yoshimura", 10.0) not in carried


def test_critical_prefers_the_limit_point_then_the_estimate(study) -> None:
    row = {"limit_load_factor": None, "instability_estimate": 0.5,
           "instability_load_factor": 0.6}  # fmt: skip
    assert study.critical(row) == 0.5
    assert study.critical({**row, "limit_load_factor": 0.7}) == 0.7
    assert study.critical({**row, "instability_estimate": None}) == 0.6
    assert study.critical({k: None for k in row}) is None


def test_verdict_names_the_coarse_increment_where_the_finer_path_differs(study) -> None:
    base = {"error": "", "limit_load_factor": None, "instability_load_factor": None,
            "instability_estimate": None}  # fmt: skip
    assert study.verdict(base) == "carries the design load"
    flipped = {**base, "coarse_critical": 0.326}
    assert study.verdict(flipped) == (
        f"carries the design load (increment 1/{study.STEPS}: loses stability at 0.326)"
    )
    lost = {**base, "instability_estimate": 0.918, "coarse_critical": 0.667}
    assert study.verdict(lost) == f"loses stability at 0.918 (increment 1/{study.STEPS}: 0.667)"
    assert study.verdict({**base, "error": "no convergence"}) == "failed: no convergence"
    ahead = {**lost, "coarse_critical": None, "stop": "critical_ahead"}
    assert study.verdict(ahead) == "loses stability at 0.918 (extrapolated, ‡)"
    assert "‡ The path's increments fail just before" in "\n".join(study._ahead_note([ahead]))
    assert study._ahead_note([lost]) == []
    rescued = {**lost, "coarse_critical": None, "coarse_error": "no convergence"}
    assert study.verdict(rescued) == f"loses stability at 0.918 (increment 1/{study.STEPS}: failed)"


def test_sensitivity_tasks_and_amplitudes(study) -> None:
    """Modes 1 .. 4 at both code amplitudes, and the first mode at the larger bows, whose
    amplitudes are the span of 4 m over 150 and 75."""
    tasks = study.sensitivity_tasks()
    assert len(tasks) == len(set(tasks)) == 4 * len(study.AMPLITUDES) + 2
    assert {k for _, k in tasks} == {1, 2, 3, 4}
    assert ("span/75", 1) in tasks and ("span/75", 2) not in tasks
    import roofs

    cp = roofs.folded("pleats", 90.0)[0]
    assert study.amplitude("span/150", cp) == pytest.approx(4.0 / 150)
    assert study.amplitude("span/75", cp) == pytest.approx(4.0 / 75)


def _row(fam, state, name, mode, factor=0.5, deflection=0.01, crit=None):
    return {"family": fam, "state": state, "imperfection": name, "mode": mode, "error": "",
            "buckling_factor": factor, "amplitude": 0.01, "deflection_nonlinear": deflection,
            "limit_load_factor": None, "instability_load_factor": crit,
            "instability_estimate": crit}  # fmt: skip


def test_sensitivity_picks_the_lowest_factor_and_names_the_worst_mode(study) -> None:
    """One roof per family, the lowest first buckling factor, baselines left out; the worst
    mode is the earliest loss of stability, else the largest deflection."""
    first = [_row("pleats", 30.0, "b/200", 1, factor=0.13), _row("pleats", 90.0, "b/200", 1),
             _row("flat", 0.0, "b/200", 1, factor=0.01),
             _row("pleats", 60.0, "b/200", 2, factor=0.01)]  # fmt: skip
    assert study.sensitivity_roofs(first) == [("pleats", 30.0)]
    perfect = {("pleats", 30.0): {"deflection_nonlinear": "0.01"}}
    rows = [_row("pleats", 30.0, n, k, deflection=0.01 * (1 + k / 10)) for n, k in
            study.sensitivity_tasks()]  # fmt: skip
    rows[study.sensitivity_tasks().index(("span/300", 2))].update(
        instability_load_factor=0.8, instability_estimate=0.8
    )
    text = study.sensitivity_section(rows, perfect)
    assert text.startswith(study.SENS_START) and text.endswith(study.SENS_END)
    # b/200: the largest deflection (mode 4); span/300: the loss of stability (mode 2)
    assert "b/200: mode 4, × 1.40 against × 1.10" in text
    assert "span/300: mode 2, loses stability at 0.800 against × 1.10" in text
    assert "1 of the 10 checks lose stability" in text
    assert text.count("| pleats | 30 |") == 4 + 1  # four modes, one amplitude row


def test_a_failed_check_is_run_again_with_the_finer_increment(study, monkeypatch) -> None:
    """A coarse path that fails gets the second look a lost stability gets: the check again
    from the first increment 1 / FINE_STEPS, kept with the coarse failure beside it."""
    calls = []

    def fake_check(fam, state, m, name, steps=study.STEPS, mode=1):
        calls.append(steps)
        row = {"family": fam, "state": state, "imperfection": name, "mode": mode,
               "error": "", "limit_load_factor": None, "instability_estimate": None,
               "instability_load_factor": None, "first_increment": 1.0 / steps}  # fmt: skip
        if steps == study.STEPS:
            return {**row, "error": "arc-length increment 10 did not converge"}
        return {**row, "limit_load_factor": 0.775}

    monkeypatch.setattr(study, "check", fake_check)
    [row] = study.run([("miura60", 15.0)], 8, None, [("b/200", 2)])
    assert calls == [study.STEPS, study.FINE_STEPS]
    assert row["error"] == "" and row["coarse_error"].startswith("arc-length increment 10")
    assert study.verdict(row) == f"loses stability at 0.775 (increment 1/{study.STEPS}: failed)"


def test_imperfect_roofs_are_cut_as_the_refined_study(study, subdivision_gradings, tmp_path):
    """The imperfect roof is the refined study's model: sub-panels graded on the Miura roofs
    (:func:`roofs.grading_of`), equal on the pleats; a cached check cut otherwise is redone."""
    import json

    seen = subdivision_gradings(study.roofs)
    for family, state in (("miura60", 30.0), ("pleats", 90.0)):
        with pytest.raises(subdivision_gradings.built):
            study.check(family, state, 2, "b/200")
    assert seen == [2.0, 1.0]
    # a cached check of equal sub-panels on a graded roof is not read back: checked again
    cache = tmp_path / "imperfection_cache.json"
    cache.write_text(json.dumps({study._key("miura60", 30.0, 2, "b/200"): {"grading": 1.0}}))
    with pytest.raises(subdivision_gradings.built):
        study.run([("miura60", 30.0)], 2, cache)
    assert seen[-1] == 2.0
