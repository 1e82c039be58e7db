"""The Python API's part of bench/fuzz_surface.py: every public entry point called with one argument of the wrong
type at a time (the others valid), each of which must raise a ParameterTypeError (a ValueError and a TypeError)
with a one-line message naming the argument; run alone it is ``fuzz_surface.py --only api``:

    python bench/fuzz_api.py [--smoke] [-v]
    python bench/fuzz_api.py --smoke     # a few cases
"""

from __future__ import annotations

import sys

from fuzz_surface import Case


# wrong types per kind of argument (a number where a number goes is no wrong type: the kinds say which is which)
WRONG = {
    "num": {"None": None, "str": "x", "bytes": b"x", "object": object(), "list": [1], "complex": 1j},
    "str": {"None": None, "int": 3, "bytes": b"x", "object": object(), "list": ["x"]},
    "path": {"None": None, "int": 3, "bytes": b"x", "object": object(), "list": ["x"]},
    "params": {"None": None, "int": 3, "str": "x", "dict": {"m1": 1}, "object": object()},
    "seq": {"None": None, "int": 3, "str": "x", "bytes": b"x", "object": object(), "complex": 1j},
    "obj": {"None": None, "int": 3, "str": "x", "dict": {"a": 1}, "object": object()},
}


def api_cases() -> list[Case]:
    """Every public entry point called with one argument of the wrong type at a time (the others valid)."""
    from ipir_mujoco.core.params import RobotParams

    def P():  # noqa: N802 (a parameter set)
        return RobotParams()

    def axes():
        from ipir_mujoco.studies.sweep_space import parse_vary

        return (parse_vary("L=0.1:0.3"),)

    def objective():
        from ipir_mujoco.studies.optimize import Objective

        return (Objective("max", "revolutions"),)

    # (name, the function, [(kind of argument, its valid value as a function of the fixture folder f)])
    entries = []

    def entry(name, target, *args):
        entries.append((name, target, args))

    import ipir_mujoco
    from ipir_mujoco import analytic, engine, registry
    from ipir_mujoco.core import route
    from ipir_mujoco.core.params import load_params
    from ipir_mujoco.studies import (atlas, bend_study, calibrate, climbing, clutch_study, compare, control_study,
                                     frames, measured, optimize, sensitivity, sweep, sweep_space, uncertainty)

    params, t = ("params", lambda f: P()), ("num", lambda f: 0.01)
    entry("ipir_mujoco.run", ipir_mujoco.run, ("str", lambda f: "analytic-approx"), params, t)
    entry("registry.run", registry.run, ("str", lambda f: "mujoco-ratchet"), params, t)
    entry("registry.variant", registry.variant, ("str", lambda f: "mujoco-ratchet"))
    entry("registry.timestep", registry.timestep, ("str", lambda f: "mujoco-ratchet"), params, ("num", lambda f: 1.0),
          ("num", lambda f: 1e-3))
    entry("registry.feedforward_table", registry.feedforward_table, ("params", lambda f: P().replace(drive="servo")))
    entry("registry.run_batch", registry.run_batch, ("str", lambda f: "mujoco-ratchet"), ("seq", lambda f: [P()]), t,
          ("num", lambda f: 1e-3))
    entry("analytic.simulate", analytic.simulate, params, ("str", lambda f: "exact"), ("str", lambda f: "unilateral"),
          t)
    entry("engine.simulate_mujoco", engine.simulate_mujoco, params, ("str", lambda f: "unilateral"),
          ("str", lambda f: "ratchet"), t)
    entry("engine.compiled_mjcf", engine.compiled_mjcf, params)
    entry("engine.save_mjcf", engine.save_mjcf, ("path", lambda f: f"{f}/x.xml"), params)
    entry("load_params", load_params, ("path", lambda f: f"{f}/config.toml"), ("seq", lambda f: ["m1=2"]))
    entry("route.read_route", route.read_route, ("path", lambda f: f"{f}/route.toml"))
    entry("route.route_from_tables", route.route_from_tables, ("seq", lambda f: [{"kind": "straight", "length": 0.4}]))
    entry("sweep_space.parse_vary", sweep_space.parse_vary, ("str", lambda f: "L=0.1,0.2"))
    entry("sweep_space.Study", sweep_space.Study, ("seq", lambda f: (sweep_space.parse_vary("L=0.1,0.2"),)))
    entry("sweep.run_sweep", sweep.run_sweep,
          ("obj", lambda f: sweep_space.Study((sweep_space.parse_vary("L=0.1,0.2"),), engines=("analytic-approx",),
                                             t_end=0.02)), ("path", lambda f: f"{f}/s"))
    entry("frames.read_sweep", frames.read_sweep, ("path", lambda f: f"{f}/swp"))
    entry("optimize.parse_objective", optimize.parse_objective, ("str", lambda f: "max:revolutions"))
    entry("optimize.parse_constraint", optimize.parse_constraint, ("str", lambda f: "revolutions>=1"))
    entry("optimize.Objective", optimize.Objective, ("str", lambda f: "max"), ("str", lambda f: "revolutions"))
    entry("optimize.Constraint", optimize.Constraint, ("str", lambda f: "revolutions"), ("str", lambda f: ">="),
          ("num", lambda f: 1.0))
    entry("optimize.Problem", optimize.Problem, ("seq", lambda f: axes()), ("seq", lambda f: objective()))
    entry("optimize.run_optimize", optimize.run_optimize,
          ("obj", lambda f: optimize.Problem(axes(), objective(), budget=2, verify=None, t_end=0.02)),
          ("path", lambda f: f"{f}/o"))
    entry("sensitivity.run_sensitivity", sensitivity.run_sensitivity, ("seq", lambda f: axes()),
          ("seq", lambda f: ("revolutions",)), ("path", lambda f: f"{f}/sen"))
    entry("atlas.Atlas", atlas.Atlas, ("seq", lambda f: axes()))
    entry("bend_study.run_study", bend_study.run_study, params)
    entry("clutch_study.run_study", clutch_study.run_study, params, ("seq", lambda f: (1e4,)),
          ("seq", lambda f: (0.0,)),
          ("seq", lambda f: ("startup",)))
    entry("control_study.run_study", control_study.run_study, params, ("seq", lambda f: (10.0,)),
          ("seq", lambda f: (0.0,)))
    entry("climbing.climb_study", climbing.climb_study, params, ("seq", lambda f: [0.0]))
    entry("compare.load_run", compare.load_run, ("path", lambda f: f"{f}/run"))
    entry("compare.compare_runs", compare.compare_runs, ("obj", lambda f: compare.load_run(f"{f}/run")),
          ("obj", lambda f: compare.load_run(f"{f}/run2")))
    entry("measured.read_measured", measured.read_measured, ("path", lambda f: f"{f}/measured.csv"))
    entry("calibrate.parse_fit", calibrate.parse_fit, ("str", lambda f: "L=0.1:0.3"))
    entry("uncertainty.parse_event", uncertainty.parse_event, ("str", lambda f: "revolutions>1"))
    cases = []
    for name, target, args in entries:
        makers = [make for _, make in args]
        for position, (kind, _) in enumerate(args):
            for label, bad in WRONG[kind].items():
                if name == "load_params" and position == 0 and bad is None:
                    continue  # None: no config file, a valid call
                cases.append(Case(f"{name} arg {position} = {label}", call=(target, makers, position, bad),
                                  wrong_type=True, timeout=60.0))
    # a wrong type given by keyword to the entry points with keyword options
    for name, call in {
        "run(dt_out='x')": lambda f: registry.run("analytic-approx", RobotParams(), 0.01, dt_out="x"),
        "run(until_steady='yes')": lambda f: registry.run("analytic-approx", RobotParams(drive="motor"), 0.01,
                                                          until_steady="yes"),
        "run(progress=3)": lambda f: registry.run("analytic-approx", RobotParams(), 0.01, progress=3),
        "run(wall_budget_s='1')": lambda f: registry.run("mujoco-ratchet", RobotParams(), 0.01, wall_budget_s="1"),
        "run(route='x.toml')": lambda f: registry.run("mujoco-wheels", RobotParams(), 0.01, route="x.toml"),
        "RobotParams(m1='1')": lambda f: RobotParams(m1="1"),
        "RobotParams(drive=1)": lambda f: RobotParams(drive=1),
        "RobotParams(mu_wall=[0.5])": lambda f: RobotParams(mu_wall=[0.5]),
        "run_sensitivity(samples='4')": lambda f: sensitivity.run_sensitivity(axes(), ("revolutions",), f"{f}/x",
                                                                              samples="4"),
        "Study(t_end=None)": lambda f: sweep_space.Study(axes(), t_end=None, sample=2),
        "Study(sample='2')": lambda f: sweep_space.Study(axes(), sample="2"),
        "Problem(budget='5')": lambda f: optimize.Problem(axes(), objective(), budget="5"),
        "Problem(verify=3)": lambda f: optimize.Problem(axes(), objective(), verify=3),
        "Problem(engine=None)": lambda f: optimize.Problem(axes(), objective(), engine=None),
        "bend_study.run_study(ratios='2')": lambda f: bend_study.run_study(RobotParams(), "2"),
        "clutch_study.run_study(points='startup')": lambda f: clutch_study.run_study(RobotParams(), (1e4,), (0.0,),
                                                                                    "startup"),
    }.items():
        cases.append(Case(name, call=call, wrong_type=True, timeout=60.0))
    return cases


if __name__ == "__main__":
    import argparse

    from fuzz_surface import main

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--smoke", action="store_true", help="a few cases")
    parser.add_argument("-v", "--verbose", action="store_true", help="also print every clean case")
    args = parser.parse_args()
    sys.exit(main(["--only", "api"] + ["--smoke"] * args.smoke + ["-v"] * args.verbose))
