/* The per-step loop of a serial MuJoCo run, compiled, and its sampling: see ipir_mujoco/engine/loop/stepper.py.
 *
 * It does, step for step, what the pure-Python loop (stepper.PythonSteps, the clutch controllers and the recorder
 * in recorder.py) does: the clutch update before each mj_step, the clutch bookkeeping after it, the drive's work
 * and the work against the resistances (and the grips' against skidding), and at each output sample the record
 * (state, torque, works, clutch reactions, the loop's force, the excursion, and MuJoCo's energies, loop gap and
 * momentum at the start of the next step); the same double arithmetic in the same order (built with
 * -ffp-contract=off, so no fused multiply-add changes a rounding), so the two paths agree bit for bit. It is
 * compiled against the headers of the installed mujoco and linked against its libmujoco (setup.py), and reads
 * mjModel and mjData through their structs; the module records the header's version (MJVERSION_HEADER), which
 * native.py checks against the running library before any use, with the library instance (handlers()) and the
 * mjModel and mjData behind the bindings' objects (check()).
 *
 * What belongs to a clutch controller (its update, bookkeeping, work rates, reactions, deferred forces) is its
 * table entry's (_stepper.h; controllers/_clutch_table.c, each controller's block and functions in its family's
 * file there); this file is the loop, the sample and the module. The field names are exported (the loop's CONFIG and STATE, each
 * controller's in CONTROLLERS), so stepper.py builds its indices from them, as are the names of the recorder's
 * SCALARS and DEFERRED columns, which native.py checks against recorder.py's. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "_stepper.h"

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* what record() writes per sample: one row of each (Recorder's scalars and deferred arrays, in this order) */
#define SCALAR_FIELDS(X)                                                                          \
  X(motor_torque) X(loop_fx) X(loop_fy) X(loop_fz) X(held1) X(held2) X(lambda1) X(lambda2)         \
  X(motor_work) X(friction_work) X(clutch_damper_work) X(skid_work) X(wheels1) X(wheels2)
#define DEFERRED_FIELDS(X)                                                                        \
  X(kinetic) X(potential) X(loop_gap) X(momentum) X(clutch_force1) X(clutch_force2)               \
  X(clutch_overlap1) X(clutch_overlap2) X(clutch_spring)

#define AS_ENUM(name) R_##name,
enum { SCALAR_FIELDS(AS_ENUM) N_SCALARS };
#undef AS_ENUM
#define AS_ENUM(name) D_##name,
enum { DEFERRED_FIELDS(AS_ENUM) N_DEFERRED };
#undef AS_ENUM
_Static_assert((int)D_clutch_force1 == (int)DEFERRED_CLUTCH, "a controller's deferred part starts at clutch_force1");
_Static_assert((int)N_DEFERRED == (int)DEFERRED_CLUTCH + (int)DEFERRED_VALUES, "a controller's deferred part ends the row");

/* what record() returns besides STEPS_DONE: MuJoCo raised a warning in the last sample's interval */
enum { RECORD_WARNED = 3 };

typedef void (*error_fn)(const char *msg);

/* the recorder's and the loop's arrays are numpy float64, MuJoCo's arrays are read as such */
_Static_assert(sizeof(mjtNum) == sizeof(double), "MuJoCo built with single-precision mjtNum");

#define CONTROLLER(cfg) (CONTROLLERS[(cfg)[C_controller]])

/* A MuJoCo error inside mj_step: MuJoCo's legacy error handler, borrowed while loops run (installed by
 * the first to start, given back by the last to end: both under the GIL), jumps back into the loop of
 * the thread that raised it, as the bindings' own handler does for their calls. */
static _Thread_local jmp_buf *error_jump = NULL;
static _Thread_local char error_text[1024];
static error_fn previous_error = NULL;
static int loops_running = 0;

static void on_mujoco_error(const char *msg) {
  if (error_jump != NULL) {
    snprintf(error_text, sizeof(error_text), "%s", msg);
    longjmp(*error_jump, 1);
  }
  if (previous_error != NULL) {
    previous_error(msg);
  } else { /* not inside a loop of ours: MuJoCo's default, the message and exit */
    fprintf(stderr, "ERROR: %s\n", msg);
    exit(EXIT_FAILURE);
  }
}

/* nstep steps; before the last one the velocities are copied into ``dest`` (if not NULL). Returns
 * STEPS_DONE, or the MISSING_* code of the rows a step did not produce (the state is then not written back) */
