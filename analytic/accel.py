"""The optional compiler for the analytic integration kernels (numba), when it is worth loading, and its switch.

The kernels (:mod:`.kernels`, :mod:`.dop853`, :mod:`.dense`) are plain Python on scalars and small float
arrays, marked with :func:`jit`. Compiled by numba (a dependency of the package where its wheels exist),
they run the same operations in the same order, so they give the same floats (no fast-math: the compiled
code rounds as Python does; tests/test_fast_kernels.py holds the two paths equal); a run may start in
Python and go on compiled, and give the same result.

Compiling has a price: importing numba and loading the machine code cached on disk cost several tenths of
a second in every process (the first run on a machine also compiles, about 15 s, once), more than a short
run's whole integration in Python. So by default the kernels start as Python, and a process compiles them
(:func:`accelerate`) once its analytic runs have spent :data:`LOAD_COST_S` in Python: rent until the rent
paid equals the price, then buy, which never costs more than twice the better choice made in hindsight.
A long run, a sweep's worker or a validation switches within its first half second; a default
``ipir-mujoco simulate`` never loads numba.

``IPIR_MUJOCO_JIT`` (read at import): ``auto`` (default) as above; ``1`` compiles at the first run; ``0``
never compiles (the Python source only). numba's own ``NUMBA_DISABLE_JIT=1`` counts as ``0``.
"""

from __future__ import annotations

import hashlib
import importlib.util
import logging
import os
import sys
import threading
import time
from pathlib import Path

# s between two "still compiling" notes (a terminal's status line; a log shows one every HEARTBEAT_S)
from ipir_mujoco.core.options import LIVE_HEARTBEAT_S as HEARTBEAT_S

MODES = ("auto", "1", "0")
MODE = os.environ.get("IPIR_MUJOCO_JIT", "auto").strip().lower() or "auto"
if MODE not in MODES:  # an unknown value means what it would mean to numba users: leave the default
    MODE = "auto"
LOAD_COST_S = 0.5  # s of Python-mode integration after which a process compiles (about numba's load cost)

ACCELERATED = False  # True once the kernels run compiled in this process (read it as accel.ACCELERATED)
# the modules whose functions are compiled and call each other
_COMPILED_MODULES = ("kernel_base", "route_geometry", "route_scrub", "route_kernels", "kernels", "dense",
                     "dop853")
_FUNCTIONS: list = []  # every @jit function, in definition order
_spent = 0.0  # s of analytic integration run in Python so far (auto mode)
_refused = False  # numba is missing, disabled, or failed to compile: never try again
log = logging.getLogger("ipir_mujoco")


def jit(function):
    """Mark ``function`` as a kernel :func:`accelerate` compiles; until then it runs as the Python it is."""
    _FUNCTIONS.append(function)
    return function


def available() -> bool:
    """Whether the kernels may be compiled here: numba installed, and neither IPIR_MUJOCO_JIT=0 nor
    NUMBA_DISABLE_JIT=1 set."""
    if MODE == "0" or os.environ.get("NUMBA_DISABLE_JIT", "0").strip() not in ("", "0"):
        return False
    return importlib.util.find_spec("numba") is not None


def accelerate() -> bool:
    """Compile the kernels now (load them from numba's cache where it holds them) and run them compiled from
    here on in this process; True if they are compiled. Each kernel module's functions, and every name other
    kernel modules bound them to, are replaced by their compiled dispatchers, so compiled kernels call
    compiled kernels."""
    global ACCELERATED, _refused
    if ACCELERATED or _refused:
        return ACCELERATED
    if not available():
        _refused = True
        return False
    loaded = set(sys.modules)
    try:
        import numba
    except BaseException:  # Ctrl-C (or anything) while numba loads: leave no half-loaded module (numba's or one
        # it imports) behind, so that the next try imports them afresh rather than failing on missing attributes
        for name in set(sys.modules) - loaded:
            del sys.modules[name]
        raise

    if numba.config.DISABLE_JIT:
        _refused = True
        return False
    _drop_stale_cache()
    if compilation_pending():
        log.info("compiling the analytic engines' kernels for this machine, once (12-15 s on an idle machine, "
                 "longer under load; later runs reuse them)")
        _heartbeat()
    compiled = {id(f): numba.njit(cache=True, nogil=True, error_model="numpy")(f) for f in _FUNCTIONS}
    for name in _COMPILED_MODULES:
        module = sys.modules[f"{__package__}.{name}"]
        for attribute, value in list(vars(module).items()):
            if id(value) in compiled:
                setattr(module, attribute, compiled[id(value)])
    ACCELERATED = True
    return True


