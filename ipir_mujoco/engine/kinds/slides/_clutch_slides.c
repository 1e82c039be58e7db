/* The slide model's clutch controllers, compiled (see _stepper.h): NoClutch, Ratchet, Locks (two rules) in
 * slide_clutches.py and CompliantClutches in compliant.py, step for step as there (the same double arithmetic in
 * the same order: tests/test_mujoco_stepper.py holds the two equal bit for bit). */
#include "../../controllers/_clutch_parts.h"

/* the slide model's work rates (loop_rows.FrictionPower, the loop's power): the slides' frictionloss rows follow
 * the ne equality rows, one per dof with friction (the loop's friction_dofs), read only if there; no skidding */
static int friction_work(const int64_t *cfg, double *st, double *rolling, double *skidding) {
  (void)st;
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force, *qvel = d->qvel;
  const int64_t nfric = cfg[C_nfric];
  const int ne = d->ne;
  *skidding = 0.0;
  if (nfric > 0 && d->nf != nfric) return MISSING_FRICTION_ROWS;
  if (nfric == 2) {
    *rolling = efc_force[ne] * qvel[cfg[C_fric_a]] + efc_force[ne + 1] * qvel[cfg[C_fric_b]];
  } else if (nfric == 1) {
    *rolling = efc_force[ne] * qvel[cfg[C_fric_a]];
  } else {
    *rolling = 0.0;
  }
  return STEPS_DONE;
}

/* ---- NoClutch: nothing to do, no reactions ---- */
#define NONE_CONFIG(X, P)
#define NONE_STATE(X, P)
FIELDS(NONE_CONFIG, NC)
FIELDS(NONE_STATE, NS)

/* no reactions, no wheels (also the compliant clutches': their forces come from the deferred values) */
static int no_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  (void)cfg;
  (void)st;
  for (int i = 0; i < N_REACTIONS; i++) out[i] = 0.0;
  return STEPS_DONE;
}

const Controller NO_CLUTCH = {"none", BLOCK_NAMES(NONE_CONFIG, NC, NONE_STATE, NS), .before_step = no_before_step,
                              .after_step = no_after_step, .work = friction_work, .reactions = no_reactions,
                              .deferred = no_deferred};

/* ---- Ratchet: each slide's lower limit follows its running maximum ---- */
#define RATCHET_CONFIG(X, P) X(P, x_q0) X(P, x_q1) X(P, joint0) X(P, joint1) X(P, fric_off0) X(P, fric_off1)
#define RATCHET_STATE(X, P) X(P, bound0) X(P, bound1) X(P, margin0) X(P, margin1) X(P, resist0) X(P, resist1)
FIELDS(RATCHET_CONFIG, RC)
FIELDS(RATCHET_STATE, RS)

static void ratchet_before(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  double *s = BLOCK_STATE(st);
  const mjtNum *qpos = DATA(cfg)->qpos;
  mjtNum *range = MODEL(cfg)->jnt_range;
  for (int i = 0; i < 2; i++) {
    double x = qpos[c[RC_x_q0 + i]];
    const double give = follow(&s[RS_bound0 + i], x, 0);
    if (give < 0.0) {
      range[2 * c[RC_joint0 + i]] = x - s[RS_margin0 + i];
    } else if (give > st[S_excursion]) {
      st[S_excursion] = give;
    }
  }
}

/* Ratchet.reactions: the limit rows follow the equality and friction rows, in joint order */
static int ratchet_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne, nf = d->nf, nl = d->nl;
  if (nf != cfg[C_nfric]) return MISSING_FRICTION_ROWS; /* as FrictionRows.forces: never a row not a slide's */
  const int start = ne + nf;
  double rear = 0.0, front = 0.0, f[2];
  if (nl == 2) {
    rear = efc_force[start];
    front = efc_force[start + 1];
    if (c[RC_joint0] > c[RC_joint1]) {
      double swap = rear;
      rear = front;
      front = swap;
    }
  } else if (nl == 1) {
    if (d->efc_id[start] == c[RC_joint0]) {
      rear = efc_force[start];
    } else {
      front = efc_force[start];
    }
  }
  friction_forces(efc_force, ne, c + RC_fric_off0, f);
  const double hold[2] = {rear, front};
  for (int i = 0; i < 2; i++) {
    const double r = s[RS_resist0 + i];
    int held = hold[i] > 0.0 || f[i] > -r;
    out[i] = held ? 1.0 : 0.0;
    out[2 + i] = held ? clutch_share(hold[i] + f[i], r) : 0.0;
  }
  out[4] = out[5] = 0.0;
  return STEPS_DONE;
}

