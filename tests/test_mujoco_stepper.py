"""The compiled stepping loop gives the pure-Python loop's numbers bit for bit, and steps aside safely.

The pure-Python loop (``IPIR_MUJOCO_STEPPER=python``) is the engine as it was before the compiled loop
(the same code, moved into ``stepper.PythonSteps``); the compiled loop must reproduce it exactly: the same
double arithmetic in the same order, so every column, energy figure, accuracy record and stall is equal,
not merely close.
"""

from __future__ import annotations

import os
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams, SimulationError
from ipir_mujoco.engine import CrankServo, simulate_mujoco
from ipir_mujoco.engine.loop import native, stepper
from kind_setup import started_setup
from ipir_mujoco.engine.modelkinds import loop_rows
from ipir_mujoco.engine.run.batch import run_ratchet_batch
from ipir_mujoco.engine.clutches import Ratchet
from ipir_mujoco.engine.builders.model import (MOTOR, SolverSettings, build_model, build_spec, default_mjcf, drive_control,
                                      set_closed_loop_state)


def built() -> tuple[bool, str]:
    """Whether the compiled loop is built and checks out here (whatever IPIR_MUJOCO_STEPPER says: these
    tests choose the loop themselves)."""
    try:
        native.compiled()
    except stepper.LayoutError as exc:
        return False, str(exc)
    return True, ""


COMPILED, WHY_NOT = built()
needs_compiled = pytest.mark.skipif(not COMPILED, reason=f"no compiled loop here: {WHY_NOT}")


@pytest.fixture(autouse=True)
def default_loop(monkeypatch):
    """Each test starts with the engine's default choice of loop."""
    monkeypatch.delenv(stepper.ENV, raising=False)

# every clutch, both lock rules, the motor, gravity both ways, compliant springs with damping and play,
# a stall and a coarse run the monitor warns about (name: parameters, clutch rule, MuJoCo clutch, t_end [s], options)
DESIGNS = {
    "ratchet": (RobotParams(), "unilateral", "ratchet", 0.4, {}),
    "locks, paper's rule": (RobotParams(), "kinematic", "lock", 0.3, {}),
    "locks, unilateral": (RobotParams(), "unilateral", "lock", 0.3, {}),
    "compliant, motor, climb": (RobotParams(drive="motor", incline=20.0, clutch_stiffness=1e6, clutch_damping=300.0,
                                            clutch_backlash=5e-4), "unilateral", "ratchet", 0.3, {}),
    "motor, 30 deg climb": (RobotParams(drive="motor", incline=30.0), "unilateral", "ratchet", 0.3, {}),
    "no clutch, downhill": (RobotParams(F_r1=0.0, F_r2=0.5, incline=-10.0), "unilateral", "none", 0.2, {}),
    "stall": (RobotParams(drive="motor", M_stall=0.02), "unilateral", "ratchet", 1.0, {}),
    "coarse step, warned": (RobotParams(), "unilateral", "ratchet", 0.5,
                            {"settings": SolverSettings(timestep=5e-4), "dt_out": 5e-4, "accuracy": "warn"}),
    # finite grip: skids at the motor's cruise, a riser sliding back, a grip below the rolling resistance, none
    "grip, motor": (RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0), "unilateral", "ratchet", 0.5, {}),
    "grip, riser": (RobotParams(drive="motor", M_stall=1.0, incline=90.0, mu_wall=0.3, F_n1=20.0, F_n2=20.0),
                    "unilateral", "ratchet", 0.3, {}),
    # these two skid at every stroke, and the skid check (engine/run/skid_check.py) stops them at 'stop': they are
    # here to compare the two loops, which 'warn' does the same as 'stop' up to the check
    "grip below F_r": (RobotParams(mu_wall=0.05, F_n1=10.0, F_n2=10.0), "unilateral", "ratchet", 0.3,
                       {"accuracy": "warn"}),
    "no grip, no resistance": (RobotParams(mu_wall=0.0, F_n1=10.0, F_n2=10.0, F_r1=0.0), "unilateral", "ratchet",
                               0.3, {"accuracy": "warn"}),
    "grip, stall": (RobotParams(incline=90.0, phi0=1.5707963267948966, mu_wall=0.5, F_n1=10.0, F_n2=30.0),
                    "unilateral", "ratchet", 1.0, {}),
    "compliant grip, damped, play": (RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=300.0,
                                                 clutch_backlash=5e-4, mu_wall=0.5, F_n1=10.0, F_n2=10.0),
                                     "unilateral", "ratchet", 0.12, {}),
    "compliant grip, none, climb": (RobotParams(clutch_stiffness=1e5, mu_wall=0.0, F_n1=20.0, F_n2=20.0,
                                                incline=10.0), "unilateral", "ratchet", 0.15, {}),
    # the round pipe's hub ratchets: a straight pipe with unlimited grip; a riser on a grip that cannot carry the
    # robot (it skids back); the README's finite grip, where a wheel also leaves its wall. (A route's bends are
    # the same loop: the wall's contacts are MuJoCo's rows like any other.) The skidding ones at the automatic
    # step given (1e-4 s): the wheels' skid check would rerun each at finer steps, 7-15 times the work, in the
    # same loop
    "wheels, straight pipe": (RobotParams(drive="motor"), "unilateral", "ratchet", 0.1, {"model": "wheels"}),
    "wheels, riser skids": (RobotParams(drive="motor", mu_wall=0.18, incline=90.0), "unilateral", "ratchet", 0.1,
                            {"model": "wheels", "settings": SolverSettings(timestep=1e-4)}),
    "wheels, grip, a wheel lifts": (RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0), "unilateral",
                                    "ratchet", 0.1, {"model": "wheels", "settings": SolverSettings(timestep=1e-4)}),
}


