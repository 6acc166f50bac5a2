"""The module names of barhinge 0.1 that were renamed stay importable, warn, and give the
same objects as the new names (CHANGELOG, "Renamed")."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import barhinge as bh
from barhinge import _deprecated


@pytest.fixture(autouse=True)
def _restore_package_attributes():
    """Importing an old name binds it on its parent package; undo that after each test so the
    rest of the suite sees ``bh.solve`` as the function again."""
    import barhinge.plot

    saved = {pkg: dict(vars(pkg)) for pkg in (bh, barhinge.plot)}
    for pkg in saved:
        for name in ("patterns", "solve", "control"):
            if name in vars(pkg) and not callable(vars(pkg)[name]):
                delattr(pkg, name)
    yield
    for pkg, attributes in saved.items():
        for name in ("patterns", "solve", "control"):
            if name in attributes:
                setattr(pkg, name, attributes[name])
            elif name in vars(pkg):
                delattr(pkg, name)
    for name in list(sys.modules):
        if _deprecated.new_name(name) is not None:
            del sys.modules[name]


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("barhinge.patterns", "barhinge.families"),
        ("barhinge.patterns.miura", "barhinge.families.miura"),
        ("barhinge.solve.newton", "barhinge.solver.newton"),
        ("barhinge.solve.controls", "barhinge.solver.bordered"),
        ("barhinge.control", "barhinge.actuators.curves"),
        ("barhinge.plot.control", "barhinge.plot.curves"),
        ("barhinge.output.fields", "barhinge.fields"),
    ],
)
def test_old_module_name_warns_and_is_the_new_module(old: str, new: str) -> None:
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=" is renamed barhinge."):
        module = importlib.import_module(old)
    renamed = importlib.import_module(new)
    if hasattr(renamed, "__path__"):  # a package: an alias forwarding every name
        assert all(getattr(module, name) is getattr(renamed, name) for name in renamed.__all__)
    else:
        assert module is renamed
    # importing an old sub-module never rebinds a name of the renamed package
    assert callable(importlib.import_module("barhinge.families").miura)


def test_bh_patterns_attribute_is_bh_families() -> None:
    with pytest.warns(DeprecationWarning, match="barhinge.patterns is renamed barhinge.families"):
        old = bh.patterns
    assert old is bh.families
    assert old.miura is bh.families.miura


def test_old_sub_module_import_keeps_the_package_functions() -> None:
    with pytest.warns(DeprecationWarning):
        import barhinge.patterns.miura  # noqa: F401
        from barhinge.patterns import miura
    assert miura is bh.families.miura and callable(miura)


def test_solve_stays_callable_when_the_old_package_is_imported() -> None:
    # A fresh interpreter: importing the old package name binds ``barhinge.solve`` to a
    # module, which must still call the solver function.
    code = (
        "import warnings; warnings.simplefilter('ignore')\n"
        "import barhinge as bh, barhinge.solve\n"
        "from barhinge.solver.newton import solve\n"
        "assert callable(bh.solve)\n"
        "assert bh.solve.SolverOptions is bh.solver.SolverOptions\n"
        "print(type(bh.solve).__name__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "_CallableSolverAlias"


def test_new_names_import_without_warnings(recwarn: pytest.WarningsRecorder) -> None:
    for name in ("barhinge.families", "barhinge.solver", "barhinge.actuators.curves"):
        importlib.import_module(name)
    assert not [w for w in recwarn if issubclass(w.category, DeprecationWarning)]


def test_new_name_maps_sub_modules() -> None:
    assert _deprecated.new_name("barhinge.solve.branch") == "barhinge.solver.branch"
    assert _deprecated.new_name("barhinge.solver.branch") is None
    assert _deprecated.new_name("barhinge.controls") is None
