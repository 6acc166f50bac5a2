"""Sparse assembly of bar-and-hinge element contributions.

The sparsity pattern of the tangent and the map from every element-matrix entry to its
position in the CSR ``data`` array are built once per model (:class:`Assembler`); each
evaluation is then one ``bincount`` scatter of the element values into a fresh data array
that shares the pattern's ``indices`` and ``indptr``.

Only the upper triangle (diagonal included) of each symmetric element matrix is scattered, into
the upper triangle of the global matrix, and mirrored by one gather; this halves the scatter
and makes the global matrix exactly symmetric. The scatter is a product with a precomputed
0/1 summation matrix (faster than ``bincount`` because its reads are ordered). Element values are *entry-major*: an array
``(n_entries, n_el)`` with the elements on the last axis (what the vectorised kernels produce).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["Assembler", "element_dofs"]


def element_dofs(conn: np.ndarray) -> np.ndarray:
    """(n_el, 3 * nodes_per_element) global dof indices, xyz interleaved per node."""
    return (3 * conn[:, :, None] + np.arange(3)[None, None, :]).reshape(len(conn), 3 * conn.shape[1])


class Assembler:
    """Scatter maps for groups of elements sharing one global vector and matrix.

    Parameters
    ----------
    n_nodes : int
    groups : list of (n_el, nodes_per_element) int arrays (e.g. bars, hinges)
    """

    def __init__(self, n_nodes: int, groups: list[np.ndarray]) -> None:
        self.n_nodes = int(n_nodes)
        self.n_dof = 3 * self.n_nodes
        n = self.n_dof
        dofs = [element_dofs(np.asarray(g, dtype=np.int64)) for g in groups]
        self.dofs = dofs
        self.triu = [np.triu_indices(D.shape[1]) for D in dofs]
        keys = []
        for D, (iu, ju) in zip(dofs, self.triu, strict=True):
            r, c = D[:, iu].T, D[:, ju].T  # entry-major (n_entries, n_el)
            keys.append((np.minimum(r, c) * n + np.maximum(r, c)).ravel())
        allkeys = np.concatenate(keys) if keys else np.zeros(0, np.int64)
        # one sort: the summation matrix S (n_upper x n_values) with S @ values = upper data
        order = np.argsort(allkeys, kind="stable")
        sk = allkeys[order]
        first = np.ones(len(sk), bool)
        first[1:] = sk[1:] != sk[:-1]
        ukey = sk[first]
        self.n_upper = len(ukey)
        starts = np.append(np.flatnonzero(first), len(sk))
        itype = np.int32 if len(sk) < 2**31 else np.int64
        self._sum = sp.csr_matrix(
            (np.ones(len(sk)), order.astype(itype), starts.astype(itype)),
            shape=(self.n_upper, len(sk)),
        )
        ur, uc = ukey // n, ukey % n
        off = ur != uc
        rows = np.concatenate([ur, uc[off]])
        cols = np.concatenate([uc, ur[off]])
        src = np.concatenate([np.arange(self.n_upper), np.flatnonzero(off)])
        order = np.lexsort((cols, rows))
        rows, cols, self._gather = rows[order], cols[order], src[order]
        itype = np.int32 if n < 2**31 and len(cols) < 2**31 else np.int64
        self.indices = cols.astype(itype)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(
            itype
        )
        self.nnz = len(cols)
        self._fdofs = np.concatenate([D.T.ravel() for D in dofs]) if dofs else np.zeros(0, int)

    def force(self, element_vectors: list[np.ndarray]) -> np.ndarray:
        """(n_dof,) sum of entry-major element vectors ``(3 * nodes, n_el)`` of each group."""
        val = np.concatenate([f.ravel() for f in element_vectors])
        return np.bincount(self._fdofs, weights=val, minlength=self.n_dof)

    def value_buffers(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """A flat value array and its per-group views ``(m (m + 1) / 2, n_el)``: write the
        element values into the views and pass the flat array to :meth:`matrix_packed`
        (saves a copy)."""
        sizes = [(len(iu), D.shape[0]) for D, (iu, _) in zip(self.dofs, self.triu, strict=True)]
        flat = np.empty(sum(a * b for a, b in sizes))
        views, o = [], 0
        for a, b in sizes:
            views.append(flat[o : o + a * b].reshape(a, b))
            o += a * b
        return flat, views

    def matrix_packed(self, element_upper: list[np.ndarray] | np.ndarray) -> sp.csr_matrix:
        """(n_dof, n_dof) CSR sum of symmetric element matrices given by their packed upper
        triangles, entry-major ``(m (m + 1) / 2, n_el)`` in ``numpy.triu_indices(m)`` order
        (a list with one array per group, or the flat array of :meth:`value_buffers`)."""
        if isinstance(element_upper, np.ndarray):
            vals = element_upper
        else:
            vals = np.concatenate([v.ravel() for v in element_upper])
        upper = self._sum @ vals
        K = sp.csr_matrix(
            (upper[self._gather], self.indices, self.indptr), shape=(self.n_dof, self.n_dof)
        )
        K.has_sorted_indices = True
        return K

    def matrix(self, element_matrices: list[np.ndarray]) -> sp.csr_matrix:
        """(n_dof, n_dof) CSR sum of symmetric element matrices ``(n_el, m, m)`` (element-major
        convenience form of :meth:`matrix_packed`)."""
        return self.matrix_packed(
            [Ke[:, iu, ju].T for Ke, (iu, ju) in zip(element_matrices, self.triu, strict=True)]
        )

    def pattern(self) -> sp.csr_matrix:
        """The sparsity pattern (ones) as CSR."""
        return sp.csr_matrix(
            (np.ones(self.nnz), self.indices, self.indptr), shape=(self.n_dof, self.n_dof)
        )
