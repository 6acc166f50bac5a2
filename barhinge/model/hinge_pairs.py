"""Coupling of two hinge angles: the energy ``c (rho_i - rho_i0) (rho_j - rho_j0)``.

One stiffness per hinge (``k (rho - rho0)^2 / 2``) fixes a discrete plate's Poisson ratio
(on square cells at ``-1/3``, whatever the sheet's; Wardetzky et al. 2007). Couplings
between the angles of one cell let the cell's energy be any quadratic form of its angles,
so that it can store the Kirchhoff plate energy of every uniform curvature with the sheet's
own ``nu`` (:mod:`barhinge.model.plate_hinges`).

With ``d = rho - rho0`` and a symmetric coupling matrix ``C`` (zero diagonal; ``c`` on the
entries ``(i, j)`` and ``(j, i)`` of every pair) the energy is ``d^T C d / 2``. Its moment on
hinge ``i`` is ``(C d)_i``: it adds to the hinge's own moment, so the force and the
``moment x Hessian of the angle`` part of the tangent go through the hinge kernel unchanged.
What is left is the cross term ``c (g_i g_j^T + g_j g_i^T)`` of every pair (``g`` the angle
gradients): all of them together are ``G^T C G`` with ``G`` the (n_hinges, n_dof) matrix of
the angle gradients, one sparse product per evaluation into entries the model's pattern
holds (:func:`pair_nodes`). Per-pair element matrices (up to 231 values per pair on the
union of the two hinges' nodes) took most of a refined panel's memory.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from barhinge.errors import ConfigError

__all__ = ["pair_matrix", "pair_nodes"]


def pair_nodes(hinges: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(n_pairs, 8) int: the nodes of both hinges of every pair (a node shared by the two
    appears twice): every node pair of a row is an entry of the couplings' tangent.

    Parameters
    ----------
    hinges : (n_hinges, 4) int
    pairs : (n_pairs, 2) int hinge indices
    """
    H, P = np.asarray(hinges, np.int64), np.asarray(pairs, np.int64).reshape(-1, 2)
    return np.concatenate([H[P[:, 0]], H[P[:, 1]]], axis=1)


def pair_matrix(n_hinges: int, pairs: np.ndarray, pair_k: np.ndarray) -> sp.csr_matrix:
    """(n_hinges, n_hinges) symmetric coupling matrix ``C`` (zero diagonal)."""
    i, j = pairs[:, 0], pairs[:, 1]
    if np.any(i == j):
        raise ConfigError("a hinge pair couples a hinge with itself; put that in hinge_k")
    C = sp.coo_matrix(
        (np.concatenate([pair_k, pair_k]), (np.concatenate([i, j]), np.concatenate([j, i]))),
        shape=(n_hinges, n_hinges),
    )
    return C.tocsr()
