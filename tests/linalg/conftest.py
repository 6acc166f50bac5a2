"""Shared fixtures of the linear-algebra tests."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
import scipy.sparse as sp


def _beam_fourth_difference(n: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """``A = D^2`` (D the second difference with zero ends: a simply supported beam, ghost
    nodes mirrored) and the exact solution of ``A w = 1``: the quartic
    ``w_i = (i^4 - 2 N i^3 - i^2 + (N^3 + N) i) / 24``, ``N = n + 1`` (second differences
    of polynomials are exact: ``D`` of the parabola ``-i (N - i) / 2`` is 1, ``D`` of w is
    that parabola, and w vanishes at i = 0 and N). Integers below 2^53: exact in double."""
    D = sp.diags([np.ones(n - 1), -2.0 * np.ones(n), np.ones(n - 1)], [-1, 0, 1], format="csr")
    i = np.arange(1, n + 1, dtype=float)
    N = n + 1.0
    return sp.csr_matrix(D @ D), (i**4 - 2 * N * i**3 - i**2 + (N**3 + N) * i) / 24.0


@pytest.fixture
def beam_fourth_difference() -> Callable[[int], tuple[sp.csr_matrix, np.ndarray]]:
    """:func:`_beam_fourth_difference`: a system of condition ~1.7e13 at n = 3000 with a
    closed-form solution."""
    return _beam_fourth_difference
