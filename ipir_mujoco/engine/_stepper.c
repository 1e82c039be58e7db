/* The per-step loop of a serial MuJoCo run, compiled: see ipir_mujoco/engine/stepper.py.
 *
 * It does, step for step, what the pure-Python loop (stepper.PythonSteps and the clutch controllers in
 * clutches.py and compliant.py) does: the clutch update before each mj_step, the clutch bookkeeping after
 * it, the drive's work and the work against the resistances; the same double arithmetic in the same order
 * (built with -ffp-contract=off, so no fused multiply-add changes a rounding), so the two paths agree bit for
 * bit. It includes no MuJoCo header: Python passes the address of mj_step (from the loaded libmujoco), of
 * every array it touches, and of the two mjData fields that move between steps (the efc_force pointer and
 * the counts ne and nf), whose offsets it reads from the running mujoco's own struct description and checks on the
 * live MjData before every run.
 *
 * Layout: two arrays owned by Python, one int64 per CONFIG field (addresses, indices, flags) and one double
 * per STATE field (what the loop reads and writes); the field names are exported, so stepper.py builds its
 * indices from this file.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CONFIG_FIELDS(X)                                                                         \
  X(model) X(data) X(step) X(user_error) X(efc_force_field) X(ne_field) X(nf_field)              \
  X(qpos) X(qvel) X(ctrl) X(actuator_force) X(qvel_before)                                       \
  X(jnt_range) X(eq_data) X(eq_data_stride) X(eq_active) X(eq_rows) X(biasprm) X(biasprm_stride) \
  X(nv) X(clutch) X(motor) X(crank_q) X(crank_v) X(nfric) X(fric_a) X(fric_b)                    \
  X(slide_q0) X(slide_q1) X(slide_v0) X(slide_v1) X(joint0) X(joint1)                            \
  X(eq0) X(eq1) X(rod_q) X(rod_v) X(act0) X(act1) X(implicit)

#define STATE_FIELDS(X)                                                                          \
  X(dt) X(slope) X(torque) X(motor_work) X(friction_work) X(omega_prev) X(excursion)     \
  X(bound0) X(bound1) X(margin0) X(margin1)                                                      \
  X(held0) X(held1) X(force0) X(force1) X(r) X(L)                                                \
  X(anchor0) X(anchor1) X(overlap0) X(overlap1) X(v_before0) X(v_before1) X(damped0) X(damped1) \
  X(damper_work) X(k) X(c) X(backlash)

#define AS_ENUM(name) C_##name,
enum { CONFIG_FIELDS(AS_ENUM) N_CONFIG };
#undef AS_ENUM
#define AS_ENUM(name) S_##name,
enum { STATE_FIELDS(AS_ENUM) N_STATE };
#undef AS_ENUM

/* the clutch kinds (stepper.CLUTCH_KINDS holds the same order) */
enum { NO_CLUTCH = 0, RATCHET = 1, LOCK_KINEMATIC = 2, LOCK_UNILATERAL = 3, COMPLIANT = 4 };

/* what steps() returns: done, or which constraint rows it was to read are absent after a step (the
 * Python loop raises for the same two: clutches.MISSING_ROWS holds the same order) */
enum { STEPS_DONE = 0, MISSING_LOCK_ROW = 1, MISSING_FRICTION_ROWS = 2 };

typedef void (*step_fn)(const void *m, void *d);
typedef void (*error_fn)(const char *msg);

#define PTR(type, field) ((type)(intptr_t)cfg[C_##field])

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

/* first constraint row of equality eq (active): the active equalities' rows come first, in id order */
static int64_t equality_row(const int64_t *cfg, int64_t eq) {
  const unsigned char *active = PTR(const unsigned char *, eq_active);
  const int64_t *rows = PTR(const int64_t *, eq_rows);
  int64_t row = 0;
  for (int64_t e = 0; e < eq; e++) {
    if (active[e]) row += rows[e];
  }
  return row;
}

/* Locks._apply: engage (anchored where the module stands) or release each lock */
static void apply_locks(const int64_t *cfg, double *st, int want0, int want1) {
  const double *qpos = PTR(const double *, qpos);
  double *eq_data = PTR(double *, eq_data);
  unsigned char *active = PTR(unsigned char *, eq_active);
  const int want[2] = {want0, want1};
  const int64_t eq[2] = {cfg[C_eq0], cfg[C_eq1]}, adr[2] = {cfg[C_slide_q0], cfg[C_slide_q1]};
  for (int i = 0; i < 2; i++) {
    int now = st[S_held0 + i] != 0.0;
    if (want[i] && !now) eq_data[eq[i] * cfg[C_eq_data_stride]] = qpos[adr[i]];
    if (want[i] != now) active[eq[i]] = (unsigned char)want[i];
    st[S_held0 + i] = want[i] ? 1.0 : 0.0;
  }
}