const Controller RATCHET = {"ratchet", BLOCK_NAMES(RATCHET_CONFIG, RC, RATCHET_STATE, RS),
                            .before_step = ratchet_before, .after_step = no_after_step, .work = friction_work,
                            .reactions = ratchet_reactions, .deferred = no_deferred};

/* ---- Locks: a joint-equality lock per module, by the paper's rule or the one-way rule ---- */
#define LOCKS_CONFIG(X, P)                                                                                     \
  X(P, x_q0) X(P, x_q1) X(P, x_v0) X(P, x_v1) X(P, eq0) X(P, eq1) X(P, rod_q) X(P, rod_v) X(P, fric_off0)  \
  X(P, fric_off1)
#define LOCKS_STATE(X, P) X(P, held0) X(P, held1) X(P, force0) X(P, force1) X(P, r) X(P, L) X(P, resist0) X(P, resist1)
FIELDS(LOCKS_CONFIG, LC)
FIELDS(LOCKS_STATE, LS)

/* Locks._apply: engage (anchored where the module stands) or release each lock */
static void apply_locks(const int64_t *cfg, double *s, int want0, int want1) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const mjtNum *qpos = DATA(cfg)->qpos;
  mjtNum *eq_data = MODEL(cfg)->eq_data;
  mjtBool *active = DATA(cfg)->eq_active;
  const int want[2] = {want0, want1};
  for (int i = 0; i < 2; i++) {
    int now = s[LS_held0 + i] != 0.0;
    if (want[i] && !now) eq_data[c[LC_eq0 + i] * mjNEQDATA] = qpos[c[LC_x_q0 + i]];
    if (want[i] != now) active[c[LC_eq0 + i]] = (mjtBool)want[i];
    s[LS_held0 + i] = want[i] ? 1.0 : 0.0;
  }
}

/* Locks.before_step's first part: a held module's give below its lock's anchor is excursion */
static void lock_excursion(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjtNum *qpos = DATA(cfg)->qpos, *eq_data = MODEL(cfg)->eq_data;
  for (int i = 0; i < 2; i++) {
    if (s[LS_held0 + i] != 0.0) {
      double back = eq_data[c[LC_eq0 + i] * mjNEQDATA] - qpos[c[LC_x_q0 + i]];
      if (back > st[S_excursion]) st[S_excursion] = back;
    }
  }
}

/* the paper's rule (Locks.gap_rate: -r sin(phi) omega - L sin(beta) beta_dot): front locked while the gap
 * shrinks, rear while it grows */
static void lock_kinematic_before(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  double *s = BLOCK_STATE(st);
  const mjtNum *qpos = DATA(cfg)->qpos, *qvel = DATA(cfg)->qvel;
  lock_excursion(cfg, st);
  double phi = qpos[cfg[C_crank_q]], omega = qvel[cfg[C_crank_v]];
  double beta = phi + qpos[c[LC_rod_q]], beta_rate = omega + qvel[c[LC_rod_v]];
  double s_dot = -s[LS_r] * sin(phi) * omega - s[LS_L] * sin(beta) * beta_rate;
  if (s_dot < 0) {
    apply_locks(cfg, s, 0, 1);
  } else if (s_dot > 0) {
    apply_locks(cfg, s, 1, 0);
  }
}

/* the one-way rule: a held module stays locked while its lock pushes, a free one locks when it moves back */
static void lock_unilateral_before(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  double *s = BLOCK_STATE(st);
  const mjtNum *qvel = DATA(cfg)->qvel;
  lock_excursion(cfg, st);
  int want0 = s[LS_held0] != 0.0 ? s[LS_force0] >= 0.0 : qvel[c[LC_x_v0]] < 0.0;
  int want1 = s[LS_held1] != 0.0 ? s[LS_force1] >= 0.0 : qvel[c[LC_x_v1]] < 0.0;
  apply_locks(cfg, s, want0, want1);
}