def both_paths(monkeypatch, *args, **options):
    """The same run with the Python loop and with the compiled one (checked to have done the stepping)."""
    monkeypatch.setenv(stepper.ENV, "python")
    python = simulate_mujoco(*args, **options)
    monkeypatch.delenv(stepper.ENV)
    calls = {"compiled": 0, "python record": 0}
    compiled_record, python_record = stepper.CompiledSteps.record, stepper.PythonSteps.record

    def spy_compiled(self, *a):
        calls["compiled"] += 1
        return compiled_record(self, *a)

    def spy_python(self, *a):  # the Python record around C steps: the fallback, not wanted here
        calls["python record"] += isinstance(self, stepper.CompiledSteps)
        return python_record(self, *a)

    monkeypatch.setattr(stepper.CompiledSteps, "record", spy_compiled)
    monkeypatch.setattr(stepper.PythonSteps, "record", spy_python)
    compiled = simulate_mujoco(*args, **options)
    assert calls["compiled"] > 0 and calls["python record"] == 0, calls  # stepped and recorded in C
    return python, compiled


def timeless(value):
    """``value`` without its wall times (keys starting 'wall', as bench/fingerprint.py leaves them out): the rigid
    limit's runs record each one's, which no two runs share."""
    if isinstance(value, dict):
        return {k: timeless(v) for k, v in value.items() if not k.startswith("wall")}
    if isinstance(value, list):
        return [timeless(v) for v in value]
    return value


@needs_compiled
@pytest.mark.parametrize("name", DESIGNS)
def test_the_compiled_loop_equals_the_python_loop_bit_for_bit(monkeypatch, name):
    params, rule, implementation, t_end, options = DESIGNS[name]
    options = {"dt_out": 1e-3, **options}
    python, compiled = both_paths(monkeypatch, params, rule, implementation, t_end, **options)
    assert python.series.keys() == compiled.series.keys()
    for column, values in python.series.items():
        np.testing.assert_array_equal(compiled.series[column], values, err_msg=column)
    assert compiled.energy == python.energy and compiled.accuracy == python.accuracy
    assert compiled.stall == python.stall and timeless(compiled.settings) == timeless(python.settings)
    assert compiled.t_end == python.t_end and len(python.series["t"]) > 100
    if name in ("stall", "grip, stall"):
        assert compiled.stall is not None and compiled.t_end < 1.0
    if name == "coarse step, warned":
        assert not compiled.accuracy["ok"]  # the monitor's crossing, its time and value, alike
    if name in ("wheels, riser skids", "wheels, grip, a wheel lifts"):  # the skid branches were taken
        wheels = np.concatenate([compiled.series["wheels1"], compiled.series["wheels2"]])
        assert (wheels == -1.0).sum() > 10 and compiled.energy["skid_j"] > 1e-3
    if name == "wheels, grip, a wheel lifts":
        assert compiled.summary["wheel_off_s"] > 0.0


