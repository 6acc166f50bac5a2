"""The roof shell check in its quick mode (studies/roofs/shell_check.py): the shell reference
converges on its own (observed order near its theoretical 2 for CST + Morley, see
tests/model/test_model_shell.py for the textbook plates) and the bar-and-hinge stiffness
moves towards it under panel subdivision."""

from __future__ import annotations

import math

import pytest


@pytest.fixture(scope="module")
def study(load_study):
    mod = load_study("roofs/shell_check.py", "roofs_shell_check")  # runs the quick mode
    return mod


def test_shell_reference_converges(study) -> None:
    (r,) = study.RESULTS
    assert 1.2 < r["shell_rate"] < 2.5
    assert r["shell_uncertainty"] < 0.03
    # every level carries the whole load (plan area x 1 kN/m^2)
    loads = [s["load"] for s in r["shell"]]
    assert max(loads) == pytest.approx(min(loads), rel=1e-12)


def test_bar_hinge_error_shrinks_under_subdivision(study) -> None:
    (r,) = study.RESULTS
    for v in study.VARIANTS:
        e = [abs(x) for x in r["errors"][v]]
        assert e[1] < e[0]
        assert not math.isnan(r["rate"][v]) and r["rate"][v] > 0
    assert "| pleats | 90 |" in study.table(study.RESULTS)


def test_flat_plate_shell_approaches_navier(study) -> None:
    """The shell's compliance stiffness of the simply supported square plate approaches the
    Navier series value (an independent closed form) from below (Morley is soft)."""
    r = [s["ratio"] for s in study.PLATE["shell"]]
    assert r[0] < r[1] < 1.0
    assert r[-1] > 0.9


def test_membrane_bending_split(study) -> None:
    """The split's variants scale one part of the sheet as stated (membrane E t or plate
    E t^3 times ``STIFFENED``, the other kept), and a linear model whose stiffness matrix
    only grows (K + (s - 1) K_part, K_part positive semi-definite) cannot get softer: every
    variant is at least as stiff as the sheet at every level."""
    mats = study.split_materials()
    sheet = mats["sheet"]
    s = study.STIFFENED
    mem, pla = mats["stiff membranes"], mats["stiff plates"]
    assert mem.E * mem.t == pytest.approx(s * sheet.E * sheet.t, rel=1e-12)
    assert mem.E * mem.t**3 == pytest.approx(sheet.E * sheet.t**3, rel=1e-12)
    assert pla.E * pla.t == pytest.approx(sheet.E * sheet.t, rel=1e-12)
    assert pla.E * pla.t**3 == pytest.approx(s * sheet.E * sheet.t**3, rel=1e-12)
    for split in (study.PLATE["split"], study.PLATE["sides"]):  # uniform and graded meshes
        k0 = split["sheet"]["stiffness"]
        for name in ("stiff membranes", "stiff plates"):
            k = split[name]["stiffness"]
            assert all(a >= (1 - 1e-9) * b for a, b in zip(k, k0, strict=True))
    assert study.sides_finding(study.PLATE["sides"]).startswith("7. ")


def test_extrapolation_refuses_a_sequence_outside_its_asymptotic_range(study) -> None:
    """Richardson on h, h/2, h/4: a sequence 1 + c 4^-r (order 2) extrapolates to its limit
    1 exactly; one whose changes barely shrink (observed order below ``MIN_ORDER``, here the
    graded Yoshimura shell's last levels, 1439, 1334, 1234 kN/m) is not extrapolated: the
    finest value stands with an unknown error, never a reference of the wrong sign."""
    ref, p, unc = study.extrapolate([1 + 3.0 * 4.0**-r for r in (1, 2, 3)])
    assert ref == pytest.approx(1.0, rel=1e-12) and p == pytest.approx(2.0, rel=1e-12)
    assert unc == pytest.approx(3.0 * 4.0**-3, rel=1e-12)  # the finest level's error
    ref, p, unc = study.extrapolate([1439.1, 1334.3, 1233.9])
    assert p < study.MIN_ORDER
    assert ref == 1233.9 and math.isinf(unc)


def test_main_rule_is_refined_past_the_fixed_levels(study) -> None:
    """The main rule goes on refining while its stiffness still changes by 2 % or more and the
    next level fits the DOF budget; the other rules keep their levels, and the table shows
    the ragged levels with dashes."""
    (r,) = study.RESULTS
    main = [b["m"] for b in r["bar_hinge"][study.MAIN_RULE]]
    assert main[: len(study.BH_LEVELS)] == study.BH_LEVELS and len(main) > len(study.BH_LEVELS)
    assert max(b["n_dof"] for b in r["bar_hinge"][study.MAIN_RULE]) <= study.DOF_BUDGET
    assert [b["m"] for b in r["bar_hinge"]["plate"]] == study.BH_LEVELS
    text = study.table(study.RESULTS)
    assert f"m = {main[-1]} |" in text
    plate_row = next(line for line in text.splitlines() if "| plate |" in line)
    assert plate_row.rstrip().split("|")[-3].strip() == "–"
