"""Sparse assembly of bar-and-hinge element contributions.

The sparsity pattern of the tangent and the map from every element-matrix entry to its
position in the CSR ``data`` array are built once per model (:class:`Assembler`), at the
level of 3x3 node-pair blocks (one ``unique`` over node pairs, then arithmetic, with 32-bit
indices wherever the counts allow and the temporaries bounded by one element group); each
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

import functools
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

__all__ = ["Assembler", "element_dofs"]

#: structures of added matrices whose positions an Assembler keeps (:meth:`add_entries`;
#: the least recently used goes first)
ENTRY_STRUCTURES = 2


def element_dofs(conn: np.ndarray) -> np.ndarray:
    """(n_el, 3 * nodes_per_element) global dof indices, xyz interleaved per node."""
    return (3 * conn[:, :, None] + np.arange(3)[None, None, :]).reshape(
        len(conn), 3 * conn.shape[1]
    )


def _node_pair_keys(conn: np.ndarray, n_nodes: int) -> np.ndarray:
    """``min * n_nodes + max`` of every node pair ``(a, b)``, ``a <= b`` locally, of every
    element (entry-major: pair by pair, the elements within)."""
    la, lb = np.triu_indices(conn.shape[1])
    cT = np.ascontiguousarray(conn.T)  # node slot-major: the pair rows below are contiguous
    A, B = cT[la], cT[lb]
    keys = np.minimum(A, B)
    keys *= n_nodes
    keys += np.maximum(A, B)
    return keys.ravel()


class Assembler:
    """Scatter maps for groups of elements sharing one global vector and matrix.

    Parameters
    ----------
    n_nodes : int
    groups : list of (n_el, nodes_per_element) int arrays (e.g. bars, hinges)
    pattern_groups : list of (n_el, nodes_per_element) int arrays, optional
        Elements whose node pairs are in the pattern but whose values are added by the
        caller (:meth:`add_entries`): no scatter map is kept for them.
    """

    def __init__(
        self, n_nodes: int, groups: list[np.ndarray], pattern_groups: Sequence[np.ndarray] = ()
    ) -> None:
        self.n_nodes = N = int(n_nodes)
        self.n_dof = n = 3 * N
        conns = [np.asarray(g, dtype=np.int64) for g in groups]
        self.dofs = [element_dofs(c) for c in conns]
        self.triu = [np.triu_indices(D.shape[1]) for D in self.dofs]
        self._fdofs = (
            np.concatenate([D.T.ravel() for D in self.dofs]) if self.dofs else np.zeros(0, int)
        )
        n_packed = sum(len(iu) * len(c) for c, (iu, _) in zip(conns, self.triu, strict=True))

        # 1. node-pair blocks: every element couples its node pairs (a <= b locally)
        pair_keys = [_node_pair_keys(c, N) for c in conns]
        pair_of = [np.triu_indices(c.shape[1]) for c in conns]
        n_valued = sum(len(k) for k in pair_keys)  # the pattern groups' keys come after
        pair_keys += [_node_pair_keys(np.asarray(g, dtype=np.int64), N) for g in pattern_groups]
        allp = np.concatenate(pair_keys) if pair_keys else np.zeros(0, np.int64)
        del pair_keys
        ublk, inv = np.unique(allp, return_inverse=True)
        del allp
        nblk = len(ublk)
        self.n_upper = 9 * nblk  # a 3x3 slot per node-pair block (upper part on diagonals)
        # index dtype of every map below: int32 wherever the counts allow (halves the maps)
        itype = np.int32 if max(n_packed, 2 * self.n_upper, n) < 2**31 - 1 else np.int64
        inv = inv.ravel()[:n_valued].astype(itype)
        self._fdofs = self._fdofs.astype(itype)

        # 2. slot of every packed element entry (entry-major), one entry row at a time so
        #    the temporaries stay the size of one group's element count
        slot = np.empty(n_packed, itype)
        off_pair = off_slot = 0
        for c, (la, lb), (iu, ju) in zip(conns, pair_of, self.triu, strict=True):
            ne = len(c)
            blk = inv[off_pair : off_pair + ne * len(la)].reshape(len(la), ne)
            off_pair += ne * len(la)
            pidx = {(int(a), int(b)): q for q, (a, b) in enumerate(zip(la, lb, strict=True))}
            for r, s in zip(iu, ju, strict=True):
                a, b, ra, cb = r // 3, s // 3, r % 3, s % 3
                swapped = c[:, a] > c[:, b]
                comp = np.where(swapped, 3 * cb + ra, 3 * ra + cb).astype(itype)
                np.add(blk[pidx[(int(a), int(b))]] * 9, comp, out=slot[off_slot : off_slot + ne])
                off_slot += ne
        del inv

        # the 0/1 summation matrix, built directly in CSR (rows = slots, sorted by a stable
        # argsort of the slots; no COO intermediate)
        order = np.argsort(slot, kind="stable").astype(itype)
        counts = np.bincount(slot, minlength=self.n_upper)
        del slot
        indptr_sum = np.zeros(self.n_upper + 1, itype)
        np.cumsum(counts, out=indptr_sum[1:])
        del counts
        self._sum = sp.csr_matrix(
            (np.ones(n_packed), order, indptr_sum), shape=(self.n_upper, n_packed), copy=False
        )
        self._sum.has_sorted_indices = False
        del order

        # 3. full symmetric CSR pattern from the blocks, and the gather from the slots
        bA, bB = (ublk // N).astype(itype), (ublk % N).astype(itype)
        del ublk
        offd = bA != bB
        rn = np.concatenate([bA, bB[offd]])
        cn = np.concatenate([bB, bA[offd]])
        bid = np.concatenate([np.arange(nblk, dtype=itype), np.flatnonzero(offd).astype(itype)])
        tr = np.concatenate([np.zeros(nblk, bool), np.ones(int(offd.sum()), bool)])
        del bA, bB, offd
        o = np.lexsort((cn, rn))
        rn, cn, bid, tr = rn[o], cn[o], bid[o], tr[o]
        del o
        diag = rn == cn
        indptr_n = np.zeros(N + 1, itype)
        np.cumsum(np.bincount(rn, minlength=N), out=indptr_n[1:])
        del rn
        deg = np.diff(indptr_n)
        seg_len = np.repeat(3 * deg, 3)  # dof row (A, i) holds 3 entries per neighbour
        seg_start = np.zeros(n + 1, itype)
        np.cumsum(seg_len, out=seg_start[1:])
        total = int(seg_start[-1])
        seg = np.repeat(np.arange(n, dtype=itype), seg_len)
        del seg_len
        p = np.arange(total, dtype=itype) - seg_start[seg]
        k = np.repeat(indptr_n[:-1], 3)[seg]
        k += p // 3
        i = (seg % 3).astype(np.int8)
        del seg
        j = (p % 3).astype(np.int8)
        del p
        lo, hi = np.minimum(i, j), np.maximum(i, j)
        comp = np.where(diag[k], 3 * lo + hi, np.where(tr[k], 3 * j + i, 3 * i + j))
        del lo, hi, i
        self._gather = bid[k] * 9
        self._gather += comp
        del comp
        self.indices = 3 * cn[k]
        self.indices += j
        self.indptr = seg_start
        self.nnz = total

    @property
    def nbytes(self) -> int:
        """Bytes held by the scatter maps and the pattern (bytes; the scratch buffer of
        :meth:`value_buffers` excluded)."""
        arrays = [self._fdofs, self._gather, self.indices, self.indptr, *self.dofs]
        arrays += [self._sum.data, self._sum.indices, self._sum.indptr]
        return int(sum(a.nbytes for a in arrays))

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_flat", None)  # scratch buffer: not worth pickling
        state.pop("_entry_cache", None)  # positions found again on the first call
        return state

    def force(self, element_vectors: list[np.ndarray]) -> np.ndarray:
        """(n_dof,) sum of entry-major element vectors ``(3 * nodes, n_el)`` of each group
        (the first groups, in order: groups left out contribute nothing)."""
        val = np.concatenate([f.ravel() for f in element_vectors])
        return np.bincount(self._fdofs[: len(val)], weights=val, minlength=self.n_dof)

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
        (a list with one array per group, or the flat array of :meth:`value_buffers`; groups
        left out at the end contribute nothing)."""
        if isinstance(element_upper, np.ndarray):
            vals = element_upper
        else:
            vals = np.concatenate([v.ravel() for v in element_upper])
        if len(vals) < self._sum.shape[1]:  # groups left out contribute nothing
            vals = np.concatenate([vals, np.zeros(self._sum.shape[1] - len(vals))])
        upper = self._sum @ vals
        K = sp.csr_matrix(
            (upper[self._gather], self.indices, self.indptr), shape=(self.n_dof, self.n_dof)
        )
        K.has_sorted_indices = True
        return K

    def add_entries(self, K: sp.csr_matrix, M: sp.spmatrix) -> None:
        """Add the symmetric sparse matrix ``M``, whose entries lie in the pattern (e.g. the
        ``pattern_groups``), into ``K`` (a matrix of this pattern) in place. Only the upper
        triangle of ``M`` is read and mirrored, so ``K`` stays exactly symmetric.

        A CSR or CSC ``M`` of a structure (format, ``indptr``, ``indices``) seen in a recent
        call reuses that call's positions: a model adds matrices of the same structures at
        every evaluation, and the search for their positions is made once."""
        if sp.issparse(M) and M.format in ("csr", "csc"):
            cached = self._entry_positions(M)
            if cached is not None:
                up, pos_up, strict, pos_mirror = cached
                data = M.data
                K.data[pos_up] += data[up]
                K.data[pos_mirror] += data[strict]
                return
        C = sp.triu(M, format="coo")
        C.sum_duplicates()  # one entry per position: the fancy-index adds below are exact
        r, c = C.row.astype(np.int64), C.col.astype(np.int64)
        K.data[self._positions(r, c)] += C.data
        off = r != c
        K.data[self._positions(c[off], r[off])] += C.data[off]

    def _entry_positions(
        self, M: sp.csr_matrix | sp.csc_matrix
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """For the entries of the CSR or CSC matrix ``M`` in storage order: (its upper-triangle
        entries, their positions in ``data``, its strictly upper entries, the positions of
        their mirrors), kept for the ``ENTRY_STRUCTURES`` most recently used structures and
        found again when a matrix of one of them comes; None where ``M`` stores a position
        twice (the adds need one entry per position)."""
        cache = self.__dict__.setdefault("_entry_cache", [])
        for i, (indptr, indices, fmt, kept) in enumerate(cache):
            if (
                fmt == M.format
                and indptr.shape == M.indptr.shape
                and indices.shape == M.indices.shape
                and np.array_equal(indptr, M.indptr)
                and np.array_equal(indices, M.indices)
            ):
                cache.append(cache.pop(i))  # the most recently used last
                return kept
        outer = np.repeat(np.arange(len(M.indptr) - 1, dtype=np.int64), np.diff(M.indptr))
        inner = M.indices.astype(np.int64)
        r, c = (outer, inner) if M.format == "csr" else (inner, outer)
        up = np.flatnonzero(c >= r)
        pos_up = self._positions(r[up], c[up])
        strict = up[c[up] > r[up]]
        pos_mirror = self._positions(c[strict], r[strict])
        result = None
        seen = np.zeros(self.nnz, bool)
        seen[pos_up] = True
        if np.count_nonzero(seen) == pos_up.size:  # no position stored twice
            itype = np.int32 if max(self.nnz, M.nnz) < 2**31 - 1 else np.int64
            result = (
                up.astype(itype),
                pos_up.astype(itype),
                strict.astype(itype),
                pos_mirror.astype(itype),
            )
        # the least recently used structure goes (a model adds its hinge couplings and its
        # bar couplings, whose structure changes where entries cancel exactly)
        cache.append((M.indptr.copy(), M.indices.copy(), M.format, result))
        del cache[:-ENTRY_STRUCTURES]
        return result

    def _positions(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Positions in ``data`` of the entries ``(rows, cols)`` of the pattern."""
        keys = self._pattern_keys
        want = rows * self.n_dof + cols
        pos = np.minimum(np.searchsorted(keys, want), max(len(keys) - 1, 0))
        if len(want) and not np.array_equal(keys[pos], want):
            raise ValueError("entries outside the assembler's sparsity pattern")
        return pos

    @functools.cached_property
    def _pattern_keys(self) -> np.ndarray:
        """Sorted ``row * n_dof + column`` of every entry of the pattern."""
        rows = np.repeat(np.arange(self.n_dof, dtype=np.int64), np.diff(self.indptr))
        return rows * self.n_dof + self.indices

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
