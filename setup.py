"""The one compiled piece: the serial MuJoCo engine's stepping loop (ipir_mujoco/engine/_stepper.c).

All package metadata is in pyproject.toml. The extension is optional: without a C compiler the install
goes on and the engine steps in Python, with the same results (ipir_mujoco/engine/stepper.py).
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class OptionalBuildExt(build_ext):
    """Build the stepper if a compiler is at hand; otherwise say so and install without it."""

    def build_extension(self, ext):
        if self.compiler.compiler_type == "unix":
            # no fused multiply-add: the C loop must round exactly as the Python loop does
            ext.extra_compile_args = ["-O2", "-ffp-contract=off", "-std=c11"]
        try:
            super().build_extension(ext)
        except Exception as exc:  # noqa: BLE001 - any build failure leaves the pure-Python loop
            print(f"warning: the compiled MuJoCo stepper was not built ({exc}); serial MuJoCo runs will step in "
                  "Python (same results, slower)")


setup(
    ext_modules=[Extension("ipir_mujoco.engine._stepper", ["ipir_mujoco/engine/_stepper.c"], optional=True)],
    cmdclass={"build_ext": OptionalBuildExt},
)
