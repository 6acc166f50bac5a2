"""The index dtype of sparse maps and patterns (one rule for the package)."""

from __future__ import annotations

import numpy as np

__all__ = ["index_dtype"]


def index_dtype(*counts: int) -> type[np.signedinteger]:
    """``numpy.int32`` when every count (array sizes, nonzeros, largest index) is at most
    2**31 - 1 (scipy.sparse's rule), else ``numpy.int64``: 32-bit indices halve the maps,
    and scipy.sparse keeps int32 index arrays of matrices that small without copying."""
    return np.int32 if max(counts, default=0) <= np.iinfo(np.int32).max else np.int64