static int steps(const int64_t *cfg, double *st, long long nstep, double *dest) {
  const mjModel *m = MODEL(cfg);
  mjData *d = DATA(cfg);
  const Controller *ctl = CONTROLLER(cfg);
  const mjtNum *qvel = d->qvel, *force = d->actuator_force;
  const int64_t motor = cfg[C_motor], crank_v = cfg[C_crank_v];
  const double dt = st[S_dt], slope = st[S_slope];
  double torque = st[S_torque], wm = st[S_motor_work], wf = st[S_friction_work], omega_prev = st[S_omega_prev];
  double ws = st[S_skid_work];
  for (long long n = 0; n < nstep; n++) {
    ctl->before_step(cfg, st);
    if (n == nstep - 1 && dest != NULL) memcpy(dest, qvel, (size_t)m->nv * sizeof(mjtNum));
    mj_step(m, d);
    int status = ctl->after_step(cfg, st);
    if (status != STEPS_DONE) return status;
    double omega = qvel[crank_v];
    torque = force[motor] + slope * (omega - omega_prev);
    wm += torque * omega * dt;
    double rolling, skidding; /* the loop's work rates (PythonSteps' power): the resistances', against skidding */
    if ((status = ctl->work(cfg, st, &rolling, &skidding)) != STEPS_DONE) return status;
    wf -= rolling * dt;
    ws -= skidding * dt;
    omega_prev = omega;
  }
  st[S_torque] = torque;
  st[S_motor_work] = wm;
  st[S_friction_work] = wf;
  st[S_omega_prev] = omega_prev;
  st[S_skid_work] = ws;
  return STEPS_DONE;
}

/* Recorder.sample: the state after the last step as row ``row`` */
static int sample(const int64_t *cfg, const double *st, int64_t row) {
  const int64_t nq = MODEL(cfg)->nq, nv = MODEL(cfg)->nv;
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne;
  double held[N_REACTIONS];
  int status = CONTROLLER(cfg)->reactions(cfg, st, held);
  if (status != STEPS_DONE) return status;
  PTR(double *, rec_t)[row] = d->time;
  memcpy(PTR(double *, rec_qpos) + row * nq, d->qpos, (size_t)nq * sizeof(mjtNum));
  memcpy(PTR(double *, rec_qvel) + row * nv, d->qvel, (size_t)nv * sizeof(mjtNum));
  double *out = PTR(double *, rec_scalars) + row * N_SCALARS;
  int64_t loop = equality_row(cfg, cfg[C_loop_eq]);
  out[R_motor_torque] = st[S_torque];
  out[R_loop_fx] = ne >= loop + 3 ? efc_force[loop] : 0.0;
  out[R_loop_fy] = ne >= loop + 3 ? efc_force[loop + 1] : 0.0;
  out[R_loop_fz] = ne >= loop + 3 ? efc_force[loop + 2] : 0.0;
  out[R_held1] = held[0];
  out[R_held2] = held[1];
  out[R_lambda1] = held[2];
  out[R_lambda2] = held[3];
  out[R_motor_work] = st[S_motor_work];
  out[R_friction_work] = st[S_friction_work];
  out[R_clutch_damper_work] = st[S_damper_work]; /* 0 but for the compliant clutches' dampers */
  out[R_skid_work] = st[S_skid_work];            /* 0 but with finite grip */
  out[R_wheels1] = held[4];
  out[R_wheels2] = held[5];
  PTR(double *, rec_excursion)[row] = st[S_excursion];
  return STEPS_DONE;
}

/* Recorder.fill_deferred: MuJoCo's values at the start of the step just taken and the controller's deferred values
 * (ClutchController.deferred_values: the compliant clutches' forces, the overlaps their before_step set for that
 * state and CompliantClutches.stepped_spring_energy; zeros for the others) */
static void fill_deferred(const int64_t *cfg, int64_t row, const double *st) {
  const mjModel *m = MODEL(cfg);
  mjData *d = DATA(cfg);
  const mjtNum *rod = d->site_xpos + 3 * cfg[C_rod_site], *front = d->xpos + 3 * cfg[C_front_body];
  double *out = PTR(double *, rec_deferred) + row * N_DEFERRED;
  double sx = rod[0], sy = rod[1], sz = rod[2], bx = front[0], by = front[1], bz = front[2];
  double ox = st[S_pin_x], oy = st[S_pin_y], oz = st[S_pin_z];
  double dx = sx - bx - ox, dy = sy - by - oy, dz = sz - bz - oz;
  out[D_loop_gap] = sqrt(dx * dx + dy * dy + dz * dz);
  mj_subtreeVel(m, d);
  out[D_momentum] = d->subtree_linvel[0] * st[S_total_mass];
  out[D_potential] = d->energy[0];
  out[D_kinetic] = d->energy[1];
  CONTROLLER(cfg)->deferred(cfg, st, out + D_clutch_force1);
}

