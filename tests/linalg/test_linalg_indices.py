"""Positions of entries in a CSR pattern, against a dense map of the pattern."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.linalg.indices import index_dtype, pattern_positions


@pytest.mark.parametrize("n_samples", [7, 5000])  # a few (linear scans), many (binary search)
def test_pattern_positions_match_a_dense_map_of_the_pattern(n_samples: int) -> None:
    rng = np.random.default_rng(3)
    A = sp.random(60, 80, density=0.1, random_state=4, format="csr")
    A.sort_indices()
    where = np.full(A.shape, -1)  # dense map: the index into A.data of every stored entry
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    where[rows, A.indices] = np.arange(A.nnz)
    r, c = rng.integers(0, 60, n_samples), rng.integers(0, 80, n_samples)
    pos = pattern_positions(A.indptr, A.indices, r, c)
    assert pos.dtype == np.int64
    np.testing.assert_array_equal(pos, where[r, c])
    assert (pos >= 0).any() and (pos < 0).any()


def test_pattern_positions_of_every_stored_entry_and_of_none() -> None:
    A = sp.random(30, 30, density=0.2, random_state=5, format="csr")
    A.sort_indices()
    rows = np.repeat(np.arange(30), np.diff(A.indptr))
    np.testing.assert_array_equal(pattern_positions(A.indptr, A.indices, rows, A.indices),
                                  np.arange(A.nnz))  # fmt: skip
    assert pattern_positions(A.indptr, A.indices, [], []).shape == (0,)


def test_index_dtype_is_32_bit_up_to_the_scipy_limit() -> None:
    assert index_dtype(2**31 - 1, 5) is np.int32
    assert index_dtype(2**31) is np.int64


def test_gather_into_equals_fancy_indexing_across_chunks(monkeypatch) -> None:
    """The chunked gather writes ``values[index]`` into ``out`` whatever the chunk size,
    including an index shorter than a chunk and one ending inside a chunk."""
    from barhinge.linalg import indices

    rng = np.random.default_rng(8)
    values = rng.standard_normal(1000)
    index = rng.integers(0, 1000, 2503).astype(np.int32)
    for chunk in (7, 1000, 4096):
        monkeypatch.setattr(indices, "GATHER_CHUNK", chunk)
        out = np.full(len(index), np.nan)
        assert indices.gather_into(values, index, out) is out
        np.testing.assert_array_equal(out, values[index])
