"""One executor for chunked work: in process, on a local Dask cluster, or on an existing one.

Work is a function and a list of items (chunks of directions, sweep cases). The function
runs where the executor puts it; its results come back to the calling process one by one,
as they finish, so that the caller alone writes them (to a Zarr store, region by region):
nothing is written twice, and a worker that dies costs only the tasks it held, which Dask
runs again elsewhere (``distributed.scheduler.allowed-failures`` times, then the item is
reported failed).

Scheduler addresses (``--scheduler``):

* ``none`` (or ``serial``): in this process, one item after the other;
* ``local`` (the default): a new :class:`distributed.LocalCluster` on this machine, on the
  loopback interface, one worker process per core with one Dask thread each, and Dr.Jit's
  thread pool in each worker sized so that the workers together use the cores once; never
  more workers than cores, nor than the memory limit holds tasks of their estimated size
  (:func:`local_workers`);
* ``tcp://HOST:PORT`` (or any address :class:`distributed.Client` accepts): an existing
  cluster (``dask scheduler`` + ``dask worker`` with the same speclight installed).

Mitsuba scenes cannot be pickled: the function receives plain data (the scenario, arrays) and
builds its scene inside the task, keeping it per worker with :func:`worker_cached`.
"""

from __future__ import annotations

import logging
import os
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from speclight.errors import InputError

T = TypeVar("T")
R = TypeVar("R")

#: Environment variable read by :mod:`speclight.render.variant`: Dr.Jit threads per process.
RENDER_THREADS_ENV = "SPECLIGHT_RENDER_THREADS"
MALLOC_TRIM_ENV = "MALLOC_TRIM_THRESHOLD_"
SERIAL_NAMES = ("none", "serial")
LOCAL_NAMES = ("local", "")
FIELD = "--scheduler"


@dataclass
class Outcome(Generic[T, R]):
    """One item's end: its result, or the error text (``"TypeName: message"``)."""

    item: T
    result: R | None = None
    error: str | None = None