/* Locks.after_step (one-way rule): each held lock's row; MISSING_LOCK_ROW if it is not among the equality rows */
static int lock_unilateral_after(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  for (int i = 0; i < 2; i++) {
    if (s[LS_held0 + i] != 0.0) {
      int64_t row = equality_row(cfg, c[LC_eq0 + i]);
      if (row >= d->ne) return MISSING_LOCK_ROW;
      s[LS_force0 + i] = d->efc_force[row];
    } else {
      s[LS_force0 + i] = 0.0;
    }
  }
  return STEPS_DONE;
}

/* Locks.reactions */
static int locks_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS], int kinematic) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne;
  if (d->nf != cfg[C_nfric]) return MISSING_FRICTION_ROWS;
  const int locked[2] = {s[LS_held0] != 0.0, s[LS_held1] != 0.0};
  const int whole = kinematic && !(locked[0] && locked[1]);
  double f[2];
  friction_forces(efc_force, ne, c + LC_fric_off0, f);
  for (int i = 0; i < 2; i++) {
    const double r = s[LS_resist0 + i];
    double lock = 0.0;
    if (locked[i]) {
      int64_t row = equality_row(cfg, c[LC_eq0 + i]);
      if (row >= ne) return MISSING_LOCK_ROW;
      lock = efc_force[row];
    }
    int held = locked[i] || (!kinematic && f[i] > -r);
    double total = lock + f[i];
    out[i] = held ? 1.0 : 0.0;
    out[2 + i] = !held ? 0.0 : whole ? total : clutch_share(total, r);
  }
  out[4] = out[5] = 0.0;
  return STEPS_DONE;
}

static int lock_kinematic_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  return locks_reactions(cfg, st, out, 1);
}

static int lock_unilateral_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  return locks_reactions(cfg, st, out, 0);
}

const Controller LOCK_KINEMATIC = {"lock_kinematic", BLOCK_NAMES(LOCKS_CONFIG, LC, LOCKS_STATE, LS),
                                   .before_step = lock_kinematic_before, .after_step = no_after_step,
                                   .work = friction_work, .reactions = lock_kinematic_reactions,
                                   .deferred = no_deferred};
const Controller LOCK_UNILATERAL = {"lock_unilateral", BLOCK_NAMES(LOCKS_CONFIG, LC, LOCKS_STATE, LS),
                                    .before_step = lock_unilateral_before, .after_step = lock_unilateral_after,
                                    .work = friction_work, .reactions = lock_unilateral_reactions,
                                    .deferred = no_deferred};

/* ---- CompliantClutches: the compliant part on the slides ---- */
#define COMPLIANT_SLIDES_CONFIG(X, P) COMPLIANT_CONFIG(X, P) X(P, x_q0) X(P, x_q1) X(P, x_v0) X(P, x_v1)
FIELDS(COMPLIANT_SLIDES_CONFIG, CC)
FIELDS(COMPLIANT_STATE, CS)

static void compliant_slides_before(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const mjtNum *qpos = DATA(cfg)->qpos, *qvel = DATA(cfg)->qvel;
  for (int i = 0; i < 2; i++) {
    compliant_before(cfg, c, BLOCK_STATE(st), i, qpos[c[CC_x_q0 + i]], qvel[c[CC_x_v0 + i]]);
  }
}

static int compliant_slides_after(const int64_t *cfg, double *st) {
  const int64_t *c = BLOCK_CONFIG(cfg);
  const mjtNum *qvel = DATA(cfg)->qvel;
  const double speed[2] = {qvel[c[CC_x_v0]], qvel[c[CC_x_v1]]};
  compliant_after(cfg, st, c, BLOCK_STATE(st), speed);
  return STEPS_DONE;
}

static void compliant_slides_deferred(const int64_t *cfg, const double *st, double *out) {
  compliant_deferred(cfg, st, BLOCK_CONFIG(cfg), BLOCK_STATE(st), out);
}

const Controller COMPLIANT = {"compliant", BLOCK_NAMES(COMPLIANT_SLIDES_CONFIG, CC, COMPLIANT_STATE, CS),
                              .before_step = compliant_slides_before, .after_step = compliant_slides_after,
                              .work = friction_work, .reactions = no_reactions, .deferred = compliant_slides_deferred};
