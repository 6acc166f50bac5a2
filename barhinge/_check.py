"""Checks of values where they enter barhinge (TOML scenes, dataclass fields, arguments).

Each helper takes the value and its key (a dotted TOML path such as ``model.material.E``, or
an argument name) and returns the value converted, or raises :class:`ConfigError` with one
line that starts with the key and names the bad value and what was expected. Booleans are
never numbers here (TOML ``true`` is not ``1``), and integers are never taken from floats
(``21.7`` is not an edge id).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from barhinge.errors import ConfigError

__all__ = [
    "boolean",
    "show",
    "choice",
    "float_array",
    "int_array",
    "integer",
    "number",
    "prefixed",
    "text",
]


def show(value: Any) -> str:
    """Short one-line representation of a bad value."""
    s = repr(value) if not isinstance(value, np.ndarray) else repr(value.tolist())
    s = " ".join(s.split())
    return s if len(s) <= 60 else s[:57] + "..."


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(
        v, bool | np.bool_
    )


def number(
    value: Any,
    key: str,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """A finite real number in the range given (closed bounds unless ``*_open``)."""
    if not _is_number(value):
        raise ConfigError(f"{key} = {show(value)}; expected a number")
    try:
        v = float(value)
    except OverflowError:
        v = math.inf
    if not math.isfinite(v):
        raise ConfigError(f"{key} = {show(value)}; expected a finite number")
    below = lo is not None and (v <= lo if lo_open else v < lo)
    above = hi is not None and (v >= hi if hi_open else v > hi)
    if below or above:
        raise ConfigError(f"{key} = {show(value)}; expected {_range(lo, hi, lo_open, hi_open)}")
    return v


def _range(lo: Any, hi: Any, lo_open: bool = False, hi_open: bool = False) -> str:
    if lo is not None and hi is not None:
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        return f"a number in {left}{lo:g}, {hi:g}{right}"
    if lo is not None:
        return f"a number {'>' if lo_open else '>='} {lo:g}"
    return f"a number {'<' if hi_open else '<='} {hi:g}"


def integer(value: Any, key: str, lo: int | None = None, hi: int | None = None) -> int:
    """An integer (not a bool, not a float) in ``[lo, hi]``."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise ConfigError(f"{key} = {show(value)}; expected an integer")
    v = int(value)
    if lo is not None and v < lo:
        raise ConfigError(f"{key} = {show(value)}; expected an integer >= {lo}")
    if hi is not None and v > hi:
        raise ConfigError(f"{key} = {show(value)}; expected an integer <= {hi}")
    return v


def boolean(value: Any, key: str) -> bool:
    """``True`` or ``False`` (not 0 / 1)."""
    if not isinstance(value, bool | np.bool_):
        raise ConfigError(f"{key} = {show(value)}; expected true or false")
    return bool(value)


def text(value: Any, key: str) -> str:
    """A string."""
    if not isinstance(value, str):
        raise ConfigError(f"{key} = {show(value)}; expected a string")
    return value


def choice(value: Any, key: str, choices: tuple[str, ...] | list[str]) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise ConfigError(f"{key} = {show(value)}; expected one of {', '.join(choices)}")
    return value


def _nested_numbers(value: Any, key: str, want_int: bool) -> None:
    """Reject bools, strings and other non-numbers anywhere in a nested list."""
    stack = [value]
    while stack:
        v = stack.pop()
        if isinstance(v, np.ndarray):
            if v.dtype == bool or not (
                np.issubdtype(v.dtype, np.integer)
                or (not want_int and np.issubdtype(v.dtype, np.floating))
            ):
                what = "integers" if want_int else "numbers"
                raise ConfigError(f"{key} = {show(v)}; expected {what}")
            continue
        if isinstance(v, list | tuple):
            stack.extend(v)
            continue
        ok = (
            isinstance(v, int | np.integer) and not isinstance(v, bool | np.bool_)
            if want_int
            else _is_number(v)
        )
        if not ok:
            what = "integers" if want_int else "numbers"
            raise ConfigError(f"{key} has the entry {show(v)}; expected {what}")


def int_array(value: Any, key: str, lo: int | None = None, hi: int | None = None) -> np.ndarray:
    """A flat int64 array from an integer or a list of integers, each in ``[lo, hi]``."""
    _nested_numbers(value, key, want_int=True)
    try:
        a = np.asarray(value, dtype=np.int64).ravel()
    except (OverflowError, ValueError, TypeError):
        raise ConfigError(f"{key} = {show(value)}; expected a list of integers") from None
    bad = np.zeros(a.shape, bool)
    if lo is not None:
        bad |= a < lo
    if hi is not None:
        bad |= a > hi
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        rng = f"{lo}..{hi}" if lo is not None and hi is not None else f">= {lo}"
        raise ConfigError(f"{key} has the entry {int(a[i])}; expected integers in {rng}")
    return a


def float_array(
    value: Any,
    key: str,
    shape: tuple[int | None, ...] | None = None,
    *,
    finite: bool = True,
    allow_nan: bool = False,
) -> np.ndarray:
    """A float array of ``shape`` (None = any length on that axis), finite unless told."""
    _nested_numbers(value, key, want_int=False)
    try:
        a = np.array(value, dtype=float)
    except (OverflowError, ValueError, TypeError):
        raise ConfigError(f"{key} = {show(value)}; expected an array of numbers") from None
    if shape is not None:
        ok = a.ndim == len(shape) and all(
            s is None or s == n for s, n in zip(shape, a.shape, strict=True)
        )
        if not ok:
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
            if len(shape) == 1:
                want = want[:-1] + ",)"
            raise ConfigError(f"{key} must have shape {want}, got {a.shape}")
    if finite:
        bad = ~np.isfinite(a)
        if allow_nan:
            bad &= ~np.isnan(a)
        if bad.any():
            idx = tuple(int(i) for i in np.argwhere(bad)[0])
            where = f"[{', '.join(map(str, idx))}]" if idx else ""
            raise ConfigError(f"{key}{where} = {a[bad].ravel()[0]}; expected finite numbers")
    return a


class prefixed:  # noqa: N801 - used as a context manager, reads like a function
    """Context manager: a :class:`ConfigError` whose message starts with one of ``names`` is
    re-raised with ``prefix`` in front (so ``E = inf ...`` from ``Material`` becomes
    ``model.material.E = inf ...`` when it came from a TOML scene)."""

    def __init__(self, prefix: str, names: set[str] | tuple[str, ...] | None = None) -> None:
        self.prefix = prefix
        self.names = names

    def __enter__(self) -> None:
        return None

    def __exit__(self, tp: Any, exc: BaseException | None, tb: Any) -> bool:
        if exc is None or not isinstance(exc, ConfigError):
            return False
        msg = str(exc)
        head = msg.split(" ", 1)[0].split("[", 1)[0]
        if self.names is not None and not ({head, head.split(".", 1)[0]} & set(self.names)):
            return False
        raise ConfigError(f"{self.prefix}{msg}") from None