class Executor:
    """Runs ``fn`` over items and hands back :class:`Outcome` objects as they finish."""

    def __init__(self, description: str, client: Any = None, dashboard_link: str | None = None):
        self.description = description
        self.client = client
        self.dashboard_link = dashboard_link

    @property
    def serial(self) -> bool:
        return self.client is None

    def run(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        *,
        label: str = "chunks",
        progress: bool = False,
    ) -> Iterator[Outcome[T, R]]:
        """``fn(item)`` for every item; outcomes in the order they finish.

        An exception raised by ``fn`` becomes the outcome's ``error`` (the run goes on); so
        does a task whose workers died more often than Dask allows.
        """
        outcomes = self._serial(fn, items) if self.serial else self._dask(fn, items)
        yield from _with_progress(outcomes, len(items), label, progress)

    def _serial(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[Outcome[T, R]]:
        for item in items:
            try:
                yield Outcome(item, fn(item))
            except Exception as exc:  # recorded; the run goes on
                yield Outcome(item, error=error_text(exc))

    def _dask(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[Outcome[T, R]]:
        from distributed import as_completed

        futures = self.client.map(fn, list(items), pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        done = as_completed(futures)
        for future in done:
            item = items[index[future.key]]
            try:
                yield Outcome(item, future.result())
            except Exception as exc:  # the task's own error, or KilledWorker
                yield Outcome(item, error=error_text(exc))
            finally:
                future.release()


def error_text(exc: BaseException) -> str:
    """``"TypeName: message"``, one line."""
    return f"{type(exc).__name__}: {exc}".replace("\n", " ").strip()


def local_workers(
    requested: int | None, task_bytes: int = 0, limit_bytes: int | None = None
) -> tuple[int, str | None]:
    """Workers of a local cluster: ``requested`` (default: the cores), at most the cores and
    at most as many tasks of ``task_bytes`` (their estimated peak memory) as the memory limit
    (:func:`speclight.simulation.memory.memory_limit_bytes`) holds; at least one.

    Returns the count and, when it is below what was asked, a one-line note saying why.
    """
    from speclight.simulation.memory import memory_limit_bytes

    cores = os.cpu_count() or 1
    asked = max(1, int(requested or cores))
    limit = memory_limit_bytes() if limit_bytes is None else int(limit_bytes)
    by_memory = max(1, limit // task_bytes) if task_bytes > 0 else asked
    workers = min(asked, cores, by_memory)
    if workers == asked:
        return workers, None
    why = []
    if cores < asked:
        why.append(f"{cores} cores here")
    if by_memory < asked:
        why.append(
            f"memory for {by_memory} tasks of {task_bytes / 1024**3:.3g} GiB under the limit "
            f"of {limit / 1024**3:.3g} GiB"
        )
    shown = f"--workers {asked}" if requested else f"{asked} workers (one per core)"
    return workers, f"{shown}: using {workers} ({'; '.join(why)})"


@contextmanager
def open_executor(
    scheduler: str | None = "local",
    *,
    n_workers: int | None = None,
    announce: bool = False,
    connect_timeout_s: float = 10.0,
    task_bytes: int = 0,
) -> Iterator[Executor]:
    """The executor for a ``--scheduler`` value (see the module docstring).

    Parameters
    ----------
    scheduler
        ``none``/``serial``, ``local`` (or ``None``) or a scheduler address.
    n_workers
        Workers of a local cluster (default: the cores of this machine; capped by
        :func:`local_workers`).
    announce
        Print one line on stderr: where the work runs and the dashboard address.
    connect_timeout_s
        How long to wait for an existing scheduler to answer.
    task_bytes
        The estimated peak memory of one task [bytes] (0: unknown).
    """
    name = (scheduler or "local").strip()
    if name.lower() in SERIAL_NAMES:
        yield Executor("in this process (serial)")
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - a dependency of speclight
        raise InputError(
            f"{FIELD} = '{name}' needs dask.distributed (pip install 'dask[distributed]'); "
            "or use --scheduler none",
            field=FIELD,
        ) from None
    cluster = None
    if name.lower() in LOCAL_NAMES:
        cores = os.cpu_count() or 1
        workers, note = local_workers(n_workers, task_bytes)
        if note and announce:
            print(note, file=sys.stderr)
        threads = max(1, cores // workers)
        with _lean_worker_defaults():
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",
                silence_logs=logging.CRITICAL,  # a failed task is reported as its outcome
                env={RENDER_THREADS_ENV: str(threads)},
            )
        client = Client(cluster)
        description = (
            f"a local Dask cluster of {workers} workers ({threads} render thread"
            f"{'s' if threads > 1 else ''} each)"
        )
    else:
        try:
            client = Client(name, timeout=f"{connect_timeout_s}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(
                f"{FIELD} = '{name}': no Dask scheduler answers there ({error_text(exc)}); "
                "accepted: none, local, or the address of a running scheduler "
                "(tcp://HOST:PORT)",
                field=FIELD,
            ) from None
        n = len(client.scheduler_info().get("workers", {}))
        description = f"the Dask cluster at {name} ({n} workers)"
    executor = Executor(description, client, client.dashboard_link)
    if announce:
        print(f"running on {description}; dashboard: {client.dashboard_link}", file=sys.stderr)
    try:
        yield executor
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


@contextmanager
def _lean_worker_defaults() -> Iterator[None]:
    """Start local workers without two Dask defaults that slow speclight's tasks down.

    * ``MALLOC_TRIM_THRESHOLD_=65536``, which Dask's nanny sets in each worker's environment
      (and in this process's, to spawn it). Setting it turns off glibc's dynamic mmap
      threshold: every array over 128 KiB is then mapped and page-faulted anew, and a render
      chunk, which makes many, ran 2.1 times slower in a worker than in this process
      (BENCHMARKS.md, reflectivity maps; +60 % CPU per sweep case). Workers keep glibc's
      defaults instead; a value this process had before any cluster is kept.
    * the workers' statistical profiler (a stack sample of every thread every 10 ms, for the
      dashboard's profile page): +25 % CPU per sweep case (BENCHMARKS.md, "Sweep").

    Workers of an existing cluster keep their own settings (docs/scale-out.md says how to
    start them the same way).
    """
    import dask

    key = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
    dask_value = dask.config.get(key, default=None)
    if dask_value is not None and os.environ.get(MALLOC_TRIM_ENV) == str(dask_value):
        os.environ.pop(MALLOC_TRIM_ENV)  # left by an earlier cluster of this process
    with dask.config.set({key: None, "distributed.worker.profile.enabled": False}):
        yield


def _with_progress(
    outcomes: Iterator[Outcome[T, R]], total: int, label: str, progress: bool
) -> Iterator[Outcome[T, R]]:
    if not (progress and sys.stderr.isatty()):
        yield from outcomes
        return
    from rich.progress import Progress

    with Progress(transient=True) as bar:
        task = bar.add_task(label, total=total)
        for outcome in outcomes:
            yield outcome
            bar.advance(task)
