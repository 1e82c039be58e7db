"""Benchmark: how far the steady figures lie from the periodic limit, with and without the limit estimate.

Run on demand (not part of the test suite):

    python bench/steady_limit.py [--smoke]

``--smoke``: the first design, MuJoCo left out (a check that it runs, not a measurement).

For each design of tests/test_steady_limit.py and each engine (the one-way-clutch equations, MuJoCo's
ratchet) it prints the relative error against that test's converged reference of the summary's steady
figures (speed, distance per revolution, energy per metre, efficiency) and of the same figures read as the
steady window's raw totals (what the summary reported before the limit estimate), the stated accuracy, and
the wall time of the run to its steady state against the reference's, as a ratio in one run (the estimate
itself costs no simulation).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))

from test_steady_limit import DESIGNS, FIGURES, T_CAP, VARIANTS, raw_figures, reference  # noqa: E402

from ipir_mujoco import registry  # noqa: E402
from ipir_mujoco.core.cycles import LIMIT_ACCURACY, cycles  # noqa: E402
from ipir_mujoco.core.params import RobotParams  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    smoke = parser.parse_args().smoke
    designs = dict(list(DESIGNS.items())[:1]) if smoke else DESIGNS
    variants = {"analytic": VARIANTS["analytic"]} if smoke else VARIANTS
    short = {"steady_speed_m_s": "speed", "distance_per_rev_m": "dist/rev", "energy_per_metre_j_m": "J/m",
             "efficiency": "eff"}
    print(f"{'design':34s} {'engine':8s} " + " ".join(f"{short[k]:>19s}" for k in FIGURES) + "   ref/run wall")
    print(f"{'':34s} {'':8s} " + " ".join(f"{'summary   window':>19s}" for _ in FIGURES))
    worst = {engine: 0.0 for engine in variants}
    for name, fields in designs.items():
        params = RobotParams(**fields)
        for engine, variant in variants.items():
            started = time.perf_counter()
            run = registry.run(variant, params, T_CAP, dt_out=1e-3, until_steady=True)
            wall = time.perf_counter() - started
            started = time.perf_counter()
            limit = reference(engine, params, run.summary["t_steady_s"])
            wall_ref = time.perf_counter() - started
            window = raw_figures(cycles(run.series)[-3:]) if engine == "analytic" else \
                raw_figures([c for c in cycles(run.series) if c.t_end <= run.summary["t_steady_s"] + 1e-12][-3:])
            cells = []
            for key in FIGURES:
                error = run.summary[key] / limit[key] - 1
                worst[engine] = max(worst[engine], abs(error))
                cells.append(f"{error:+9.1e} {window[key] / limit[key] - 1:+9.1e}")
            print(f"{name:34s} {engine:8s} " + " ".join(cells) + f"   {wall_ref / wall:6.1f}x", flush=True)
    for engine, error in worst.items():
        print(f"{engine}: largest |error| of the summary's steady figures {error:.1e} "
              f"(stated accuracy {LIMIT_ACCURACY[engine]:.0e})")


if __name__ == "__main__":
    main()
