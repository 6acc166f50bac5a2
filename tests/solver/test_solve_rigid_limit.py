"""Rigid limit: a Miura sheet folded by actuators converges to rigid-origami kinematics.

Reference: Schenk & Guest (2013), "Geometry of Miura-folded metamaterials", PNAS 110(9),
3276-3281, Eq. 1 (cell dimensions S, L as functions of the facet angle theta) and Eq. 2
(in-plane Poisson's ratio nu_SL = -cos^2(theta) tan^2(gamma)); the fold angles of the two
crease families are rho_zigzag = 2 theta and tan(rho_straight / 2) = cos(gamma) tan(theta)
(both via ``bh.families.miura_geometry``).

The compliant sheet starts stress-free at theta = 10 deg and the creases of one straight
crease line are driven to their rigid angles at theta = 40 deg; the rest follows through the
bars and panels. Scaling bars and panel bending by a stiffness ratio r (folds unchanged), the
deviation from the closed forms must fall like 1/r: the slope of log(error) against log(r)
is checked to be -1 within 0.15. The ratios start at 10: with the default (plate-calibrated)
panel bending the 1/r regime starts there (the Filipov 2017 hinges were ~4x stiffer, so r = 1
was already in it).
"""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.families import miura_line_creases
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene

NX = NY = 3
GAMMA = 60.0
TH0, TH1, STEPS = 10.0, 40.0, 6
RATIOS = np.array([10.0, 100.0, 1000.0])


def _theta_of_straight(rho_deg: float) -> float:
    """Facet angle from the straight-crease fold angle, inverting tan(rho/2) = cos(g) tan(th)."""
    r = np.radians(abs(rho_deg))
    return float(np.degrees(np.arctan(np.tan(r / 2) / np.cos(np.radians(GAMMA)))))


def _dims(X: np.ndarray) -> tuple[float, float]:
    """Cell half-length L (x) and half-width S (y) from the middle row / column of the grid
    (vertex (i, j) has id j (2 NX + 1) + i)."""
    ni, nj = 2 * NX + 1, 2 * NY + 1
    vid = lambda i, j: j * ni + i  # noqa: E731
    L = np.linalg.norm(X[vid(ni - 1, NY)] - X[vid(0, NY)]) / (2 * NX)
    S = np.linalg.norm(X[vid(NX, nj - 1)] - X[vid(NX, 0)]) / (2 * NY)
    return float(L), float(S)


@pytest.fixture(scope="module")
def errors() -> dict[str, np.ndarray]:
    cp0 = bh.families.miura(NX, NY, alpha=GAMMA, fold=TH0)
    cp1 = bh.families.miura(NX, NY, alpha=GAMMA, fold=TH1)
    edges = miura_line_creases(bh.families.miura(NX, NY, alpha=GAMMA))
    creases = cp0.crease_edges
    g1 = bh.families.miura_geometry(1.0, 1.0, GAMMA, TH1)
    out: dict[str, list[float]] = {"angle": [], "L": [], "S": [], "nu": []}
    for r in RATIOS:
        model = BarHingeModel.from_pattern(
            cp0,
            "N5B8",
            Material(E=1e6, nu=0.3, t=0.01),
            fold_stiffness=1e-2,
            stiffness_ratio=float(r),
        )
        acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp1.fold_angles)[edges])
        path = bh.solve(Scene(model, actuators=acts, steps=STEPS))
        rho = path.fold_angles_deg[-1][creases]
        out["angle"].append(np.abs(rho - np.asarray(cp1.fold_angles)[creases]).max())
        L, S = _dims(path.X[-1])
        out["L"].append(abs(L - g1.L))
        out["S"].append(abs(S - g1.S))
        # Poisson's ratio by central differences over states k-1, k+1, compared with the same
        # differences of the closed-form dimensions at the states' facet angles
        k = STEPS - 1
        th = [_theta_of_straight(path.actuator_targets_deg[i, 0]) for i in (k - 1, k, k + 1)]
        (La, Sa), (Lk, Sk), (Lb, Sb) = (_dims(path.X[i]) for i in (k - 1, k, k + 1))
        nu = -((Lb - La) / Lk) / ((Sb - Sa) / Sk)
        ga, gk, gb = (bh.families.miura_geometry(1.0, 1.0, GAMMA, t) for t in th)
        nu_rigid = -((gb.L - ga.L) / gk.L) / ((gb.S - ga.S) / gk.S)
        # the rigid difference quotient itself reproduces S&G Eq. 2 to O(dtheta^2)
        assert nu_rigid == pytest.approx(gk.nu_SL, rel=1e-2)
        out["nu"].append(abs(nu - nu_rigid))
    return {k: np.asarray(v) for k, v in out.items()}


@pytest.mark.parametrize("quantity", ["angle", "L", "S", "nu"])
def test_error_falls_like_one_over_stiffness_ratio(errors, quantity):
    e = errors[quantity]
    slope = np.polyfit(np.log(RATIOS), np.log(e), 1)[0]
    assert slope == pytest.approx(-1.0, abs=0.15), (quantity, e)


def test_stiffest_sheet_matches_closed_forms(errors):
    # at r = 1000 the fold angles are within 0.5 deg and the dimensions within 0.1 %
    assert errors["angle"][-1] < 0.5
    assert errors["L"][-1] < 1e-3 and errors["S"][-1] < 1e-3
