"""Thread policy for the numerical libraries barhinge calls.

Two kinds of work need different threading:

* **small dense calls** (the DOF analysis: thousands of SVDs and products of a few hundred
  entries each): a multithreaded BLAS spends more time waking its threads than computing,
  and on a busy machine it competes with other processes for the same cores.
  :func:`dense_calls` runs them with one BLAS thread.
* **large sparse factorisations** (the bar-and-hinge tangent and the rigid corrector's
  normal matrix through MKL PARDISO): threads pay off, but only as many as there are free
  cores. :func:`sparse_solves` limits MKL to the cores the load average leaves free (at
  least one) and other BLAS libraries to one thread.

barhinge's own work runs on :func:`worker_threads` threads: the element kernels of a
tangent or force evaluation, chunk by chunk (numpy releases Python's lock inside each
vector operation), and the result files (zlib compression releases it too).
:func:`parallel_map` runs such work on one pool per process, in the order given.

The policy is set by the environment variable ``BARHINGE_THREADS``:

``auto`` (default)
    as above;
``off``
    barhinge sets no limits (the libraries' own defaults, or ``OMP_NUM_THREADS`` and the
    like);
an integer ``n``
    MKL (PARDISO) ``n`` threads instead of the free cores, and ``n`` worker threads; the small
    dense calls keep one BLAS thread as under ``auto`` (a BLAS library's threads spin after
    each call, and with two of them OpenBLAS took a core from every tangent evaluation of a
    fold).

Limits are applied with threadpoolctl for the duration of one public call and restored
afterwards.
"""

from __future__ import annotations

import contextlib
import functools
import os
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any, TypeVar

from threadpoolctl import ThreadpoolController, threadpool_limits

from barhinge.errors import ConfigError

__all__ = [
    "dense_calls",
    "free_cores",
    "parallel_map",
    "policy",
    "single_threaded_dense",
    "sparse_solves",
    "threads_for_sparse",
    "worker_threads",
]

F = TypeVar("F", bound=Callable[..., Any])
T = TypeVar("T")
R = TypeVar("R")

ENV = "BARHINGE_THREADS"


def policy() -> str | int:
    """``"auto"``, ``"off"`` or a thread count, from ``BARHINGE_THREADS``."""
    raw = os.environ.get(ENV, "auto").strip().lower() or "auto"
    if raw in ("auto", "off"):
        return raw
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise ConfigError(f"{ENV} = {raw!r}; expected 'auto', 'off' or a whole number >= 1")
    return n


def cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def worker_threads() -> int:
    """Threads barhinge runs its own work on (element kernels, result files): the count of
    ``BARHINGE_THREADS`` when it is a number, one under ``off``, else the process's cores
    (not the free ones: the load average a solve's own factorisations leave on the machine
    is no reason to evaluate its next tangent on one thread)."""
    p = policy()
    if isinstance(p, int):
        return p
    return 1 if p == "off" else cores()


#: (process id, threads, pool) of the pool :func:`parallel_map` runs on
_pool: tuple[int, int, ThreadPoolExecutor] | None = None
_pool_lock = threading.Lock()
_in_worker = threading.local()


def _mark_worker() -> None:
    _in_worker.flag = True


def _worker_pool(n: int) -> ThreadPoolExecutor:
    """The process's pool of ``n`` threads (made again after a fork or a new count)."""
    global _pool
    with _pool_lock:
        pid = os.getpid()
        if _pool is None or _pool[0] != pid or _pool[1] != n:
            if _pool is not None and _pool[0] == pid:
                _pool[2].shutdown(wait=False)
            pool = ThreadPoolExecutor(n, "barhinge-worker", initializer=_mark_worker)
            _pool = (pid, n, pool)
        return _pool[2]


def parallel_map(fn: Callable[[T], R], items: Iterable[T]) -> list[R]:
    """``[fn(item) for item in items]`` on :func:`worker_threads` threads, results in the
    order of ``items``; serial with one thread, one item, or when called from one of the
    pool's own threads (no nested wait on the same pool). ``fn`` must write only what no
    other item writes. The first error raised by any item is raised after all have run."""
    items = list(items)
    n = worker_threads()
    if n <= 1 or len(items) < 2 or getattr(_in_worker, "flag", False):
        return [fn(item) for item in items]
    futures = [_worker_pool(n).submit(fn, item) for item in items]
    errors = [f.exception() for f in futures]
    for err in errors:
        if err is not None:
            raise err
    return [f.result() for f in futures]


def free_cores() -> int:
    """Cores not taken by other work: the usable cores less the one-minute load average
    (rounded), at least 1."""
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return cores()
    return max(1, min(cores(), cores() - round(load) + 1))


@contextlib.contextmanager
def dense_calls() -> Iterator[None]:
    """One BLAS thread for small dense linear algebra (policies ``auto`` and ``n``), nothing
    changed for ``off``."""
    if policy() == "off":
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield


@contextlib.contextmanager
def sparse_solves() -> Iterator[None]:
    """MKL (PARDISO) threads matched to the free cores (policy ``auto``) or ``n`` (a fixed
    policy), any other BLAS one thread (the solver's dense work is small); nothing changed
    for ``off``."""
    p = policy()
    if p == "off":
        yield
        return
    controller = ThreadpoolController()
    with contextlib.ExitStack() as stack:
        mkl = controller.select(internal_api="mkl")
        if mkl.lib_controllers:
            stack.enter_context(mkl.limit(limits=free_cores() if p == "auto" else p))
        for api in ("openblas", "blis"):
            other = controller.select(internal_api=api)
            if other.lib_controllers:
                stack.enter_context(other.limit(limits=1))
        yield


def _within(context: Callable[[], contextlib.AbstractContextManager[None]]):
    """A decorator running its function inside ``context()``."""

    def decorate(fn: F) -> F:
        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            with context():
                return fn(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate


#: decorator: run the function inside :func:`dense_calls`
single_threaded_dense = _within(dense_calls)
#: decorator: run the function inside :func:`sparse_solves`
threads_for_sparse = _within(sparse_solves)
