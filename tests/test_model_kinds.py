"""The MuJoCo engine's seam: every model kind x clutch controller keeps one contract.

- each kind picks the controller its parameters call for, and that controller reports reactions as
  (held, held, force, force) and wheels as two states of ROLLING, STANDING, SKIDDING;
- ``registry.timestep`` is the step every run of the variant takes (a run that skidded: the step it starts
  from, halved as its skid check records), and ``every_step=True`` gives one sample per step (so a mean over
  samples is the mean over steps);
- *held* means one thing in every variant, the analytic ones included: no sample holds a module while its
  wheels skid back (on a riser whose grip cannot carry the robot, where every variant skids).
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.results import Mode
from ipir_mujoco.engine import kinds
from ipir_mujoco.engine.loop.controller import ROLLING, SKID_SPEED, SKIDDING, STANDING, ClutchController
from kind_setup import started_setup

GRIP = dict(mu_wall=0.5, F_n1=10.0, F_n2=10.0)
COMPLIANT = dict(clutch_stiffness=1e5, clutch_damping=5.0)
# (variant, params, the kind it must choose, the controller it must make)
CASES = [
    ("mujoco-ratchet", RobotParams(), kinds.SLIDES, "Ratchet"),
    ("mujoco-ratchet", RobotParams(**COMPLIANT), kinds.SLIDES, "CompliantClutches"),
    ("mujoco-lock", RobotParams(), kinds.SLIDES, "Locks"),
    ("mujoco-lock-unilateral", RobotParams(), kinds.SLIDES, "Locks"),
    ("mujoco-ratchet", RobotParams(**GRIP), kinds.GRIP_SLIDES, "GripRatchet"),
    ("mujoco-ratchet", RobotParams(**GRIP, **COMPLIANT), kinds.GRIP_SLIDES, "CompliantGrip"),
    ("mujoco-wheels", RobotParams(), kinds.WHEELS, "WheelRatchet"),
    ("mujoco-wheels", RobotParams(mu_wall=0.8), kinds.WHEELS, "WheelRatchet"),
]
IDS = [f"{v}-{c}-{'grip' if p.mu_wall else 'unlimited'}" for v, p, _, c in CASES]
STATES = {float(ROLLING), float(STANDING), float(SKIDDING)}




@pytest.mark.parametrize("variant, params, kind, controller", CASES, ids=IDS)
def test_each_kind_makes_its_controller_and_it_reports_the_protocols_shapes(variant, params, kind, controller):
    setup = started_setup(variant, params)
    assert kinds.kind_for(registry.variant(variant).model, params) is kind
    ctl = setup.controller
    assert type(ctl).__name__ == controller
    for name in ClutchController.__annotations__:  # every attribute the protocol names
        assert hasattr(ctl, name), name
    methods = [name for name, value in vars(ClutchController).items() if callable(value) and not name.startswith("_")]
    assert {"load_compiled", "deferred_values", "clutch_columns", "modes", "after_step"} <= set(methods)
    assert all(callable(getattr(ctl, name, None)) for name in methods)  # every method: the loop tests none
    steps, _ = setup.steps(np.empty((2, setup.model.nv)))
    for _ in range(3):  # a few steps of the run's own loop, then read what a sample reads
        steps.run(20)
        reactions, wheels = ctl.reactions(), ctl.wheels()
        assert len(reactions) == 4 and all(isinstance(h, (bool, np.bool_)) for h in reactions[:2])
        assert all(isinstance(f, float) and math.isfinite(f) for f in reactions[2:])
        assert len(wheels) == 2 and set(map(float, wheels)) <= STATES
        assert ctl.excursion >= 0.0 and ctl.damper_work >= 0.0 or not ctl.deferred
        assert ctl.deferred == (controller.startswith("Compliant"))


def test_no_clutch_is_a_controller_of_the_slide_kind_too():
    setup = started_setup("mujoco-ratchet", RobotParams(), implementation="none")
    assert type(setup.controller).__name__ == "NoClutch" and setup.controller.reactions() == (False, False, 0.0, 0.0)
    assert setup.controller.wheels() == (0.0, 0.0)


@pytest.mark.parametrize("variant, params, kind, controller", CASES, ids=IDS)
def test_registry_timestep_is_the_step_every_run_takes_and_every_step_samples_each(variant, params, kind,
                                                                                  controller):
    t_end = 0.004
    step = registry.timestep(variant, params, t_end, 1e-3)
    run = registry.run(variant, params, t_end, dt_out=1e-3)
    # a run whose modules skidded is verified at half its step (engine/run/skid_check.py) and kept at the finer step
    # where the two agree: registry.timestep is the step it starts from, and its halvings are recorded
    halvings = len(run.settings.get("skid_check", []))
    assert run.settings["timestep"] == step / 2**halvings
    step = registry.timestep(variant, params, t_end, 1e-4)  # the step is a whole fraction of dt_out (its default)
    every = registry.run(variant, params, t_end, every_step=True)
    step /= 2 ** len(every.settings.get("skid_check", []))  # sampled at each step of the run it keeps
    assert every.settings["timestep"] == step and every.settings["dt_out"] == step
    t = every.series["t"]
    # one sample per step: as many as steps (t_end / step, floored as the run does) plus the start
    assert t.size == math.floor(t_end / step * (1 + 1e-12)) + 1
    np.testing.assert_allclose(np.diff(t), step, rtol=1e-9)  # MuJoCo's clock adds the step each time


RISER = RobotParams(drive="motor", mu_wall=0.18, incline=90.0)  # grip 9 N per module, weight 9.81 N: it skids
HELD_VARIANTS = [("analytic-unilateral", RISER), ("analytic-approx-unilateral", RISER), ("mujoco-ratchet", RISER),
                 ("mujoco-ratchet", RISER.replace(clutch_stiffness=1e6)), ("mujoco-wheels", RISER)]


@pytest.mark.parametrize("variant, params", HELD_VARIANTS,
                         ids=[f"{v}-{'compliant' if p.clutch_stiffness else 'rigid'}" for v, p in HELD_VARIANTS])
def test_a_skidding_module_is_never_held_in_any_variant(variant, params):
    run = registry.run(variant, params, 0.1, dt_out=1e-3)
    mode = run.series["mode"]
    skidding = 0
    for k, locked in ((1, "rear_locked"), (2, "front_locked")):
        skids = run.series[f"wheels{k}"] == SKIDDING
        held = np.array([getattr(Mode(int(m)), locked) for m in mode])
        skidding += int(skids.sum())
        assert not np.any(held & skids), f"module {k}: {int((held & skids).sum())} held samples while skidding"
    assert skidding > 0  # the design skids in this variant: the check above had something to check
    if params.clutch_stiffness is None:  # rigid clutches: a held module stands (docs/cli.md, "held")
        assert not np.any(held_moving_back(run.series))


def held_moving_back(series: dict) -> np.ndarray:
    """The user's check of *held* (docs/cli.md), per sample: whether the mode holds a module whose v is below
    -SKID_SPEED."""
    held = [np.array([getattr(Mode(int(m)), locked) for m in series["mode"]], dtype=bool)
            for locked in ("rear_locked", "front_locked")]
    return (held[0] & (series["v1"] < -SKID_SPEED)) | (held[1] & (series["v2"] < -SKID_SPEED))


# the issue's skidding design on the wheels (motor, mu_wall 0.5, F_n 5 N): its hubs hold while its body tips and
# slides back; 0.3 s holds its first skids
ISSUE_51 = RobotParams(drive="motor", mu_wall=0.5, F_n1=5.0, F_n2=5.0)


@pytest.mark.slow
def test_a_held_module_stands_on_the_wheels_as_on_the_slides():
    """Held means one thing a user can check: no sample reads a module held while its speed along the pipe is below
    -SKID_SPEED (the wheeled model read 171 of 1000 samples so on the issue's design, 1 s); and the module's wheels
    read skidding there (the mode and wheels1/2 agree)."""
    run = registry.run("mujoco-wheels", ISSUE_51, 0.3, dt_out=1e-3, accuracy="warn")
    s = run.series
    back = (s["v1"] < -SKID_SPEED) | (s["v2"] < -SKID_SPEED)
    assert back.sum() > 10  # the design moves back: the check below has something to check
    assert not np.any(held_moving_back(s))
    for k in (1, 2):  # a module moving back that its hubs hold is skidding (its rolling forward is v > 0)
        holding = (s[f"wheels{k}"] != 1.0) & (s[f"v{k}"] < -SKID_SPEED)
        assert np.all(s[f"wheels{k}"][holding] == SKIDDING)


def test_kinds_are_named_once_and_unknown_models_are_one_line():
    """Every folder of engine/kinds/ with an __init__.py is a kind, named as its folder, registered once; its
    variants are the registry's."""
    folders = sorted(p.parent.name for p in Path(kinds.__file__).parent.glob("*/__init__.py"))
    assert [name.replace("-", "_") for name in kinds.KINDS] == folders
    assert {kinds.SLIDES, kinds.GRIP_SLIDES, kinds.WHEELS} <= set(kinds.KINDS.values())
    assert set(kinds.MODELS) == set(registry.MUJOCO_MODELS)
    for kind in kinds.KINDS.values():
        assert kind.template().is_file(), kind.name  # its MJCF template, in the repository's mjcf/ folder
        for row in kind.variants:
            v = registry.variant(row["name"])
            assert (v.engine, v.model, v.clutch, v.rule) == ("mujoco", kind.model, row["clutch"], row["rule"])
    assert kinds.MODELS[:1] == ("slides",) and "wheels" in kinds.MODELS
    with pytest.raises(ValueError, match=f"mujoco model 'tracks' is unknown; allowed: {', '.join(kinds.MODELS)}$"):
        kinds.kind_for("tracks", RobotParams())
    assert [kind.accuracy for kind in (kinds.SLIDES, kinds.GRIP_SLIDES, kinds.WHEELS)] == ["stop", "stop", "warn"]
    assert isinstance(started_setup("mujoco-ratchet", RobotParams()).model, mujoco.MjModel)


def test_every_engine_audits_the_energy_terms_of_the_one_table():
    """Both engines' audits report each term under the table's key (core.energy), its column's change over the
    run, and a residual that closes the table's balance; a run with compliant clutches on finite grip has every
    term."""
    from ipir_mujoco.core import energy

    p = RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0, clutch_stiffness=1e5, clutch_damping=5.0)
    for variant in ("analytic-unilateral", "mujoco-ratchet"):
        run = registry.run(variant, p, 0.05, dt_out=1e-3)
        terms = energy.terms_of(run.series)
        assert terms == energy.ENERGY_TERMS, variant  # every term, in the table's order
        assert set(run.energy) == {t.audit_key for t in terms} | {energy.RESIDUAL_KEY}
        change = energy.changes(run.series)
        for term in terms:
            assert run.energy[term.audit_key] == pytest.approx(change[term], rel=1e-12, abs=1e-15), term
        total = energy.by_role(change)
        closed = total["input"] - total["dissipated"] - total["kinetic"] - total["stored"]
        # the residual is the balance of the table's roles (to the last ulps of the summed terms)
        assert run.energy[energy.RESIDUAL_KEY] == pytest.approx(closed, abs=1e-12 * abs(total["input"]))


