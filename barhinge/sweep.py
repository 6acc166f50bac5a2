"""Parameter sweeps: map a function over a grid, serially, on a local Dask cluster or a remote one.

A study (``STUDY.toml``) names a point function ``"module:function"`` and a parameter grid::

    [study]
    name = "demo"
    function = "mypkg.points:run"   # called as run(**params), returns a small JSON-able dict
    paths = ["."]                   # folders put on sys.path (client and workers) for the import
    out = "results/demo"            # output folder (relative to the TOML file)
    batch_size = 1                  # points per task (batch points shorter than ~0.1 s)

    [grid]                          # the Cartesian product of these lists
    spacing = [1.0, 2.0]
    kappa = [0.0, 0.1, 0.2]

    [fixed]                         # passed to every point (part of its identity)
    steps = 20

    [[points]]                      # extra explicit points (merged with [fixed])
    spacing = 3.0
    kappa = 0.5

Output folder::

    points/<id>.json    one record per finished point (written by the client, atomically)
    summary.csv         one row per point of the study (summary.parquet too if pyarrow exists)
    study.json          the study that produced them

A point's identity is a stable hash of its parameters (:func:`point_id`). A rerun skips the
points that already have a record (``retry_failed=True`` reruns the failed ones), so an
interrupted sweep resumes where it stopped. The client is the only writer and keys records by
point id, so a point that Dask re-executes after a worker died still yields exactly one record.
A point that raises records ``{"type", "message"}`` and the sweep goes on; so does a point whose
result holds NaN or an infinity (``NonFiniteResult``, naming the key) and a point that kills the
worker running it (``KilledWorker``: every point Dask gives up on is run again alone, and only
one that still kills its workers fails). Every JSON file written is strict JSON (no ``NaN``).
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import datetime as _dt
import hashlib
import importlib
import itertools
import json
import logging
import math
import os
import socket
import sys
import time
import tomllib
import uuid
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, Literal

from barhinge._json import default
from barhinge.errors import ConfigError

__all__ = [
    "Point",
    "Study",
    "SweepReport",
    "load_study",
    "point_id",
    "read_records",
    "run_batch",
    "run_study",
    "write_summary",
]

log = logging.getLogger(__name__)

Mode = Literal["serial", "local", "dask"]
Record = dict[str, Any]

_STUDY_KEYS = {"name", "function", "paths", "out", "batch_size"}
_TOP_KEYS = {"study", "grid", "fixed", "points"}
_RESERVED = ("id", "status", "error_type", "error_message", "elapsed_s", "worker")


# ------------------------------------------------------------------------------ identity
def _canonical(params: dict[str, Any]) -> str:
    return json.dumps(params, sort_keys=True, separators=(",", ":"), default=default)


def _dumps(obj: Any, **kw: Any) -> str:
    """Strict JSON (ValueError on NaN or an infinity), numpy values converted."""
    return json.dumps(obj, default=default, allow_nan=False, **kw)


def _non_finite(v: Any, where: str, found: list[str]) -> Any:
    """``v`` (parsed JSON) with NaN and infinities replaced by None; each one found is
    appended to ``found`` as ``"'<where>' is nan"``."""
    if isinstance(v, float) and not math.isfinite(v):
        found.append(f"'{where}' is {v}")
        return None
    if isinstance(v, dict):
        return {k: _non_finite(x, f"{where}.{k}" if where else str(k), found) for k, x in v.items()}
    if isinstance(v, list):
        return [_non_finite(x, f"{where}[{i}]", found) for i, x in enumerate(v)]
    return v


def _check_finite(v: Any, where: str) -> None:
    """ConfigError naming the first NaN or infinity in a study parameter."""
    found: list[str] = []
    _non_finite(v, "", found)
    if found:
        key, value = found[0][1:].split("' is ")
        raise ConfigError(
            f"study {where} {key} = {value}; expected finite numbers (records are strict JSON)"
        )


_JSON_SCALARS = (str, int, float, bool, type(None))


def _not_json(v: Any, where: str) -> str | None:
    """``"<where> = <value> (<type>)"`` for the first value of ``v`` that has no JSON form
    (a TOML date or time, a set, an object), else None."""
    if isinstance(v, dict):
        for k, x in v.items():
            if not isinstance(k, str):
                return f"{where} key {k!r} ({type(k).__name__})"
            bad = _not_json(x, f"{where}.{k}" if where else k)
            if bad:
                return bad
        return None
    if isinstance(v, list | tuple):
        for i, x in enumerate(v):
            bad = _not_json(x, f"{where}[{i}]")
            if bad:
                return bad
        return None
    if isinstance(v, _JSON_SCALARS) or hasattr(v, "tolist") or isinstance(v, Path):
        return None
    return f"{where} = {v!r} ({type(v).__name__})"


def _check_json(v: Any, where: str) -> None:
    """ConfigError naming the first study parameter without a JSON form."""
    bad = _not_json(v, "")
    if bad:
        raise ConfigError(
            f"study {where} {bad.lstrip('.')}; expected numbers, text, true/false, lists or "
            "tables (dates and times are not parameters: write them as text)"
        )


def point_id(params: dict[str, Any]) -> str:
    """Stable identity of a parameter point: 16 hex digits of SHA-256 of its canonical JSON.

    Key order does not matter; value types do (``1`` and ``1.0`` are different points).
    """
    return hashlib.sha256(_canonical(params).encode()).hexdigest()[:16]


@dataclasses.dataclass(frozen=True)
class Point:
    """One parameter point: ``id`` = :func:`point_id` of ``params``."""

    id: str
    params: dict[str, Any]


# ------------------------------------------------------------------------------ study
@dataclasses.dataclass(frozen=True)
class Study:
    """A point function mapped over a parameter grid.

    Parameters
    ----------
    function : str
        ``"module:function"``; called as ``function(**params)``, returns a dict of JSON-able
        values (numpy arrays and scalars are converted).
    grid : dict of lists
        Cartesian product, in the order given (the last key varies fastest).
    fixed : dict
        Parameters added to every point.
    points : sequence of dicts
        Explicit extra points (merged with ``fixed``).
    name, out : study name and output folder.
    batch_size : int
        Points per task on a cluster.
    paths : sequence of str
        Absolute folders put on ``sys.path`` before importing ``function`` (also on workers,
        which must see the same file system).
    """

    function: str
    grid: dict[str, list[Any]] = dataclasses.field(default_factory=dict)
    fixed: dict[str, Any] = dataclasses.field(default_factory=dict)
    points: tuple[dict[str, Any], ...] = ()
    name: str = "study"
    out: Path | None = None
    batch_size: int = 1
    paths: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.function, str) or self.function.count(":") != 1:
            raise ConfigError(f"study function must be 'module:function', got {self.function!r}")
        for k, v in self.grid.items():
            if not isinstance(v, list) or not v:
                raise ConfigError(f"grid entry {k!r} must be a non-empty list, got {v!r}")
        if (
            isinstance(self.batch_size, bool)
            or not isinstance(self.batch_size, int)
            or self.batch_size < 1
        ):
            raise ConfigError(f"batch_size must be an integer >= 1, got {self.batch_size!r}")
        for i, p in enumerate(self.points):
            if not isinstance(p, dict):
                raise ConfigError(f"study [[points]] {i}: {p!r}; expected a table")
        for value, where in (
            (self.grid, "[grid]"),
            (self.fixed, "[fixed]"),
            *((p, f"[[points]] {i}:") for i, p in enumerate(self.points)),
        ):
            _check_json(value, where)
            _check_finite(value, where)

    def expand(self) -> list[Point]:
        """All points: the grid product then the explicit points; repeats dropped."""
        rows: list[dict[str, Any]] = []
        if self.grid:
            keys = list(self.grid)
            rows += [
                dict(zip(keys, vals, strict=True))
                for vals in itertools.product(*self.grid.values())
            ]
        rows += [dict(p) for p in self.points]
        if not rows:
            rows = [{}]
        out: dict[str, Point] = {}
        for r in rows:
            params = {**self.fixed, **r}
            pid = point_id(params)
            out.setdefault(pid, Point(pid, params))
        return list(out.values())


def load_study(path: str | Path) -> Study:
    """Read a study TOML (see the module docstring); relative paths are taken from its folder."""
    path = Path(path)
    data = _read_toml(path)
    _check_tables(path, data)
    st = data.get("study", {})
    _check_study_table(path, st)
    if not all(isinstance(p, dict) for p in data.get("points", [])):
        raise ConfigError(f"study file {path}: every [[points]] entry must be a table")
    base = path.resolve().parent
    out = st.get("out")
    return Study(
        function=st["function"],
        grid=dict(data.get("grid", {})),
        fixed=dict(data.get("fixed", {})),
        points=tuple(data.get("points", [])),
        name=str(st.get("name", path.stem)),
        out=(base / out) if out else base / f"{path.stem}-results",
        batch_size=st.get("batch_size", 1),
        paths=tuple(str(base / p) for p in st.get("paths", [])),
    )


def _read_toml(path: Path) -> dict[str, Any]:
    """The TOML file ``path`` as a dict; ConfigError naming what is wrong with the file."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"study file {path} does not exist") from None
    except IsADirectoryError:
        raise ConfigError(f"study file {path} is a folder; expected a TOML file") from None
    except UnicodeDecodeError:
        raise ConfigError(f"study file {path} is not text (UTF-8 TOML expected)") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"study file {path} is not valid TOML: {exc}") from None


