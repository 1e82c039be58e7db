"""The MJCF a run uses, for a user's own MuJoCo code: ``simulate --save-mjcf FILE.xml``, :func:`compiled_mjcf`.

The model is built through the one run setup (:class:`.run_setup.RunSetup`), as a run of the same options
builds it: the same model kind, parameter set, MuJoCo settings (the timestep the engine would choose, or the
one given) and route; its initial state goes in as the keyframe ``run_start`` (``mj_resetDataKeyframe``).

What the file cannot hold is what this package does in Python between MuJoCo's steps; the header comment
says it for the run at hand (:func:`between_steps`). Above all, the one-way clutches are controllers that
move joint limits before every ``mj_step``: opened in plain MuJoCo (``python -m mujoco.viewer --mjcf
FILE.xml``) the robot does not crawl, its modules rock in place.
"""

from __future__ import annotations

from pathlib import Path

import mujoco

from ipir_mujoco.core.checks import check_path
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams, require_params

from ..kinds import kind_for
from ..builders.model import SolverSettings
from .run_setup import RunSetup

KEYFRAME = "run_start"


def between_steps(params: RobotParams, implementation: str, rule: str, model: str) -> list[str]:
    """What the package's Python does between MuJoCo's steps in a run of these options, one sentence each."""
    out = kind_for(model, params).between_steps(params, implementation, rule)
    drive = {"torque": f"The crank's actuator holds ctrl = M = {params.M:g} N m all run (set once at the start).",
             "motor": "The motor is MuJoCo's own actuator (its gain and bias in this file); ctrl = 1, the full "
                      "voltage, set once at the start.",
             "servo": f"A speed controller (PI with anti-windup, feedforward '{params.feedforward}') sets ctrl every "
                      f"1 / control_rate = {1 / params.control_rate:g} s (ipir_mujoco.core.control)."}
    out.append(drive.get(params.drive, f"drive '{params.drive}'."))
    out.append(f"The run starts from the keyframe '{KEYFRAME}' (mj_resetDataKeyframe): the loop closed at phi0, "
               "at rest or at omega0, with its ctrl.")
    out.append("The accuracy monitor, progress and steady-state watch read the state; they change nothing.")
    return out


def compiled_mjcf(params: RobotParams, clutch: str = "unilateral", implementation: str = "ratchet", *,
                  model: str = "slides", t_end: float = 1.0, dt_out: float = 1e-4,
                  settings: SolverSettings | None = None, mjcf=None, route=None) -> str:
    """The MJCF (an XML string) of the model a :func:`.simulate.simulate_mujoco` run of these arguments
    compiles, with its initial state as the keyframe 'run_start' and a header comment on what the package
    does between steps. ``settings`` None: the timestep the engine chooses for ``t_end`` [s] and ``dt_out``
    [s] (before any refinement its accuracy monitor may make); bad arguments raise ParameterError as the
    run would."""
    params = require_params(params)
    kind = kind_for(model, params)
    params = kind.check(params, implementation, clutch, route, False)
    if settings is None:
        settings, _why = kind.settings(params, t_end, dt_out, None, implementation, route=route)
    specs = []
    setup = RunSetup(kind, params, settings, implementation=implementation, rule=clutch, mjcf=mjcf, route=route,
                     decorate=specs.append)
    setup.start()
    if not specs:  # pragma: no cover - every kind passes decorate on
        raise ParameterError(f"model={model!r} does not expose its MJCF")
    xml = specs[0].to_xml()
    # the initial state at full precision (MuJoCo's XML writer prints 6 significant digits)
    d = setup.data
    state = " ".join(f'{name}="{" ".join(repr(float(v)) for v in values)}"' for name, values in
                     (("qpos", d.qpos), ("qvel", d.qvel), ("act", d.act), ("ctrl", d.ctrl)) if len(values))
    xml = xml.replace("</mujoco>", f'  <keyframe>\n    <key name="{KEYFRAME}" time="0" {state}/>\n  </keyframe>\n'
                                   "</mujoco>")
    lines = ["This is the model ipir-mujoco compiles for this run (model kind '" + model + "', MuJoCo clutch '"
             + implementation + "', rule '" + clutch + f"', timestep {settings.timestep:g} s), written by "
             "simulate --save-mjcf. It is not the whole robot: the package steps it with its own controllers.",
             "Its numbers are MuJoCo's XML writer's, to 6 significant digits (the keyframe's to 17): the "
             "model compiled from this file differs from the run's by that rounding, a few parts in a million.",
             *between_steps(params, implementation, clutch, model),
             "Opened on its own (python -m mujoco.viewer --mjcf FILE.xml) the robot therefore does not crawl. "
             "The package's docs (mjcf/README.md) give the evidence for every setting."]
    comment = "<!--\n" + "\n".join("  " + line.replace("--", "- -") for line in _wrap(lines)) + "\n-->\n"
    return comment + xml


def _wrap(sentences: list[str], width: int = 100) -> list[str]:
    import textwrap

    out = []
    for sentence in sentences:
        out += textwrap.wrap(sentence, width) + [""]
    return out[:-1]


def save_mjcf(path, params: RobotParams, clutch: str = "unilateral", implementation: str = "ratchet",
              **options) -> Path:
    """Write :func:`compiled_mjcf` to ``path`` (a .xml file); return the path. Nothing is written if the
    arguments are refused."""
    check_path("path", path, "a path ending in .xml")
    if not str(path).endswith(".xml"):
        raise ParameterError(f"path={path!r} is not an .xml file name; allowed: a path ending in .xml")
    text = compiled_mjcf(params, clutch, implementation, **options)
    target = Path(path)
    target.write_text(text, encoding="utf-8")
    return target