/* how many warnings MuJoCo has raised on this mjData so far */
static long long warnings(const mjData *d) {
  long long total = 0;
  for (int w = 0; w < mjNWARNING; w++) total += d->warning[w].number;
  return total;
}

/* simulate._integrate's sampling loop (stepper.PythonSteps.record): up to nsamples output intervals of sps steps
 * (the last one cut at ``remaining`` steps), each recorded as a row; the first step of an interval fills the
 * deferred values of the row before it (``pending``, -1: none). Rows go from st[count] on; st[count] and
 * st[steps_done] count them. Returns STEPS_DONE, RECORD_WARNED (MuJoCo warned in the last interval, not recorded) or a
 * MISSING_* code. */
static int record(const int64_t *cfg, double *st, long long nsamples, long long sps, long long remaining,
                  long long pending) {
  const int64_t nv = MODEL(cfg)->nv;
  double *before = PTR(double *, qvel_before);
  for (long long s = 0; s < nsamples && remaining > 0; s++) {
    const long long k = sps < remaining ? sps : remaining;
    const int64_t row = (int64_t)st[S_count];
    const long long warned = warnings(DATA(cfg));
    int status;
    if (pending >= 0) {
      status = steps(cfg, st, 1, k == 1 ? before + row * nv : NULL);
      if (status != STEPS_DONE) return status;
      fill_deferred(cfg, pending, st);
      if (k > 1 && (status = steps(cfg, st, k - 1, before + row * nv)) != STEPS_DONE) return status;
    } else if ((status = steps(cfg, st, k, before + row * nv)) != STEPS_DONE) {
      return status;
    }
    remaining -= k;
    st[S_steps_done] += (double)k;
    if (warnings(DATA(cfg)) != warned) return RECORD_WARNED; /* as the Python loop: the interval is not recorded */
    if ((status = sample(cfg, st, row)) != STEPS_DONE) return status;
    st[S_count] = (double)(row + 1);
    pending = row;
  }
  return STEPS_DONE;
}

/* Calls record(cfg, st, arguments...) (what = 'r') or steps(cfg, st, nstep, dest) (what = 's') without the GIL,
 * with MuJoCo's errors caught. Returns the status, or -1 with RuntimeError (MuJoCo's message: the run's data is
 * then as the bindings leave it after such an error, not to be stepped on) or LookupError (the MISSING_* code
 * as its argument: a step did not produce the rows the loop reads) set. */
static int guarded(const int64_t *cfg, double *st, char what, const long long *a, double *dest) {
  int failed = 0;
  volatile int status = STEPS_DONE; /* set between setjmp and a possible longjmp */
  jmp_buf jump;
  if (loops_running++ == 0) {
    previous_error = mju_user_error;
    mju_user_error = on_mujoco_error;
  }
  Py_BEGIN_ALLOW_THREADS
  error_jump = &jump;
  if (setjmp(jump) == 0) {
    status = what == 'r' ? record(cfg, st, a[0], a[1], a[2], a[3]) : steps(cfg, st, a[0], dest);
  } else {
    failed = 1;
  }
  error_jump = NULL;
  Py_END_ALLOW_THREADS
  if (--loops_running == 0) mju_user_error = previous_error;
  if (failed) {
    PyErr_SetString(PyExc_RuntimeError, error_text);
    return -1;
  }
  if (status == MISSING_LOCK_ROW || status == MISSING_FRICTION_ROWS) {
    PyObject *code = PyLong_FromLong(status);
    if (code != NULL) {
      PyErr_SetObject(PyExc_LookupError, code);
      Py_DECREF(code);
    }
    return -1;
  }
  return status;
}

/* run(config address, state address, nstep, qvel_before row or -1): see steps(). Returns None. */
static PyObject *run(PyObject *self, PyObject *args) {
  (void)self;
  unsigned long long cfg_adr, st_adr;
  long long nstep, row;
  if (!PyArg_ParseTuple(args, "KKLL", &cfg_adr, &st_adr, &nstep, &row)) return NULL;
  const int64_t *cfg = (const int64_t *)(intptr_t)cfg_adr;
  double *dest = row >= 0 ? PTR(double *, qvel_before) + row * MODEL(cfg)->nv : NULL;
  if (guarded(cfg, (double *)(intptr_t)st_adr, 's', &nstep, dest) < 0) return NULL;
  Py_RETURN_NONE;
}

/* record(config address, state address, nsamples, steps per sample, steps remaining, pending row or -1): see
 * record(). Returns its status (an int). */
