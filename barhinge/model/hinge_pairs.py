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
gradients), assembled here as an element over the union of the two hinges' nodes (5 to 8
nodes; pairs are grouped by that count, so every group has a fixed element size).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from barhinge.errors import ConfigError

__all__ = ["PairLayout", "pair_layout", "pair_matrix", "pair_upper_values"]


@dataclasses.dataclass(frozen=True)
class PairLayout:
    """Element layout of the pairs of one size group.

    Attributes
    ----------
    pairs : (n,) int, indices into the model's pair list
    nodes : (n, u) int, the union of the two hinges' nodes (each node once)
    rows_i, rows_j : (12, n) int, row of each gradient entry of hinge i / j (node-major,
        xyz) in the element's ``3 u`` vector
    """

    pairs: np.ndarray
    nodes: np.ndarray
    rows_i: np.ndarray
    rows_j: np.ndarray


def pair_layout(hinges: np.ndarray, pairs: np.ndarray) -> list[PairLayout]:
    """Group the pairs by the number of distinct nodes of their two hinges (built once).

    Parameters
    ----------
    hinges : (n_hinges, 4) int
    pairs : (n_pairs, 2) int hinge indices
    """
    if len(pairs) == 0:
        return []
    both = np.concatenate([hinges[pairs[:, 0]], hinges[pairs[:, 1]]], axis=1)  # (n, 8)
    srt = np.sort(both, axis=1)
    first = np.ones_like(srt, dtype=bool)
    first[:, 1:] = srt[:, 1:] != srt[:, :-1]
    count = first.sum(axis=1)
    out = []
    for u in np.unique(count):
        sel = np.flatnonzero(count == u)
        nodes = srt[sel][first[sel]].reshape(len(sel), int(u))
        # position of each of the 8 hinge nodes in the sorted unique list
        big = int(hinges.max()) + 1
        off = (np.arange(len(sel)) * big)[:, None]
        pos = np.searchsorted((nodes + off).ravel(), (both[sel] + off).ravel()).reshape(-1, 8)
        pos -= (np.arange(len(sel)) * int(u))[:, None]
        rows = (3 * pos[:, :, None] + np.arange(3)).reshape(len(sel), 24).T  # (24, n)
        out.append(PairLayout(sel, nodes, rows[:12].copy(), rows[12:].copy()))
    return out


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


def pair_upper_values(
    layout: PairLayout, grad: np.ndarray, pairs: np.ndarray, pair_k: np.ndarray, out: np.ndarray
) -> None:
    """Packed upper triangle (entry-major) of ``c (G_i G_j^T + G_j G_i^T)`` of one group.

    Parameters
    ----------
    layout : the group
    grad : (12, n_hinges) component-major angle gradients of all hinges
    pairs, pair_k : the model's pairs and couplings
    out : (m (m + 1) / 2, n) with ``m = 3 u``, written in place
    """
    n = len(layout.pairs)
    m = 3 * layout.nodes.shape[1]
    p = pairs[layout.pairs]
    cols = np.arange(n)
    Gi = np.zeros((m, n))
    Gj = np.zeros((m, n))
    Gi[layout.rows_i, cols] = grad[:, p[:, 0]]
    Gj[layout.rows_j, cols] = grad[:, p[:, 1]]
    Gi *= pair_k[layout.pairs]
    iu, ju = np.triu_indices(m)
    np.multiply(Gi[iu], Gj[ju], out=out)
    out += Gj[iu] * Gi[ju]
