"""Shared fixture of the study tests: load a study script in its quick mode."""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest

STUDIES = Path(__file__).resolve().parents[2] / "studies"


@pytest.fixture(scope="module")
def load_study() -> Callable[[str, str], ModuleType]:
    """``load(path, name)``: the study script ``studies/<path>`` imported as ``name``.
    Importing a study runs its quick mode (its results stay at module level)."""

    def load(path: str, name: str) -> ModuleType:
        spec = importlib.util.spec_from_file_location(name, STUDIES / path)
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        assert mod.QUICK
        return mod

    return load


class SubdivisionBuilt(Exception):
    """Raised by the stand-in of :func:`subdivision_gradings` once a roof model is asked for."""


@pytest.fixture
def subdivision_gradings(monkeypatch) -> Callable[[ModuleType], list[float]]:
    """``record(roofs)``: replace ``roofs.subdivided_roof`` (the study's shared module) by a
    stand-in that records the ``grading`` it is asked for and raises ``record.built``
    (:class:`SubdivisionBuilt`); returns the list it records into."""

    def record(roofs: ModuleType) -> list[float]:
        seen: list[float] = []

        def built(*args, grading: float = 1.0, **kwargs):
            seen.append(grading)
            raise SubdivisionBuilt

        monkeypatch.setattr(roofs, "subdivided_roof", built)
        return seen

    record.built = SubdivisionBuilt  # type: ignore[attr-defined]
    return record
