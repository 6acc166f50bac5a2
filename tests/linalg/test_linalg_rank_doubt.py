"""The inertia-based sparse rank: agrees with the dense SVD on real patterns, states the gap of
the cut, reports an ambiguous cut as a range, and turns library failures into RankError."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from barhinge.kinematics.constraints import RigidConstraints
from barhinge.linalg import nullspace as nsm
from barhinge.linalg.nullspace import GAP_CERTAIN, RankError, null_space
from barhinge.pattern.io import read


def _matrix(sigmas: np.ndarray, m: int, seed: int = 0) -> np.ndarray:
    """(m, n) matrix with the given singular values (n = len(sigmas))."""
    rng = np.random.default_rng(seed)
    n = len(sigmas)
    U = np.linalg.qr(rng.standard_normal((m, n)))[0]
    V = np.linalg.qr(rng.standard_normal((n, n)))[0]
    return (U * sigmas) @ V.T


def test_sparse_inertia_agrees_with_dense_svd_on_a_real_tessellation(shared_patterns):
    """Huffman's waterbomb tessellation (1 077 crease variables, flat: 357 DOF): the
    inertia count, the null space and the singular values at the cut equal the dense SVD's."""
    cp = read(shared_patterns / "origami-simulator" / "huffmanWaterbomb.svg")
    rc = RigidConstraints.from_pattern(cp)
    J = rc.jacobian(rc.rho0)
    dense = null_space(J, dense_limit=10**6)
    sparse = null_space(J, dense_limit=0)
    assert sparse.method == "sparse-inertia"
    assert dense.rank == sparse.rank == J.shape[1] - 357
    Pd = dense.basis @ dense.basis.T
    Ps = sparse.basis @ sparse.basis.T
    assert np.abs(Pd - Ps).max() < 1e-8
    assert sparse.sigma_gap == pytest.approx(dense.sigma_gap, rel=1e-3)
    assert sparse.sigma_below < 1e-8 and dense.sigma_below < 1e-12
    assert sparse.certain and dense.certain


@pytest.mark.parametrize("dense_limit", [10**6, 0])
def test_clear_cut_is_certain(dense_limit):
    """Singular values 1 ... 1e-2 and three exact zeros: rank n - 3, gap ratio >= 1e3."""
    s = np.concatenate([np.logspace(0, -2, 697), [0.0, 0.0, 0.0]])
    ns = null_space(sp.csr_matrix(_matrix(s, 720)), dense_limit=dense_limit)
    assert ns.rank == 697 and ns.certain and ns.gap_ratio >= GAP_CERTAIN
    assert ns.rank_candidates == (697, 697)
    assert ns.sigma_gap == pytest.approx(1e-2, rel=1e-3)


@pytest.mark.parametrize("dense_limit", [10**6, 0])
def test_ambiguous_cut_gives_both_candidates(dense_limit):
    """Singular values 1 ... 1e-1, then 5e-6, 5e-8, 2e-9, 0: the cut (1e-8 dense, 1e-6
    sparse) has a gap ratio below 1e3, so it is flagged and the rank is given as the range
    between the nearest clear cuts on either side."""
    tail = np.array([5e-6, 5e-8, 2e-9, 0.0])  # dense cut 1e-8: 2 zero, 2 nonzero
    s = np.concatenate([np.logspace(0, -1, 696), tail])
    ns = null_space(sp.csr_matrix(_matrix(s, 720)), dense_limit=dense_limit)
    n = len(s)
    assert not ns.certain and ns.gap_ratio < GAP_CERTAIN
    lo, hi = ns.rank_candidates
    assert lo < hi and lo <= ns.rank <= hi
    assert lo == 696  # the next clear gap: 1e-1 down to 5e-6
    # the exact zero is certain (dense); the sparse method cannot separate 2e-9 from 0
    assert n - hi == (1 if dense_limit else 2)


def test_library_failure_is_a_rank_error(monkeypatch):
    """A factorisation that fails in every backend gives RankError (a ConvergenceError, exit
    code 3 in the CLI), not the library's exception."""

    class Broken:
        def factorize(self, A):
            raise RuntimeError("simulated MKL failure")

    monkeypatch.setattr(nsm, "_backend", lambda name: Broken())
    J = sp.random(800, 700, density=0.01, random_state=0, format="csr")
    with pytest.raises(RankError, match="inertia"):
        null_space(J, dense_limit=0)
