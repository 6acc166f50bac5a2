"""Read a crease pattern from a file, choosing the reader by suffix (.fold or .svg)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = ["read", "READERS"]

#: file suffix -> reader module and function name
READERS = {
    ".fold": ("barhinge.pattern.fold", "read_fold"),
    ".svg": ("barhinge.pattern.svg", "read_svg"),
}


def read(path: str | Path, **kwargs: Any) -> CreasePattern:
    """Read a crease pattern from a ``.fold`` or ``.svg`` file.

    Parameters
    ----------
    path : path
        The file; its suffix (case-insensitive) selects the reader.
    **kwargs
        Passed to :func:`barhinge.pattern.fold.read_fold` or
        :func:`barhinge.pattern.svg.read_svg`.
    """
    import importlib

    path = Path(path)
    try:
        module, name = READERS[path.suffix.lower()]
    except KeyError:
        if path.suffix.lower() == ".toml":
            raise PatternError(
                f"{path.name} is a scene TOML, not a crease pattern: crease patterns are read "
                f"from {' or '.join(READERS)} files (the scene's [pattern] table names its file "
                f"or family)"
            ) from None
        raise PatternError(
            f"{path.name}: unknown crease-pattern file type {path.suffix!r}; expected "
            f"{' or '.join(READERS)}"
        ) from None
    if path.is_dir():
        raise PatternError(f"{path}: is a folder, not a crease-pattern file")
    if not path.is_file():
        raise PatternError(f"{path}: no such file")
    return getattr(importlib.import_module(module), name)(path, **kwargs)
