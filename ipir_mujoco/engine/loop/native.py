"""The compiled stepping loop's binding: the extension module, checked against the running mujoco.

``_stepper.c`` is compiled against the headers of the mujoco installed where it was built and linked against
that mujoco's libmujoco by its SONAME, with no search path (``setup.py``): imported after ``mujoco``, it calls
the libmujoco the bindings loaded. It is used only if, checked once per process: it imports, it was built
from this package's sources (the recorder's columns), the headers' version (``MJVERSION_HEADER``) is the
running library's (``mujoco.mj_version()``), and the library it calls is the bindings' very instance. If
not, :func:`compiled` raises :class:`LayoutError` with one line saying why (``stepper.compiled_status()``
reports it) and the engine steps in Python.

The mjModel and mjData behind the bindings' objects: the bindings have no public accessor for them, so
their ``_address`` (the bindings' own, covered by their test suite) is read, only once the versions agree,
and checked before every run: what the C module reads there must be what the bindings report
(:func:`pointers`).
"""

from __future__ import annotations

import functools
import importlib
import importlib.util

import mujoco
import numpy as np

from .controller import LayoutError  # noqa: F401  (the compiled loop's error: what it relies on does not hold)
from .recorder import DEFERRED, SCALARS

EXTENSION = f"{__package__}._stepper"
REBUILD = "reinstall ipir-mujoco with pip's --no-build-isolation to build it against the running mujoco"


def address(array: np.ndarray) -> int:
    """The address of an array's first element (fixed for the life of the array)."""
    return int(array.ctypes.data)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


@functools.lru_cache(maxsize=None)
def _compiled_cached():
    """(the extension module, "compiled"), or (None, the one line saying why it is not used)."""
    if importlib.util.find_spec(EXTENSION) is None:
        return None, "the compiled stepper is not built; reinstall with a C compiler"
    try:
        stepper = importlib.import_module(EXTENSION)
    except ImportError as exc:  # its libmujoco is neither the one loaded nor anywhere the linker looks
        return None, _one_line(f"the compiled stepper cannot be loaded with mujoco {mujoco.__version__} "
                               f"({exc}): {REBUILD}")
    if (tuple(stepper.SCALARS), tuple(stepper.DEFERRED)) != (SCALARS, DEFERRED):
        return None, "the compiled stepper was built from other sources than this package's; reinstall it"
    header, running = stepper.MJVERSION_HEADER, mujoco.mj_version()
    if header != running:
        return None, (f"the compiled stepper was built against MuJoCo's headers of version {header}, the running "
                      f"mujoco {mujoco.__version__} is version {running}: {REBUILD}")
    if not _same_library(stepper):
        return None, f"the compiled stepper's libmujoco is not the one mujoco {mujoco.__version__} loaded: {REBUILD}"
    return stepper, "compiled"


def _same_library(stepper) -> bool:
    """Whether the libmujoco the extension calls is the bindings' instance: a warning handler set through the
    bindings (and only then) shows in its ``mju_user_warning``."""
    if mujoco.get_mju_user_warning() is not None:
        return stepper.handlers()[1]
    unset = not stepper.handlers()[1]
    try:
        mujoco.set_mju_user_warning(lambda message: None)
        return unset and stepper.handlers()[1]
    finally:
        mujoco.set_mju_user_warning(None)


def compiled():
    """The extension module, checked to fit the running mujoco; raises :class:`LayoutError` (one line)."""
    found, why = _compiled_cached()
    if found is None:
        raise LayoutError(why)
    return found


def pointers(stepper, model: mujoco.MjModel, data: mujoco.MjData) -> tuple[int, int]:
    """The addresses of ``model``'s mjModel and ``data``'s mjData (``data`` of ``model``), checked: the sizes,
    timestep, time and array pointers the C module reads there are the bindings'."""
    try:
        found = model._address, data._address
    except AttributeError as exc:
        raise LayoutError(f"mujoco {mujoco.__version__}'s bindings do not give the mjModel and mjData: {exc}")
    expected = (model.nq, model.nv, model.opt.timestep, address(model.jnt_range), address(model.eq_data),
                address(data.qpos), address(data.qvel), data.time)
    read = stepper.check(*found)
    if read != expected:
        raise LayoutError(f"mujoco {mujoco.__version__}'s MjModel and MjData._address do not check out: "
                          f"read {read}, expected {expected}")
    return found
