"""Run a study's independent tasks on all cores: process pools whose workers die with the caller.

:func:`worker_init`, :func:`kill_workers` and :func:`end_pool` are what every pool of the package shares (the
sweep's two pools, :func:`map_unordered`'s, the design and atlas evaluators'); :func:`map_unordered` runs
independent tasks and hands back each result as it finishes.
"""

from __future__ import annotations

import concurrent.futures as futures
import os
import signal
import sys
import threading
import time
from typing import Callable, Iterable, TypeVar

Item = TypeVar("Item")


def worker_init(parent: int) -> None:
    """A pool worker's start: Ctrl-C is the main process's business (``parent``: its pid); the worker dies
    with it (Linux: PR_SET_PDEATHSIG; elsewhere a watcher thread that polls the parent every second)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            PR_SET_PDEATHSIG = 1
            if libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent died before the request took effect
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass

    def watch() -> None:  # elsewhere: notice the parent's death within a second
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="parent-watch").start()


def kill_workers(pool: futures.ProcessPoolExecutor) -> None:
    """End a process pool's workers at once (they ignore Ctrl-C and may be deep in a long task)."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.kill()


MANAGER_JOIN_S = 5.0  # s: the most a killed pool's manager thread is waited for (it ends as soon as it sees them dead)


def end_pool(pool: futures.ProcessPoolExecutor, kill: bool) -> None:
    """Shut a process pool down: at once with its workers killed (``kill``: Ctrl-C, a stuck task), or after its
    running tasks; its pending tasks cancelled. Either way its manager thread has ended when this returns (after
    a kill, within MANAGER_JOIN_S). Why: Python 3.11's exit hook wakes every pool's manager thread through a pipe
    which that thread closes as it ends, without a lock between the two; a manager still ending at exit had the
    hook print a traceback (``OSError: [Errno 9] Bad file descriptor``) after a sweep's one-line Ctrl-C message
    (tests/test_interrupts.py, once in CI)."""
    manager = getattr(pool, "_executor_manager_thread", None)  # shutdown() forgets it
    if kill:
        kill_workers(pool)
    pool.shutdown(wait=not kill, cancel_futures=True)
    if manager is not None and manager.is_alive():
        manager.join(MANAGER_JOIN_S)


def map_unordered(task: Callable[[Item], object], items: Iterable[Item], workers: int,
                  on_result: Callable[[Item, object], None]) -> None:
    """Call ``task(item)`` for every item and ``on_result(item, result)`` here as each finishes.

    ``workers`` processes (1: one by one in this process, in the given order, which is also the order
    the pool starts them: put the longest first). ``task`` must be picklable (a module-level function or
    a functools.partial of one). Workers ignore Ctrl-C and die with this process (see
    :func:`worker_init`); if anything goes wrong here, they are killed.
    """
    items = list(items)
    if workers <= 1 or len(items) <= 1:
        for item in items:
            on_result(item, task(item))
        return
    pool = futures.ProcessPoolExecutor(max_workers=workers, initializer=worker_init, initargs=(os.getpid(),))
    complete = False
    try:
        pending = {pool.submit(task, item): item for item in items}
        for future in futures.as_completed(pending):
            on_result(pending[future], future.result())
        complete = True
    finally:
        end_pool(pool, kill=not complete)
