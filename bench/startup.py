"""Benchmark: how long the command takes to start, as a ratio to the interpreter loading numpy.

Run on demand (not part of the test suite), from the repository root:

    python bench/startup.py [--repeats 5] [--smoke]

Each command runs as a whole process on this interpreter (the ``ipir-mujoco``
script beside it, else the package run as a module), its output thrown away;
the floor is ``python -c "import numpy"`` on the same interpreter. The runs are
interleaved (floor, then each command, repeated), each time is the best of the
repeats, and the ratio is taken between the bests, so that a machine's load
moves the floor and the commands alike: wall time, and CPU time (user +
system, the operating system's count for the finished process), which other
jobs on a shared machine disturb less. Targets:

- ``ipir-mujoco --help`` and ``ipir-mujoco params``: at most 1.5 x the floor;
- ``ipir-mujoco simulate`` (the paper's case, 1 s, with its summary): at most
  2.5 x the floor.

The package's modules run from their bytecode cache (``__pycache__``), as an
installed package's do: the bench runs each command once before it times it,
with ``PYTHONDONTWRITEBYTECODE`` unset, so that the cache is written. The
first line gives the machine's load average (the targets are for an idle
machine: on a busy one the bests of 5 scatter). ``--smoke`` runs each command
once: a check that the bench runs, not a measurement.
To see where a command's start-up goes: ``python -X importtime -m ipir_mujoco
--help 2> imports.txt`` (each module's own and cumulative microseconds).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

FLOOR = ("-c", "import numpy")
# (row, arguments of the command, the most it may take as a multiple of the floor)
COMMANDS = (("ipir-mujoco --help", ("--help",), 1.5),
            ("ipir-mujoco params", ("params",), 1.5),
            ("ipir-mujoco simulate (the paper's case, 1 s)", ("simulate",), 2.5))


def command_prefix() -> list[str]:
    """How to start the command on this interpreter: its console script beside the interpreter, else -m."""
    script = Path(sys.executable).parent / "ipir-mujoco"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "ipir_mujoco"]


def timed(argv: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall time [s], CPU time [s], user + system) of one whole process, output discarded; it must succeed."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    subprocess.run(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - started
    now = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (now.ru_utime - used.ru_utime) + (now.ru_stime - used.ru_stime)


def measure(repeats: int) -> tuple[tuple[float, float], list[tuple[str, tuple[float, float], float]]]:
    """(the floor's best (wall, CPU) times [s], [(row, its best (wall, CPU) times [s], wanted ratio)])."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    prefix = command_prefix()
    argvs = [prefix + list(args) for _, args, _ in COMMANDS]
    for argv in argvs:  # the bytecode cache written, the numba decision of a short run taken
        timed(argv, env)
    floor, best = (math.inf, math.inf), [(math.inf, math.inf)] * len(argvs)
    for _ in range(repeats):
        floor = tuple(map(min, floor, timed([sys.executable, *FLOOR], env)))
        for i, argv in enumerate(argvs):
            best[i] = tuple(map(min, best[i], timed(argv, env)))
    return floor, [(name, t, wanted) for (name, _, wanted), t in zip(COMMANDS, best)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs of each command; the best is kept (default 5)")
    parser.add_argument("--smoke", action="store_true", help="each command once (not a measurement)")
    args = parser.parse_args()
    repeats = 1 if args.smoke else args.repeats
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on {os.cpu_count()} cores; best of {repeats}; "
          f"{sys.executable}", flush=True)
    floor, rows = measure(repeats)
    print(f"\nfloor: python -c \"import numpy\" {floor[0] * 1e3:.0f} ms wall, {floor[1] * 1e3:.0f} ms CPU\n")
    print("| command | best wall | ratio | best CPU | ratio | wanted |\n|---|---|---|---|---|---|")
    for name, (wall, cpu), wanted in rows:
        print(f"| {name} | {wall * 1e3:.0f} ms | {wall / floor[0]:.2f} | {cpu * 1e3:.0f} ms | {cpu / floor[1]:.2f} "
              f"| <= {wanted:g} |")


if __name__ == "__main__":
    main()
