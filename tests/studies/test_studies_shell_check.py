"""The roof shell check in its quick mode (studies/roofs/shell_check.py): the shell reference
converges on its own (observed order near its theoretical 2 for CST + Morley, see
tests/model/test_model_shell.py for the textbook plates) and the bar-and-hinge stiffness
moves towards it under panel subdivision."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

RUN = Path(__file__).resolve().parents[2] / "studies" / "roofs" / "shell_check.py"


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("roofs_shell_check", RUN)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # runs the quick mode at import
    assert mod.QUICK
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
