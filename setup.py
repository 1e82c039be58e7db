"""The one compiled piece: the serial MuJoCo engine's stepping loop (ipir_mujoco/engine/_stepper.c).

All package metadata is in pyproject.toml. The extension is optional (``optional=True``: setuptools warns and
goes on when it cannot be built): without a C compiler the install goes on and the engine steps in Python,
with the same results (ipir_mujoco/engine/stepper.py).
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class BuildExt(build_ext):
    """The stepper's compiler flags, where the compiler takes them."""

    def build_extension(self, ext):
        if self.compiler.compiler_type == "unix":
            # no fused multiply-add: the C loop must round exactly as the Python loop does
            ext.extra_compile_args = ["-O2", "-ffp-contract=off", "-std=c11"]
        super().build_extension(ext)


setup(
    ext_modules=[Extension("ipir_mujoco.engine._stepper", ["ipir_mujoco/engine/_stepper.c"], optional=True)],
    cmdclass={"build_ext": BuildExt},
)