def _check_tables(path: Path, data: dict[str, Any]) -> None:
    """The top-level tables of a study file: known names and the right kinds."""
    for key, kind in (("study", dict), ("grid", dict), ("fixed", dict), ("points", list)):
        if key in data and not isinstance(data[key], kind):
            what = "a table" if kind is dict else "an array of tables"
            raise ConfigError(
                f"study file {path}: {key} = {data[key]!r}; expected {what} ([{key}])"
            )
    unknown = set(data) - _TOP_KEYS
    if unknown:
        raise ConfigError(
            f"study file {path}: unknown table(s) {sorted(unknown)}; expected {sorted(_TOP_KEYS)}"
        )


def _check_study_table(path: Path, st: dict[str, Any]) -> None:
    """The [study] table: known keys, ``function = 'module:function'``, text names."""
    unknown = set(st) - _STUDY_KEYS
    if unknown:
        raise ConfigError(
            f"study file {path}: unknown [study] key(s) {sorted(unknown)}; "
            f"expected {sorted(_STUDY_KEYS)}"
        )
    if "function" not in st:
        raise ConfigError(f"study file {path}: [study] needs function = 'module:function'")
    if not isinstance(st["function"], str) or st["function"].count(":") != 1:
        raise ConfigError(
            f"study file {path}: [study] function = {st['function']!r}; expected 'module:function'"
        )
    paths = st.get("paths", [])
    if not (isinstance(paths, list) and all(isinstance(p, str) for p in paths)):
        raise ConfigError(
            f"study file {path}: [study] paths = {paths!r}; expected a list of folder names"
        )
    for key in ("name", "out"):
        if key in st and not isinstance(st[key], str):
            raise ConfigError(f"study file {path}: [study] {key} = {st[key]!r}; expected text")


