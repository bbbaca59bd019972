"""Where candidate evaluations run: in this process, or on ``dask.distributed``.

:func:`executor` gives a local Dask cluster on this machine by default (``workers`` worker
processes, one thread each, bound to 127.0.0.1), or a client of an existing scheduler
(``scheduler`` or the environment variable ``DASK_SCHEDULER_ADDRESS``); ``workers=0`` runs
in this process.  The problem (system, data, scenarios) is sent to every worker once; each
task then carries only a parameter vector and a task key, and results come back in the
order they were submitted, so the optimiser sees the same numbers whatever ran them."""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import threading
from collections.abc import Callable, Sequence
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError

TaskFn = Callable[..., Any]


def _call(problem: Any, method: str, cand: Any, key: Any) -> Any:
    return getattr(problem, method)(cand, key)


class LocalExecutor:
    """Everything in this process (``--workers 0``)."""

    workers = 0
    address = "in-process"

    def __init__(self) -> None:
        self._problem: Any = None

    def bind(self, problem: Any) -> None:
        self._problem = problem

    def map(self, method: str, items: Sequence[tuple[Any, Any]]) -> list[Any]:
        return [_call(self._problem, method, c, k) for c, k in items]

    def close(self) -> None:
        self._problem = None


class DaskExecutor:
    """Tasks on a ``dask.distributed`` cluster (a LocalCluster this object owns, or an
    existing scheduler)."""

    def __init__(self, client: Any, cluster: Any = None) -> None:
        self.client = client
        self.cluster = cluster
        self._problem: Any = None
        info = client.scheduler_info()
        self.workers = len(info.get("workers", {}))
        self.address = str(client.scheduler.address)

    def bind(self, problem: Any) -> None:
        # Broadcast once: later tasks refer to it by key instead of shipping the data again.
        self._problem = self.client.scatter(problem, broadcast=True, hash=False)

    def map(self, method: str, items: Sequence[tuple[Any, Any]]) -> list[Any]:
        futures = [self.client.submit(_call, self._problem, method, c, k, pure=False) for c, k in items]
        try:
            return list(self.client.gather(futures))
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                # Cancelling leaves distributed's gather tasks with an exception nobody
                # retrieves; asyncio would print each one ("Task exception was never
                # retrieved ... AllExit") after the user asked to stop.
                logging.getLogger("asyncio").setLevel(logging.CRITICAL)
            self.client.cancel(futures)
            raise

    def close(self) -> None:
        if self._problem is not None:
            with contextlib.suppress(Exception):  # best effort on shutdown
                self.client.cancel(self._problem)
        self._problem = None
        if self.cluster is not None:
            self.client.close()
            self.cluster.close()


def _import_distributed() -> Any:
    from fuzzyctl.extras import require

    require(("distributed",), "running on Dask workers (--workers 0 runs in this process)")
    import distributed

    return distributed


def local_cluster(workers: int) -> tuple[Any, Any]:
    """A LocalCluster of ``workers`` single-threaded worker processes on 127.0.0.1 (no
    dashboard) and a client of it."""
    distributed = _import_distributed()
    # Ctrl-C in a terminal reaches the whole process group.  The worker processes start with
    # SIGINT ignored (they inherit it), so that only this process stops - keeping the best
    # candidate so far - instead of every worker dying with a traceback.
    main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if main else None
    if main:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cluster = distributed.LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            # The scheduler's small HTTP server (health, metrics) on a free loopback port, so
            # that two clusters never fight over 8787; no dashboard pages.
            dashboard_address="127.0.0.1:0",
            scheduler_kwargs={"dashboard": False},
            silence_logs=logging.ERROR,
        )
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    return distributed.Client(cluster, set_as_default=False), cluster


def executor(
    workers: int | None = None, scheduler: str | None = None, client: Any = None
) -> LocalExecutor | DaskExecutor:
    """The executor for ``--workers`` / ``--scheduler`` (see the module docstring)."""
    if client is not None:
        return DaskExecutor(client)
    address = scheduler or os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    if address:
        if workers:
            raise FuzzyctlError("give either --workers or --scheduler, not both")
        distributed = _import_distributed()
        try:
            c = distributed.Client(address, timeout=10, set_as_default=False)
        except OSError as exc:
            raise FuzzyctlError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        return DaskExecutor(c, cluster=_Closer(c))
    if workers is None:
        workers = default_workers()
    if workers < 0:
        raise FuzzyctlError(f"--workers must be >= 0, got {workers}")
    if workers == 0:
        return LocalExecutor()
    c, cluster = local_cluster(workers)
    return DaskExecutor(c, cluster=cluster)


class _Closer:
    """Closes only our client of a scheduler someone else runs."""

    def __init__(self, client: Any) -> None:
        self.client = client

    def close(self) -> None:
        pass


def default_workers() -> int:
    """One worker per CPU this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)
