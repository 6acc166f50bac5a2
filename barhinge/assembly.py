"""Sparse assembly of bar-and-hinge element contributions.

The sparsity pattern of the tangent and the maps from the element values to its CSR ``data``
array are built once per model (:class:`Assembler`), at the level of 3x3 node-pair blocks
(one ``unique`` over node pairs, then arithmetic, with 32-bit indices wherever the counts
allow and the temporaries bounded by one element group).

Element values are stored in a *block layout*: every node pair of every element (an
*instance*) holds its 3x3 block, component-major ``(9, n_instances)``, with the elements on
the last axis (what the vectorised kernels write, row by row, through :class:`PackedRows`).
Only the upper triangle (diagonal included) of each symmetric element matrix is written. An
evaluation sums the instances into the node-pair blocks of the global upper triangle with two
0/1 summation matrices (one per orientation of the pair: an instance whose first node is the
larger adds its block transposed), nine sparse products each, and gathers the full matrix's
values from the sums into the buffer the sums were made in (they are never held beside
them); the global matrix is exactly symmetric. The summation matrices are
kept per chunk of ``ASSEMBLY_CHUNK`` elements, so an evaluation can write and sum one chunk's
values at a time (:meth:`Assembler.block_sums_filled`) and never hold the whole value array.
The maps hold one entry per node pair of an element, not per matrix entry: 7 to 8 times
smaller than a map of the entries (the 12-node hinges have 78 upper entries in 10 node
pairs), at the same speed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from barhinge.linalg.indices import index_dtype, pattern_positions
from barhinge.linalg.threads import parallel_map

__all__ = ["Assembler", "PackedRows", "element_dofs"]

#: structures of added matrices whose positions an Assembler keeps (:meth:`add_entries`;
#: the least recently used goes first)
ENTRY_STRUCTURES = 2
#: a value buffer up to this size is kept between evaluations (bytes); a larger one (about
#: 0.9 GB at 1 M DOF) is allocated by every evaluation and freed with it, so it does not
#: stay beside the factorisation, whose memory peak sets the largest model a machine takes
KEEP_SCRATCH_BYTES = 256 * 2**20
#: elements per chunk of the summation into node-pair blocks: an evaluation that writes its
#: values chunk by chunk (:meth:`Assembler.block_sums_filled`) holds one chunk's values
#: (9 x node pairs x chunk floats: 47 MB for the hinges) where the whole array is 0.9 GB at
#: 1 M DOF. (16384 held 35 MB less and was ~10 % slower an evaluation at 70 x 70; the peak
#: of a large assembly is where its sums and the tangent's values are held together.)
ASSEMBLY_CHUNK = 65536


def element_dofs(conn: np.ndarray) -> np.ndarray:
    """(n_el, 3 * nodes_per_element) global dof indices, xyz interleaved per node."""
    return (3 * conn[:, :, None] + np.arange(3)[None, None, :]).reshape(
        len(conn), 3 * conn.shape[1]
    )


def _node_pairs(conn: np.ndarray, itype: type[np.signedinteger]) -> tuple[np.ndarray, np.ndarray]:
    """``(min, max)`` of every node pair ``(a, b)``, ``a <= b`` locally, of every element
    (entry-major: pair by pair, the elements within), as ``itype`` arrays."""
    la, lb = np.triu_indices(conn.shape[1])
    cT = np.ascontiguousarray(conn.T, dtype=itype)  # node slot-major: pair rows contiguous
    A, B = cT[la], cT[lb]
    return np.minimum(A, B).ravel(), np.maximum(A, B).ravel()


def _block_pattern(
    lo: np.ndarray, hi: np.ndarray, n_nodes: int
) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix]:
    """The distinct node pairs ``(lo, hi)`` (``lo <= hi``) in row-major order and a CSR
    matrix of them whose values are their ordinals (float, exact below 2**53).

    scipy's COO-to-CSR conversion counts the pairs into rows and merges duplicates within a
    row (a bucket sort): several times faster and smaller than ``numpy.unique`` of 64-bit
    keys on the millions of node pairs of coupled hinges."""
    # the conversion merges duplicates and sorts each row (canonical format)
    S = sp.csr_matrix((np.ones(len(lo), bool), (lo, hi)), shape=(n_nodes, n_nodes))
    nblk = S.nnz
    rows = np.repeat(np.arange(n_nodes, dtype=S.indices.dtype), np.diff(S.indptr))
    ordinals = sp.csr_matrix(
        (np.arange(nblk, dtype=float), S.indices, S.indptr), shape=S.shape, copy=False
    )
    ordinals.has_canonical_format = True
    return rows, S.indices, ordinals


#: component ``3 j + i`` of a 3x3 block for its component ``3 i + j`` (the transpose)
_TRANSPOSED = np.array([0, 3, 6, 1, 4, 7, 2, 5, 8])

#: instances of a chunk from which its nine components are summed side by side on the
#: worker threads (below, the threads' hand-over costs more than the sums)
PARALLEL_INSTANCES = 1 << 14
#: tangent values gathered from the block sums per part, the parts side by side on the
#: worker threads (:meth:`Assembler.matrix_from_sums`)
GATHER_PART = 1 << 18
#: element-vector entries summed at a time by :meth:`Assembler.force`
FORCE_CHUNK = 1 << 20
#: tangent entries filled at a time by :meth:`Assembler.matrix_from_sums` (whole node rows)
SUMS_FILL_CHUNK = 1 << 20


class _Chunk(NamedTuple):
    """The summation of one chunk of a group's elements into the node-pair blocks."""

    start: int  # the chunk's first element in its group
    stop: int  # one past its last
    out: slice | np.ndarray  # the blocks it adds to: a range, or their indices where sparse
    direct: sp.csr_matrix  # (blocks of ``out``, instances of the chunk) 0/1: as they are
    swapped: sp.csr_matrix  # the same for the instances added transposed