# ------------------------------------------------------------------------------ worker side
def _resolve(function: str, paths: Sequence[str]) -> Callable[..., Any]:
    for p in paths:
        if p not in sys.path:
            sys.path.insert(0, p)
    mod_name, fn_name = function.split(":")
    try:
        fn = getattr(importlib.import_module(mod_name), fn_name)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"cannot import study function {function!r}: {exc}") from None
    return fn


def _one_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else ""


def _run_point(fn: Callable[..., Any], pid: str, params: dict[str, Any]) -> Record:
    t0 = time.perf_counter()
    rec: Record = {"id": pid, "params": params, "status": "ok", "result": None, "error": None}
    try:
        res = fn(**params)
        if not isinstance(res, dict):
            res = {"value": res}
        found: list[str] = []
        rec["result"] = _non_finite(json.loads(json.dumps(res, default=default)), "", found)
        if found:  # kept as null; the point failed (a NaN is no result, and not strict JSON)
            rec["status"] = "failed"
            more = f" ({len(found)} non-finite values)" if len(found) > 1 else ""
            rec["error"] = {
                "type": "NonFiniteResult",
                "message": f"result {', '.join(found[:3])}{more}; expected finite numbers",
            }
    except Exception as exc:  # a failing point is recorded, the sweep goes on
        rec["status"] = "failed"
        rec["error"] = {"type": type(exc).__name__, "message": _one_line(exc)}
    rec["elapsed_s"] = time.perf_counter() - t0
    rec["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    rec["finished_at"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    return rec


def run_batch(
    function: str, paths: Sequence[str], batch: Sequence[tuple[str, dict[str, Any]]]
) -> list[Record]:
    """Run a batch of points ``[(id, params), ...]``; the task sent to workers.

    Returns one record per point (``status`` "ok" with ``result``, or "failed" with
    ``error = {"type", "message"}``).
    """
    try:
        fn = _resolve(function, paths)
    except ConfigError as exc:
        return [_failed(pid, params, exc) for pid, params in batch]
    return [_run_point(fn, pid, params) for pid, params in batch]


def _failed(
    pid: str, params: dict[str, Any], exc: BaseException, message: str | None = None
) -> Record:
    return {
        "id": pid,
        "params": params,
        "status": "failed",
        "result": None,
        "error": {"type": type(exc).__name__, "message": message or _one_line(exc)},
        "elapsed_s": None,
        "worker": None,
        "finished_at": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
    }


# ------------------------------------------------------------------------------ records
def _points_dir(out: Path) -> Path:
    return out / "points"


def _atomic_write(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def write_record(out: Path, rec: Record) -> Path:
    """Write ``points/<id>.json`` atomically (temporary file + rename)."""
    path = _points_dir(out) / f"{rec['id']}.json"
    _atomic_write(path, _dumps(rec, indent=1))
    return path


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not strict JSON")


def read_records(out: str | Path) -> dict[str, Record]:
    """All point records in an output folder, keyed by point id (unreadable files skipped,
    and so are records holding NaN or Infinity, which older versions wrote: a rerun runs those
    points again)."""
    pdir = _points_dir(Path(out))
    recs: dict[str, Record] = {}
    if not pdir.is_dir():
        return recs
    for f in sorted(pdir.glob("*.json")):
        if f.name.startswith("."):
            continue
        try:
            rec = json.loads(f.read_text(), parse_constant=_no_constant)
        except (OSError, ValueError) as exc:
            log.warning("ignoring unreadable record %s (%s); the point will be rerun", f, exc)
            continue
        if rec.get("id") == f.stem:
            recs[f.stem] = rec
    return recs


_MAX_CELL = 1000  # longer non-scalar results stay in the point records only


def _cell(v: Any) -> Any:
    if v is None or isinstance(v, str | int | float | bool):
        return v
    text = _dumps(v)
    return text if len(text) <= _MAX_CELL else "(see points/<id>.json)"


def write_summary(out: str | Path, points: Sequence[Point], records: dict[str, Record]) -> Path:
    """Write ``summary.csv`` (and ``summary.parquet`` if pyarrow exists): one row per point.

    Columns: id, status, the parameters, the result's keys (non-scalar values as JSON, or a
    pointer to the record when longer than 1000 characters; a key
    that clashes with a parameter or a fixed column becomes ``result.<key>``), error_type,
    error_message, elapsed_s, worker. Points without a record have status "pending".
    """
    out = Path(out)
    rows: list[dict[str, Any]] = []
    pcols: dict[str, None] = {}
    rcols: dict[str, None] = {}
    for p in points:
        pcols.update(dict.fromkeys(p.params))
    for p in points:
        rec = records.get(p.id)
        row: dict[str, Any] = {"id": p.id, "status": rec["status"] if rec else "pending"}
        row.update({k: _cell(v) for k, v in p.params.items()})
        if rec:
            for k, v in (rec.get("result") or {}).items():
                col = f"result.{k}" if (k in pcols or k in _RESERVED) else k
                rcols[col] = None
                row[col] = _cell(v)
            err = rec.get("error") or {}
            row.update(
                error_type=err.get("type"),
                error_message=err.get("message"),
                elapsed_s=rec.get("elapsed_s"),
                worker=rec.get("worker"),
            )
        rows.append(row)
    cols = ["id", "status", *pcols, *rcols, "error_type", "error_message", "elapsed_s", "worker"]
    path = out / "summary.csv"
    tag = f"{os.getpid()}.{uuid.uuid4().hex[:8]}"
    tmp = path.with_name(f".summary.{tag}.csv.tmp")
    with tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, restval="")
        w.writeheader()
        w.writerows(rows)
    tmpq = None
    with contextlib.suppress(ImportError):
        import pyarrow as pa
        import pyarrow.parquet as pq

        tmpq = path.with_name(f".summary.{tag}.parquet.tmp")
        pq.write_table(pa.Table.from_pylist([{c: r.get(c) for c in cols} for r in rows]), tmpq)
    # the two never disagree: the old parquet goes first, so a kill in between leaves the new
    # csv alone (or both old ones)
    (out / "summary.parquet").unlink(missing_ok=True)
    os.replace(tmp, path)
    if tmpq is not None:
        os.replace(tmpq, out / "summary.parquet")
    return path


def _remove_summary(out: Path) -> None:
    """Remove the summary files of ``out`` (they describe another study)."""
    for name in ("summary.parquet", "summary.csv"):
        (out / name).unlink(missing_ok=True)


# ------------------------------------------------------------------------------ driver
@dataclasses.dataclass
class SweepReport:
    """Live counts of a sweep (updated as records arrive) and its records."""

    out: Path
    total: int
    skipped: int = 0
    pending: int = 0
    done: int = 0
    failed: int = 0
    elapsed_s: float = 0.0
    records: dict[str, Record] = dataclasses.field(default_factory=dict)

    @property
    def finished(self) -> int:
        """Points finished in this run (ok or failed)."""
        return self.done + self.failed


def _batches(todo: list[Point], size: int) -> Iterator[list[tuple[str, dict[str, Any]]]]:
    for i in range(0, len(todo), size):
        yield [(p.id, p.params) for p in todo[i : i + size]]


def _serial(study: Study, todo: list[Point]) -> Iterator[list[Record]]:
    fn = _resolve(study.function, study.paths)
    for p in todo:
        yield [_run_point(fn, p.id, p.params)]


@contextlib.contextmanager
def _dask_client(scheduler: str | None, workers: int | None, timeout_s: float) -> Iterator[Any]:
    from distributed import Client, LocalCluster

    cluster = None
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout=f"{timeout_s}s")
            except OSError as exc:
                raise ConfigError(
                    f"cannot connect to the Dask scheduler {scheduler}: {exc}"
                ) from None
        else:
            n = workers or max(1, min(2, os.cpu_count() or 1))
            cluster = LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None
            )
            client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
    finally:
        if cluster is not None:
            cluster.close()


