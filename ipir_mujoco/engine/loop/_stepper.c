/* The per-step loop of a serial MuJoCo run, compiled, and its sampling: see ipir_mujoco/engine/loop/stepper.py.
 *
 * It does, step for step, what the pure-Python loop (stepper.PythonSteps, the clutch controllers in
 * clutches.py, compliant.py and, on finite grip, grip.py and grip_compliant.py, the recorder in recorder.py)
 * does: the clutch update before each mj_step, the clutch bookkeeping after it, the drive's work and the work
 * against the resistances (and the grips' against skidding), and at each output
 * sample the record (state, torque, works, clutch reactions, the loop's force, the excursion, and MuJoCo's
 * energies, loop gap and momentum at the start of the next step); the same double arithmetic in the same
 * order (built with -ffp-contract=off, so no fused multiply-add changes a rounding), so the two paths agree
 * bit for bit. It is compiled against the headers of the installed mujoco and linked against its libmujoco
 * (setup.py), and reads mjModel and mjData through their structs; the module records the header's version
 * (MJVERSION_HEADER), which native.py checks against the running library before any use, with the library
 * instance (handlers()) and the mjModel and mjData behind the bindings' objects (check()).
 *
 * Layout: two arrays owned by Python, one int64 per CONFIG field (addresses, indices, flags) and one double
 * per STATE field (what the loop reads and writes); the field names are exported, so stepper.py builds its
 * indices from this file, as are the names of the recorder's SCALARS and DEFERRED columns, which native.py
 * checks against recorder.py's. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <mujoco/mujoco.h>

#include <math.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CONFIG_FIELDS(X)                                                                         \
  X(model) X(data) X(qvel_before) X(eq_rows)                                                     \
  X(clutch) X(motor) X(crank_q) X(crank_v) X(nfric) X(fric_a) X(fric_b)                          \
  X(slide_q0) X(slide_q1) X(slide_v0) X(slide_v1) X(joint0) X(joint1)                            \
  X(eq0) X(eq1) X(rod_q) X(rod_v) X(act0) X(act1) X(implicit)                                   \
  X(rod_site) X(front_body) X(loop_eq) X(fric_off0) X(fric_off1)                                 \
  X(rec_t) X(rec_qpos) X(rec_qvel) X(rec_scalars) X(rec_deferred) X(rec_excursion)               \
  X(grip) X(skid_q0) X(skid_q1) X(skid_v0) X(skid_v1) X(skid_j0) X(skid_j1) X(roll_t0) X(roll_t1) \
  X(roll_off0) X(roll_off1) X(grip_off0) X(grip_off1) X(rolling_tendon)

#define STATE_FIELDS(X)                                                                          \
  X(dt) X(slope) X(torque) X(motor_work) X(friction_work) X(omega_prev) X(excursion)     \
  X(bound0) X(bound1) X(margin0) X(margin1)                                                      \
  X(held0) X(held1) X(force0) X(force1) X(r) X(L)                                                \
  X(anchor0) X(anchor1) X(overlap0) X(overlap1) X(v_before0) X(v_before1) X(damped0) X(damped1) \
  X(damper_work) X(k) X(c) X(backlash)                                                          \
  X(resist0) X(resist1) X(pin_x) X(pin_y) X(pin_z) X(total_mass) X(count) X(steps_done)         \
  X(skid_work) X(lmax0) X(lmax1) X(cmin0) X(cmin1) X(tmargin0) X(tmargin1) X(cmargin0) X(cmargin1) \
  X(grip0) X(grip1) X(rest_speed) X(tracking0) X(tracking1)

/* what record() writes per sample: one row of each (Recorder's scalars and deferred arrays, in this order) */
#define SCALAR_FIELDS(X)                                                                          \
  X(motor_torque) X(loop_fx) X(loop_fy) X(held1) X(held2) X(lambda1) X(lambda2) X(motor_work)     \
  X(friction_work) X(clutch_damper_work) X(skid_work) X(wheels1) X(wheels2)
#define DEFERRED_FIELDS(X)                                                                        \
  X(kinetic) X(potential) X(loop_gap) X(momentum) X(clutch_force1) X(clutch_force2)               \
  X(clutch_overlap1) X(clutch_overlap2) X(clutch_spring)

