"""The stepping loop of a serial MuJoCo run: compiled (C) where it can be, the same loop in Python otherwise.

Between two output samples a run takes k steps, and each step the engine
updates the clutches before ``mj_step`` (the model kind's clutch controller,
:mod:`.controller`), does the clutches' bookkeeping after it and adds the drive's
work and the work against the resistances and, where the model has any, against
skidding (the work rates ``power(v)`` the model kind gives the loop: its rows'
forces times their speeds); then it records the sample (:mod:`.recorder`). It
holds no test on which model kind or controller runs.
:class:`PythonSteps` is that loop in Python: :meth:`PythonSteps.record` takes a
block of output intervals and records each. :class:`CompiledSteps` hands the
block to ``_stepper.c`` (a C extension built at install time), which calls the
library's own ``mj_step``, does the same double arithmetic in the same order
and writes the samples (state, torque, works, clutch reactions, the loop's
force, the excursion, and MuJoCo's energies, loop gap and momentum at each
sample) into the recorder's arrays, so both give the same numbers bit for bit
(``tests/test_mujoco_stepper.py``); it syncs the clutch controller's state
back after each call. Between blocks (every BLOCK_TIME of simulated
time) everything else stays in Python: the accuracy monitor (fed from the
block's arrays), progress, budgets, steady state and stalls.

Why a loop in C rather than MuJoCo's control callback: ``mjcb_control`` runs
after the constraint rows are assembled, so a ratchet bound written there acts
a step late, and the friction rows' forces of a step are gone by the next
callback; the loop keeps today's order exactly (``mjcf/README.md`` has the
measurements). The C code is built against MuJoCo's headers and checked
against the running mujoco by :mod:`.native`. Anything that does not check out
there, a crank servo (a Python function of time) or ``IPIR_MUJOCO_STEPPER=python``
in the environment selects :class:`PythonSteps`; :func:`compiled_status` says
which and why, in one line.
"""

from __future__ import annotations

import os
from operator import itemgetter

import mujoco
import numpy as np

from .native import LayoutError, compiled, pointers
from .native import address as array_address
from .recorder import Recorder
from .rows import EQUALITY_ROWS, missing_rows

ENV = "IPIR_MUJOCO_STEPPER"  # 'python' forces the pure-Python loop
DONE, WARNED = 0, 3  # what record() returns: all intervals taken, or MuJoCo warned in the last one (_stepper.c's)


class PythonSteps:
    """k steps of the run's loop in Python (the reference: :class:`CompiledSteps` must equal it).

    ``qvel_before`` (n_samples, nv): the recorder's array; before the last step of a call to
    :meth:`run` the velocities are copied into the row it names. ``torque`` [N m]: the drive's torque
    from the initial ``mj_forward``. ``power(v)``: the work rates after a step, ``v`` the velocities as a
    list: (the resistances' rows' force times their speed, the rows' against skidding: a finite grip's, the
    wheels' contacts') [W] (the model kind's, :meth:`ipir_mujoco.engine.kinds.base.ModelKind.loop_options`).
    ``friction_dofs``: the dofs with friction whose rows follow the equality rows (the slides'; none where
    ``power`` reads other rows), which the compiled loop and the slide controllers read. After each call:
    ``torque`` (over the last step) [N m], cumulative ``motor_work``, ``friction_work`` and ``skid_work`` [J].
    """

    compiled = False

    def __init__(self, model, data, controller, qvel_before, *, motor, crank_q, crank_v, slope, friction_dofs,
                 torque, power, servo=None):
        self.model, self.data, self.controller, self.qvel_before = model, data, controller, qvel_before
        self.motor, self.crank_q, self.crank_v, self.slope = motor, crank_q, crank_v, slope
        self.friction_dofs, self.servo = list(friction_dofs), servo
        self.fric_a, self.fric_b = (self.friction_dofs + [0, 0])[:2]  # the slides' dofs (0: no row)
        self.torque, self.motor_work, self.friction_work = torque, 0.0, 0.0
        self.omega_prev = data.qvel.item(crank_v)
        self.skid_work = 0.0  # the cumulative work against skidding [J] (a finite grip's, the wheels' contacts')
        self.power = power

    def run(self, nstep: int, row: int = -1) -> None:
        """``nstep`` steps; the velocities before the last one go to ``qvel_before[row]`` (row >= 0).

        The inner loop works on Python floats (one ``tolist`` per array read). The work against the
        resistances (and against skidding) is the rows' force times the speed they act at after the step
        (``power``)."""
        m, d, ctl = self.model, self.data, self.controller
        dt, qvel, qpos, ctrl = m.opt.timestep, d.qvel, d.qpos, d.ctrl
        step, before, after, servo = mujoco.mj_step, ctl.before_step, ctl.after_step, self.servo
        motor, cq, cv, slope = self.motor, self.crank_q, self.crank_v, self.slope
        power = self.power
        torque, wm, wf, ws = self.torque, self.motor_work, self.friction_work, self.skid_work
        omega_prev = self.omega_prev
        for j in range(nstep):
            if servo is not None:
                ctrl[motor] = servo.torque(d.time, qpos[cq], qvel[cv])
            before()
            if j == nstep - 1 and row >= 0:
                self.qvel_before[row] = qvel
            step(m, d)
            after()
            v = qvel.tolist()
            omega = v[cv]
            torque = d.actuator_force.item(motor) + slope * (omega - omega_prev)
            wm += torque * omega * dt
            rolling, skidding = power(v)
            wf -= rolling * dt
            ws -= skidding * dt
            omega_prev = omega
        self.torque, self.motor_work, self.friction_work, self.omega_prev = torque, wm, wf, omega_prev
        self.skid_work = ws

    def record(self, rec: Recorder, nsamples: int, sps: int, remaining: int, pending: int,
               messages: list[str]) -> tuple[int, int]:
        """Up to ``nsamples`` output intervals of ``sps`` steps each (the last one cut at ``remaining``
        steps), each recorded as a sample of ``rec``; an interval's first step is where MuJoCo computes the
        previous sample's deferred values (``pending``: its row, -1 for none), so they are filled after it.
        Stops, without recording it, after an interval in which MuJoCo warned (``messages`` grew). Returns
        (DONE or WARNED, steps taken)."""
        ctl, warned, taken = self.controller, len(messages), 0
        for _ in range(nsamples):
            if remaining <= 0:
                break
            k = min(sps, remaining)
            if pending >= 0:
                self.run(1, rec.count if k == 1 else -1)
                rec.fill_deferred(pending)
                if k > 1:
                    self.run(k - 1, rec.count)
            else:
                self.run(k, rec.count)
            remaining -= k
            taken += k
            if len(messages) != warned:  # the state may be MuJoCo's reset: nothing to record
                return WARNED, taken
            pending = rec.sample(self.torque, self.motor_work, self.friction_work, ctl.sampled_reactions(),
                                 ctl.damper_work, ctl.excursion, self.skid_work, ctl.wheels())
        return DONE, taken


