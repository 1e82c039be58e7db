"""The compiled stepping loop's binding: the extension module, the MuJoCo library it calls, the mjData layout.

``_stepper.c`` includes no MuJoCo header, so it does not depend on the version it was built against: this
module finds ``mj_step`` and ``mj_subtreeVel`` in the libmujoco the bindings loaded (checked to be that very
instance), and the byte offsets of the mjData fields the loop reads between steps (the ``efc_force`` and
``efc_id`` pointers, the constraint counts, time, the warning counters) from the running mujoco's own
description of its structs (``mujoco.introspect``), checked against a live MjData before every run. Anything
that does not check out raises :class:`LayoutError`, and the engine steps in Python instead.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os

import mujoco
import numpy as np

from .recorder import DEFERRED, SCALARS

_DATA_FIELDS = ("warning", "time", "qpos", "qvel", "ne", "nf", "nl", "nefc", "efc_id", "efc_force")


class LayoutError(RuntimeError):
    """What the compiled loop relies on does not hold here (the pure-Python loop is used instead)."""


def address(array: np.ndarray) -> int:
    """The address of an array's first element (fixed for the life of the array)."""
    return int(array.ctypes.data)


@functools.lru_cache(maxsize=None)
def _compiled_cached():
    try:
        from . import _stepper
    except ImportError as exc:
        return None, f"the compiled stepper is not built ({exc}); reinstall with a C compiler"
    if (tuple(_stepper.SCALARS), tuple(_stepper.DEFERRED)) != (SCALARS, DEFERRED):
        return None, "the compiled stepper was built from other sources than this package's; reinstall it"
    try:
        library = _library()
        mjdata_offsets()
    except (LayoutError, ImportError, OSError, AttributeError, KeyError, TypeError, ValueError) as exc:
        return None, f"the compiled stepper cannot be used with mujoco {mujoco.__version__}: {exc}"
    return (_stepper, library), "compiled"


def compiled():
    found, why = _compiled_cached()
    if found is None:
        raise LayoutError(why)
    return found


def _library() -> dict[str, int]:
    """Addresses of ``mj_step``, ``mj_subtreeVel`` and the legacy error handler pointer in the libmujoco the
    bindings use."""
    folder = os.path.dirname(mujoco.__file__)
    paths = sorted(glob.glob(os.path.join(folder, "libmujoco.so*"))
                   + glob.glob(os.path.join(folder, "libmujoco*.dylib")))
    if not paths:
        raise LayoutError(f"no libmujoco beside the bindings in {folder}")
    lib = ctypes.CDLL(paths[0])
    # the instance the bindings use: a warning handler set through them shows in this library's global
    if mujoco.get_mju_user_warning() is not None:
        same = ctypes.c_void_p.in_dll(lib, "mju_user_warning").value is not None
    else:
        try:
            mujoco.set_mju_user_warning(lambda message: None)
            same = ctypes.c_void_p.in_dll(lib, "mju_user_warning").value is not None
        finally:
            mujoco.set_mju_user_warning(None)
    if not same:
        raise LayoutError(f"{paths[0]} is not the library instance the bindings use")
    try:
        user_error = ctypes.addressof(ctypes.c_void_p.in_dll(lib, "mju_user_error"))
    except ValueError:  # no legacy handler: a MuJoCo error inside the loop is then MuJoCo's default (exit)
        user_error = 0
    return {"mj_step": ctypes.cast(lib.mj_step, ctypes.c_void_p).value,
            "mj_subtreeVel": ctypes.cast(lib.mj_subtreeVel, ctypes.c_void_p).value, "mju_user_error": user_error}


_SCALARS = {"mjtNum": ctypes.c_double, "double": ctypes.c_double, "float": ctypes.c_float, "int": ctypes.c_int,
            "unsigned int": ctypes.c_uint, "size_t": ctypes.c_size_t, "uintptr_t": ctypes.c_size_t,
            "mjtSize": ctypes.c_int64, "mjtBool": ctypes.c_bool, "mjtByte": ctypes.c_ubyte}


@functools.lru_cache(maxsize=None)
def mjdata_offsets() -> dict[str, int]:
    """Byte offsets of :data:`_DATA_FIELDS` in mjData, from ``mujoco.introspect``'s declaration of the
    struct laid out by ctypes (the platform's C rules); only the fields up to the last one needed."""
    from mujoco.introspect import ast_nodes, enums, structs

    def ctype(t):
        if isinstance(t, ast_nodes.PointerType):
            return ctypes.c_void_p
        if isinstance(t, ast_nodes.ArrayType):
            inner = ctype(t.inner_type)
            for extent in reversed(t.extents):
                inner = inner * extent
            return inner
        if isinstance(t, ast_nodes.ValueType):
            if t.name in _SCALARS:
                return _SCALARS[t.name]
            if t.name in enums.ENUMS:
                return ctypes.c_int
            if t.name in structs.STRUCTS:
                return struct(t.name, None)
        raise LayoutError(f"mjData field type {t!r} is not understood")

    def struct(name, last):
        fields = []
        for field in structs.STRUCTS[name].fields:
            fields.append((field.name, ctype(field.type)))
            if field.name == last:
                break
        return type(name, (ctypes.Structure,), {"_fields_": fields})

    stat = [(f.name, getattr(f.type, "name", None)) for f in structs.STRUCTS["mjWarningStat"].fields]
    if stat != [("lastinfo", "int"), ("number", "int")]:  # _stepper.c counts warnings on this layout
        raise LayoutError(f"mjWarningStat is {stat}, not (int lastinfo, int number)")
    names = [f.name for f in structs.STRUCTS["mjData"].fields]
    missing = [n for n in _DATA_FIELDS if n not in names]
    if missing:
        raise LayoutError(f"mjData has no field {missing[0]!r}")
    layout = struct("mjData", max(_DATA_FIELDS, key=names.index))
    return {n: getattr(layout, n).offset for n in _DATA_FIELDS}


def check_layout(data: mujoco.MjData) -> dict[str, int]:
    """The offsets, checked on ``data`` (after ``mj_forward``): every field read at its offset must be what
    the bindings report."""
    offsets = mjdata_offsets()
    base = data._address
    read = {n: ctypes.c_int.from_address(base + offsets[n]).value for n in ("ne", "nf", "nl", "nefc")}
    read["time"] = ctypes.c_double.from_address(base + offsets["time"]).value
    for n in ("qpos", "qvel", "efc_id", "efc_force"):
        read[n] = ctypes.c_void_p.from_address(base + offsets[n]).value
    # each mjWarningStat is (lastinfo, number), two ints
    read["warning"] = [ctypes.c_int.from_address(base + offsets["warning"] + 8 * w + 4).value
                       for w in range(len(data.warning))]
    expected = {n: int(getattr(data, n)) for n in ("ne", "nf", "nl", "nefc")}
    expected["time"] = float(data.time)
    for n in ("qpos", "qvel", "efc_id", "efc_force"):
        expected[n] = address(getattr(data, n)) if getattr(data, n).size else read[n]
    expected["warning"] = data.warning.number.tolist()
    if data.nefc == 0 or read != expected:
        raise LayoutError(f"the mjData layout does not check out: read {read}, expected {expected}")
    return offsets