#define AS_ENUM(name) C_##name,
enum { CONFIG_FIELDS(AS_ENUM) N_CONFIG };
#undef AS_ENUM
#define AS_ENUM(name) S_##name,
enum { STATE_FIELDS(AS_ENUM) N_STATE };
#undef AS_ENUM
#define AS_ENUM(name) R_##name,
enum { SCALAR_FIELDS(AS_ENUM) N_SCALARS };
#undef AS_ENUM
#define AS_ENUM(name) D_##name,
enum { DEFERRED_FIELDS(AS_ENUM) N_DEFERRED };
#undef AS_ENUM

/* the clutch kinds (stepper.CLUTCH_KINDS holds the same order) */
enum {
  NO_CLUTCH = 0, RATCHET = 1, LOCK_KINEMATIC = 2, LOCK_UNILATERAL = 3, COMPLIANT = 4, GRIP_RATCHET = 5,
  COMPLIANT_GRIP = 6
};

/* what steps() returns: done, or which constraint rows it was to read are absent after a step (the
 * Python loop raises for the same two: clutches.MISSING_ROWS holds the same order) */
enum { STEPS_DONE = 0, MISSING_LOCK_ROW = 1, MISSING_FRICTION_ROWS = 2 };
/* what record() returns besides STEPS_DONE: MuJoCo raised a warning in the last sample's interval */
enum { RECORD_WARNED = 3 };

typedef void (*error_fn)(const char *msg);

/* the recorder's and the loop's arrays are numpy float64, MuJoCo's arrays are read as such */
_Static_assert(sizeof(mjtNum) == sizeof(double), "MuJoCo built with single-precision mjtNum");

#define PTR(type, field) ((type)(intptr_t)cfg[C_##field])
#define MODEL(cfg) ((mjModel *)(intptr_t)(cfg)[C_model])
#define DATA(cfg) ((mjData *)(intptr_t)(cfg)[C_data])

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
  const mjtBool *active = DATA(cfg)->eq_active;
  const int64_t *rows = PTR(const int64_t *, eq_rows);
  int64_t row = 0;
  for (int64_t e = 0; e < eq; e++) {
    if (active[e]) row += rows[e];
  }
  return row;
}

/* Locks._apply: engage (anchored where the module stands) or release each lock */
static void apply_locks(const int64_t *cfg, double *st, int want0, int want1) {
  const mjtNum *qpos = DATA(cfg)->qpos;
  mjtNum *eq_data = MODEL(cfg)->eq_data;
  mjtBool *active = DATA(cfg)->eq_active;
  const int want[2] = {want0, want1};
  const int64_t eq[2] = {cfg[C_eq0], cfg[C_eq1]}, adr[2] = {cfg[C_slide_q0], cfg[C_slide_q1]};
  for (int i = 0; i < 2; i++) {
    int now = st[S_held0 + i] != 0.0;
    if (want[i] && !now) eq_data[eq[i] * mjNEQDATA] = qpos[adr[i]];
    if (want[i] != now) active[eq[i]] = (mjtBool)want[i];
    st[S_held0 + i] = want[i] ? 1.0 : 0.0;
  }
}

/* grip.lower_bound / grip.upper_bound: one margin below (above) value, moved by ulps until MuJoCo's distance
 * to it is below the margin */
static double lower_bound(double value, double margin) {
  double bound = value - margin;
  while (value - bound >= margin) bound = nextafter(bound, INFINITY);
  return bound;
}

static double upper_bound(double value, double margin) {
  double bound = value + margin;
  while (bound - value >= margin) bound = nextafter(bound, -INFINITY);
  return bound;
}

/* the carriage update of both grip controllers (GripRatchet and CompliantGrip.before_step): module i's carriage
   at c may only move back, its forward bound lowered to its running minimum; a carriage pushed forward again
   counts as excursion */
