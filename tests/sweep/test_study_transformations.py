"""The six-pattern transformation study in its quick mode (studies/transformations/run.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

RUN = Path(__file__).resolve().parents[2] / "studies" / "transformations" / "run.py"


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("transformations")
    mp = pytest.MonkeyPatch()
    mp.setenv("BARHINGE_STUDY_OUT", str(out))
    try:
        spec = importlib.util.spec_from_file_location("transformations_run", RUN)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)  # runs the quick sweep at import
    finally:
        mp.undo()
    return mod


def _result(mod, pattern: str, spacing: int, kappa_L: float) -> dict:
    (rec,) = [
        r
        for r in mod.RECORDS.values()
        if (r["params"]["pattern"], r["params"]["spacing"], r["params"]["kappa_L"])
        == (pattern, spacing, kappa_L)
    ]
    assert rec["status"] == "ok", rec["error"]
    return rec["result"]


def test_every_run_has_one_record_with_result_or_reason(study) -> None:
    n = len(study.PATTERNS) * len(study.SPACINGS) * len(study.KAPPA_L)
    assert len(study.RECORDS) == n == study.REPORT.total
    for rec in study.RECORDS.values():
        assert rec["status"] == "ok" or (rec["error"]["type"] and rec["error"]["message"])
    assert {f[0] for f in study.FAILED} <= {"russo_pleat", "resch"} | set(study.PATTERNS)


def test_synchronised_miura_folds_rigidly_and_alike(study) -> None:
    """kappa = 0: all actuators at the same base angle. The Miura-ori has one DOF (Schenk &
    Guest 2013, PNAS 110:3276), so every copy of a crease folds alike and the sheet stays
    globally flat (K = 0), reached by rigid kinematics."""
    for spacing in study.SPACINGS:
        r = _result(study, "miura", spacing, 0.0)
        assert r["model"] == "rigid"
        assert r["nonsync_deg"] < 1e-9 and abs(r["KL2"]) < 1e-9
        assert r["actuator_error_deg"] < 1e-9


def test_curved_control_of_miura_needs_straining_and_gives_a_saddle(study) -> None:
    """kappa L = 1: the curve asks the actuators for different angles, which over-determines
    the one-DOF rigid Miura-ori; the bar-and-hinge model reaches them by straining the panels,
    the local folding is no longer synchronised and the global form is anticlastic (K < 0): the
    Miura-ori has a positive Poisson's ratio in out-of-plane bending, so it bends into a saddle
    (Schenk & Guest 2013, PNAS 110:3276, abstract)."""
    r = _result(study, "miura", 1, 1.0)
    assert r["model"] == "bar-hinge" and r["rigid_error"]
    assert r["actuator_error_deg"] < 1e-6
    assert r["nonsync_deg"] > 1.0
    assert r["K"] < 0 and r["k1"] > 0 > r["k2"]
    for p in ("miura", "miura_nonuniform"):  # curvature de-synchronises the local folding
        grid = study.RESULTS[p]["nonsync_deg"]
        assert np.all(grid[:, study.KAPPA_L.index(1.0)] > grid[:, study.KAPPA_L.index(0.0)] + 1)
