"""The result folder of a run: written atomically, one run replaced whole, marked by its
manifest ``barhinge-run.json`` (files and sizes, version, command, scene, ``converged``,
``reason``); single files replaced in one step (:func:`atomic_file`).

docs/outputs.md describes the folder and its manifest.
"""

from __future__ import annotations

import contextlib
import ctypes
import datetime
import errno
import glob
import json
import logging
import os
import secrets
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from barhinge._json import jsonable
from barhinge.errors import ConfigError

__all__ = [
    "MANIFEST",
    "RunFolder",
    "add_to_manifest",
    "atomic_file",
    "check_output_folder",
    "read_manifest",
    "result_folder",
]

log = logging.getLogger(__name__)

#: name of the manifest that marks a folder as one barhinge run
MANIFEST = "barhinge-run.json"
#: version of the manifest's layout
MANIFEST_FORMAT = 1
_TMP_TAG = "barhinge-tmp"  # .<name>.barhinge-tmp-<pid>-<hex>: a run being written
_OLD_TAG = "barhinge-old"  # .<name>.barhinge-old-<pid>-<hex>: a replaced run being removed


def _sibling(out: Path, tag: str) -> Path:
    return out.with_name(f".{out.name}.{tag}-{os.getpid()}-{secrets.token_hex(4)}")


def _pid_alive(pid: int) -> bool:
    if os.name != "posix":  # os.kill(pid, 0) would terminate the process on Windows
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: alive, someone else's
        return True
    return True


def _remove_leftovers(out: Path) -> None:
    """Remove temporary siblings of ``out`` left by runs that were killed (their process is
    gone); those of live processes are left alone."""
    for tag in (_TMP_TAG, _OLD_TAG):
        for p in out.parent.glob(f".{glob.escape(out.name)}.{tag}-*"):
            pid = p.name.rsplit("-", 2)[-2]
            if pid.isdigit() and not _pid_alive(int(pid)):
                log.info("removing %s, left by a killed run", p)
                shutil.rmtree(p, ignore_errors=True)


def _listed_files(folder: Path) -> dict[str, int]:
    """Relative POSIX path -> size of every file under ``folder`` (the manifest excluded)."""
    return {
        p.relative_to(folder).as_posix(): p.stat().st_size
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != MANIFEST
    }


