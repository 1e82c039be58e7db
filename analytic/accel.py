"""The optional compiler for the analytic integration kernels (numba), and the switch to turn it off.

The kernels (:mod:`.kernels`, :mod:`.dop853`, :mod:`.dense`) are plain Python on scalars and
small float arrays. With numba installed (``pip install 'ipir-mujoco[fast]'``)
they are compiled on their first call and cached on disk (``cache=True``: the
first run on a machine pays the compilation, about 10 s, later processes load
it in well under a second); without it the same source runs as Python, slower
but with the same results (same operations, same order; the compiled code uses
no fast-math, so it rounds as Python does).

Set the environment variable ``IPIR_MUJOCO_JIT=0`` before the first import to
run the Python source even where numba is installed (a test compares the two).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

try:
    if os.environ.get("IPIR_MUJOCO_JIT", "1") == "0":
        raise ImportError("compilation turned off by IPIR_MUJOCO_JIT=0")
    import numba
except ImportError:  # the fallback: the kernels run as Python
    numba = None

# True: the kernels are compiled (numba's own NUMBA_DISABLE_JIT=1 leaves them Python)
ACCELERATED = numba is not None and not numba.config.DISABLE_JIT
_COMPILED_MODULES = ("kernels", "dense", "dop853")  # the modules whose functions are compiled and call each other


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


if ACCELERATED:
    _drop_stale_cache()


def jit(function):
    """``function`` compiled in nopython mode with an on-disk cache, or ``function`` itself without numba."""
    if numba is None:
        return function
    return numba.njit(cache=True, nogil=True, error_model="numpy")(function)


def compilation_pending() -> bool:
    """True when the kernels will be compiled on their first call in this process (no cached machine
    code where numba keeps it: NUMBA_CACHE_DIR if set, else beside the sources or, where those cannot
    be written, the user's cache folder), so that a caller can say why the first run takes longer.
    False without numba."""
    if numba is None:
        return False
    if os.environ.get("NUMBA_CACHE_DIR"):
        places = [Path(os.environ["NUMBA_CACHE_DIR"])]
    else:
        places = [Path(__file__).parent / "__pycache__", Path.home() / ".cache" / "numba"]
    return not any(any(place.rglob("dop853.*.nbi")) for place in places if place.is_dir())
