"""The constant-strain-triangle (CST) membrane written in the bars' strains.

A triangle's three side strains determine its uniform in-plane strain: with ``t_k`` the unit
direction of side ``k`` in the reference state, the Green strain of that side is
``eps_k = t_k^T E t_k = T_k . [E_11, E_22, 2 E_12]`` with ``T_k = [c_k^2, s_k^2, c_k s_k]``
(``c_k, s_k`` the components of ``t_k`` in the triangle's plane). The plane-stress energy of
the triangle (area ``A``, thickness ``t``, plane-stress matrix ``D`` in Voigt form) is then

    ``W = A t / 2 [E]^T D [E] = eps^T C_tri eps / 2``,  ``C_tri = A t T^-T D T^-1``.

Summed over the triangles, ``W = eps^T C eps / 2`` with ``C`` a sparse symmetric matrix over
the bars: its diagonal takes the place of a bar's ``EA L0`` and its off-diagonal entries
couple the sides of each triangle. A bar model is the special case of a diagonal ``C``; no
diagonal ``C`` is isotropic for every triangle shape (a bar triangle is isotropic only when
equilateral with ``nu = 1/3``, the Cauchy lattice), while the CST is exact for every shape:
it passes the membrane patch test by construction, and with the Green strain its energy is
the St Venant-Kirchhoff membrane's at any rotation. The sides of a triangle are bars of the
model already, so the couplings add no entry to the tangent's sparsity pattern.

References: Turner, Clough, Martin & Topp (1956), J. Aeronaut. Sci. 23, 805-823 (the CST);
the strain-of-sides form: Argyris (1965) "natural" strains, J. R. Aeronaut. Soc. 69, 711-713.
"""

from __future__ import annotations

import numpy as np

from barhinge.errors import ConfigError
from barhinge.model.material import Material

__all__ = ["cst_bar_matrix", "plane_stress_voigt", "triangle_side_matrices"]


def plane_stress_voigt(material: Material) -> np.ndarray:
    """(3, 3) plane-stress stiffness in Voigt form (engineering shear strain ``2 E_12``),
    force / length^2."""
    nu, E = material.nu, material.E
    c = E / (1.0 - nu * nu)
    return c * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])


def triangle_side_matrices(P: np.ndarray, material: Material) -> np.ndarray:
    """(n_tri, 3, 3) ``C_tri`` of the triangles ``P`` (n_tri, 3, 3 xyz), sides in the order
    ``(P1 P2, P2 P0, P0 P1)`` (side ``k`` opposite corner ``k``): the membrane energy is
    ``eps^T C_tri eps / 2`` for the sides' Green strains ``eps`` (force x length).

    Raises
    ------
    ConfigError
        If a triangle is degenerate (area below 1e-12 of its longest side squared).
    """
    P = np.asarray(P, float)
    sides = np.stack([P[:, 2] - P[:, 1], P[:, 0] - P[:, 2], P[:, 1] - P[:, 0]], axis=1)
    L = np.linalg.norm(sides, axis=2)  # (n, 3)
    normal = np.cross(sides[:, 2], -sides[:, 1])  # (P1 - P0) x (P2 - P0)
    twoA = np.linalg.norm(normal, axis=1)
    bad = twoA <= 1e-12 * L.max(axis=1) ** 2
    if bad.any():
        raise ConfigError(
            f"{int(bad.sum())} degenerate triangle(s) (zero area, first: triangle "
            f"{int(np.flatnonzero(bad)[0])}); the CST membrane needs triangles with area"
        )
    e1 = sides[:, 2] / L[:, 2, None]
    e2 = np.cross(normal / twoA[:, None], e1)
    c = np.einsum("nki,ni->nk", sides, e1) / L
    s = np.einsum("nki,ni->nk", sides, e2) / L
    T = np.stack([c * c, s * s, c * s], axis=2)  # (n, 3 sides, 3 strain components)
    Tinv = np.linalg.inv(T)
    D = plane_stress_voigt(material)
    At = 0.5 * twoA * material.t
    return At[:, None, None] * np.einsum("nji,jk,nkl->nil", Tinv, D, Tinv)


def cst_bar_matrix(
    X: np.ndarray, triangles: np.ndarray, bars: np.ndarray, material: Material
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The CST membrane of every triangle as a matrix over the bars (module docstring).

    Parameters
    ----------
    X : (n_nodes, 3) reference coordinates.
    triangles : (n_tri, 3) int node triples.
    bars : (n_bars, 2) int; every side of every triangle must be a bar.
    material : Material

    Returns
    -------
    diagonal : (n_bars,) ``C_bb`` (force x length; a bar's ``EA L0``).
    pairs : (n_pairs, 2) int bars ``i < j`` sharing a triangle.
    coupling : (n_pairs,) ``C_ij``: the energy holds ``C_ij eps_i eps_j`` for each pair.
    """
    X = np.asarray(X, float)
    tri = np.asarray(triangles, np.int64)
    B = np.sort(np.asarray(bars, np.int64), axis=1)
    n = len(X)
    keys = B[:, 0] * n + B[:, 1]
    order = np.argsort(keys)
    sk = keys[order]
    ends = np.stack([tri[:, [1, 2]], tri[:, [2, 0]], tri[:, [0, 1]]], axis=1)  # (nt, 3, 2)
    ends = np.sort(ends, axis=2)
    want = ends[..., 0] * n + ends[..., 1]
    pos = np.minimum(np.searchsorted(sk, want), len(sk) - 1)
    if not np.array_equal(sk[pos], want):
        raise ConfigError("a triangle side is not a bar of the model")
    side_bar = order[pos]  # (nt, 3)
    Ct = triangle_side_matrices(X[tri], material)
    diagonal = np.zeros(len(B))
    np.add.at(diagonal, side_bar.ravel(), np.einsum("nkk->nk", Ct).ravel())
    ka, kb = np.triu_indices(3, 1)
    bi, bj = side_bar[:, ka].ravel(), side_bar[:, kb].ravel()
    cij = Ct[:, ka, kb].ravel()
    lo, hi = np.minimum(bi, bj), np.maximum(bi, bj)
    uk, inv = np.unique(lo * len(B) + hi, return_inverse=True)
    coupling = np.bincount(inv.ravel(), weights=cij, minlength=len(uk))
    pairs = np.stack([uk // len(B), uk % len(B)], axis=1)
    return diagonal, pairs, coupling
