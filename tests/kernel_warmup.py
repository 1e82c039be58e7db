"""Compile the analytic kernels (numba, where installed) once for the test suite: tests/conftest.py runs
:func:`warm_up` in the one pytest process, or, under pytest-xdist, :func:`main` in a process of its own that the
controller starts while the workers start and collect (about 10 s each), the workers waiting for its ready file
before their first test (:func:`wait_for`) and then loading the cached code.

The first compilation on a machine takes about 15-40 s and the command line then says so on stderr, which the
command-line tests read; every later process loads the cached code. The compile's heartbeat (analytic/accel.py),
a thread that says "still compiling" / "kernels compiled" every HEARTBEAT_S while numba works, is put to sleep for
good here: its lines would land in whichever test's stderr runs when it wakes (a cold cache in CI: "kernels
compiled (27 s)" inside tests/test_clutch_study.py). tests/test_fast_kernels.py tests it with its own period.

    python tests/kernel_warmup.py READY_FILE    # compile, then write READY_FILE (whatever the outcome)
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

WAIT_S = 900.0  # the most a worker waits for the compile (a bound on a stuck one; it takes 15-40 s)


def warm_up() -> None:
    """Compile the kernels in this process (or load the cache) with the heartbeat asleep, and call each analytic
    engine once briefly: numba compiles each kernel at its first call."""
    from ipir_mujoco.analytic import accel, compile_kernels

    period = accel.HEARTBEAT_S
    accel.HEARTBEAT_S = 1e9  # read once as the thread goes to sleep: a thread started now never wakes to log
    try:
        compile_kernels()  # compile now (or load the cache), each engine called once, along a route too
    finally:
        accel.HEARTBEAT_S = period


def wait_for(ready: Path) -> None:
    """Return once ``ready`` exists (the compile process wrote it), or after WAIT_S."""
    deadline = time.monotonic() + WAIT_S
    while not ready.exists() and time.monotonic() < deadline:
        time.sleep(0.1)


def main(argv: list[str]) -> int:
    ready = Path(argv[0])
    try:
        warm_up()
    finally:  # written whatever happened: the workers then load what is cached, or compile as any process would
        partial = ready.with_suffix(".partial")
        partial.write_text("done\n")
        partial.replace(ready)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