def _dask(
    study: Study,
    todo: list[Point],
    batch_size: int,
    scheduler: str | None,
    workers: int | None,
    timeout_s: float,
) -> Iterator[list[Record]]:
    from distributed import KilledWorker, as_completed

    with _dask_client(scheduler, workers, timeout_s=timeout_s) as client:
        futures = {}
        tag = uuid.uuid4().hex[:8]
        for batch in _batches(todo, batch_size):
            key = f"barhinge-point-{batch[0][0]}-{tag}"
            fut = client.submit(
                run_batch, study.function, list(study.paths), batch, key=key, pure=False
            )
            futures[fut] = batch
        suspects: list[tuple[str, dict[str, Any]]] = []
        for fut in as_completed(futures):
            batch = futures[fut]
            try:
                recs = fut.result()
            except KilledWorker:  # on a worker that died: the killer, or in its queue
                suspects += batch
                continue
            except Exception as exc:  # e.g. a lost connection
                recs = [_failed(pid, params, exc) for pid, params in batch]
            yield recs
        if suspects:
            log.info("%d points were on workers that died; running them alone", len(suspects))
        for pid, params in suspects:  # alone on the cluster: a death is this point's doing
            fut = client.submit(
                run_batch, study.function, list(study.paths), [(pid, params)],
                key=f"barhinge-alone-{pid}-{tag}", pure=False,
            )  # fmt: skip
            try:
                recs = fut.result()
            except KilledWorker as exc:
                n = int(getattr(exc, "allowed_failures", 0)) + 1
                last = getattr(getattr(exc, "last_worker", None), "address", "unknown")
                msg = (
                    f"worker died (killed {n} time{'s' if n != 1 else ''}) running this point "
                    f"alone; last worker {last}"
                )
                recs = [_failed(pid, params, exc, message=msg)]
            except Exception as exc:
                recs = [_failed(pid, params, exc)]
            yield recs