static PyObject *record_samples(PyObject *self, PyObject *args) {
  (void)self;
  unsigned long long cfg_adr, st_adr;
  long long a[4];
  if (!PyArg_ParseTuple(args, "KKLLLL", &cfg_adr, &st_adr, &a[0], &a[1], &a[2], &a[3])) return NULL;
  int status = guarded((const int64_t *)(intptr_t)cfg_adr, (double *)(intptr_t)st_adr, 'r', a, NULL);
  return status < 0 ? NULL : PyLong_FromLong(status);
}

/* check(model address, data address): what this module reads there, to compare with what the bindings report
 * for the same objects: (nq, nv, timestep, jnt_range, eq_data, qpos, qvel, time), the pointers as ints */
static PyObject *check(PyObject *self, PyObject *args) {
  (void)self;
  unsigned long long m_adr, d_adr;
  if (!PyArg_ParseTuple(args, "KK", &m_adr, &d_adr)) return NULL;
  const mjModel *m = (const mjModel *)(intptr_t)m_adr;
  const mjData *d = (const mjData *)(intptr_t)d_adr;
  return Py_BuildValue("LLdKKKKd", (long long)m->nq, (long long)m->nv, m->opt.timestep,
                       (unsigned long long)(uintptr_t)m->jnt_range, (unsigned long long)(uintptr_t)m->eq_data,
                       (unsigned long long)(uintptr_t)d->qpos, (unsigned long long)(uintptr_t)d->qvel, d->time);
}

/* handlers(): whether the linked library's mju_user_error and mju_user_warning are set (bools) */
static PyObject *handlers(PyObject *self, PyObject *args) {
  (void)self;
  (void)args;
  return Py_BuildValue("(NN)", PyBool_FromLong(mju_user_error != NULL), PyBool_FromLong(mju_user_warning != NULL));
}

static PyMethodDef methods[] = {
    {"run", run, METH_VARARGS, "run(config, state, nstep, row): nstep steps of a serial run (see stepper.py)"},
    {"record", record_samples, METH_VARARGS,
     "record(config, state, nsamples, sps, remaining, pending): recorded output intervals (see stepper.py)"},
    {"check", check, METH_VARARGS, "check(model, data): fields read at these addresses (see native.py)"},
    {"handlers", handlers, METH_NOARGS, "handlers(): whether mju_user_error, mju_user_warning are set"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_stepper", NULL, -1, methods, NULL, NULL, NULL, NULL};

#define AS_NAME(name) #name,
static const char *const config_names[] = {LOOP_CONFIG(AS_NAME)};
static const char *const state_names[] = {LOOP_STATE(AS_NAME)};
static const char *const scalar_names[] = {SCALAR_FIELDS(AS_NAME)};
static const char *const deferred_names[] = {DEFERRED_FIELDS(AS_NAME)};
#undef AS_NAME

static PyObject *names(const char *const *list, int n) {
  PyObject *tuple = PyTuple_New(n);
  if (tuple == NULL) return NULL;
  for (int i = 0; i < n; i++) {
    PyObject *name = PyUnicode_FromString(list[i]);
    if (name == NULL) {
      Py_DECREF(tuple);
      return NULL;
    }
    PyTuple_SET_ITEM(tuple, i, name);
  }
  return tuple;
}

/* the table of controllers: per controller (name, its CONFIG names, its STATE names), in their order */
static PyObject *controllers(void) {
  PyObject *table = PyTuple_New(N_CONTROLLERS);
  if (table == NULL) return NULL;
  for (int i = 0; i < N_CONTROLLERS; i++) {
    const Controller *c = CONTROLLERS[i];
    PyObject *entry = Py_BuildValue("(sNN)", c->name, names(c->config, c->n_config), names(c->state, c->n_state));
    if (entry == NULL) {
      Py_DECREF(table);
      return NULL;
    }
    PyTuple_SET_ITEM(table, i, entry);
  }
  return table;
}

PyMODINIT_FUNC PyInit__stepper(void) {
  PyObject *mod = PyModule_Create(&module);
  if (mod == NULL) return NULL;
  if (PyModule_AddObject(mod, "CONFIG", names(config_names, N_CONFIG)) < 0 ||
      PyModule_AddObject(mod, "STATE", names(state_names, N_STATE)) < 0 ||
      PyModule_AddObject(mod, "SCALARS", names(scalar_names, N_SCALARS)) < 0 ||
      PyModule_AddObject(mod, "DEFERRED", names(deferred_names, N_DEFERRED)) < 0 ||
      PyModule_AddObject(mod, "CONTROLLERS", controllers()) < 0 ||
      PyModule_AddIntConstant(mod, "WARNED", RECORD_WARNED) < 0 ||
      PyModule_AddIntConstant(mod, "MJVERSION_HEADER", mjVERSION_HEADER) < 0) {
    Py_DECREF(mod);
    return NULL;
  }
  return mod;
}