class CompiledSteps(PythonSteps):
    """The same loop in C (``_stepper.c``); same constructor and attributes as :class:`PythonSteps`.

    Its two arrays (CONFIG: int64 indices and addresses, STATE: doubles) hold the loop's block and then the
    clutch controller's own block, which the controller lays out itself (``load_compiled``: :meth:`use` its
    compiled kind, then :meth:`set_config`, :meth:`set_state` by its fields' names). The controller's state is
    copied in at construction and back after every :meth:`run`, so the controller reports (``reactions``,
    ``excursion``, the compliant clutches' overlaps and dissipation) as after the Python loop. Raises
    :class:`LayoutError` if what the C code relies on does not check out for this model and data.
    """

    compiled = True

    def __init__(self, model, data, controller, qvel_before, **options):
        if options.get("servo") is not None:
            raise LayoutError("a crank servo is a Python function of time")
        super().__init__(model, data, controller, qvel_before, **options)
        stepper = compiled()
        model_address, data_address = pointers(stepper, model, data)
        self._module = stepper
        self._cfg = np.zeros(len(stepper.CONFIG), dtype=np.int64)
        self._st = np.zeros(len(stepper.STATE))
        self.C = {name: i for i, name in enumerate(stepper.CONFIG)}
        self.S = {name: i for i, name in enumerate(stepper.STATE)}
        if not (qvel_before.flags.c_contiguous and qvel_before.dtype == np.float64
                and qvel_before.shape[1:] == (model.nv,)):
            raise LayoutError("qvel_before must be a C-contiguous float64 array of rows of nv")
        self._set_config(
            model=model_address, data=data_address, qvel_before=array_address(qvel_before), motor=self.motor,
            crank_q=self.crank_q, crank_v=self.crank_v, nfric=len(self.friction_dofs), fric_a=self.fric_a,
            fric_b=self.fric_b)
        self._eq_rows = np.array([EQUALITY_ROWS.get(int(t), 1) for t in model.eq_type], dtype=np.int64)
        self._cfg[self.C["eq_rows"]] = array_address(self._eq_rows) if self._eq_rows.size else 0
        self._set_state(dt=model.opt.timestep, slope=self.slope, torque=self.torque,
                        motor_work=0.0, friction_work=0.0, omega_prev=self.omega_prev)
        self._load_controller()
        self._args = (array_address(self._cfg), array_address(self._st))
        self._common = itemgetter(*(self.S[n] for n in ("torque", "motor_work", "friction_work", "omega_prev",
                                                         "skid_work")))

    def run(self, nstep: int, row: int = -1) -> None:
        if row >= len(self.qvel_before):
            raise IndexError(f"row {row} is out of bounds for qvel_before of {len(self.qvel_before)} rows")
        try:
            self._module.run(*self._args, nstep, row)
        except RuntimeError as exc:  # MuJoCo's error, raised as the bindings raise it
            raise mujoco.FatalError(str(exc)) from None
        except LookupError as exc:  # rows the loop reads are absent: the Python loop's error
            raise missing_rows(exc.args[0], self.data.time) from None
        state = self._st.tolist()
        self.torque, self.motor_work, self.friction_work, self.omega_prev, self.skid_work = self._common(state)
        self._sync(state)

    def record(self, rec: Recorder, nsamples: int, sps: int, remaining: int, pending: int,
               messages: list[str]) -> tuple[int, int]:
        if rec is not self._rec:
            self._bind(rec)
        st, S = self._st, self.S
        st[S["count"]], st[S["steps_done"]] = rec.count, 0.0
        try:
            status = self._module.record(*self._args, nsamples, sps, remaining, pending)
        except RuntimeError as exc:
            raise mujoco.FatalError(str(exc)) from None
        except LookupError as exc:
            raise missing_rows(exc.args[0], self.data.time) from None
        finally:
            rec.count = int(st[S["count"]])
        state = st.tolist()
        self.torque, self.motor_work, self.friction_work, self.omega_prev, self.skid_work = self._common(state)
        self._sync(state)
        return status, int(state[S["steps_done"]])

    def _bind(self, rec: Recorder) -> None:
        """Where the C loop writes ``rec``'s samples (its arrays: C-contiguous float64, qvel_before the
        loop's own) and what it reads for them (the rod end's site, the front module's body, the loop)."""
        self._set_config(
            rod_site=rec.site, front_body=rec.front, loop_eq=rec.loop_id, rec_t=array_address(rec.t),
            rec_qpos=array_address(rec.qpos), rec_qvel=array_address(rec.qvel),
            rec_scalars=array_address(rec.scalars), rec_deferred=array_address(rec.deferred),
            rec_excursion=array_address(rec.excursion))
        ox, oy, oz = rec.pin_offset
        self._set_state(pin_x=ox, pin_y=oy, pin_z=oz, total_mass=rec.total_mass)
        self._rec = rec

    def use(self, kind: str) -> None:
        """Append the block of the compiled controller ``kind`` (a name in ``_stepper.CONTROLLERS``) to the
        arrays; its fields are then set by name. Called once, by the controller's ``load_compiled``."""
        table = {entry[0]: (index, *entry[1:]) for index, entry in enumerate(self._module.CONTROLLERS)}
        if kind not in table or self._kind is not None:
            raise LayoutError(f"no compiled controller {kind!r}, or a second one")
        index, config, state = table[kind]
        clash = (set(config) & set(self.C)) | (set(state) & set(self.S))
        if clash:
            raise LayoutError(f"the compiled controller {kind!r} repeats the loop's fields {sorted(clash)}")
        self._cfg = np.concatenate([self._cfg, np.zeros(len(config), dtype=np.int64)])
        self._st = np.concatenate([self._st, np.zeros(len(state))])
        self.C.update({name: len(self.C) + i for i, name in enumerate(config)})
        self.S.update({name: len(self.S) + i for i, name in enumerate(state)})
        self._kind = kind
        self._set_config(controller=index)

    def keep(self, *objects) -> None:
        """Keep ``objects`` (arrays whose addresses a controller wrote into its block) alive as long as the loop."""
        self._kept.extend(objects)

    def _set_config(self, **values) -> None:
        for name, value in values.items():
            self._cfg[self.C[name]] = int(value)

    def _set_state(self, **values) -> None:
        for name, value in values.items():
            self._st[self.S[name]] = float(value)

    def _load_controller(self) -> None:
        """The controller's block, written by the controller itself (``load_compiled(loop)``: :meth:`use`, then
        its fields, after checking that the loop's work rates ``power`` are the ones its compiled form counts),
        which returns its sync (reading its state back from a list of the state's values)."""
        ctl = self.controller
        self._kind, self._rec, self._kept = None, None, []
        self._sync = ctl.load_compiled(self)
        if self._kind is None:
            raise LayoutError(f"{type(ctl).__name__}.load_compiled chose no compiled controller")

    def getter(self, *names):
        """A function reading the STATE fields ``names`` from a list of the state's values, in that order."""
        return itemgetter(*(self.S[n] for n in names))

    set_config = property(lambda self: self._set_config)
    set_state = property(lambda self: self._set_state)


def make_steps(model, data, controller, qvel_before, **options) -> PythonSteps:
    """The compiled loop if it is available and checks out for this run, else the Python loop."""
    if os.environ.get(ENV, "").strip().lower() != "python":
        try:
            return CompiledSteps(model, data, controller, qvel_before, **options)
        except LayoutError:
            pass
    return PythonSteps(model, data, controller, qvel_before, **options)


def compiled_status() -> tuple[bool, str]:
    """(whether serial runs step in C, why not if they do not); a run with a crank servo always steps in
    Python."""
    if os.environ.get(ENV, "").strip().lower() == "python":
        return False, f"{ENV}=python is set"
    try:
        compiled()
    except LayoutError as exc:
        return False, str(exc)
    return True, "compiled"


