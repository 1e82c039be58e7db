"""The optional compiler for the analytic integration kernels (numba), and the switch to turn it off.

The kernels (:mod:`.kernels`, :mod:`.dop853`) are plain Python on scalars and
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

import os

try:
    if os.environ.get("IPIR_MUJOCO_JIT", "1") == "0":
        raise ImportError("compilation turned off by IPIR_MUJOCO_JIT=0")
    import numba
except ImportError:  # the fallback: the kernels run as Python
    numba = None

ACCELERATED = numba is not None  # True: the kernels are compiled


def jit(function):
    """``function`` compiled in nopython mode with an on-disk cache, or ``function`` itself without numba."""
    if numba is None:
        return function
    return numba.njit(cache=True, nogil=True, error_model="numpy")(function)