@needs_compiled
def test_each_compiled_controller_has_its_own_block():
    """The extension's table of controllers: one entry per name, each block's fields its own (none repeats
    another of the block or one of the loop's)."""
    module = native.compiled()
    names = [entry[0] for entry in module.CONTROLLERS]
    assert len(set(names)) == len(names) and {"ratchet", "grip_ratchet", "wheel_ratchet"} <= set(names)
    for name, config, state in module.CONTROLLERS:
        assert len(set(config)) == len(config) and len(set(state)) == len(state), name
        assert not set(config) & set(module.CONFIG) and not set(state) & set(module.STATE), name


@needs_compiled
@pytest.mark.parametrize("variant, params, implementation", [
    ("mujoco-ratchet", RobotParams(), None), ("mujoco-ratchet", RobotParams(), "none"),
    ("mujoco-ratchet", RobotParams(clutch_stiffness=1e5), None), ("mujoco-lock", RobotParams(), None),
    ("mujoco-lock-unilateral", RobotParams(), None), ("mujoco-ratchet", RobotParams(mu_wall=0.5), None),
    ("mujoco-ratchet", RobotParams(mu_wall=0.5, clutch_stiffness=1e5), None), ("mujoco-wheels", RobotParams(), None),
    ("mujoco-wheels", RobotParams(mu_wall=0.5), None)])
def test_every_controller_of_every_model_kind_steps_compiled(variant, params, implementation):
    """No model kind's controller falls back to the Python loop where the compiled one is built."""
    setup = started_setup(variant, params, implementation)
    steps, _ = setup.steps(np.empty((2, setup.model.nv)))
    assert type(steps) is stepper.CompiledSteps


@needs_compiled
def test_the_steady_state_stop_and_the_monitors_stop_are_the_same(monkeypatch):
    steady = both_paths(monkeypatch, RobotParams(drive="motor"), "unilateral", "ratchet", 4.0, dt_out=1e-3,
                        until_steady=True)
    assert steady[0].summary["steady"] and steady[0].t_end < 4.0
    np.testing.assert_array_equal(steady[1].series["t"], steady[0].series["t"])
    assert steady[1].summary["t_steady_s"] == steady[0].summary["t_steady_s"]
    messages = []
    for path in ("python", ""):
        monkeypatch.setenv(stepper.ENV, path)
        with pytest.raises(SimulationError) as failure:
            simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.5, dt_out=5e-4,
                            settings=SolverSettings(timestep=5e-4))
        messages.append(str(failure.value))
    assert messages[0] == messages[1] and "accuracy check failed at t=" in messages[0]


@needs_compiled
def test_mujocos_warning_inside_the_compiled_loop_fails_the_run_as_before(monkeypatch, tmp_path):
    """MuJoCo detects the blow-up inside the C loop (which released the GIL); its warning reaches the
    engine's handler as from the Python loop: the same one-line error, no MUJOCO_LOG.TXT."""
    monkeypatch.chdir(tmp_path)
    messages = []
    for path in ("python", ""):
        monkeypatch.setenv(stepper.ENV, path)
        with pytest.raises(SimulationError, match=r"unstable after t=\d") as failure:
            simulate_mujoco(RobotParams(M=50.0), "kinematic", "lock", 1.0, dt_out=5e-3,
                            settings=SolverSettings(timestep=5e-3), accuracy="warn")
        messages.append(str(failure.value))
    assert messages[0] == messages[1]
    assert list(tmp_path.iterdir()) == []


