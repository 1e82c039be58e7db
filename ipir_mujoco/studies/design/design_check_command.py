"""The design check (``ipir-mujoco design-check``): the round-pipe robot's closed-form design rules for one design,
no simulation. Its rules: :mod:`.design_rules`."""

from __future__ import annotations

import argparse

from ..command import add_model_options, check_input_file, model_params
from ..contract import Declaration


def add_options(cmd: argparse.ArgumentParser) -> None:
    add_model_options(cmd)
    cmd.add_argument("--route", metavar="FILE.toml", default=None,
                     help="a route (as simulate --route): the bend rules take its bends")
    cmd.add_argument("--json", action="store_true", help="print {\"rules\": [...], \"holds\": ...} as JSON")


def run(args: argparse.Namespace, figures) -> None:
    from ipir_mujoco.engine.kinds.wheels.model import check_wheels_params

    from ipir_mujoco.core.results import json_text
    from .design_rules import design_rules

    params = model_params(args)
    check_wheels_params(params)  # the wheeled model's own refusals: a robot that does not fit its pipe
    route = None
    if args.route is not None:
        from ipir_mujoco.core.route import read_route

        check_input_file("--route", args.route)
        route = read_route(args.route)
        route.check_pipe(params.pipe_diameter)
    result = design_rules(params, route)
    if args.json:  # a figure without bound (a side load where the wheels hold nothing) is null, as in a summary
        print(json_text(result))
    else:
        print(format_rules(result))


STUDY = Declaration(
    "design-check", "the round-pipe robot's design rules (closed form, no simulation), each with its margin",
    "For one design of the wheeled robot in its round pipe: each closed-form rule with its value, limit, margin and "
    "whether it holds: the stall push against each module's grip, the restart torque, the weight against the press, "
    "a wheel's lift at stall (and at speed, for the motor), the rings' sideways grip, the tightest bend the "
    "geometry passes and the wheels' scrub in a bend (docs/model.md, 'The round pipe: design rules'). Exit status "
    "0 whatever the verdicts.",
    options=add_options, run=run)


def format_rules(result: dict) -> str:
    """One line per rule: name, value, limit, margin and unit, whether it holds, why; the verdict last."""
    def number(value) -> str:
        return "-" if value is None else f"{value:.4g}"

    lines = [f"{'rule':20s} {'value':>10s} {'limit':>10s} {'margin':>10s} {'unit':5s} holds"]
    for r in result["rules"]:
        lines.append(f"{r['name']:20s} {number(r['value']):>10s} {number(r['limit']):>10s} "
                     f"{number(r['margin']):>10s} {r['unit']:5s} {'yes' if r['holds'] else 'NO '}   {r['why']}")
    failing = [r["name"] for r in result["rules"] if not r["holds"]]
    lines.append("every rule holds" if result["holds"] else f"rules that do not hold: {', '.join(failing)}")
    return "\n".join(lines)
