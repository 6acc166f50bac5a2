"""``--accuracy`` against the shell (studies/roofs/accuracy_check.py): the scene the check hands
to the chooser is the refine study's roof (same model, supports and load at every level), so
the chooser's picks can be compared with that study's shell references; the table counts a
pick as met only within its target (or the shell reference's own uncertainty)."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="module")
def check(load_study):
    return load_study("roofs/accuracy_check.py", "roofs_accuracy_check")


@pytest.mark.parametrize(("family", "state"), [("miura_arc", 60.0), ("yoshimura", 20.0)])
def test_the_chooser_levels_are_the_refine_study_roofs(check, family, state) -> None:
    """m = 2: the chooser's subdivided scene (supports on edges whose ends are supported, the
    plan load read back from the one-facet scene) and the study's roof (supported lines, plan
    load on every cell) give the same stiffness to round-off; the arched Miura has jagged
    support ends, the Yoshimura triangular facets."""
    from barhinge.analysis.accuracy import _response, subdivided_scene
    from barhinge.analysis.stiffness import linear_response

    roofs = check.roofs
    cp, flat_xy, _ = roofs.folded(family, state)
    sv, se = roofs.support_lines(cp, flat_xy, roofs.FAMILIES[family]["axis"])
    model, S, _ = roofs.subdivided_roof(cp, sv, se, 2, "coupled")
    F = roofs.plan_load(model, roofs.Q)
    U, _ = linear_response(model, F, S)
    study = float(F[:, 2].sum() ** 2 / np.sum(F * U))
    scene = subdivided_scene(check.roof_scene(family, state), 2)
    np.testing.assert_array_equal(np.asarray(scene.supports).any(axis=1), S.any(axis=1))
    assert _response(scene)[0]["stiffness"] == pytest.approx(study, rel=1e-9)


def test_the_table_counts_only_picks_within_their_target(check) -> None:
    shells = {"pleats|90": (100.0, 0.002), "miura60|45": (100.0, 0.04)}
    rows = [
        {"family": "pleats", "state": 90.0, "target": 0.05, "chosen": "N5B8 m=32",
         "n_dof": 1000, "estimate": 0.04, "stiffness": 98.1, "reference": 100.1},
        {"family": "miura60", "state": 45.0, "target": 0.05, "chosen": "N5B8 m=16",
         "n_dof": 1000, "estimate": 0.04, "stiffness": 110.0, "reference": 112.0},
        {"family": "miura60", "state": 45.0, "target": 0.02, "chosen": None, "why": "no model"},
    ]  # fmt: skip
    act = [{"scene": "s", "target": 0.1, "chosen": "rigid", "rigid_estimate": 0.05,
            "rigid_error": 0.12, "estimate": 0.05, "error": 0.12}]  # fmt: skip
    text = check.table(rows, shells, act)
    assert "| pleats 90 | 5 % | N5B8 m=32 | 1,000 | 4.0 % | +0.1 % | -1.9 % | 0.2 % | yes |" in text
    miss = "| miura60 45 | 5 % | N5B8 m=16 | 1,000 | 4.0 % | +12.0 % | +10.0 % | 4.0 % | **no** |"
    assert miss in text
    assert "2 choices on 2 roofs; 1 meet their target" in text and "1 targets refused" in text
    assert text.rstrip().endswith("| **no** |")  # the rigid pick off by more than its target
    assert check.verdict(0.06, 0.05, 0.02) == "within the reference's uncertainty"


def test_a_missing_shell_reference_is_computed_at_the_refine_study_levels(
    check, monkeypatch
) -> None:
    """Without the refine study's cache the check computes the shell reference itself, at the
    full study's levels and budget (``roofs.SHELL_LEVELS``, ``roofs.SHELL_DOF_BUDGET``), not at
    the quick mode's that importing the study would give (three levels, 60,000 DOFs: a
    reference left unsettled), and keeps it in the dict it was handed."""
    import sys

    roofs = check.roofs
    assert roofs.SHELL_LEVELS == (1, 2, 3, 4, 5) and roofs.SHELL_DOF_BUDGET == 4_000_000
    calls = []
    levels = [{"r": r, "stiffness": 100.0 * (1.0 + 0.5**r)} for r in (1, 2, 3, 4, 5)]

    def fake(fam, state, *args):
        calls.append((fam, state, args))
        return levels

    monkeypatch.setattr(roofs, "shell_reference", fake)
    shells: dict = {}
    ref, unc = check.shell_of("miura60", 15.0, shells)
    assert calls == [("miura60", 15.0, ())]  # the defaults: the full levels
    assert shells["shell|miura60|15"] == levels
    # Richardson on an exact order-1 sequence: the limit, and its correction from r = 5
    assert ref == pytest.approx(100.0, rel=1e-9) and unc == pytest.approx(0.5**5, rel=1e-9)
    assert "refine" not in sys.modules  # the refine study's quick run is not started
    check.shell_of("miura60", 15.0, shells)
    assert len(calls) == 1  # read back