def loops(model, data, controller):
    """(the engine's choice of loop for this model, data and controller, the options it was given)."""
    options = loop_rows.loop_options(model, data)
    return stepper.make_steps(model, data, controller, np.zeros((2, model.nv)), **options), options


def ratcheted(params, model):
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)
    return data, Ratchet(model, data)


def starved_model(params, memory_out: list | None = None) -> mujoco.MjModel:
    """The ratcheted model with an arena too small once the two limit rows join the loop and friction rows:
    it compiles and starts (the forward passes fit) and fails within 200 ratcheted steps. The smallest such
    size depends on MuJoCo's version, so it is searched for (2.5 kB with mujoco 4.0). ``memory_out``
    receives that size [bytes]."""
    def compiled(memory):
        spec = build_spec(params, SolverSettings(), ratchet=True)
        spec.memory = memory
        return spec.compile()

    for memory in range(2000, 8000, 100):  # bytes
        try:
            model = compiled(memory)
            data, ratchet = ratcheted(params, model)
        except (ValueError, mujoco.FatalError):
            continue  # too small even for the forward pass at the start
        try:
            for _ in range(200):
                ratchet.before_step()
                mujoco.mj_step(model, data)
        except mujoco.FatalError:
            if memory_out is not None:
                memory_out.append(memory)
            return compiled(memory)  # afresh: the ratchet has raised this one's bounds
    pytest.skip("no arena size starves only the ratcheted steps with this MuJoCo")


@needs_compiled
def test_a_mujoco_error_inside_the_compiled_loop_is_the_bindings_error():
    """Too little arena memory for the ratchet's extra constraint rows: MuJoCo's fatal error inside mj_step
    becomes mujoco.FatalError with MuJoCo's message, as the bindings raise it, and the legacy error handler
    the loop borrowed is given back."""
    params = RobotParams()
    errors = []
    for path in ("python", "compiled"):
        model = starved_model(params)
        data, ratchet = ratcheted(params, model)
        steps, options = loops(model, data, ratchet)
        if path == "python":
            steps = stepper.PythonSteps(model, data, ratchet, steps.qvel_before, **options)
        assert steps.compiled == (path == "compiled")
        with pytest.raises(mujoco.FatalError, match="out of memory") as failure:
            steps.run(200)
        errors.append(str(failure.value))
    assert errors[0] == errors[1] and errors[0].startswith("mj_stackAlloc")
    assert native.compiled().handlers()[0] is False  # mju_user_error, as the library has it


@needs_compiled
def test_what_does_not_check_out_steps_in_python(monkeypatch):
    """An MjData._address that is not that MjData's mjData, a crank servo or the environment variable: the
    Python loop."""
    params = RobotParams()
    model = build_model(params, SolverSettings(), ratchet=True)
    data, ratchet = ratcheted(params, model)
    assert loops(model, data, ratchet)[0].compiled
    other = mujoco.MjData(model)  # a live mjData of the same model, not this one
    with monkeypatch.context() as patch:
        patch.setattr(mujoco.MjData, "_address", property(lambda self, other=other._address: other))
        with pytest.raises(stepper.LayoutError, match=r"MjData._address do not check out: read \("):
            stepper.CompiledSteps(model, data, ratchet, np.zeros((2, model.nv)), **loop_rows.loop_options(model, data))
        assert not loops(model, data, ratchet)[0].compiled
    servo = CrankServo(lambda t: 10.0 * t, lambda t: 10.0)
    assert type(stepper.make_steps(model, data, ratchet, np.zeros((2, model.nv)), servo=servo,
                                   **loops(model, data, ratchet)[1])) is stepper.PythonSteps
    monkeypatch.setenv(stepper.ENV, "python")
    assert not loops(model, data, ratchet)[0].compiled
    assert stepper.compiled_status() == (False, f"{stepper.ENV}=python is set")