HEARTBEAT_MAX = 300  # notes at most (5 min): where the cache cannot be written, compiling never shows as done
QUIET_S = 5.0  # s with no kernel compiling (and the stepper's cache written) after which compiling is done


class _Compiles:
    """numba's compiles under way in this process, from its ``numba:compile`` events (fired only when a kernel
    is compiled, not when it is loaded from the cache): how many are open, and when the last began or ended
    (time.monotonic() [s]). numba compiles each kernel at its first call, some of them well after the
    stepper's, so the heartbeat asks this rather than the cache alone whether compiling goes on."""

    def __init__(self) -> None:
        self.open = 0
        self.last = time.monotonic()

    def busy_within(self, seconds: float) -> bool:
        """True while a compile is open or one began or ended in the last ``seconds``."""
        return self.open > 0 or time.monotonic() - self.last < seconds

    def listener(self):
        """A numba event listener counting this process's compiles (numba.core.event.register it)."""
        from numba.core import event

        compiles = self

        class Counter(event.Listener):
            def on_start(self, _event) -> None:
                compiles.open += 1
                compiles.last = time.monotonic()

            def on_end(self, _event) -> None:
                compiles.open -= 1
                compiles.last = time.monotonic()

        return Counter()


def _heartbeat() -> None:
    """While the kernels compile (numba compiles each at its first call, inside the runs that follow), say
    every HEARTBEAT_S that it is still compiling, on logger 'ipir_mujoco' as a status (the record's ``status``
    true: the command line shows it as its status line, :mod:`ipir_mujoco.terminal`), until the compiled
    stepper's cache index has appeared (:func:`compilation_pending` turns False) and no kernel has been
    compiling for QUIET_S; then say how long it took (up to the last compile's end). A daemon thread: it never
    holds up the process's exit."""
    from numba.core import event

    started = time.monotonic()
    compiles = _Compiles()
    listener = compiles.listener()
    event.register("numba:compile", listener)

    def beat() -> None:
        try:
            for _ in range(HEARTBEAT_MAX):
                time.sleep(HEARTBEAT_S)
                if not compilation_pending() and not compiles.busy_within(QUIET_S):
                    log.info(f"kernels compiled ({max(compiles.last, started) - started:.0f} s)")
                    return
                log.info(f"still compiling the kernels ({time.monotonic() - started:.0f} s so far)",
                         extra={"status": True})
        finally:
            event.unregister("numba:compile", listener)

    threading.Thread(target=beat, name="ipir-compile-heartbeat", daemon=True).start()


def run_started() -> None:
    """An analytic run begins: with IPIR_MUJOCO_JIT=1, compile before it."""
    if MODE == "1":
        accelerate()


def spent(seconds: float) -> None:
    """An analytic run spent ``seconds`` [s] integrating; in auto mode, compile once the Python-mode time of
    the process reaches LOAD_COST_S (module docstring)."""
    global _spent
    if ACCELERATED or _refused or MODE != "auto":
        return
    _spent += seconds
    if _spent >= LOAD_COST_S:
        accelerate()


def _drop_stale_cache() -> None:
    """Delete the package's cached machine code when any compiled module's source has changed.

    numba invalidates a cached function when its own file changes, not when a function it calls
    from another file does: after an edit of kernels.py alone, the stepper (dop853.py) would run
    the old kernels compiled into it. A checksum of both files, kept beside the cache, decides.
    Only the package's own cache folder is touched; where it cannot be written (an installed,
    read-only package, whose files change together), nothing is done.
    """
    here = Path(__file__).parent
    cache = here / "__pycache__"
    try:
        digest = hashlib.sha256(b"".join((here / f"{m}.py").read_bytes() for m in _COMPILED_MODULES)).hexdigest()
        marker = cache / "numba-kernels.sha256"
        if marker.is_file() and marker.read_text() == digest:
            return
        for module in _COMPILED_MODULES:
            for path in [*cache.glob(f"{module}.*.nbi"), *cache.glob(f"{module}.*.nbc")]:
                path.unlink()
        cache.mkdir(exist_ok=True)
        marker.write_text(digest)
    except OSError:
        pass


def compilation_pending() -> bool:
    """True when compiling the kernels would compile rather than load them (no cached machine code where
    numba keeps it: NUMBA_CACHE_DIR if set, else beside the sources or, where those cannot be written, the
    user's cache folder), so that a caller can say why a run takes longer. False where they cannot be
    compiled."""
    if not available():
        return False
    if os.environ.get("NUMBA_CACHE_DIR"):
        places = [Path(os.environ["NUMBA_CACHE_DIR"])]
    else:
        places = [Path(__file__).parent / "__pycache__", Path.home() / ".cache" / "numba"]
    return not any(any(place.rglob("dop853.*.nbi")) for place in places if place.is_dir())
