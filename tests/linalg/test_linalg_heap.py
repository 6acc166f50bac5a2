"""Returning the heap's free pages to the operating system (glibc's malloc_trim)."""

from __future__ import annotations

import ctypes.util
import sys

import numpy as np
import pytest

from barhinge.linalg.heap import release_free_heap


def _resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or "musl" in (ctypes.util.find_library("c") or ""),
    reason="glibc's malloc_trim: Linux with glibc",
)
def test_release_free_heap_returns_the_pages_of_freed_small_arrays():
    """Arrays of 1 MB come from the heap once glibc's mmap threshold has risen to 16 MB
    (after an mmapped block of that size is freed); interleaving kept and freed ones leaves
    holes the heap keeps. After the call the resident size falls by most of the freed
    200 MB."""
    big = np.ones(2 * 2**20)  # 16 MB: mmapped, and its free raises the threshold
    del big
    arrays = [np.ones(2**17) for _ in range(400)]  # 400 x 1 MB
    keep = arrays[1::2]
    del arrays
    before = _resident_bytes()
    assert release_free_heap()
    after = _resident_bytes()
    assert before - after > 100 * 2**20
    assert sum(a.sum() for a in keep) == 200 * 2**17  # the kept arrays are intact


def test_release_free_heap_is_harmless_to_call_repeatedly():
    x = np.arange(10.0)
    first = release_free_heap()
    assert release_free_heap() is first
    assert x.sum() == 45.0


def test_release_free_heap_skips_small_models():
    """Below ``LARGE_MODEL_DOF`` DOFs the release is not made (False); from it on, it is
    made where the C library can."""
    from barhinge.linalg.heap import LARGE_MODEL_DOF

    assert release_free_heap(LARGE_MODEL_DOF - 1) is False
    assert release_free_heap(LARGE_MODEL_DOF) is release_free_heap()
