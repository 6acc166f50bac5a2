"""Single-vertex rigid folding against closed forms.

Degree-4 flat-foldable vertex, sector angles (alpha, beta, pi - alpha, pi - beta) counter-
clockwise with sector i between creases i and i+1 (Kawasaki). Its two folding modes (Huffman
1976; Tachi 2009 "Generalization of rigid-foldable quadrilateral-mesh origami", J. IASS 50;
Evans, Lang, Magleby & Howell 2015, R. Soc. Open Sci. 2:150067; stated as Theorem 6 of
Akitaya, Demaine, Horiyama, Hull, Ku & Tachi 2018, arXiv:1812.01160):

  mode A: tan(rho0/2) = tan(rho2/2) = t,  tan(rho1/2) = -p_A t,  tan(rho3/2) = p_A t,
          p_A = cos((alpha + beta)/2) / cos((alpha - beta)/2);
  mode B: tan(rho1/2) = tan(rho3/2) = t,  tan(rho0/2) = -p_B t,  tan(rho2/2) = p_B t,
          p_B = sin((beta - alpha)/2) / sin((alpha + beta)/2).

(The fold-angle multiplier of Evans et al. in the form tan(rho2/2) = k tan(rho1/2).) The rigid
path is driven by one crease from the flat state; the branch is chosen by the assignment.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import barhinge as bh
from barhinge.errors import ConvergenceError


def _check_mode(path, mode, a, b):
    t = np.tan(np.radians(path.fold_angles_deg[:, :4]) / 2)
    if mode == "A":
        p = np.cos((a + b) / 2) / np.cos((a - b) / 2)
        drive, same, minus, plus = 0, 2, 1, 3
    else:
        p = np.sin((b - a) / 2) / np.sin((a + b) / 2)
        drive, same, minus, plus = 1, 3, 0, 2
    # tolerance: the corrector closes the loop to 1e-13; tan(rho/2) <= tan(75 deg) ~ 3.7
    np.testing.assert_allclose(t[:, same], t[:, drive], rtol=0, atol=1e-10)
    np.testing.assert_allclose(t[:, minus], -p * t[:, drive], rtol=0, atol=1e-10)
    np.testing.assert_allclose(t[:, plus], p * t[:, drive], rtol=0, atol=1e-10)


@settings(max_examples=12, deadline=None)
@given(
    alpha=st.floats(25.0, 80.0),
    beta=st.floats(25.0, 80.0),
    mode=st.sampled_from(["A", "B"]),
    target=st.floats(20.0, 150.0),
)
def test_degree4_flat_foldable_vertex_follows_fold_angle_multiplier(
    vertex_pattern, alpha, beta, mode, target
):
    if mode == "B" and abs(alpha - beta) < 5.0:
        beta = alpha + 10.0  # p_B -> 0 makes mode B fold only creases 1, 3 (still valid)
    a, b = np.radians(alpha), np.radians(beta)
    sectors = [alpha, beta, 180.0 - alpha, 180.0 - beta]
    if mode == "A":
        p = np.cos((a + b) / 2) / np.cos((a - b) / 2)
        asg = ["V", "M" if p > 0 else "V", "V", "V" if p > 0 else "M"]
        drive = 0
    else:
        p = np.sin((b - a) / 2) / np.sin((a + b) / 2)
        asg = ["M" if p > 0 else "V", "V", "V" if p > 0 else "M", "V"]
        drive = 1
    cp = vertex_pattern(sectors, asg)
    path = bh.rigid_fold(cp, [drive], [target], steps=8)
    assert path.kind == "rigid" and path.converged
    np.testing.assert_allclose(
        path.fold_angles_deg[:, drive], np.linspace(0, target, 9), rtol=0, atol=1e-12
    )
    _check_mode(path, mode, a, b)


def test_miura_vertex_multiplier_is_cos_gamma(vertex_pattern):
    """Miura vertex (gamma, pi - gamma, pi - gamma, gamma) from the collinear crease: mode A
    with alpha = beta = pi - gamma, so |tan(rho_straight/2)| = cos(gamma) tan(rho_zigzag/2)
    (Schenk & Guest 2013: rho_s = 2 arctan(cos gamma tan theta), rho_z = 2 theta)."""
    g = 60.0
    cp = vertex_pattern([180 - g, 180 - g, g, g], ["V", "M", "V", "V"])
    path = bh.rigid_fold(cp, [0], [120.0], steps=6)
    rz = np.radians(path.fold_angles_deg[:, 0])
    rs = np.radians(path.fold_angles_deg[:, 1])
    np.testing.assert_allclose(
        np.abs(np.tan(rs / 2)), np.cos(np.radians(g)) * np.tan(rz / 2), rtol=0, atol=1e-12
    )


@pytest.mark.parametrize("degree", [4, 6, 8])
def test_single_vertex_dof(vertex_pattern, degree):
    """A single vertex of degree d: d creases, 3 equations -> d - 3 DOF at a folded state
    (count = rank), d - 2 at the flat state (the out-of-plane row vanishes)."""
    sectors = [360.0 / degree] * degree
    asg = ["V", "M"] * (degree // 2)
    asg[0] = "M" if degree == 4 else asg[0]  # Maekawa 3-1 for the degree-4 vertex
    cp = vertex_pattern(sectors, asg)
    rep = bh.dof(cp)
    assert rep.flat
    assert rep.counted_dof == degree - 3
    assert rep.global_dof == degree - 2
    assert rep.redundant == 1
    assert rep.folded is not None and not rep.folded.flat
    assert rep.folded.global_dof == degree - 3 == rep.folded.counted_dof
    assert rep.folded.redundant == 0
    assert rep.folded.local[0] == degree - 3
    assert len(rep.folded.actuators) == degree - 3


def test_nonflatfoldable_vertex_locks_with_a_clear_error(vertex_pattern):
    """A developable degree-4 vertex that is not flat-foldable cannot fold flat: one crease
    reaches 180 deg before the others, where panels meet (rigid path stops: locking)."""
    cp = vertex_pattern([50.0, 100.0, 120.0, 90.0], ["V", "M", "V", "V"])
    # driven crease 2 cannot reach 179 deg: crease 0 gets to 180 deg first
    with pytest.raises(ConvergenceError, match="locked: crease edge 0") as info:
        bh.rigid_fold(cp, [2], [179.0], steps=40)
    part = info.value.last_state
    assert part is not None and not part.converged and part.n_states >= 2
    assert part.fold_angles_deg[-1, 0] > 150.0
    assert np.abs(part.fold_angles_deg).max() < 180.0


def test_path_through_the_flat_state_records_the_rank_change(vertex_pattern):
    """Folding a degree-4 vertex from +60 deg through flat to -60 deg: the flat state is a
    bifurcation point (DOF 2 to first order, 1 elsewhere); the path records the change and
    continues on the mirrored branch of the same mode (fold angles flip sign)."""
    cp = vertex_pattern([70.0, 50.0, 110.0, 130.0], ["V", "M", "V", "V"])
    up = bh.rigid_fold(cp, [0], [60.0], steps=3)
    folded = cp.replaced(vertices=up.X[-1], fold_angles=up.fold_angles_deg[-1])
    path = bh.rigid_fold(folded, [0], [-60.0], steps=4)
    assert path.meta["dof"] == [1, 1, 2, 1, 1]
    assert any("DOF changed from 1 to 2" in ev for ev in path.meta["events"])
    np.testing.assert_allclose(
        path.fold_angles_deg[-1, :4], -up.fold_angles_deg[-1, :4], rtol=0, atol=1e-9
    )