/* the clutch update before a step: Ratchet, Locks, CompliantClutches.before_step */
static void before_step(const int64_t *cfg, double *st) {
  const double *qpos = PTR(const double *, qpos), *qvel = PTR(const double *, qvel);
  switch (cfg[C_clutch]) {
    case RATCHET: {
      double *range = PTR(double *, jnt_range);
      for (int i = 0; i < 2; i++) {
        double x = qpos[cfg[C_slide_q0 + i]];
        if (x > st[S_bound0 + i]) {
          st[S_bound0 + i] = x;
          range[2 * cfg[C_joint0 + i]] = x - st[S_margin0 + i];
        } else if (st[S_bound0 + i] - x > st[S_excursion]) {
          st[S_excursion] = st[S_bound0 + i] - x;
        }
      }
      break;
    }
    case LOCK_KINEMATIC:
    case LOCK_UNILATERAL: {
      const double *eq_data = PTR(const double *, eq_data);
      for (int i = 0; i < 2; i++) {
        if (st[S_held0 + i] != 0.0) {
          double back = eq_data[cfg[C_eq0 + i] * cfg[C_eq_data_stride]] - qpos[cfg[C_slide_q0 + i]];
          if (back > st[S_excursion]) st[S_excursion] = back;
        }
      }
      if (cfg[C_clutch] == LOCK_KINEMATIC) {
        /* Locks.gap_rate: -r sin(phi) omega - L sin(beta) beta_dot */
        double phi = qpos[cfg[C_crank_q]], omega = qvel[cfg[C_crank_v]];
        double beta = phi + qpos[cfg[C_rod_q]], beta_rate = omega + qvel[cfg[C_rod_v]];
        double s_dot = -st[S_r] * sin(phi) * omega - st[S_L] * sin(beta) * beta_rate;
        if (s_dot < 0) {
          apply_locks(cfg, st, 0, 1);
        } else if (s_dot > 0) {
          apply_locks(cfg, st, 1, 0);
        }
      } else {
        int want0 = st[S_held0] != 0.0 ? st[S_force0] >= 0.0 : qvel[cfg[C_slide_v0]] < 0.0;
        int want1 = st[S_held1] != 0.0 ? st[S_force1] >= 0.0 : qvel[cfg[C_slide_v1]] < 0.0;
        apply_locks(cfg, st, want0, want1);
      }
      break;
    }
    case COMPLIANT: {
      double *ctrl = PTR(double *, ctrl), *biasprm = PTR(double *, biasprm);
      for (int i = 0; i < 2; i++) {
        int64_t act = cfg[C_act0 + i];
        double x = qpos[cfg[C_slide_q0 + i]];
        if (x - st[S_backlash] > st[S_anchor0 + i]) {
          st[S_anchor0 + i] = x - st[S_backlash];
          ctrl[act] = st[S_anchor0 + i];
        }
        double d = st[S_anchor0 + i] - x;
        st[S_overlap0 + i] = d;
        st[S_v_before0 + i] = qvel[cfg[C_slide_v0 + i]];
        if ((d > 0.0) != (st[S_damped0 + i] != 0.0)) {
          st[S_damped0 + i] = d > 0.0 ? 1.0 : 0.0;
          biasprm[act * cfg[C_biasprm_stride] + 2] = d > 0.0 ? -st[S_c] : 0.0;
        }
      }
      break;
    }
    default:
      break;
  }
}

/* the clutch bookkeeping after a step: Locks (unilateral rule), CompliantClutches.after_step; returns
 * MISSING_LOCK_ROW (nothing read) if a held lock's row is not among the ne equality rows */
static int after_step(const int64_t *cfg, double *st, const double *efc_force, int ne) {
  if (cfg[C_clutch] == LOCK_UNILATERAL) {
    for (int i = 0; i < 2; i++) {
      if (st[S_held0 + i] != 0.0) {
        int64_t row = equality_row(cfg, cfg[C_eq0 + i]);
        if (row >= ne) return MISSING_LOCK_ROW;
        st[S_force0 + i] = efc_force[row];
      } else {
        st[S_force0 + i] = 0.0;
      }
    }
  } else if (cfg[C_clutch] == COMPLIANT) {
    const double *force = PTR(const double *, actuator_force), *qvel = PTR(const double *, qvel);
    double work = 0.0;
    for (int i = 0; i < 2; i++) {
      double d = st[S_overlap0 + i], applied = force[cfg[C_act0 + i]];
      if (d <= 0.0 && applied == 0.0) continue;
      double speed = qvel[cfg[C_slide_v0 + i]];
      if (applied > 0.0 && st[S_damped0 + i] != 0.0 && cfg[C_implicit]) {
        applied -= st[S_c] * (speed - st[S_v_before0 + i]);
      }
      work += ((d > 0.0 ? st[S_k] * d : 0.0) - applied) * speed;
    }
    st[S_damper_work] += work * st[S_dt];
  }
  return STEPS_DONE;
}

/* nstep steps; before the last one the velocities are copied into ``dest`` (if not NULL). Returns
 * STEPS_DONE, or the MISSING_* code of the rows a step did not produce (the state is then not written back) */