def _check_signature(study: Study, points: Sequence[Point], *, required: bool) -> None:
    """ConfigError when the point function cannot take some point's parameters: a key
    it does not accept (a typo in ``[grid]``) or a required parameter no point gives. Checked
    before anything runs, so a wrong key stops the study instead of failing every point.
    Where the function cannot be imported here (``required=False``: a cluster whose workers
    see other folders) the check is skipped and the workers report it per point."""
    import inspect

    try:
        fn = _resolve(study.function, study.paths)
    except ConfigError:
        if required:
            raise
        log.info("cannot import %s here; its parameters are checked on the workers", study.function)
        return
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # a builtin or a C function: nothing to read
        return
    params = sig.parameters.values()
    if any(p.kind is p.VAR_KEYWORD for p in params):
        accepted = None
    else:
        accepted = {p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}
    needed = [
        p.name
        for p in params
        if p.default is p.empty and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    takes = ", ".join(p.name for p in params) or "no parameters"
    for pt in points:
        extra = [k for k in pt.params if accepted is not None and k not in accepted]
        if extra:
            where = _where(study, extra[0])
            raise ConfigError(
                f"study {where} key {extra[0]!r}: the point function {study.function} does "
                f"not accept it; it takes {takes}"
            )
        missing = [k for k in needed if k not in pt.params]
        if missing:
            raise ConfigError(
                f"study point {pt.params}: the point function {study.function} needs "
                f"{missing[0]!r}, which no [grid], [fixed] or [[points]] entry gives"
            )


def _where(study: Study, key: str) -> str:
    """The table of a study that sets ``key``."""
    if key in study.grid:
        return "[grid]"
    if key in study.fixed:
        return "[fixed]"
    return "[[points]]"


def run_study(
    study: Study,
    *,
    out: str | Path | None = None,
    mode: Mode = "local",
    scheduler: str | None = None,
    workers: int | None = None,
    batch_size: int | None = None,
    retry_failed: bool = False,
    on_start: Callable[[SweepReport], None] | None = None,
    on_record: Callable[[Record, SweepReport], None] | None = None,
    summary_every_s: float = 2.0,
    connect_timeout_s: float = 30.0,
) -> SweepReport:
    """Run (or resume) a study; each point's record is written as soon as it finishes.

    Parameters
    ----------
    study : Study
    out : path, optional
        Output folder (default ``study.out``).
    mode : "serial", "local" or "dask"
        In this process; on a Dask ``LocalCluster`` of ``workers`` processes (default 2); on
        the existing cluster at ``scheduler`` (``"tcp://host:port"``, implies "dask").
    batch_size : int, optional
        Points per Dask task (default ``study.batch_size``).
    retry_failed : bool
        Rerun points whose record says "failed" (default: keep them).
    on_start, on_record : callables, optional
        Progress hooks: ``on_start(report)`` once the pending points are known,
        ``on_record(record, report)`` after each record is written.
    summary_every_s : float
        Rewrite ``summary.csv`` at most this often during the sweep (and always at the end).
    connect_timeout_s : float
        Timeout for connecting to ``scheduler`` (ConfigError when it passes).

    Returns
    -------
    SweepReport
        Counts of this run and the records of all the study's points.

    Raises
    ------
    KeyboardInterrupt
        Passed on after the summary of what finished is written; a rerun resumes.
    """
    mode = _checked_mode(mode, scheduler)
    out = Path(out) if out is not None else study.out
    if out is None:
        raise ConfigError("no output folder: give out= or set [study] out")
    t0 = time.perf_counter()
    points = study.expand()
    _check_signature(study, points, required=mode == "serial")
    same = _prepare_folder(study, out)
    records = _known_records(out, points)
    todo = [
        p
        for p in points
        if p.id not in records or (retry_failed and records[p.id].get("status") != "ok")
    ]
    rep = SweepReport(
        out=out, total=len(points), skipped=len(points) - len(todo), pending=len(todo)
    )
    rep.records = records
    if not same or not (out / "summary.csv").exists():
        write_summary(out, points, records)  # at once: what is known of this study
    if on_start:
        on_start(rep)
    log.info("study %s: %d points, %d to run (%s)", study.name, len(points), len(todo), mode)

    bs = study.batch_size if batch_size is None else int(batch_size)
    if bs < 1:
        raise ConfigError(f"batch_size must be >= 1, got {bs}")
    if not todo:
        stream: Iterator[list[Record]] = iter(())
    elif mode == "serial":
        stream = _serial(study, todo)
    else:
        stream = _dask(study, todo, bs, scheduler, workers, connect_timeout_s)
    try:
        _collect(stream, out, points, rep, t0, on_record, summary_every_s)
    finally:
        close = getattr(stream, "close", None)
        if close is not None:  # shut a cluster down now, not when the generator is collected
            close()
        write_summary(out, points, records)
        rep.elapsed_s = time.perf_counter() - t0
    return rep


def _checked_mode(mode: str, scheduler: str | None) -> Mode:
    """The run mode: "dask" whenever a scheduler is given; ConfigError on a bad one."""
    if scheduler:
        mode = "dask"
    if mode not in ("serial", "local", "dask"):
        raise ConfigError(f"mode must be 'serial', 'local' or 'dask', got {mode!r}")
    if mode == "dask" and not scheduler:
        raise ConfigError("mode 'dask' needs a scheduler address such as tcp://127.0.0.1:8786")
    return mode  # type: ignore[return-value]


def _prepare_folder(study: Study, out: Path) -> bool:
    """Create the study folder, drop temporary files of a killed run and write
    ``study.json``; True when the folder already held this very study."""
    pdir = _points_dir(out)
    pdir.mkdir(parents=True, exist_ok=True)
    for stale in [*pdir.glob(".*.tmp"), *out.glob(".*.tmp")]:  # of a killed run
        stale.unlink(missing_ok=True)
    spec = _dumps(dataclasses.asdict(study) | {"out": str(out)}, indent=1)
    try:
        same = (out / "study.json").read_text() == spec
    except (OSError, UnicodeDecodeError):
        same = False
    if not same:  # the summary of another study must not sit beside this study.json
        _remove_summary(out)
        _atomic_write(out / "study.json", spec)
    return same


def _known_records(out: Path, points: Sequence[Point]) -> dict[str, Record]:
    """The records in ``out`` of this study's points (records of other points are kept on
    disk and left alone)."""
    known = read_records(out)
    mine = {p.id for p in points}
    stray = len(set(known) - mine)
    if stray:
        log.info("%d records in %s belong to points outside this study; left alone", stray, out)
    return {k: v for k, v in known.items() if k in mine}


def _collect(
    stream: Iterator[list[Record]],
    out: Path,
    points: Sequence[Point],
    rep: SweepReport,
    t0: float,
    on_record: Callable[[Record, SweepReport], None] | None,
    summary_every_s: float,
) -> None:
    """Write each finished record as it arrives, count it in ``rep`` and rewrite the summary
    at most every ``summary_every_s`` seconds."""
    seen: set[str] = set()
    last = time.perf_counter()
    for recs in stream:
        for rec in recs:
            if rec["id"] in seen:  # cannot happen with one task per point; belt and braces
                log.warning("point %s finished twice; keeping the first record", rec["id"])
                continue
            seen.add(rec["id"])
            write_record(out, rec)
            rep.records[rec["id"]] = rec
            rep.pending -= 1
            if rec["status"] == "ok":
                rep.done += 1
            else:
                rep.failed += 1
                log.info("point %s failed: %s", rec["id"], rec["error"])
            rep.elapsed_s = time.perf_counter() - t0
            if on_record:
                on_record(rec, rep)
            if time.perf_counter() - last > summary_every_s:
                write_summary(out, points, rep.records)
                last = time.perf_counter()
