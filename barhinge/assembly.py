"""Sparse assembly of bar-and-hinge element contributions.

The sparsity pattern of the tangent and the map from every element-matrix entry to its
position in the CSR ``data`` array are built once per model (:class:`Assembler`), at the
level of 3x3 node-pair blocks (one ``unique`` over node pairs, then arithmetic); each
evaluation is then one ``bincount`` scatter of the element values into a fresh data array
that shares the pattern's ``indices`` and ``indptr``.

Only the upper triangle (diagonal included) of each symmetric element matrix is scattered, into
the upper triangle of the global matrix, and mirrored by one gather; this halves the scatter
and makes the global matrix exactly symmetric. The scatter is a product with a precomputed
0/1 summation matrix (faster than ``bincount`` because its reads are ordered). Element values
are *entry-major*: an array ``(n_entries, n_el)`` with the elements on the last axis (what
the vectorised kernels produce).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["Assembler", "element_dofs"]


def element_dofs(conn: np.ndarray) -> np.ndarray:
    """(n_el, 3 * nodes_per_element) global dof indices, xyz interleaved per node."""
    return (3 * conn[:, :, None] + np.arange(3)[None, None, :]).reshape(
        len(conn), 3 * conn.shape[1]
    )


class Assembler:
    """Scatter maps for groups of elements sharing one global vector and matrix.

    Parameters
    ----------
    n_nodes : int
    groups : list of (n_el, nodes_per_element) int arrays (e.g. bars, hinges)
    """

    def __init__(self, n_nodes: int, groups: list[np.ndarray]) -> None:
        self.n_nodes = N = int(n_nodes)
        self.n_dof = n = 3 * N
        conns = [np.asarray(g, dtype=np.int64) for g in groups]
        self.dofs = [element_dofs(c) for c in conns]
        self.triu = [np.triu_indices(D.shape[1]) for D in self.dofs]
        self._fdofs = (
            np.concatenate([D.T.ravel() for D in self.dofs]) if self.dofs else np.zeros(0, int)
        )

        # 1. node-pair blocks: every element couples its node pairs (a <= b locally)
        pair_keys, pair_of = [], []
        for c in conns:
            la, lb = np.triu_indices(c.shape[1])
            A, B = c[:, la], c[:, lb]
            pair_keys.append((np.minimum(A, B) * N + np.maximum(A, B)).T.ravel())
            pair_of.append((la, lb))
        allp = np.concatenate(pair_keys) if pair_keys else np.zeros(0, np.int64)
        ublk, inv = np.unique(allp, return_inverse=True)
        inv = inv.ravel()
        nblk = len(ublk)
        self.n_upper = 9 * nblk  # a 3x3 slot per node-pair block (upper part on diagonals)

        # 2. slot of every packed element entry (entry-major), then the 0/1 summation matrix
        slots, off = [], 0
        for c, (la, lb), (iu, ju) in zip(conns, pair_of, self.triu, strict=True):
            ne, npair = len(c), len(la)
            blk = inv[off : off + ne * npair].reshape(npair, ne)
            off += ne * npair
            pidx = {(int(a), int(b)): q for q, (a, b) in enumerate(zip(la, lb, strict=True))}
            a_loc, b_loc, ra, cb = iu // 3, ju // 3, iu % 3, ju % 3
            q = np.array([pidx[(int(a), int(b))] for a, b in zip(a_loc, b_loc, strict=True)])
            swap = (c[:, a_loc] > c[:, b_loc]).T  # (n_entries, ne)
            comp = np.where(swap, (3 * cb + ra)[:, None], (3 * ra + cb)[:, None])
            slots.append((blk[q] * 9 + comp).ravel())
        slot = np.concatenate(slots) if slots else np.zeros(0, np.int64)
        nv = len(slot)
        itype = np.int32 if max(nv, self.n_upper, n) < 2**31 - 1 else np.int64
        self._sum = sp.csr_matrix(
            (np.ones(nv), (slot.astype(itype), np.arange(nv, dtype=itype))),
            shape=(self.n_upper, nv),
        )

        # 3. full symmetric CSR pattern from the blocks, and the gather from the slots
        bA, bB = ublk // N, ublk % N
        offd = bA != bB
        rn = np.concatenate([bA, bB[offd]])
        cn = np.concatenate([bB, bA[offd]])
        bid = np.concatenate([np.arange(nblk), np.flatnonzero(offd)])
        tr = np.concatenate([np.zeros(nblk, bool), np.ones(int(offd.sum()), bool)])
        o = np.argsort(rn * N + cn)
        rn, cn, bid, tr = rn[o], cn[o], bid[o], tr[o]
        diag = rn == cn
        indptr_n = np.concatenate([[0], np.cumsum(np.bincount(rn, minlength=N))])
        deg = np.diff(indptr_n)
        seg_len = np.repeat(3 * deg, 3)  # dof row (A, i) holds 3 entries per neighbour
        seg_start = np.concatenate([[0], np.cumsum(seg_len)])
        total = int(seg_start[-1])
        seg = np.repeat(np.arange(n), seg_len)
        p = np.arange(total) - seg_start[seg]
        k = np.repeat(indptr_n[:-1], 3)[seg] + p // 3
        i, j = seg % 3, p % 3
        lo, hi = np.minimum(i, j), np.maximum(i, j)
        comp = np.where(diag[k], 3 * lo + hi, np.where(tr[k], 3 * j + i, 3 * i + j))
        self._gather = bid[k] * 9 + comp
        self.indices = (3 * cn[k] + j).astype(itype)
        self.indptr = seg_start.astype(itype)
        self.nnz = total

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_flat", None)  # scratch buffer: not worth pickling
        return state

    def force(self, element_vectors: list[np.ndarray]) -> np.ndarray:
        """(n_dof,) sum of entry-major element vectors ``(3 * nodes, n_el)`` of each group."""
        val = np.concatenate([f.ravel() for f in element_vectors])
        return np.bincount(self._fdofs, weights=val, minlength=self.n_dof)

    def value_buffers(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """A flat value array and its per-group views ``(m (m + 1) / 2, n_el)``: write the
        element values into the views and pass the flat array to :meth:`matrix_packed`
        (saves a copy). The buffer is allocated once and reused by every call (scratch only:
        the matrices returned own their data), so one Assembler must not be used from two
        threads at once."""
        sizes = [(len(iu), D.shape[0]) for D, (iu, _) in zip(self.dofs, self.triu, strict=True)]
        if getattr(self, "_flat", None) is None:
            self._flat = np.empty(sum(a * b for a, b in sizes))
        flat = self._flat
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