static int steps(const int64_t *cfg, double *st, long long nstep, double *dest) {
  const void *m = PTR(const void *, model);
  void *d = PTR(void *, data);
  step_fn step = PTR(step_fn, step);
  double *const *efc_field = PTR(double *const *, efc_force_field);
  const int *ne_field = PTR(const int *, ne_field), *nf_field = PTR(const int *, nf_field);
  const double *qvel = PTR(const double *, qvel), *force = PTR(const double *, actuator_force);
  const int64_t motor = cfg[C_motor], crank_v = cfg[C_crank_v], nfric = cfg[C_nfric];
  const int64_t fa = cfg[C_fric_a], fb = cfg[C_fric_b];
  const double dt = st[S_dt], slope = st[S_slope];
  double torque = st[S_torque], wm = st[S_motor_work], wf = st[S_friction_work], omega_prev = st[S_omega_prev];
  for (long long n = 0; n < nstep; n++) {
    before_step(cfg, st);
    if (n == nstep - 1 && dest != NULL) memcpy(dest, qvel, (size_t)cfg[C_nv] * sizeof(double));
    step(m, d);
    const double *efc_force = *efc_field;
    const int ne = *ne_field;
    if (after_step(cfg, st, efc_force, ne) != STEPS_DONE) return MISSING_LOCK_ROW;
    double omega = qvel[crank_v];
    torque = force[motor] + slope * (omega - omega_prev);
    wm += torque * omega * dt;
    /* the frictionloss rows follow the ne equality rows, one per dof with friction: read only if there */
    if (nfric > 0 && *nf_field != nfric) return MISSING_FRICTION_ROWS;
    if (nfric == 2) {
      double f0 = efc_force[ne], f1 = efc_force[ne + 1];
      wf -= (f0 * qvel[fa] + f1 * qvel[fb]) * dt;
    } else if (nfric == 1) {
      wf -= efc_force[ne] * qvel[fa] * dt;
    }
    omega_prev = omega;
  }
  st[S_torque] = torque;
  st[S_motor_work] = wm;
  st[S_friction_work] = wf;
  st[S_omega_prev] = omega_prev;
  return STEPS_DONE;
}

/* run(config address, state address, nstep, qvel_before row or -1): see steps(). Returns None; raises
 * RuntimeError with MuJoCo's message if MuJoCo reported an error (the run's data is then as the bindings
 * leave it after such an error: not to be stepped on), or LookupError with the MISSING_* code as its
 * argument if a step did not produce the rows the loop reads. */
static PyObject *run(PyObject *self, PyObject *args) {
  (void)self;
  unsigned long long cfg_adr, st_adr;
  long long nstep, row;
  if (!PyArg_ParseTuple(args, "KKLL", &cfg_adr, &st_adr, &nstep, &row)) return NULL;
  const int64_t *cfg = (const int64_t *)(intptr_t)cfg_adr;
  double *st = (double *)(intptr_t)st_adr;
  error_fn *user_error = PTR(error_fn *, user_error);
  double *dest = row >= 0 ? PTR(double *, qvel_before) + row * cfg[C_nv] : NULL;
  int failed = 0;
  volatile int status = STEPS_DONE; /* set between setjmp and a possible longjmp */
  jmp_buf jump;
  if (user_error != NULL && loops_running++ == 0) {
    previous_error = *user_error;
    *user_error = on_mujoco_error;
  }
  Py_BEGIN_ALLOW_THREADS
  error_jump = &jump;
  if (setjmp(jump) == 0) {
    status = steps(cfg, st, nstep, dest);
  } else {
    failed = 1;
  }
  error_jump = NULL;
  Py_END_ALLOW_THREADS
  if (user_error != NULL && --loops_running == 0) *user_error = previous_error;
  if (failed) {
    PyErr_SetString(PyExc_RuntimeError, error_text);
    return NULL;
  }
  if (status != STEPS_DONE) {
    PyObject *code = PyLong_FromLong(status);
    if (code != NULL) {
      PyErr_SetObject(PyExc_LookupError, code);
      Py_DECREF(code);
    }
    return NULL;
  }
  Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"run", run, METH_VARARGS, "run(config, state, nstep, row): nstep steps of a serial run (see stepper.py)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_stepper", NULL, -1, methods, NULL, NULL, NULL, NULL};

#define AS_NAME(name) #name,
static const char *const config_names[] = {CONFIG_FIELDS(AS_NAME)};
static const char *const state_names[] = {STATE_FIELDS(AS_NAME)};
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

PyMODINIT_FUNC PyInit__stepper(void) {
  PyObject *mod = PyModule_Create(&module);
  if (mod == NULL) return NULL;
  if (PyModule_AddObject(mod, "CONFIG", names(config_names, N_CONFIG)) < 0 ||
      PyModule_AddObject(mod, "STATE", names(state_names, N_STATE)) < 0) {
    Py_DECREF(mod);
    return NULL;
  }
  return mod;
}
