"""`barhinge verify` case multi_cell_flat_start: a 3 x 3 Miura sheet folded from the exact flat
state keeps every crease on its M/V assignment and approaches Schenk & Guest's rigid fold
angles (PNAS 2013, Eq. 1) as 1/stiffness ratio; and the case can fail (it sees the wrong
branch the plain tangent predictor takes)."""

from __future__ import annotations

import math

import pytest

from barhinge import verify


@pytest.fixture(scope="module")
def rows() -> dict[str, verify.Check]:
    return {r.quantity: r for r in verify.run(names=["multi_cell_flat_start"])}


def test_case_passes(rows):
    assert set(rows) == {
        "creases_against_assignment", "rho_zigzag_deg", "rho_straight_deg", "gap_order",
    }  # fmt: skip
    failed = [f"{q}: {r.computed} vs {r.reference} {r.message}" for q, r in rows.items()
              if not r.passed]  # fmt: skip
    assert not failed
    assert rows["creases_against_assignment"].computed == 0.0
    assert rows["gap_order"].computed == pytest.approx(1.0, abs=0.15)
    assert rows["rho_zigzag_deg"].time_s < 3.0


def test_references_are_schenk_guest_at_theta_30():
    """Written out here from the closed forms: zig-zag 2 theta, straight
    2 atan(cos(gamma) tan(theta)) with gamma = 60, theta = 30 deg."""
    q = {x.name: x.reference for x in verify.CASES["multi_cell_flat_start"].quantities}
    assert q["rho_zigzag_deg"] == 60.0
    straight = math.degrees(2 * math.atan(0.5 * math.tan(math.radians(30.0))))
    assert q["rho_straight_deg"] == pytest.approx(straight, rel=1e-14)


def test_gap_is_a_few_hundredths_of_a_degree(rows):
    """The rigid-limit gap at ratio 1e6 is the one the tolerances quote (~0.02 deg)."""
    for q in ("rho_zigzag_deg", "rho_straight_deg"):
        gap = abs(rows[q].computed - rows[q].reference)
        assert 0.005 < gap < 0.06, (q, gap)


def test_case_sees_the_wrong_branch_of_the_tangent_predictor():
    """With the plain tangent predictor the sheet leaves the flat state on a wrong branch:
    the case counts creases against their assignment (measured 19 of 60)."""
    out = verify._multi_cell_flat_start(flat_start="tangent")
    assert out["creases_against_assignment"] > 0
