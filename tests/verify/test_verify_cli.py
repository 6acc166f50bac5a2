"""`barhinge verify`: every reference case passes, the table is complete, failures fail.

The reference values themselves are closed forms from the literature (cited per case in
barhinge/verify.py); these tests check the runner: that the full set passes, that it covers
at least 15 published values with citations, and that a wrong reference or a crashing case
is reported as a failure with exit code 1.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from barhinge import verify
from barhinge.cli import app


@pytest.fixture(scope="module")
def full_run() -> dict:
    res = CliRunner().invoke(app, ["verify", "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.output)


def test_verify_all_pass(full_run):
    failed = [f"{c['case']}/{c['quantity']}: {c['message']}" for c in full_run["checks"]
              if not c["passed"]]  # fmt: skip
    assert not failed
    assert full_run["passed"] is True


def test_verify_covers_15_published_values(full_run):
    checks = full_run["checks"]
    assert len(checks) >= 15
    assert full_run["n_cases"] >= 10
    for c in checks:
        assert c["citation"].strip(), c
        assert c["why"].strip(), c  # every tolerance says why
        assert c["time_s"] >= 0.0
    # each case is registered with a description and at least one quantity
    for case in verify.CASES.values():
        assert case.citation and case.description and case.quantities


def test_verify_quick_is_a_subset():
    quick = {c.name for c in verify.CASES.values() if c.quick}
    assert quick and quick < set(verify.CASES)


def _bad_case(factor: float = 1.1) -> verify.Case:
    """The Filipov bar-area case with its first reference deliberately off by 10 %."""
    good = verify.CASES["filipov_bar_areas"]
    q0 = good.quantities[0]
    wrong = dataclasses.replace(q0, reference=q0.reference * factor)
    return dataclasses.replace(good, name="deliberately_wrong", quantities=(wrong,))


def test_wrong_reference_fails():
    rows = verify.run([_bad_case()])
    assert len(rows) == 1
    assert not rows[0].passed
    assert rows[0].error == pytest.approx(1 - 1 / 1.1, rel=1e-6)


def test_crashing_case_fails_with_message():
    def boom() -> dict[str, float]:
        raise RuntimeError("kaput")

    case = verify.Case("crash", "nobody 2000", "raises", boom, (verify.Quantity("x", 1.0, 1e-9,
                       "n/a"),))  # fmt: skip
    (row,) = verify.run([case])
    assert not row.passed and "kaput" in row.message


def test_cli_exit_code_1_on_failure(monkeypatch):
    bad = _bad_case()
    monkeypatch.setitem(verify.CASES, bad.name, bad)
    res = CliRunner().invoke(app, ["verify", "--case", bad.name, "--json"])
    assert res.exit_code == 1
    data = json.loads(res.output)
    assert data["n_failed"] == 1 and data["passed"] is False
    res = CliRunner().invoke(app, ["verify", "--case", bad.name])
    assert res.exit_code == 1
    assert "FAIL" in res.output


def test_cli_subprocess_table():
    """The installed entry point (through ``main``) prints the table and exits 0."""
    cmd = [sys.executable, "-c", "from barhinge.cli import main; main()", "verify", "--case",
           "filipov_bar_areas", "--case", "degree4_vertex"]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert "A_X" in res.stdout and "5/5 checks passed" in res.stdout
    assert "Filipov" in res.stdout
