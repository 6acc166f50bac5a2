"""Point functions for the sweep tests (imported by path through the study's ``paths``)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import numpy as np


def _mark(marker_dir: str, x: int) -> int:
    """Create marker ``<x>-<attempt>`` (next free attempt) holding this pid; return the attempt."""
    for attempt in range(1, 100):
        try:
            fd = os.open(Path(marker_dir) / f"{x}-{attempt}", os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            continue
        os.write(fd, str(os.getpid()).encode())
        os.close(fd)
        return attempt
    raise RuntimeError("too many attempts")


def square(x: int, marker_dir: str = "", delay: float = 0.0, fail_on: int = -1) -> dict:
    """Return x^2 after ``delay`` s; every execution leaves a marker file in ``marker_dir``.

    A file ``interrupt-<x>`` in ``marker_dir`` makes the point raise KeyboardInterrupt once
    (the file is removed); ``x == fail_on`` raises a ValueError with a two-line message.
    """
    attempt = _mark(marker_dir, x) if marker_dir else 0
    stop = Path(marker_dir) / f"interrupt-{x}" if marker_dir else None
    if stop is not None and stop.exists():
        stop.unlink()
        raise KeyboardInterrupt
    if x == fail_on:
        raise ValueError(f"x = {x} is unlucky\nsecond line of the message")
    time.sleep(delay)
    return {"y": x * x, "attempt": attempt, "pid": os.getpid(), "vec": np.array([x, 2 * x])}


def killer(x: int, marker_dir: str = "", delay: float = 0.0, kill_on: int = -1) -> dict:
    """``x == kill_on`` kills its own worker process (SIGKILL, as the OOM killer or a
    segfault would); the other points return x^2 after ``delay`` s. Every execution leaves a
    marker file ``<x>-<attempt>`` in ``marker_dir``."""
    attempt = _mark(marker_dir, x) if marker_dir else 0
    if x == kill_on:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(delay)
    return {"y": x * x, "attempt": attempt}


def non_finite(x: int) -> dict:
    """x = 1: a NaN result; x = 2: an infinity inside an array; x = 3: -inf in a nested dict;
    otherwise finite."""
    vec = np.array([x, 2.0 * x])
    if x == 2:
        vec[1] = np.inf
    out: dict = {"y": float("nan") if x == 1 else float(x * x), "vec": vec}
    out["nested"] = {"z": -np.inf if x == 3 else 0.5}
    return out
