"""Executors for independent tasks: in-process, a local process pool, or Dask.

`iter_map(func, items, jobs=..., dask=...)` yields (index, func(item)) as the items finish.
Used by sweeps (`models.sweep`) and by the reproduction (reproduce). func and the items
must be picklable (a module-level function or a picklable callable object); Dask workers must
be able to import them (rigidlcp installed on every worker).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import Any


def default_jobs() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def iter_map(func: Callable[[Any], Any], items: list, *, jobs: int | None = None,
             dask: str | None = None) -> Iterator[tuple[int, Any]]:
    """Yield (index, func(item)) as the items finish, on the chosen executor.

    jobs: worker processes (default: the CPUs this process may use); 1 runs in this process.
    dask: None, "local" (a LocalCluster of `jobs` single-threaded worker processes on
    127.0.0.1) or a scheduler address "tcp://HOST:PORT" (the workers must have rigidlcp
    installed). Closing the generator early (Ctrl-C) cancels the points not started.
    """
    jobs = default_jobs() if jobs is None else int(jobs)
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    if not items:
        return
    if dask is not None:
        yield from _iter_dask(func, items, jobs, dask)
    elif jobs == 1 or len(items) == 1:
        for k, item in enumerate(items):
            yield k, func(item)
    else:
        yield from _iter_pool(func, items, jobs)


def _iter_pool(func, items: list, jobs: int) -> Iterator[tuple[int, Any]]:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    # spawn: fresh interpreters, no inherited threads or locks (tqdm, BLAS) from this one.
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(items)),
                               mp_context=multiprocessing.get_context("spawn"))
    try:
        futures = {pool.submit(func, item): k for k, item in enumerate(items)}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                yield futures[fut], fut.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _iter_dask(func, items: list, jobs: int, address: str) -> Iterator[tuple[int, Any]]:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:  # pragma: no cover - depends on the installation
        raise ValueError("--dask needs dask.distributed: pip install 'rigidlcp[dask]'"
                         ) from None
    cluster = None
    if address == "local":
        import logging

        cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
    elif address.startswith(("tcp://", "tls://", "ws://", "wss://", "inproc://")):
        client = Client(address, timeout="30s")
    else:
        raise ValueError(f"--dask takes 'local' or a scheduler address tcp://HOST:PORT, "
                         f"got {address!r}")
    futures = []
    try:
        futures = [client.submit(func, item, pure=False) for item in items]
        index = {fut.key: k for k, fut in enumerate(futures)}
        for fut in as_completed(futures):
            yield index[fut.key], fut.result()
    finally:
        client.cancel([f for f in futures if not f.done()])
        client.close()
        if cluster is not None:
            cluster.close()


__all__ = ["iter_map", "default_jobs"]