def test_a_kind_that_leaves_out_a_required_member_fails_where_it_is_defined():
    """ModelKind is abstract: a subclass without every required member is a TypeError naming them at its
    definition (not the slide model's behaviour at its first run); a base declared abstract may leave them out,
    and neither it nor ModelKind can be made."""
    with pytest.raises(TypeError, match=r"model kind Tracks leaves out .*mjcf.*build, initial_state"):
        class Tracks(kinds.ModelKind):  # noqa: F841  (the definition is the test)
            name, model, free, variants = "tracks", "tracks", "crawls", ()

    class Half(kinds.ModelKind, abstract=True):
        name = "half"

    for base in (kinds.ModelKind, Half):
        with pytest.raises(TypeError, match="abstract"):
            base()
    # a copy of a concrete kind that overrides nothing is a kind (the slides on finite grip are one such subclass)
    assert isinstance(type("Copy", (type(kinds.SLIDES),), {"name": "copy"})(), kinds.ModelKind)


# what its params must be for each kind to take them (the first case of each kind)
KIND_PARAMS = {kind.name: params for _, params, kind, _ in reversed(CASES)}


@pytest.mark.parametrize("name", sorted(kinds.KINDS))
def test_every_kinds_model_meets_the_joint_and_body_contract(name):
    """The elements the shared run path reads by name (kinds.base.CONTRACT, docs/architecture.md "The joint and
    body contract"): each kind's built model has each, of its type; and the contract's joints are the recorder's
    and the run setup's (the crank's hinge, the rod's, each module's slide along the pipe), single-dof joints."""
    from ipir_mujoco.engine.builders.model import SolverSettings
    from ipir_mujoco.engine.kinds.base import CONTRACT

    kind = kinds.KINDS[name]
    params = KIND_PARAMS.get(name, RobotParams())
    assert kind.takes(params)
    model = kind.build(params, SolverSettings(timestep=5e-5))
    types = {"joint": mujoco.mjtObj.mjOBJ_JOINT, "body": mujoco.mjtObj.mjOBJ_BODY, "site": mujoco.mjtObj.mjOBJ_SITE,
             "equality": mujoco.mjtObj.mjOBJ_EQUALITY, "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR,
             "geom": mujoco.mjtObj.mjOBJ_GEOM}
    missing = [(what, n) for what, names in CONTRACT.items() for n in names
               if mujoco.mj_name2id(model, types[what], n) < 0]
    assert missing == []
    singles = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}
    assert all(int(model.joint(n).type[0]) in singles for n in CONTRACT["joint"])
    assert int(model.joint("rear_slide").type[0]) == int(model.joint("front_slide").type[0]) \
        == int(mujoco.mjtJoint.mjJNT_SLIDE)
    assert int(model.equality("rod_to_front").type[0]) == int(mujoco.mjtEq.mjEQ_CONNECT)
