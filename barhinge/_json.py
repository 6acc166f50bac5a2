"""JSON of barhinge's values: numpy arrays and scalars, paths and tuples become plain JSON.

The one encoder of the package: result files (``summary.json``, the manifest), the
``--json`` output of the CLI, pattern metadata and study records all use it.
"""

from __future__ import annotations

import math
from pathlib import PurePath
from typing import Any

__all__ = ["default", "jsonable"]


def default(o: object) -> object:
    """``json.dumps(..., default=default)``: numpy arrays and scalars (``tolist``) and paths;
    TypeError naming the type for anything else."""
    if hasattr(o, "tolist"):  # numpy arrays and scalars
        return o.tolist()
    if isinstance(o, PurePath):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def jsonable(o: Any, *, nan: bool = True) -> Any:
    """``o`` as plain JSON values, recursively: dict keys become strings, tuples and arrays
    lists, numpy scalars Python numbers, paths strings. With ``nan=False`` a NaN or an
    infinity becomes None (JSON has no NaN)."""
    if isinstance(o, dict):
        return {str(k): jsonable(v, nan=nan) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [jsonable(v, nan=nan) for v in o]
    if hasattr(o, "tolist"):  # numpy arrays and scalars
        return jsonable(o.tolist(), nan=nan)
    if isinstance(o, PurePath):
        return str(o)
    if not nan and isinstance(o, float) and not math.isfinite(o):
        return None
    return o
