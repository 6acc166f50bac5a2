"""Returning freed memory to the operating system between the large stages of an analysis.

numpy's arrays of up to 32 MB come from the C library's heap. When a stage frees many of
them (an assembly's element values and scatter temporaries), glibc keeps the pages for later
allocations, so the process's resident memory stays at the stage's peak while a
factorisation, which allocates through MKL, asks for more. :func:`release_free_heap` hands
the free pages back (glibc's ``malloc_trim(0)``, the call Dask's workers make for the same
reason). On a refined roof of 591 747 DOF it returned 0.14 GB after the model's
construction and 0.27 GB after the assembly of the tangent. Elsewhere (musl, macOS, Windows)
it does nothing.

The solver releases them after a large model's construction, after its assembler's, and
before each factorisation of its tangent (models of ``LARGE_MODEL_DOF`` DOFs and more):
at the 962 403 DOFs of a 200 x 200 Miura the heap kept 0.55 GB after the construction.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
from collections.abc import Callable

__all__ = ["LARGE_MODEL_DOF", "release_free_heap"]

#: models from this many DOFs release the heap between stages (``n_dof`` of
#: :func:`release_free_heap`): below it a release returns little
LARGE_MODEL_DOF = 100_000


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
    except OSError:  # no C library by that name (Windows)
        return None
    trim = getattr(libc, "malloc_trim", None)  # glibc only
    if trim is None:
        return None
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    return trim


def release_free_heap(n_dof: int | None = None) -> bool:
    """Give the heap's free pages back to the operating system; True where the C library
    can (glibc), False where it cannot (then nothing is done). Takes milliseconds.

    ``n_dof``: the DOFs of the model whose stage ended; below :data:`LARGE_MODEL_DOF`
    nothing is done (False)."""
    if n_dof is not None and n_dof < LARGE_MODEL_DOF:
        return False
    trim = _malloc_trim()
    if trim is None:
        return False
    trim(0)
    return True