def read_manifest(folder: str | Path, *, check: bool = True) -> dict[str, Any]:
    """The manifest of a result folder (``barhinge-run.json``), checked against the files.

    Parameters
    ----------
    folder : path
        A folder written by ``barhinge fold`` (or :func:`result_folder`).
    check : bool
        Also check that every listed file exists with its listed size and that the folder
        holds no other file.

    Raises
    ------
    ConfigError
        No manifest, an unreadable one, or (``check``) files that do not match it.
    """
    folder = Path(folder)
    f = folder / MANIFEST
    if not f.is_file():
        raise ConfigError(f"{folder} is not a barhinge result folder (no {MANIFEST})")
    try:
        man = json.loads(f.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ConfigError(f"{f}: unreadable manifest ({exc})") from None
    if not isinstance(man, dict) or not isinstance(man.get("files"), dict):
        raise ConfigError(f"{f}: not a barhinge manifest (expected an object with 'files')")
    if check:
        have = _listed_files(folder)
        want = man["files"]
        missing = sorted(set(want) - set(have))
        if missing:
            raise ConfigError(f"{folder}: {len(missing)} file(s) of the run missing: {missing[0]}")
        extra = sorted(set(have) - set(want))
        if extra:
            raise ConfigError(f"{folder}: {len(extra)} file(s) not of the run: {extra[0]}")
        wrong = sorted(k for k in want if have[k] != want[k])
        if wrong:
            raise ConfigError(
                f"{folder}/{wrong[0]}: {have[wrong[0]]} bytes, the manifest says {want[wrong[0]]}"
            )
    return man


def _probe_writable(out: Path) -> None:
    """ConfigError unless a folder can be made beside ``out`` (where the run is written
    before it is swapped in): its parent is created if needed and probed with a real
    folder, since permission bits do not tell (root, read-only or virtual file systems)."""
    parent = out.absolute().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        probe = tempfile.mkdtemp(prefix=".barhinge-probe-", dir=parent)
        os.rmdir(probe)
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise ConfigError(f"--out {out}: cannot write in {parent} ({why})") from None


def check_output_folder(out: str | Path, *, overwrite: bool = False) -> Path:
    """Check, before any work, that ``out`` may receive a run; returns it.

    ``out`` may be absent, an empty folder or a barhinge result folder (a manifest and no
    file outside it); anything else needs ``overwrite=True``. Refused even then: a path that
    is a file, the working directory or one of its parents, the home folder and the root.

    Raises
    ------
    ConfigError
        With one line naming the folder and what to do.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file, not a folder")
    for parent in out.absolute().parents:
        if parent.exists() and not parent.is_dir():
            raise ConfigError(f"--out {out}: {parent} is a file, not a folder")
    _probe_writable(out)
    if not out.is_dir():
        return out
    real = out.resolve()
    if real == Path.cwd().resolve() or real in Path.cwd().resolve().parents:
        raise ConfigError(f"--out {out} is the working folder or one of its parents; choose "
                          "a folder for the results")  # fmt: skip
    with contextlib.suppress(RuntimeError, KeyError):  # no home folder known
        if real == Path.home().resolve():
            raise ConfigError(f"--out {out} is the home folder; choose a folder for the results")
    if real == Path(real.anchor):
        raise ConfigError(f"--out {out} is the root folder; choose a folder for the results")
    if overwrite or not any(out.iterdir()):
        return out
    if not (out / MANIFEST).is_file():
        raise ConfigError(
            f"--out {out} is not empty and not a barhinge result folder (no {MANIFEST}); "
            "choose another folder or pass --overwrite to replace it"
        )
    try:
        listed = set(read_manifest(out, check=False)["files"])
    except ConfigError as exc:
        raise ConfigError(f"{exc}; pass --overwrite to replace the folder") from None
    extra = sorted(set(_listed_files(out)) - listed)
    if extra:
        raise ConfigError(
            f"--out {out} holds {len(extra)} file(s) that are not part of its barhinge run "
            f"({extra[0]}); pass --overwrite to replace the folder, those files included"
        )
    return out


def _exchange(a: Path, b: Path) -> bool:
    """Swap two existing paths in one step (Linux ``renameat2(RENAME_EXCHANGE)``); False
    where the system or file system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _fsync_tree(folder: Path) -> None:
    """Flush every file (and the folder) to disk, so a rename never exposes empty files
    after a power cut."""
    if os.name != "posix":
        return
    for p in [*sorted(folder.rglob("*")), folder]:
        fd = os.open(p, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


class RunFolder:
    """A result folder being written (see :func:`result_folder`).

    Attributes
    ----------
    path : Path
        The temporary folder to write into (a hidden sibling of ``out``).
    out : Path
        Where the run lands.
    manifest : dict
        Written to ``barhinge-run.json`` at the end; fill in ``scene``, ``converged``,
        ``reason``, ``message``, ``n_states`` (``files`` is listed from the folder).
    """

    def __init__(self, path: Path, out: Path, manifest: dict[str, Any]) -> None:
        self.path = path
        self.out = out
        self.manifest = manifest


@contextlib.contextmanager
def result_folder(
    out: str | Path, *, overwrite: bool = False, command: str = "fold"
) -> Iterator[RunFolder]:
    """Write a run into ``out`` atomically.

    Yields a :class:`RunFolder` whose ``path`` is a new hidden sibling of ``out`` (same
    parent, so the final rename stays on one file system). On a normal exit the manifest
    ``barhinge-run.json`` (the files and their sizes, the barhinge version, the command and
    what the caller put in ``manifest``) is written last and the folder swapped in: the old
    ``out`` is exchanged with it in one step (Linux), or moved aside first, then removed.
    On an exception (KeyboardInterrupt included) the temporary folder is removed and
    ``out`` is untouched. A reader thus sees no folder, the complete previous run or the
    complete new run; a killed run leaves only a hidden sibling, removed by the next run.

    Raises
    ------
    ConfigError
        ``out`` may not receive a run (see :func:`check_output_folder`).
    """
    from barhinge._version import __version__

    out = check_output_folder(out, overwrite=overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    _remove_leftovers(out)
    tmp = _sibling(out, _TMP_TAG)
    tmp.mkdir()
    run = RunFolder(
        tmp,
        out,
        {
            "barhinge_run": MANIFEST_FORMAT,
            "barhinge_version": __version__,
            "command": command,
            "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        },
    )
    try:
        yield run
        man = {**run.manifest, "files": _listed_files(tmp)}
        (tmp / MANIFEST).write_text(json.dumps(jsonable(man, nan=False), indent=2) + "\n")
        _fsync_tree(tmp)
        if not out.exists():
            os.rename(tmp, out)
        elif _exchange(tmp, out):
            shutil.rmtree(tmp, ignore_errors=True)  # tmp now holds the old run
        else:
            old = _sibling(out, _OLD_TAG)
            os.rename(out, old)
            os.rename(tmp, out)
            shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def atomic_file(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix) to write to; on a normal exit it
    replaces ``path`` in one step (``os.replace``), on an exception it is removed."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}-{secrets.token_hex(4)}.tmp{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def add_to_manifest(folder: str | Path, files: list[Path]) -> None:
    """List ``files`` (inside ``folder``) in its manifest, if it has one (``barhinge
    render`` adds its pictures to the run this way); the manifest is replaced atomically."""
    folder = Path(folder)
    f = folder / MANIFEST
    if not f.is_file():
        return
    man = read_manifest(folder, check=False)
    root = folder.resolve()
    for p in files:
        rel = Path(p).resolve().relative_to(root).as_posix()
        man["files"][rel] = Path(p).stat().st_size
    with atomic_file(f) as tmp:
        tmp.write_text(json.dumps(jsonable(man, nan=False), indent=2) + "\n")
