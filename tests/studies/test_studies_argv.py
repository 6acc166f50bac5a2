"""The study scripts check their options before running: ``--help`` prints the script's
description and a mistyped option is refused in one line, instead of either starting the
study's full run."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from barhinge._study_args import check_study_argv

ROOT = Path(__file__).resolve().parents[2]
#: the scripts that read their options from sys.argv (the others use argparse)
SCRIPTS = [
    "studies/roofs/refine.py",
    "studies/roofs/run.py",
    "studies/roofs/shell_check.py",
    "studies/speed_accuracy/run.py",
    "studies/stability/run.py",
]


def test_known_options_pass_and_help_prints_the_doc(capsys):
    check_study_argv("doc", ["--quick"], ["--cache"], ["--quick", "--cache=x.json"])
    with pytest.raises(SystemExit) as exc:
        check_study_argv("the script's description", ["--quick"], argv=["--help"])
    assert exc.value.code == 0
    assert "the script's description" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--publsh"], "unknown argument '--publsh'; expected any of --cache=VALUE, --quick"),
        (["--cache"], "option --cache needs a value"),
        (["--cache="], "option --cache needs a value"),
        (["--quick=1"], "option --quick takes no value"),
        (["extra"], "unknown argument 'extra'"),
    ],
)
def test_bad_options_are_refused_in_one_line(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        check_study_argv("doc", ["--quick"], ["--cache"], argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


@pytest.mark.parametrize("script", SCRIPTS)
def test_every_study_script_answers_help_and_refuses_a_typo_at_once(script):
    path = ROOT / script
    ok = subprocess.run(
        [sys.executable, str(path), "--help"], capture_output=True, text=True, timeout=120
    )
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.strip().splitlines()[0]  # the script's own description
    bad = subprocess.run(
        [sys.executable, str(path), "--no-such-option"], capture_output=True, text=True,
        timeout=120,
    )  # fmt: skip
    assert bad.returncode == 2
    assert "unknown argument '--no-such-option'" in bad.stderr
