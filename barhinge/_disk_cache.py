"""Small results kept between processes: float arrays keyed on the exact inputs and the code.

The stiffness calibration solves a few small problems per panel shape (a bounded
least-squares fit of the bar areas, a Kirchhoff-plate model of the panel in scikit-fem).
They cost little to solve but much to start: importing ``scipy.optimize`` and scikit-fem
takes longer than a small fold. Their answers are kept on disk, so a second run of the same
scene (or a sweep over sheets of the same panels) reads them instead.

What makes an entry safe to reuse
---------------------------------
* The key is a SHA-256 of the exact bytes of every input (arrays with their dtype and
  shape, strings, numbers), a namespace naming the computation, and a fingerprint of the
  code: the contents of every ``.py`` file of the installed barhinge package, the Python
  version and the installed files of the numerical libraries the computation uses. Any
  change to one of them is a different key, so an entry is only ever the answer the current
  code gives to the same inputs (bit for bit; the tests check it).
* Writes are atomic (a temporary file in the same folder, then ``os.replace``), so parallel
  processes (a Dask sweep) and an interrupted run never leave half a file. An unreadable,
  truncated or wrongly shaped entry is computed again and rewritten.
* A cache that cannot be written (a read-only home, a full disk) is skipped silently: the
  answer is computed as it would be without a cache.

Where it lives
--------------
``BARHINGE_CACHE_DIR`` names the folder; by default it is the user's cache folder
(``platformdirs.user_cache_dir("barhinge")``, ``~/.cache/barhinge`` on Linux).
``BARHINGE_CACHE=off`` turns it off. ``barhinge cache`` shows it and ``--clear`` empties it.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.util
import logging
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

logger = logging.getLogger(__name__)

__all__ = [
    "CACHE_DIR_ENV",
    "CACHE_SWITCH_ENV",
    "CacheInfo",
    "cache_dir",
    "cache_info",
    "clear_cache",
    "load_array",
    "make_key",
    "source_fingerprint",
    "store_array",
]

#: environment variable naming the cache folder
CACHE_DIR_ENV = "BARHINGE_CACHE_DIR"
#: environment variable that turns the cache off (``off``, ``0``, ``false`` or ``no``)
CACHE_SWITCH_ENV = "BARHINGE_CACHE"
_OFF = frozenset({"off", "0", "false", "no"})
#: sub-folder of the cache folder that holds the entries (``--clear`` removes only it)
_ENTRIES = "arrays"
#: suffix of an entry file
_SUFFIX = ".npy"
#: the barhinge package folder, whose sources key every entry
_PACKAGE = Path(__file__).resolve().parent


def cache_dir() -> Path | None:
    """The folder of the cache entries, or None when the cache is off (read at every call,
    so a change of the environment takes effect at once)."""
    if os.environ.get(CACHE_SWITCH_ENV, "").strip().lower() in _OFF:
        return None
    base = os.environ.get(CACHE_DIR_ENV, "").strip()
    if not base:
        import platformdirs

        base = platformdirs.user_cache_dir("barhinge", appauthor=False)
    return Path(base).expanduser() / _ENTRIES


def source_fingerprint(root: Path) -> bytes:
    """SHA-256 of the relative path and contents of every ``.py`` file under ``root``."""
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(b"\0")
        h.update(path.read_bytes())
        h.update(b"\0")
    return h.digest()


@functools.cache
def _package_fingerprint() -> bytes:
    """:func:`source_fingerprint` of barhinge, once per process (about 10 ms)."""
    return source_fingerprint(_PACKAGE)


@functools.cache
def _library_fingerprint(module: str) -> str:
    """Size and modification time of the installed entry file of ``module`` (found without
    importing it): a reinstalled or upgraded library rewrites its files."""
    spec = importlib.util.find_spec(module)
    origin = None if spec is None else spec.origin
    if origin is None or not os.path.exists(origin):
        return f"{module}:absent"
    st = os.stat(origin)
    return f"{module}:{origin}:{st.st_size}:{st.st_mtime_ns}"


def make_key(namespace: str, *parts: object, libraries: tuple[str, ...] = ()) -> str:
    """Hex key of a computation: its ``namespace``, the exact ``parts`` (numpy arrays by
    dtype, shape and bytes; str, int, float and bool by their repr; tuples element-wise),
    the code fingerprint and those of the ``libraries`` (module names) it runs on."""
    h = hashlib.sha256()
    h.update(namespace.encode())
    h.update(_package_fingerprint())
    h.update(f"python:{sys.version_info[:3]};numpy:{np.__version__}".encode())
    for module in libraries:
        h.update(_library_fingerprint(module).encode())
    _update(h, parts)
    return h.hexdigest()


def _update(h: hashlib._Hash, value: object) -> None:
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        h.update(f"array:{a.dtype.str}:{a.shape}".encode())
        h.update(a.tobytes())
    elif isinstance(value, tuple | list):
        h.update(f"seq:{len(value)}".encode())
        for item in value:
            _update(h, item)
    elif isinstance(value, str | int | float | bool | np.floating | np.integer) or value is None:
        h.update(f"{type(value).__name__}:{value!r}".encode())
    else:
        raise TypeError(f"cannot key the cache on a {type(value).__name__}")
    h.update(b";")


def _entry(folder: Path, namespace: str, key: str) -> Path:
    return folder / namespace / f"{key}{_SUFFIX}"


def load_array(namespace: str, key: str, shape: tuple[int, ...]) -> np.ndarray | None:
    """The kept float64 array of ``key``, or None (cache off, no entry, or an entry that is
    unreadable, of another shape or not finite: it will be computed again)."""
    folder = cache_dir()
    if folder is None:
        return None
    path = _entry(folder, namespace, key)
    try:
        value = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        return None
    except (OSError, ValueError, EOFError) as exc:
        logger.debug("cache entry %s unreadable (%s): computed again", path, exc)
        return None
    if value.dtype != np.float64 or value.shape != shape or not np.all(np.isfinite(value)):
        logger.debug("cache entry %s has dtype %s shape %s: computed again", path,
                     value.dtype, value.shape)  # fmt: skip
        return None
    return value


def store_array(namespace: str, key: str, value: np.ndarray) -> None:
    """Keep ``value`` (float64) under ``key``; atomic; does nothing if the cache is off or
    cannot be written."""
    folder = cache_dir()
    if folder is None:
        return
    path = _entry(folder, namespace, key)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=_SUFFIX)
        with os.fdopen(fd, "wb") as fh:
            np.save(fh, np.asarray(value, dtype=np.float64), allow_pickle=False)
        os.replace(tmp, path)
        tmp = None
    except OSError as exc:
        logger.debug("cache entry %s not written (%s)", path, exc)
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


@dataclass(frozen=True)
class CacheInfo:
    """Where the cache is and what it holds."""

    folder: Path | None
    entries: int
    bytes: int


def cache_info() -> CacheInfo:
    """The cache folder (None when off), its number of entries and their total size."""
    folder = cache_dir()
    if folder is None or not folder.is_dir():
        return CacheInfo(folder, 0, 0)
    files = [p for p in folder.rglob(f"*{_SUFFIX}") if not p.name.startswith(".tmp-")]
    return CacheInfo(folder, len(files), sum(p.stat().st_size for p in files))


def clear_cache() -> CacheInfo:
    """Remove every entry (the cache folder's ``arrays`` sub-folder); returns what it held."""
    before = cache_info()
    if before.folder is not None and before.folder.is_dir():
        shutil.rmtree(before.folder)
    return before
