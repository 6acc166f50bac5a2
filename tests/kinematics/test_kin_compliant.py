"""Compliant actuators in the rigid limit: springs to their targets instead of held creases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.verify import degree4_pattern

#: fold-spring stiffness per edge of the degree-4 vertex (creases 0..3, then the rim)
W = np.array([1.0, 2.0, 0.5, 1.5, 1.0, 1.0, 1.0, 1.0])


def _mmvm():
    return degree4_pattern().replaced(assignment=np.array(list("MMVMBBBB")))


def _closed_form_minimum(k: float, target_deg: float) -> float:
    """Fold angle of crease 0 at the least fold-plus-actuator-spring energy, by a scalar
    minimisation on the closed-form motion of the MMVM branch (Huffman 1976; Lang, Twists
    Tilings and Tessellations, 2018): rho_2 = -rho_0, rho_1 = rho_3 = 2 atan(q tan(rho_0 / 2)),
    q = sin((a + b)/2) / sin((a - b)/2), a = 70 deg, b = 50 deg."""
    a, b = math.radians(70.0), math.radians(50.0)
    q = math.sin((a + b) / 2) / math.sin((a - b) / 2)
    t = math.radians(target_deg)

    def energy(r0: float) -> float:
        r1 = 2 * math.atan(q * math.tan(r0 / 2))
        folds = W[0] * r0**2 + W[1] * r1**2 + W[2] * r0**2 + W[3] * r1**2
        return 0.5 * k * (r0 - t) ** 2 + 0.5 * folds

    lo, hi = sorted((t, 0.0))
    res = minimize_scalar(energy, bounds=(lo, hi), method="bounded", options={"xatol": 1e-13})
    return math.degrees(res.x)


@pytest.mark.parametrize("k", [3.0, 30.0, 300.0])
def test_compliant_actuator_meets_the_closed_form_energy_minimum(k):
    acts = bh.Actuators(edges=[0], targets_deg=[-40.0], stiffness=k)
    path = bh.rigid_fold(_mmvm(), acts, steps=6, fold_stiffness=W)
    rho = path.fold_angles_deg[-1]
    want = _closed_form_minimum(k, -40.0)
    assert rho[0] == pytest.approx(want, abs=1e-6)
    assert path.meta["compliant_actuators"] and not path.meta["least_squares"]
    assert path.meta["actuator_misfit_deg"][-1] == pytest.approx(abs(want + 40.0), abs=1e-6)
    # the motion stays rigid: the closed-form relations of the branch hold
    a, b = math.radians(70.0), math.radians(50.0)
    q = math.sin((a + b) / 2) / math.sin((a - b) / 2)
    r1 = math.degrees(2 * math.atan(q * math.tan(math.radians(rho[0]) / 2)))
    np.testing.assert_allclose(rho[:4], [rho[0], r1, -rho[0], r1], atol=1e-7)


def test_stiff_compliant_actuators_approach_held_ones():
    """The misfit of a spring of stiffness k against folds of stiffness ~1 falls as 1/k."""
    held = bh.rigid_fold(_mmvm(), [0], targets_deg=[-40.0], steps=6, fold_stiffness=W)
    miss = []
    for k in (1e3, 1e4):
        acts = bh.Actuators(edges=[0], targets_deg=[-40.0], stiffness=k)
        path = bh.rigid_fold(_mmvm(), acts, steps=6, fold_stiffness=W)
        miss.append(np.abs(path.fold_angles_deg[-1][:4] - held.fold_angles_deg[-1][:4]).max())
    assert miss[1] < 0.2 and miss[0] / miss[1] == pytest.approx(10.0, rel=0.05)


@pytest.mark.parametrize(
    ("stiffness", "words"),
    [(0.0, "stiffness = 0.0 for edge 0"), (-1.0, "expected a finite value > 0"),
     ([1.0, 2.0, 3.0], "has 3 entries, but actuators.edges has 2")],
)  # fmt: skip
def test_bad_actuator_stiffness_is_named(stiffness, words):
    with pytest.raises(ConfigError, match=words):
        bh.Actuators(edges=[0, 1], targets_deg=[10.0, 10.0], stiffness=stiffness)


def test_the_documented_example_runs(capsys):
    """The compliant-actuator example of docs/kinematics.md runs and prints the stretch."""
    import re
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "kinematics.md").read_text()
    blocks = [b for b in re.findall(r"```python\n(.*?)```", doc, flags=re.S) if "stiffness=" in b]
    assert len(blocks) == 1
    exec(compile(blocks[0], "docs/kinematics.md", "exec"), {})
    assert float(capsys.readouterr().out.split()[-1]) > 1.0


def test_a_fold_that_falls_back_to_flat_says_so():
    """Compliant actuators whose targets no rigid fold off the flat state meets (a 5 x 5
    Miura sheet with 27 actuators on two crossing section lines, targets of mixed sign from
    the transformation study's control-surface design at beta = 5 deg, kx L = 3, ky L = 2.8):
    the least-squares corrector closes every loop only at the flat state, which is not an
    equilibrium of the actuator springs. The error says that, not that the loop-closure
    residual failed to close (it closed, to 3e-14)."""
    from barhinge.errors import ConvergenceError

    edges = [166, 167, 168, 169, 170, 171, 172, 173, 174, 115, 14, 126, 25, 137]
    edges += [34, 148, 45, 159, 54, 65, 181, 74, 192, 85, 203, 94, 214]
    targets = [1.5, 13.1, 6.1, 19.4, 11.0, 19.4, 6.1, 13.1, 1.5, -2.5, 7.9, -1.6, 9.0, -0.3]
    targets += [10.5, 1.3, 12.1, 2.7, 16.9, 16.0, 1.3, 10.5, -0.3, 9.0, -1.6, 7.9, -2.5]
    acts = bh.Actuators(edges=edges, targets_deg=targets, stiffness=100.0)
    with pytest.raises(ConvergenceError, match="falling back to the flat state") as err:
        bh.rigid_fold(bh.families.miura(5, 5), acts, steps=8)
    assert "did not close" not in str(err.value)
    assert err.value.step == 0  # nothing converged: the first step failed