def test_a_built_stepper_is_used_with_this_mujoco():
    """Where the extension was built (a C compiler at install), it was built against this mujoco's headers,
    calls the bindings' libmujoco and serial runs step in C: this fails when the installed extension no longer
    fits the running mujoco."""
    import importlib.util

    if importlib.util.find_spec(native.EXTENSION) is None:
        pytest.skip("the compiled stepper is not built here (installed without a C compiler)")
    assert stepper.compiled_status() == (True, "compiled")
    assert native.compiled().MJVERSION_HEADER == mujoco.mj_version()
    params = RobotParams()
    model = build_model(params, SolverSettings(), ratchet=True)
    data, ratchet = ratcheted(params, model)
    assert type(loops(model, data, ratchet)[0]) is stepper.CompiledSteps


@needs_compiled
def test_the_bindings_addresses_are_their_mjmodel_and_mjdata():
    """The one private attribute the loop relies on (the bindings give no public way to their mjModel and
    mjData): ``_address``, read by the C module through MuJoCo's headers, gives the sizes, timestep, time
    and array pointers the bindings report, before and after steps. Fails if a mujoco release changes it."""
    params = RobotParams()
    model = build_model(params, SolverSettings(), ratchet=True)
    data, _ = ratcheted(params, model)
    assert native.pointers(native.compiled(), model, data) == (model._address, data._address)
    mujoco.mj_step(model, data, 10)
    assert native.pointers(native.compiled(), model, data) == (model._address, data._address)


@pytest.fixture
def fresh_check():
    """The compiled stepper's once-per-process check made again in the test, and again after it."""
    native._compiled_cached.cache_clear()
    yield
    native._compiled_cached.cache_clear()


@needs_compiled
def test_a_mujoco_of_another_version_is_refused_in_one_line(monkeypatch, fresh_check):
    """A running mujoco whose version is not the headers' the extension was built against (simulated: the
    bindings report another version): the compiled stepper is not used, one line says why, runs step in
    Python."""
    header = native.compiled().MJVERSION_HEADER
    native._compiled_cached.cache_clear()
    monkeypatch.setattr(mujoco, "mj_version", lambda: header + 1)
    compiled, why = stepper.compiled_status()
    assert not compiled and "\n" not in why
    assert why.startswith(f"the compiled stepper was built against MuJoCo's headers of version {header}, the "
                          f"running mujoco {mujoco.__version__} is version {header + 1}: reinstall ipir-mujoco")
    params = RobotParams()
    model = build_model(params, SolverSettings(), ratchet=True)
    data, ratchet = ratcheted(params, model)
    assert type(loops(model, data, ratchet)[0]) is stepper.PythonSteps


@needs_compiled
@pytest.mark.parametrize("failure, line", [
    (ImportError("libmujoco.so.3.9.0: cannot open shared object file: No such file or directory"),
     "the compiled stepper cannot be loaded with mujoco {} (libmujoco.so.3.9.0: cannot open shared object file: "
     "No such file or directory): reinstall ipir-mujoco with pip's --no-build-isolation to build it against the "
     "running mujoco"),
    (None, "the compiled stepper's libmujoco is not the one mujoco {} loaded: reinstall ipir-mujoco"),
])
def test_a_libmujoco_that_cannot_be_loaded_or_is_another_is_refused_in_one_line(monkeypatch, fresh_check, failure,
                                                                                line):
    """The extension cannot load its libmujoco (built against a mujoco that is not installed: simulated), or
    loads another instance than the bindings' (simulated: it never sees the bindings' warning handler):
    not used, in one line."""
    module = native.compiled()
    native._compiled_cached.cache_clear()
    if failure is not None:
        def load(name):
            raise failure
        monkeypatch.setattr(native.importlib, "import_module", load)
    else:
        monkeypatch.setattr(module, "handlers", lambda: (False, False))
    compiled, why = stepper.compiled_status()
    assert not compiled and "\n" not in why and why.startswith(line.format(mujoco.__version__))


RUN = (  # a short run in a fresh process: which loops recorded, the one line, every column saved to NAME
    "import numpy as np\n"
    "from ipir_mujoco.analytic import RobotParams\n"
    "from ipir_mujoco.engine import simulate_mujoco\nfrom ipir_mujoco.engine.loop import stepper\n"
    "used, python_record = set(), stepper.PythonSteps.record\n"
    "stepper.PythonSteps.record = lambda self, *a: used.add(type(self).__name__) or python_record(self, *a)\n"
    "run = simulate_mujoco(RobotParams(), 'unilateral', 'ratchet', 0.05, dt_out=1e-3)\n"
    "np.save(NAME, np.column_stack([run.series[k] for k in sorted(run.series)]))\n"
    "print(stepper.compiled_status()[1]); print(sorted(used))\n")


