"""Run a study's independent tasks on all cores: a process pool whose workers die with the caller."""

from __future__ import annotations

import concurrent.futures as futures
import os
from typing import Callable, Iterable, TypeVar

Item = TypeVar("Item")


def map_unordered(task: Callable[[Item], object], items: Iterable[Item], workers: int,
                  on_result: Callable[[Item, object], None]) -> None:
    """Call ``task(item)`` for every item and ``on_result(item, result)`` here as each finishes.

    ``workers`` processes (1: one by one in this process, in the given order, which is also the order
    the pool starts them: put the longest first). ``task`` must be picklable (a module-level function or
    a functools.partial of one). Workers ignore Ctrl-C and die with this process (see
    :func:`ipir_mujoco.studies.sweep._worker_init`); if anything goes wrong here, they are killed.
    """
    items = list(items)
    if workers <= 1 or len(items) <= 1:
        for item in items:
            on_result(item, task(item))
        return
    from .sweep import _kill_workers, _worker_init

    pool = futures.ProcessPoolExecutor(max_workers=workers, initializer=_worker_init, initargs=(os.getpid(),))
    complete = False
    try:
        pending = {pool.submit(task, item): item for item in items}
        for future in futures.as_completed(pending):
            on_result(pending[future], future.result())
        complete = True
    finally:
        if not complete:
            _kill_workers(pool)
        pool.shutdown(wait=complete, cancel_futures=True)
