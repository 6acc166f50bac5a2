"""Old module names kept importable after the renames of 0.2, with a DeprecationWarning.

=============================  ==================================
old name                       new name
=============================  ==================================
``barhinge.patterns``          ``barhinge.families``
``barhinge.solve``             ``barhinge.solver``
``barhinge.solve.controls``    ``barhinge.solver.bordered``
``barhinge.control``           ``barhinge.actuators.curves``
``barhinge.plot.control``      ``barhinge.plot.curves``
``barhinge.analysis.summary``  ``barhinge.analysis.final_state``
``barhinge.output.fields``     ``barhinge.fields``
=============================  ==================================

An old module name (or a sub-module under an old package name) is the new module object
itself; an old package name is a thin alias that forwards every attribute to the new package,
so classes and functions are the same objects under both names. ``barhinge.solve`` stays
callable as the function :func:`barhinge.solve` even when imported as a module.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings
from collections.abc import Sequence
from typing import Any

#: old module name -> new module name (sub-modules follow their package)
RENAMED_MODULES: dict[str, str] = {
    "barhinge.solve.controls": "barhinge.solver.bordered",
    "barhinge.patterns": "barhinge.families",
    "barhinge.solve": "barhinge.solver",
    "barhinge.control": "barhinge.actuators.curves",
    "barhinge.plot.control": "barhinge.plot.curves",
    "barhinge.analysis.summary": "barhinge.analysis.final_state",
    "barhinge.output.fields": "barhinge.fields",
}


def new_name(old: str) -> str | None:
    """The current name of the module ``old``, or None if it was not renamed."""
    if old in RENAMED_MODULES:
        return RENAMED_MODULES[old]
    for prefix, target in RENAMED_MODULES.items():
        if old.startswith(prefix + "."):
            return target + old[len(prefix) :]
    return None


def warn_renamed(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` is an old name of ``new``."""
    warnings.warn(
        f"{old} is renamed {new}; the old name will be removed in barhinge 0.3",
        DeprecationWarning,
        stacklevel=stacklevel,
    )


class _PackageAlias(types.ModuleType):
    """An old package name: forwards attributes to the renamed package.

    A distinct module object, so that the import system binding a sub-module on its parent
    (``import old.sub`` sets ``old.sub``) never overwrites a name of the renamed package.
    """

    __new_name__: str

    def __getattr__(self, name: str) -> Any:
        return getattr(importlib.import_module(self.__new_name__), name)


class _CallableSolverAlias(_PackageAlias):
    """``barhinge.solve`` imported as a module: also calls the function :func:`barhinge.solve`."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return importlib.import_module("barhinge.solver.newton").solve(*args, **kwargs)


class _AliasLoader(importlib.abc.Loader):
    def __init__(self, old: str, new: str) -> None:
        self.old, self.new = old, new

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        warn_renamed(self.old, self.new, stacklevel=6)
        if self.old not in RENAMED_MODULES or not hasattr(
            importlib.import_module(self.new), "__path__"
        ):
            return importlib.import_module(self.new)
        kind = _CallableSolverAlias if self.old == "barhinge.solve" else _PackageAlias
        alias = kind(self.old)
        alias.__new_name__ = self.new
        alias.__path__ = []  # sub-modules are found by the finder below
        # sub-modules already imported under the new name: the same objects under the old
        # one, so that importing them does not rebind a name on the alias
        for name, module in list(sys.modules.items()):
            if name.startswith(self.new + "."):
                sys.modules.setdefault(self.old + name[len(self.new) :], module)
        return alias

    def exec_module(self, module: types.ModuleType) -> None:
        """Nothing to run: the module is the renamed one (or the solver alias)."""


class _AliasFinder(importlib.abc.MetaPathFinder):
    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None,
        target: types.ModuleType | None = None,
    ) -> importlib.machinery.ModuleSpec | None:
        new = new_name(fullname)
        if new is None:
            return None
        spec = importlib.machinery.ModuleSpec(fullname, _AliasLoader(fullname, new))
        if fullname in RENAMED_MODULES:
            spec.submodule_search_locations = []
        return spec


def install() -> None:
    """Make the old names importable (idempotent)."""
    if not any(isinstance(f, _AliasFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _AliasFinder())
