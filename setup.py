"""The compiled pieces: the serial MuJoCo engine's stepping loop (ipir_mujoco/engine/loop/_stepper.c) and the round
pipe's exact wall contacts (ipir_mujoco/engine/builders/_pipewall.c, which the round pipe needs).

All package metadata is in pyproject.toml. The extension is compiled against the headers of the mujoco
installed where it builds (a build requirement: in pip's isolated build environment, the newest mujoco the
project allows) and linked against that mujoco's libmujoco by its SONAME, with no search path: at import the
dynamic linker takes the libmujoco the bindings have already loaded, and ipir_mujoco/engine/loop/native.py checks
that its version is the headers'. The extension is optional (``optional=True``: setuptools warns and goes on
when it cannot be built: no C compiler, no mujoco headers): the engine then steps in Python, with the same
results (ipir_mujoco/engine/loop/stepper.py).
"""

import importlib.metadata
import importlib.util
import os
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.errors import PlatformError


def mujoco_build_paths() -> tuple[str, str]:
    """(the installed mujoco's include folder, its libmujoco), found through the package (not imported)."""
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise PlatformError("no mujoco package to build the compiled stepper against")
    folder = spec.submodule_search_locations[0]
    version = importlib.metadata.version("mujoco")
    # the names the mujoco wheels give the library
    name = f"libmujoco.{version}.dylib" if sys.platform == "darwin" else f"libmujoco.so.{version}"
    include, library = os.path.join(folder, "include"), os.path.join(folder, name)
    for path in (os.path.join(include, "mujoco", "mujoco.h"), library):
        if not os.path.isfile(path):
            raise PlatformError(f"mujoco {version} has no {path} to build the compiled stepper against")
    return include, library


# the compiled loop (loop/_stepper.c) and its clutch controllers' compiled forms (controllers/_clutch_*.c: one file per
# family, their table in _clutch_table.c)
STEPPER_SOURCES = ["ipir_mujoco/engine/loop/_stepper.c", "ipir_mujoco/engine/controllers/_clutch_table.c"] + [
    f"ipir_mujoco/engine/kinds/{kind}/_clutch_{name}.c"
    for kind, name in (("slides", "slides"), ("slides_grip", "grip"), ("wheels", "wheels"))]
STEPPER_HEADERS = ["ipir_mujoco/engine/loop/_stepper.h", "ipir_mujoco/engine/controllers/_clutch_parts.h"]


class BuildExt(build_ext):
    """The stepper's MuJoCo headers and library, and its compiler flags, where the compiler takes them."""

    def build_extension(self, ext):
        if self.compiler.compiler_type != "unix":
            raise PlatformError(f"the compiled stepper is built with a unix compiler, not {self.compiler.compiler_type}")
        include, library = mujoco_build_paths()
        ext.include_dirs = [include]
        ext.extra_objects = [library]  # recorded by its SONAME (install name on macOS): no path
        # no fused multiply-add: the C loop must round exactly as the Python loop does
        ext.extra_compile_args = ["-O2", "-ffp-contract=off", "-std=c11"]
        if sys.platform == "darwin":  # the wheel's install name is @rpath/...: beside an installed mujoco (from
            # ipir_mujoco/engine/<folder>/, where both extensions are)
            ext.extra_link_args = ["-Wl,-rpath,@loader_path/../../../mujoco"]
        super().build_extension(ext)


setup(
    ext_modules=[Extension("ipir_mujoco.engine.loop._stepper", STEPPER_SOURCES, depends=STEPPER_HEADERS,
                           optional=True),
                 Extension("ipir_mujoco.engine.builders._pipewall", ["ipir_mujoco/engine/builders/_pipewall.c"], optional=True)],
    cmdclass={"build_ext": BuildExt},
)
