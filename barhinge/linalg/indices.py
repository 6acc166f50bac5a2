"""The index dtype of sparse maps and patterns (one rule for the package)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["gather_into", "index_dtype", "pattern_positions"]

#: entries gathered at a time by :func:`gather_into`
GATHER_CHUNK = 1 << 20


def index_dtype(*counts: int) -> type[np.signedinteger]:
    """``numpy.int32`` when every count (array sizes, nonzeros, largest index) is at most
    2**31 - 1 (scipy.sparse's rule), else ``numpy.int64``: 32-bit indices halve the maps,
    and scipy.sparse keeps int32 index arrays of matrices that small without copying."""
    return np.int32 if max(counts, default=0) <= np.iinfo(np.int32).max else np.int64


def pattern_positions(
    indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray, cols: np.ndarray
) -> np.ndarray:
    """(len(rows),) int64: the index into the values of the CSR pattern ``(indptr, indices)``
    (sorted indices, no duplicates) of every entry ``(rows[q], cols[q])``, -1 where the
    pattern has none.

    One look-up per entry in its row (scipy's CSR sampling: a binary search per entry for
    many entries), through a CSR of the pattern whose values are the 1-based positions."""
    rows, cols = np.asarray(rows, np.int64).ravel(), np.asarray(cols, np.int64).ravel()
    if not len(rows):
        return np.zeros(0, np.int64)
    n_rows = len(indptr) - 1
    n_cols = int(max(indices.max(initial=-1), np.max(cols, initial=-1))) + 1
    ordinals = sp.csr_matrix(
        (np.arange(1, len(indices) + 1, dtype=float), indices, indptr),
        shape=(n_rows, n_cols),
        copy=False,
    )
    ordinals.has_canonical_format = True
    found = ordinals[rows, cols]
    return np.asarray(found, dtype=np.int64).ravel() - 1


def gather_into(values: np.ndarray, index: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``out[:] = values[index]`` (``index`` valid: built by the caller's own maps) in
    chunks of ``GATHER_CHUNK`` entries, and ``out``.

    ``numpy.take(..., out=out)`` buffers its whole output in its default mode (a second
    array of ``out``'s size: 125 MB for the bordered matrix of a 200 x 200 Miura, beside
    the factor held): chunk by chunk, the temporaries stay below 10 MB."""
    for s in range(0, len(index), GATHER_CHUNK):
        e = s + GATHER_CHUNK
        np.take(values, index[s:e], out=out[s:e], mode="clip")
    return out