@needs_compiled
def test_the_fallback_runs_the_python_loop_with_no_traceback(tmp_path):
    """In a fresh process whose mujoco reports another version (simulated before the package is imported):
    simulate_mujoco steps in Python, gives the numbers of the Python loop IPIR_MUJOCO_STEPPER=python selects,
    and nothing reaches stderr."""
    mismatched = "import mujoco\nheader = mujoco.mj_version()\nmujoco.mj_version = lambda: header + 1\n"
    done = subprocess.run([sys.executable, "-c", mismatched + RUN.replace("NAME", "'run.npy'")], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    line, used = done.stdout.splitlines()
    assert line.startswith("the compiled stepper was built against MuJoCo's headers") and used == "['PythonSteps']"
    subprocess.run([sys.executable, "-c", RUN.replace("NAME", "'reference.npy'")], cwd=tmp_path, check=True,
                   env={**os.environ, stepper.ENV: "python"}, capture_output=True)
    np.testing.assert_array_equal(np.load(tmp_path / "run.npy"), np.load(tmp_path / "reference.npy"))


def edited_template(old: str, new: str) -> str:
    """The shipped MJCF's text with its one ``old`` replaced by ``new``."""
    text = default_mjcf().read_text()
    assert text.count(old) == 1
    return text.replace(old, new)


def test_a_mujoco_error_ends_the_run_with_one_line(monkeypatch, tmp_path):
    """MuJoCo's fatal error inside a step (the arena too small for the ratchet's rows) ends simulate_mujoco
    with a SimulationError naming the last good time and MuJoCo's reason, from either loop: no traceback."""
    memory = []
    starved_model(RobotParams(), memory)
    path = tmp_path / "starved.xml"
    path.write_text(edited_template('<compiler ', f'<size memory="{memory[0]}"/>\n  <compiler '))
    messages = []
    for loop in ("python", ""):
        monkeypatch.setenv(stepper.ENV, loop)
        with pytest.raises(SimulationError, match=r"^MuJoCo failed after t=[0-9.e-]+ s: mj_stackAlloc.*memory") as e:
            simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.1, dt_out=1e-3, settings=SolverSettings(),
                            mjcf=path)
        messages.append(str(e.value))
    assert messages[0] == messages[1] and "\n" not in messages[0]


def test_a_mujoco_error_fails_only_that_batched_design(monkeypatch, tmp_path):
    """The same starved arena in a batch: mujoco.batch raises for the designs whose ratchet rows do not fit,
    and each of those ends as the serial engine's one-line error for the same model, word for word; a design
    that needs no ratchet rows (no drive torque: it never moves) runs to the end in the same batch."""
    from ipir_mujoco.engine.builders import model as builder

    memory = []
    starved_model(RobotParams(), memory)
    path = tmp_path / "starved.xml"
    path.write_text(edited_template('<compiler ', f'<size memory="{memory[0]}"/>\n  <compiler '))
    build = builder.build_model  # the slide kind's builder, which the batch builds every design with
    monkeypatch.setattr(builder, "build_model", lambda params, settings, mjcf=None, ratchet=False, decorate=None:
                        build(params, settings, path, ratchet, decorate))
    designs = [RobotParams(), RobotParams(M=0.1), RobotParams(M=0.0)]
    outcomes = run_ratchet_batch(designs, 0.1, dt_out=1e-3, settings=SolverSettings(), nthread=1)
    for params, outcome in zip(designs[:2], outcomes):
        with pytest.raises(SimulationError) as serial:
            simulate_mujoco(params, "unilateral", "ratchet", 0.1, dt_out=1e-3, settings=SolverSettings(), mjcf=path)
        assert outcome["error"] == str(serial.value) and "\n" not in outcome["error"]
        assert outcome["error"].startswith("MuJoCo failed after t=") and "memory" in outcome["error"]
    assert "error" not in outcomes[2] and outcomes[2]["series"]["t"][-1] == pytest.approx(0.1)