static void carriage_ratchet(const int64_t *cfg, double *st, mjtNum *range, int i, double c) {
  if (c < st[S_cmin0 + i]) {
    st[S_cmin0 + i] = c;
    range[2 * cfg[C_skid_j0 + i] + 1] = upper_bound(c, st[S_cmargin0 + i]);
  } else if (c - st[S_cmin0 + i] > st[S_excursion]) {
    st[S_excursion] = c - st[S_cmin0 + i];
  }
}

/* the clutch update before a step: Ratchet, Locks, CompliantClutches, GripRatchet, CompliantGrip.before_step */
static void before_step(const int64_t *cfg, double *st) {
  const mjtNum *qpos = DATA(cfg)->qpos, *qvel = DATA(cfg)->qvel;
  switch (cfg[C_clutch]) {
    case RATCHET: {
      mjtNum *range = MODEL(cfg)->jnt_range;
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
      const mjtNum *eq_data = MODEL(cfg)->eq_data;
      for (int i = 0; i < 2; i++) {
        if (st[S_held0 + i] != 0.0) {
          double back = eq_data[cfg[C_eq0 + i] * mjNEQDATA] - qpos[cfg[C_slide_q0 + i]];
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
      mjtNum *ctrl = DATA(cfg)->ctrl, *biasprm = MODEL(cfg)->actuator_biasprm;
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
          biasprm[act * mjNBIAS + 2] = d > 0.0 ? -st[S_c] : 0.0;
        }
      }
      break;
    }
    case GRIP_RATCHET: {
      mjtNum *tendon_range = MODEL(cfg)->tendon_range, *range = MODEL(cfg)->jnt_range;
      for (int i = 0; i < 2; i++) {
        double c = qpos[cfg[C_skid_q0 + i]];
        double roll = qpos[cfg[C_slide_q0 + i]] - c;
        if (roll > st[S_lmax0 + i]) {
          st[S_lmax0 + i] = roll;
          tendon_range[2 * cfg[C_roll_t0 + i]] = lower_bound(roll, st[S_tmargin0 + i]);
        } else if (st[S_lmax0 + i] - roll > st[S_excursion]) {
          st[S_excursion] = st[S_lmax0 + i] - roll;
        }
        carriage_ratchet(cfg, st, range, i, c);
      }
      break;
    }
    case COMPLIANT_GRIP: { /* CompliantGrip.before_step: the compliant clutch in the roll's coordinate, the wall */
      mjtNum *ctrl = DATA(cfg)->ctrl, *biasprm = MODEL(cfg)->actuator_biasprm, *range = MODEL(cfg)->jnt_range;
      for (int i = 0; i < 2; i++) {
        int64_t act = cfg[C_act0 + i];
        double c = qpos[cfg[C_skid_q0 + i]];
        double roll = qpos[cfg[C_slide_q0 + i]] - c;
        const int tracking = roll - st[S_backlash] > st[S_anchor0 + i];
        st[S_tracking0 + i] = tracking ? 1.0 : 0.0;
        if (tracking) {
          st[S_anchor0 + i] = roll - st[S_backlash];
          ctrl[act] = st[S_anchor0 + i];
        }
        double d = st[S_anchor0 + i] - roll;
        st[S_overlap0 + i] = d;
        st[S_v_before0 + i] = qvel[cfg[C_slide_v0 + i]] - qvel[cfg[C_skid_v0 + i]];
        if ((d > 0.0) != (st[S_damped0 + i] != 0.0)) {
          st[S_damped0 + i] = d > 0.0 ? 1.0 : 0.0;
          biasprm[act * mjNBIAS + 2] = d > 0.0 ? -st[S_c] : 0.0;
        }
        carriage_ratchet(cfg, st, range, i, c);
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
  } else if (cfg[C_clutch] == COMPLIANT || cfg[C_clutch] == COMPLIANT_GRIP) {
    const mjtNum *force = DATA(cfg)->actuator_force, *qvel = DATA(cfg)->qvel;
    const int on_roll = cfg[C_clutch] == COMPLIANT_GRIP; /* CompliantGrip.after_step: at the roll's speed */
    double work = 0.0;
    for (int i = 0; i < 2; i++) {
      double d = st[S_overlap0 + i], applied = force[cfg[C_act0 + i]];
      if (d <= 0.0 && applied == 0.0) continue;
      double speed = on_roll ? qvel[cfg[C_slide_v0 + i]] - qvel[cfg[C_skid_v0 + i]] : qvel[cfg[C_slide_v0 + i]];
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
  const mjModel *m = MODEL(cfg);
  mjData *d = DATA(cfg);
  const mjtNum *qvel = d->qvel, *force = d->actuator_force;
  const int64_t motor = cfg[C_motor], crank_v = cfg[C_crank_v], nfric = cfg[C_nfric];
  const int64_t fa = cfg[C_fric_a], fb = cfg[C_fric_b];
  const double dt = st[S_dt], slope = st[S_slope];
  double torque = st[S_torque], wm = st[S_motor_work], wf = st[S_friction_work], omega_prev = st[S_omega_prev];
  double ws = st[S_skid_work];
  const int grip = cfg[C_grip] != 0, tendon = cfg[C_rolling_tendon] != 0;
  for (long long n = 0; n < nstep; n++) {
    before_step(cfg, st);
    if (n == nstep - 1 && dest != NULL) memcpy(dest, qvel, (size_t)m->nv * sizeof(mjtNum));
    mj_step(m, d);
    const mjtNum *efc_force = d->efc_force;
    const int ne = d->ne;
    int status = after_step(cfg, st, efc_force, ne);
    if (status != STEPS_DONE) return status;
    double omega = qvel[crank_v];
    torque = force[motor] + slope * (omega - omega_prev);
    wm += torque * omega * dt;
    /* the frictionloss rows follow the ne equality rows, one per dof with friction: read only if there */
    if (grip) { /* PythonSteps._friction_power: the rolling resistances' rows and the grips' */
      if (d->nf != nfric) return MISSING_FRICTION_ROWS;
      double rolling = 0.0, skidding = 0.0;
      for (int i = 0; i < 2; i++) {
        const int64_t roll = cfg[C_roll_off0 + i], grip_row = cfg[C_grip_off0 + i];
        const double vx = qvel[cfg[C_slide_v0 + i]], vc = qvel[cfg[C_skid_v0 + i]];
        if (roll >= 0) rolling += efc_force[ne + roll] * (tendon ? vx - vc : vx);
        if (grip_row >= 0) skidding += efc_force[ne + grip_row] * vc;
      }
      wf -= rolling * dt;
      ws -= skidding * dt;
    } else if (nfric > 0 && d->nf != nfric) {
      return MISSING_FRICTION_ROWS;
    } else if (nfric == 2) {
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
  st[S_skid_work] = ws;
  return STEPS_DONE;
}

/* clutches.clutch_share: the clutch's part of a held module's total hold (Python's max and min, in order) */
static double clutch_share(double hold, double resistance) {
  double bounded = -resistance > hold ? -resistance : hold;
  double pushed = 0.0 < bounded ? 0.0 : bounded;
  return hold - pushed;
}

/* clutches.FrictionRows.forces: the slides' frictionloss rows (0.0 for a slide without one); the step just
 * taken has checked that the rows are there */
static void friction_forces(const int64_t *cfg, const double *efc_force, int ne, double out[2]) {
  for (int i = 0; i < 2; i++) {
    int64_t offset = cfg[C_fric_off0 + i];
    out[i] = offset >= 0 ? efc_force[ne + offset] : 0.0;
  }
}

/* GripRatchet.states: per module its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share
 * of the hold, from the rolls' limit rows (the limit rows follow the equality and friction rows) and the
 * friction rows at their fixed offsets; out as reactions() writes it */
static int grip_states(const int64_t *cfg, const double *st, double out[6]) {
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force, *qvel = d->qvel;
  const int ne = d->ne, nf = d->nf, nl = d->nl;
  double clutch[2] = {0.0, 0.0};
  const int start = ne + nf;
  for (int row = start; row < start + nl; row++) {
    if (d->efc_type[row] == mjCNSTR_LIMIT_TENDON) clutch[d->efc_id[row] == cfg[C_roll_t0] ? 0 : 1] = efc_force[row];
  }
  if (nf != cfg[C_nfric]) return MISSING_FRICTION_ROWS;
  for (int i = 0; i < 2; i++) {
    const int64_t g = cfg[C_grip_off0 + i], r = cfg[C_roll_off0 + i];
    const double grip_force = g >= 0 ? efc_force[ne + g] : 0.0, roll_force = r >= 0 ? efc_force[ne + r] : 0.0;
    const double hold = clutch[i] + roll_force, F = st[S_resist0 + i], G = st[S_grip0 + i];
    double state, share;
    if (!(clutch[i] > 0.0 || roll_force > -F)) {
      state = 1.0;
      share = 0.0;
    } else {
      const int skids = G > 0.0 ? grip_force >= G : qvel[cfg[C_skid_v0 + i]] < -st[S_rest_speed];
      state = skids ? -1.0 : 0.0;
      share = clutch_share(hold, F);
    }
    out[i] = state == 0.0 ? 1.0 : 0.0;
    out[2 + i] = share;
    out[4 + i] = state;
  }
  return STEPS_DONE;
}

/* the clutch controller's reactions() after the last step: (rear held, front held, rear [N], front [N]) and, with
 * finite grip, the wheels' states (0.0 otherwise) */
static int reactions(const int64_t *cfg, const double *st, double out[6]) {
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne, nf = d->nf, nl = d->nl;
  const double r[2] = {st[S_resist0], st[S_resist1]};
  double f[2], hold[2];
  /* as FrictionRows.forces (the rigid clutches' reactions read it): never a row that is not a slide's */
  const int64_t kind = cfg[C_clutch];
  if ((kind == RATCHET || kind == LOCK_KINEMATIC || kind == LOCK_UNILATERAL) && nf != cfg[C_nfric]) {
    return MISSING_FRICTION_ROWS;
  }
  out[4] = out[5] = 0.0;
  switch (kind) {
    case GRIP_RATCHET:
      return grip_states(cfg, st, out);
    case COMPLIANT_GRIP: { /* CompliantGrip.wheels; its forces come from the deferred values, as the compliant's */
      if (nf != cfg[C_nfric]) return MISSING_FRICTION_ROWS;
      const mjtNum *qvel = d->qvel;
      out[0] = out[1] = out[2] = out[3] = 0.0;
      for (int i = 0; i < 2; i++) {
        const int64_t g = cfg[C_grip_off0 + i];
        const double grip_force = g >= 0 ? efc_force[ne + g] : 0.0, G = st[S_grip0 + i];
        const double vc = qvel[cfg[C_skid_v0 + i]];
        const int skids = G > 0.0 ? grip_force >= G : vc < -st[S_rest_speed];
        if (skids) {
          out[4 + i] = -1.0;
        } else if (st[S_tracking0 + i] != 0.0 && qvel[cfg[C_slide_v0 + i]] - vc > st[S_rest_speed]) {
          out[4 + i] = 1.0;
        } else {
          out[4 + i] = 0.0;
        }
      }
      return STEPS_DONE;
    }
    case RATCHET: {
      /* Ratchet.reactions: the limit rows follow the equality and friction rows, in joint order */
      const int start = ne + nf;
      double rear = 0.0, front = 0.0;
      if (nl == 2) {
        rear = efc_force[start];
        front = efc_force[start + 1];
        if (cfg[C_joint0] > cfg[C_joint1]) {
          double swap = rear;
          rear = front;
          front = swap;
        }
      } else if (nl == 1) {
        if (d->efc_id[start] == cfg[C_joint0]) {
          rear = efc_force[start];
        } else {
          front = efc_force[start];
        }
      }
      friction_forces(cfg, efc_force, ne, f);
      hold[0] = rear;
      hold[1] = front;
      for (int i = 0; i < 2; i++) {
        int held = hold[i] > 0.0 || f[i] > -r[i];
        out[i] = held ? 1.0 : 0.0;
        out[2 + i] = held ? clutch_share(hold[i] + f[i], r[i]) : 0.0;
      }
      return STEPS_DONE;
    }
    case LOCK_KINEMATIC:
    case LOCK_UNILATERAL: {
      /* Locks.reactions */
      const int kinematic = kind == LOCK_KINEMATIC;
      const int locked[2] = {st[S_held0] != 0.0, st[S_held1] != 0.0};
      const int whole = kinematic && !(locked[0] && locked[1]);
      friction_forces(cfg, efc_force, ne, f);
      for (int i = 0; i < 2; i++) {
        double lock = 0.0;
        if (locked[i]) {
          int64_t row = equality_row(cfg, cfg[C_eq0 + i]);
          if (row >= ne) return MISSING_LOCK_ROW;
          lock = efc_force[row];
        }
        int held = locked[i] || (!kinematic && f[i] > -r[i]);
        double total = lock + f[i];
        out[i] = held ? 1.0 : 0.0;
        out[2 + i] = !held ? 0.0 : whole ? total : clutch_share(total, r[i]);
      }
      return STEPS_DONE;
    }
    default: /* NoClutch; the compliant clutches' samples take their forces from the deferred values */
      out[0] = out[1] = out[2] = out[3] = 0.0;
      return STEPS_DONE;
  }
}

/* Recorder.sample: the state after the last step as row ``row`` */
static int sample(const int64_t *cfg, const double *st, int64_t row) {
  const int64_t nq = MODEL(cfg)->nq, nv = MODEL(cfg)->nv;
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne;
  double held[6];
  int status = reactions(cfg, st, held);
  if (status != STEPS_DONE) return status;
  PTR(double *, rec_t)[row] = d->time;
  memcpy(PTR(double *, rec_qpos) + row * nq, d->qpos, (size_t)nq * sizeof(mjtNum));
  memcpy(PTR(double *, rec_qvel) + row * nv, d->qvel, (size_t)nv * sizeof(mjtNum));
  double *out = PTR(double *, rec_scalars) + row * N_SCALARS;
  int64_t loop = equality_row(cfg, cfg[C_loop_eq]);
  out[R_motor_torque] = st[S_torque];
  out[R_loop_fx] = ne >= loop + 3 ? efc_force[loop] : 0.0;
  out[R_loop_fy] = ne >= loop + 3 ? efc_force[loop + 1] : 0.0;
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

/* Recorder.fill_deferred: MuJoCo's values at the start of the step just taken; with compliant clutches also
 * their forces, the overlaps their before_step set for that state and CompliantClutches.stepped_spring_energy */
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
  out[D_clutch_force1] = out[D_clutch_force2] = out[D_clutch_overlap1] = out[D_clutch_overlap2] = 0.0;
  out[D_clutch_spring] = 0.0;
  if (cfg[C_clutch] == COMPLIANT || cfg[C_clutch] == COMPLIANT_GRIP) {
    const mjtNum *force = d->actuator_force;
    const double k = st[S_k], dt = st[S_dt];
    double spring = 0.0;
    for (int i = 0; i < 2; i++) {
      double d = st[S_overlap0 + i];
      out[D_clutch_force1 + i] = force[cfg[C_act0 + i]];
      out[D_clutch_overlap1 + i] = d;
      if (d > 0.0) spring += 0.5 * k * d * (d + dt * st[S_v_before0 + i]);
    }
    out[D_clutch_spring] = spring;
  }
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
static const char *const config_names[] = {CONFIG_FIELDS(AS_NAME)};
static const char *const state_names[] = {STATE_FIELDS(AS_NAME)};
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

PyMODINIT_FUNC PyInit__stepper(void) {
  PyObject *mod = PyModule_Create(&module);
  if (mod == NULL) return NULL;
  if (PyModule_AddObject(mod, "CONFIG", names(config_names, N_CONFIG)) < 0 ||
      PyModule_AddObject(mod, "STATE", names(state_names, N_STATE)) < 0 ||
      PyModule_AddObject(mod, "SCALARS", names(scalar_names, N_SCALARS)) < 0 ||
      PyModule_AddObject(mod, "DEFERRED", names(deferred_names, N_DEFERRED)) < 0 ||
      PyModule_AddIntConstant(mod, "WARNED", RECORD_WARNED) < 0 ||
      PyModule_AddIntConstant(mod, "MJVERSION_HEADER", mjVERSION_HEADER) < 0) {
    Py_DECREF(mod);
    return NULL;
  }
  return mod;
}