def _chunk_summation(
    start: int,
    stop: int,
    block: np.ndarray,
    swapped: np.ndarray,
    local: np.ndarray,
    itype: type[np.signedinteger],
    ones: np.ndarray,
) -> _Chunk:
    """The summation matrices of one chunk whose instances (pair-major, the chunk's elements
    within) add to the blocks ``block``, transposed where ``swapped``. The blocks it touches
    are addressed as one range where they fill most of it (meshes numbered along the sheet),
    else by index; ``local`` is an ``(n_blocks,)`` scratch array of zeros (left zero); the
    matrices' values are views of ``ones`` (at least as long as ``block``)."""
    local[block] = 1  # the touched blocks, found without sorting
    touched = np.flatnonzero(local)
    local[touched] = 0
    lo, hi = int(touched[0]), int(touched[-1]) + 1
    if hi - lo <= 4 * len(touched):
        out: slice | np.ndarray = slice(lo, hi)
        rows = (block - lo).astype(itype)
        n_rows = hi - lo
    else:
        out = touched.astype(itype)
        local[touched] = np.arange(len(touched), dtype=itype)
        rows = local[block]
        local[touched] = 0
        n_rows = len(touched)

    def summation(mask: np.ndarray) -> sp.csr_matrix:
        cols = np.flatnonzero(mask).astype(itype)
        S = sp.csr_matrix((ones[: len(cols)], (rows[cols], cols)), shape=(n_rows, len(block)))
        S.data = ones[: S.nnz]  # the conversion copied its values: a view of ``ones`` instead
        return S

    return _Chunk(start, stop, out, summation(~swapped), summation(swapped))


def _parts(start: int, stop: int, size: int) -> list[slice]:
    """``[start, stop)`` in slices of ``size``."""
    return [slice(p, min(p + size, stop)) for p in range(start, stop, size)]