@pytest.mark.parametrize("flag, controller", [("mjDSBL_FRICTIONLOSS", "ratchet"), ("mjDSBL_EQUALITY", "lock")])
def test_rows_the_loop_reads_are_checked_after_every_step(flag, controller):
    """A step after which the rows the loop reads are absent (the friction rows, a held lock's equality row;
    here disabled in the model's options between two calls) is a one-line SimulationError from both loops,
    never a read of another row or past the end."""
    from ipir_mujoco.engine.clutches import Locks

    params, messages = RobotParams(), []
    for path in ("python", "compiled"):
        if controller == "ratchet":
            model = build_model(params, SolverSettings(), ratchet=True)
            data, ctl = ratcheted(params, model)
        else:
            model = build_model(params, SolverSettings())
            data = mujoco.MjData(model)
            set_closed_loop_state(model, data, params)
            data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
            ctl = Locks(model, data, "unilateral", params.r, params.L)
            mujoco.mj_forward(model, data)
        steps, options = loops(model, data, ctl)
        if path == "python":
            steps = stepper.PythonSteps(model, data, ctl, steps.qvel_before, **options)
        assert steps.compiled == (path == "compiled" and COMPILED)
        steps.run(10)
        model.opt.disableflags |= int(getattr(mujoco.mjtDisableBit, flag))
        with pytest.raises(SimulationError, match=r"^MuJoCo's step to t=0.0011 s produced no") as failure:
            steps.run(5)
        messages.append(str(failure.value))
    assert messages[0] == messages[1]


def test_friction_off_the_slides_is_refused(tmp_path):
    """The loop counts the work against the resistances on the two slides only: frictionloss on another
    joint of a given MJCF is refused up front, not silently left out of the energy audit."""
    from ipir_mujoco.analytic import ParameterError

    path = tmp_path / "crank_friction.xml"
    path.write_text(edited_template('<joint name="crank_hinge" class="linkage"/>',
                                    '<joint name="crank_hinge" class="linkage" frictionloss="0.01"/>'))
    with pytest.raises(ParameterError, match=r"^frictionloss on 'crank_hinge' in the MJCF model: .* allowed: "):
        simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.01, mjcf=path)


@pytest.mark.parametrize("name", ["ratchet", "locks, paper's rule", "stall", "grip, stall",
                                  "compliant grip, damped, play"])
def test_a_run_stepped_in_parts_of_a_block_is_the_same_run(monkeypatch, name):
    """A block whose steps take long is stepped in parts, its progress reported between them (so that a slow run's
    status line moves every second): the parts change nothing. Every part one sample (the finest split; how it is
    split depends on the machine's speed) gives the block-at-once run's numbers bit for bit, its stall included,
    and calls the progress between the parts (PROGRESS_WALL_S at 0: at every sample) but never past t_end."""
    from ipir_mujoco.engine.run import block_checks
    from ipir_mujoco.engine.run import simulate as run_module

    params, rule, implementation, t_end, options = DESIGNS[name]
    options = {"dt_out": 1e-3, **options}
    whole = simulate_mujoco(params, rule, implementation, t_end, **options)
    monkeypatch.setattr(run_module, "chunk_after", lambda chunk, block, recorded, wall: 1)
    monkeypatch.setattr(block_checks, "PROGRESS_WALL_S", 0.0)
    said = []
    parts = simulate_mujoco(params, rule, implementation, t_end, progress=said.append, **options)
    for column, values in whole.series.items():
        np.testing.assert_array_equal(parts.series[column], values, err_msg=column)
    assert parts.energy == whole.energy and parts.accuracy == whole.accuracy and parts.stall == whole.stall
    # a report per sample of the run after its first block (stepped whole: no rate measured yet; 50 samples at
    # dt_out 1 ms), in order
    assert len(said) >= len(whole.series["t"]) - 51 and said == sorted(said) and said[-1] <= whole.t_end
