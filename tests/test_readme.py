"""The README keeps its promises: two set-up commands on its first screen, and its Python
example runs and folds the Miura as stated (rigid DOF 1; actuator reaches its target)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def test_first_screen_has_the_two_setup_commands() -> None:
    first = README.read_text().splitlines()[:30]
    text = "\n".join(first)
    assert "barhinge fold" in text
    assert "pytest" in text
    assert sum("python3 -m venv" in line for line in first) == 2


def test_python_example_runs(tmp_path: Path, monkeypatch) -> None:
    block = re.search(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert block is not None
    monkeypatch.chdir(tmp_path)
    ns: dict = {"__name__": "readme_example"}
    exec(compile(block.group(1), str(README), "exec"), ns)
    # Schenk & Guest (2013): a Miura-ori sheet with rigid panels is a 1-DOF mechanism
    assert ns["rep"].mechanism.global_dof == 1
    a = ns["a"]
    np.testing.assert_allclose(
        ns["fp"].fold_angles_deg[-1, a], ns["cp"].fold_angles[a] / 2, atol=1e-6
    )
    assert ns["path"].converged and ns["fp"].converged