def _add_chunk(sums: np.ndarray, V: np.ndarray, chunk: _Chunk) -> None:
    """Add the ``(9, instances)`` values ``V`` of one chunk into the block sums: the nine
    components side by side on the worker threads where the chunk is large (each writes
    its own row of ``sums``; the sums do not depend on the number of threads)."""

    def component(c: int) -> None:
        sums[c, chunk.out] += chunk.direct @ V[c] + chunk.swapped @ V[_TRANSPOSED[c]]

    if V.shape[1] >= PARALLEL_INSTANCES:
        parallel_map(component, range(9))
    else:
        for c in range(9):
            component(c)


class PackedRows:
    """The packed upper-triangle rows of one group's element matrices in the assembler's
    block layout: ``rows[p]`` is the ``(n_el,)`` row (a writable view) of packed entry ``p``
    (``numpy.triu_indices(m)`` order), ``rows[:, cols]`` the same rows of the elements
    ``cols`` (a slice). What the vectorised kernels write into (``out``)."""

    __slots__ = ("buf", "comp", "pair")

    def __init__(self, buf: np.ndarray, comp: np.ndarray, pair: np.ndarray) -> None:
        self.buf = buf  # (9, node pairs, n_el)
        self.comp = comp  # (n_packed,) block component of each packed entry
        self.pair = pair  # (n_packed,) node pair of each packed entry

    def __getitem__(self, key: int | tuple[slice, slice]) -> Any:
        if isinstance(key, tuple):
            rows, cols = key
            if rows != slice(None) or not isinstance(cols, slice):
                raise IndexError("PackedRows takes rows[p] or rows[:, slice]")
            return PackedRows(self.buf[:, :, cols], self.comp, self.pair)
        return self.buf[self.comp[key], self.pair[key]]


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
        pair_of = [np.triu_indices(c.shape[1]) for c in conns]
        n_inst = sum(len(la) * len(c) for c, (la, _) in zip(conns, pair_of, strict=True))
        ntype = index_dtype(N)
        pairs = [_node_pairs(c, ntype) for c in conns]
        pairs += [_node_pairs(np.asarray(g), ntype) for g in pattern_groups]
        lo = np.concatenate([a for a, _ in pairs]) if pairs else np.zeros(0, ntype)
        hi = np.concatenate([b for _, b in pairs]) if pairs else np.zeros(0, ntype)
        del pairs
        bA, bB, ordinals = _block_pattern(lo, hi, N)
        nblk = len(bA)
        self.n_upper = 9 * nblk  # a 3x3 slot per node-pair block (upper part on diagonals)
        # index dtype of every map below: int32 wherever the counts allow (halves the maps)
        itype = index_dtype(n_packed, 2 * self.n_upper, n)
        # the block of every valued instance (the pattern groups' pairs come after them)
        inv = np.asarray(ordinals[lo[:n_inst], hi[:n_inst]]).ravel().astype(itype)
        del lo, hi, ordinals
        self._fdofs = self._fdofs.astype(itype)
        # the per-group (n_el, 3 * nodes) dofs: views of the entry-major force map (one copy)
        views, start = [], 0
        for D in self.dofs:
            views.append(self._fdofs[start : start + D.size].reshape(D.shape[1], D.shape[0]).T)
            start += D.size
        self.dofs = views

        # 2. the block layout of the element values and its 0/1 summation matrices: every
        #    element node pair (an *instance*, pair-major, the elements within) adds its 3x3
        #    block, 9 components row-major, to one node-pair block; values are stored
        #    component-major, ``(9, n_instances)``. An instance whose first node is the larger
        #    (swapped) adds its block transposed: one summation matrix per orientation.
        swapped = np.empty(n_inst, bool)
        #: per group: (first instance, node pairs, elements, packed entry -> component,
        #: packed entry -> node pair)
        self._layout: list[tuple[int, int, int, np.ndarray, np.ndarray]] = []
        off = 0
        for c, (la, lb), (iu, ju) in zip(conns, pair_of, self.triu, strict=True):
            ne, npair = len(c), len(la)
            for q in range(npair):  # one row of pairs at a time: temporaries of one group
                swapped[off + q * ne : off + (q + 1) * ne] = c[:, la[q]] > c[:, lb[q]]
            pidx = {(int(a), int(b)): q for q, (a, b) in enumerate(zip(la, lb, strict=True))}
            comp = (3 * (iu % 3) + ju % 3).astype(np.intp)
            pair = np.array([pidx[(int(r) // 3, int(t) // 3)] for r, t in zip(iu, ju, strict=True)])
            self._layout.append((off, npair, ne, comp, pair.astype(np.intp)))
            off += npair * ne
        self.n_instances = n_inst

        # the summation matrices chunk by chunk of elements (ASSEMBLY_CHUNK per chunk): an
        # evaluation needs the values of one chunk at a time (block_sums_filled)
        # (every summation's values are ones: views of one array, not a copy per chunk)
        local = np.zeros(nblk, itype)  # scratch of _chunk_summation
        most = max(
            (npair * min(ne, ASSEMBLY_CHUNK) for _, npair, ne, _, _ in self._layout), default=0
        )
        self._ones = np.ones(most)
        self._chunks: list[list[_Chunk]] = []
        for off, npair, ne, _, _ in self._layout:
            chunks = []
            for e0 in range(0, ne, ASSEMBLY_CHUNK):
                e1 = min(e0 + ASSEMBLY_CHUNK, ne)
                inst = (off + np.arange(npair)[:, None] * ne + np.arange(e0, e1)[None, :]).ravel()
                chunks.append(
                    _chunk_summation(e0, e1, inv[inst], swapped[inst], local, itype, self._ones)
                )
            self._chunks.append(chunks)
        del swapped, inv, local
        self._n_blocks = nblk

        # 3. full symmetric CSR pattern from the blocks, and the gather from the block sums
        #    (block-major: block b's component c at 9 b + c)
        bA, bB = bA.astype(itype), bB.astype(itype)
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
        self._blocks_indptr = indptr_n  # (N + 1,) the full pattern's blocks of each node row
        deg = np.diff(indptr_n)
        self._max_row_blocks = int(deg.max(initial=0))  # the most blocks of one node row
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
        self._gather = bid[k] * itype(9)
        self._gather += comp.astype(itype)
        del comp
        self.indices = 3 * cn[k]
        self.indices += j
        self.indptr = seg_start
        self.nnz = total

    @property
    def nbytes(self) -> int:
        """Bytes held by the scatter maps and the pattern (bytes; the scratch buffer of
        :meth:`value_buffers` excluded)."""
        arrays = [self._fdofs, self._gather, self.indices, self.indptr, self._ones]
        arrays.append(self._blocks_indptr)
        for chunk in (c for group in self._chunks for c in group):
            for S in (chunk.direct, chunk.swapped):
                arrays += [S.indices, S.indptr]  # their data: views of self._ones
            if isinstance(chunk.out, np.ndarray):
                arrays.append(chunk.out)
        return int(sum(a.nbytes for a in arrays))

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_flat", None)  # scratch buffer: not worth pickling
        state.pop("_entry_cache", None)  # positions found again on the first call
        return state

    def force(self, element_vectors: list[np.ndarray]) -> np.ndarray:
        """(n_dof,) sum of entry-major element vectors ``(3 * nodes, n_el)`` of each group
        (the first groups, in order: groups left out contribute nothing), group by group
        and ``FORCE_CHUNK`` entries at a time (no concatenated copy of the element vectors,
        no 64-bit copy of the whole map: ``numpy.bincount`` made one, 92 MB for the hinges
        of a 200 x 200 Miura; ``numpy.add.at`` in chunks measured as fast)."""
        out = np.zeros(self.n_dof)
        start = 0
        for f in element_vectors:
            val = f.ravel()
            for s in range(0, len(val), FORCE_CHUNK):
                e = min(s + FORCE_CHUNK, len(val))
                np.add.at(out, self._fdofs[start + s : start + e], val[s:e])
            start += len(val)
        return out

    def add_force(self, out: np.ndarray, group: int, sl: slice, values: np.ndarray) -> None:
        """Add the entry-major element vectors ``values`` ``(3 * nodes, n)`` of the elements
        ``sl`` of ``group`` into the ``(n_dof,)`` vector ``out`` (an evaluation sums its
        force chunk by chunk, as it writes the element matrices)."""
        np.add.at(out, self.dofs[group][sl].T.ravel(), values.ravel())

    def _group_views(self, flat: np.ndarray) -> list[PackedRows]:
        """The packed rows of every group in the block-layout array ``flat``."""
        V = flat.reshape(9, self.n_instances)
        return [
            PackedRows(V[:, o : o + npair * ne].reshape(9, npair, ne), comp, pair)
            for o, npair, ne, comp, pair in self._layout
        ]

    def value_buffers(self) -> tuple[np.ndarray, list[PackedRows]]:
        """A flat value array and its per-group packed rows: row ``p`` of group ``g``,
        ``views[g][p]`` (``(n_el,)``, writable), holds entry ``p`` of the packed upper
        triangle (``numpy.triu_indices(m)`` order) of every element matrix of the group. Write
        the element values into the rows and pass the flat array to :meth:`matrix_packed`
        (saves a copy). A buffer of up to ``KEEP_SCRATCH_BYTES`` is allocated once and reused
        by every call (scratch only: the matrices returned own their data), so one Assembler
        must not be used from two threads at once; a larger one is new at every call and
        freed with the caller's reference."""
        flat = getattr(self, "_flat", None)
        if flat is None:
            # zeros: the lower components of the diagonal blocks are never written
            flat = np.zeros(9 * self.n_instances)
            if flat.nbytes <= KEEP_SCRATCH_BYTES:
                self._flat = flat
        return flat, self._group_views(flat)

    def matrix_packed(self, element_upper: list[np.ndarray] | np.ndarray) -> sp.csr_matrix:
        """(n_dof, n_dof) CSR sum of symmetric element matrices given by their packed upper
        triangles: a list with one array per group, entry-major ``(m (m + 1) / 2, n_el)`` in
        ``numpy.triu_indices(m)`` order (groups left out at the end contribute nothing), or
        the flat array of :meth:`value_buffers`."""
        if isinstance(element_upper, np.ndarray):
            vals = element_upper
            if vals.shape != (9 * self.n_instances,):
                raise ValueError(
                    f"a flat value array has {9 * self.n_instances} entries (value_buffers); "
                    f"got shape {vals.shape}"
                )
        else:
            vals = np.zeros(9 * self.n_instances)
            for view, arr in zip(self._group_views(vals), element_upper, strict=False):
                view.buf[view.comp, view.pair] = arr
        return self.matrix_from_sums(self.block_sums(vals))

    def block_sums(self, flat: np.ndarray) -> np.ndarray:
        """(9, n_blocks) sums of the element node-pair blocks of the flat value array of
        :meth:`value_buffers` (component-major): :meth:`matrix_from_sums` makes the matrix.
        Between the two the caller can drop the value array (about 0.9 GB at 1 M DOF), so
        that it is not held beside the matrix's values."""
        V = flat.reshape(9, self.n_instances)
        sums = self._new_sums()
        for (off, npair, ne, _, _), chunks in zip(self._layout, self._chunks, strict=True):
            Vg = V[:, off : off + npair * ne].reshape(9, npair, ne)
            for chunk in chunks:  # a copy of the chunk's values where it is not the group
                _add_chunk(sums, Vg[:, :, chunk.start : chunk.stop].reshape(9, -1), chunk)
        return sums

    def block_sums_filled(self, fill: Callable[[int, slice, PackedRows], None]) -> np.ndarray:
        """(9, n_blocks) block sums (as :meth:`block_sums`) of element values written chunk
        by chunk: ``fill(g, sl, rows)`` writes the packed rows (:meth:`value_buffers`'
        layout) of the elements ``sl`` (a slice) of group ``g`` into ``rows``, the
        :class:`PackedRows` of a scratch buffer of those elements only, and must write every
        packed row. At most ``ASSEMBLY_CHUNK`` elements' values exist at a time (the whole
        array would be about 0.9 GB at 1 M DOF, beside a held factorisation)."""
        sums = self._new_sums()
        groups = zip(self._layout, self._chunks, strict=True)
        for g, ((_, npair, ne, comp, pair), chunks) in enumerate(groups):
            full = min(ne, ASSEMBLY_CHUNK)
            scratch = np.zeros(9 * npair * full)  # the lower diagonal components stay 0
            for chunk in chunks:
                n = chunk.stop - chunk.start
                buf = scratch[: 9 * npair * n].reshape(9, npair, n)
                if n < full:  # the last chunk, laid out shorter: no stale value stays
                    buf[...] = 0.0
                fill(g, slice(chunk.start, chunk.stop), PackedRows(buf, comp, pair))
                _add_chunk(sums, buf.reshape(9, -1), chunk)
        return sums

    def _new_sums(self) -> np.ndarray:
        """Zeroed ``(9, n_blocks)`` block sums, block-major in memory (a transposed view),
        at the start of a buffer of the tangent's ``nnz`` values: :meth:`matrix_from_sums`
        fills the tangent's values into that same buffer, so the sums and the values are
        never held side by side (140 MB and 242 MB at 200 x 200)."""
        nblk = self._n_blocks
        return np.zeros(self.nnz)[: 9 * nblk].reshape(nblk, 9).T

    def _values_buffer(self, sums: np.ndarray) -> np.ndarray | None:
        """The ``nnz`` buffer ``sums`` of :meth:`_new_sums` lies at the start of, else None."""
        base = sums
        while base.base is not None:
            base = base.base
        nblk = self._n_blocks
        fits = base.ndim == 1 and len(base) == self.nnz and base.dtype == np.float64
        laid = sums.shape == (9, nblk) and sums.strides == (8, 72)
        if fits and laid and sums.ctypes.data == base.ctypes.data:
            return base
        return None

    def matrix_from_sums(self, sums: np.ndarray) -> sp.csr_matrix:
        """(n_dof, n_dof) CSR matrix of the block sums of :meth:`block_sums` (its pattern's
        arrays shared).

        Its values are gathered from the sums whole node rows at a time (about
        ``SUMS_FILL_CHUNK`` entries), from the last rows to the first, into the buffer the
        sums of :meth:`block_sums` lie at the start of (other sums are copied into a new one
        first): node row A's values start at or after the sums of every node-pair block the
        rows before it read, so a chunk of rows only overwrites sums no earlier row reads
        (``sums`` is then consumed)."""
        data = self._values_buffer(sums)
        nblk = self._n_blocks
        if data is None:
            data = np.empty(self.nnz)
            data[: 9 * nblk].reshape(nblk, 9)[...] = sums.T
        flat = data[: 9 * nblk]
        ip = self._blocks_indptr
        a1 = self.n_nodes
        read = np.empty(min(SUMS_FILL_CHUNK + 9 * self._max_row_blocks, self.nnz))

        def gather(part: slice) -> None:
            np.take(flat, self._gather[part], out=read[part.start - p0 : part.stop - p0])

        def write(part: slice) -> None:
            data[part] = read[part.start - p0 : part.stop - p0]

        while a1 > 0:
            # node rows [a0, a1): their entries [9 ip[a0], 9 ip[a1])
            a0 = int(np.searchsorted(ip, ip[a1] - SUMS_FILL_CHUNK // 9, side="left"))
            a0 = max(min(a0, a1 - 1), 0)
            p0, p1 = 9 * int(ip[a0]), 9 * int(ip[a1])
            # read every value of the rows (in parts, side by side), then write them
            parts = _parts(p0, p1, GATHER_PART)
            parallel_map(gather, parts)
            parallel_map(write, parts)
            a1 = a0
        K = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n_dof, self.n_dof))
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
            itype = index_dtype(self.nnz, M.nnz)
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
        pos = pattern_positions(self.indptr, self.indices, rows, cols)
        if len(pos) and pos.min() < 0:
            raise ValueError("entries outside the assembler's sparsity pattern")
        return pos

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
