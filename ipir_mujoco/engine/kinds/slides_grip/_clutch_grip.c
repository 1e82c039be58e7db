/* The finite-grip clutch controllers, compiled (see _stepper.h): GripRatchet (grip.py) and CompliantGrip
 * (compliant_grip.py), step for step as there. Each block starts with the carriages' part (GRIP_PART,
 * _clutch_parts.h); their work rates are the grip rows' (grip_work). */
#include "../../controllers/_clutch_parts.h"

/* ---- GripRatchet: the roll's lower limit follows its running maximum, the carriage's upper its minimum ---- */
#define GRIP_RATCHET_CONFIG(X, P) GRIP_CONFIG(X, P) X(P, roll_t0) X(P, roll_t1)
#define GRIP_RATCHET_STATE(X, P) \
  GRIP_STATE(X, P) X(P, lmax0) X(P, lmax1) X(P, tmargin0) X(P, tmargin1) X(P, resist0) X(P, resist1)
FIELDS(GRIP_RATCHET_CONFIG, GC)
FIELDS(GRIP_RATCHET_STATE, GS)

static void grip_ratchet_before(const int64_t *cfg, double *st) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  double *s = BLOCK_STATE(st);
  const mjtNum *qpos = DATA(cfg)->qpos;
  mjtNum *tendon_range = MODEL(cfg)->tendon_range;
  for (int i = 0; i < 2; i++) {
    double c = qpos[g[GC_c_q0 + i]];
    double roll = qpos[g[GC_x_q0 + i]] - c;
    const double give = follow(&s[GS_lmax0 + i], roll, 0);
    if (give < 0.0) {
      tendon_range[2 * g[GC_roll_t0 + i]] = lower_bound(roll, s[GS_tmargin0 + i]);
    } else if (give > st[S_excursion]) {
      st[S_excursion] = give;
    }
    carriage_ratchet(cfg, st, i, c);
  }
}

/* GripRatchet.states: per module its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share
 * of the hold, from the rolls' limit rows (the limit rows follow the equality and friction rows) and the
 * friction rows at their fixed offsets */
static int grip_ratchet_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force;
  const int ne = d->ne, nf = d->nf, nl = d->nl;
  double clutch[2] = {0.0, 0.0};
  const int start = ne + nf;
  for (int row = start; row < start + nl; row++) {
    if (d->efc_type[row] == mjCNSTR_LIMIT_TENDON) clutch[d->efc_id[row] == g[GC_roll_t0] ? 0 : 1] = efc_force[row];
  }
  if (nf != g[GC_count]) return MISSING_FRICTION_ROWS;
  for (int i = 0; i < 2; i++) {
    const int64_t r = g[GC_roll_off0 + i];
    const double roll_force = r >= 0 ? efc_force[ne + r] : 0.0;
    const double hold = clutch[i] + roll_force, F = s[GS_resist0 + i];
    double state, share;
    if (!(clutch[i] > 0.0 || roll_force > -F)) {
      state = 1.0;
      share = 0.0;
    } else {
      state = grip_skids(cfg, st, i) ? -1.0 : 0.0;
      share = clutch_share(hold, F);
    }
    out[i] = state == 0.0 ? 1.0 : 0.0;
    out[2 + i] = share;
    out[4 + i] = state;
  }
  return STEPS_DONE;
}

const Controller GRIP_RATCHET = {"grip_ratchet", BLOCK_NAMES(GRIP_RATCHET_CONFIG, GC, GRIP_RATCHET_STATE, GS),
                                 .before_step = grip_ratchet_before, .after_step = no_after_step,
                                 .work = grip_work, .reactions = grip_ratchet_reactions, .deferred = no_deferred};

/* ---- CompliantGrip: the compliant part on the roll L_i = x_i - c_i, the carriages' running bound ---- */
#define COMPLIANT_GRIP_CONFIG(X, P) GRIP_CONFIG(X, P) COMPLIANT_CONFIG(X, P)
#define COMPLIANT_GRIP_STATE(X, P) GRIP_STATE(X, P) COMPLIANT_STATE(X, P)
FIELDS(COMPLIANT_GRIP_CONFIG, KC)
FIELDS(COMPLIANT_GRIP_STATE, KS)
/* where the compliant part starts in the block: after the carriages' */
#define SPRING_CONFIG(cfg) (BLOCK_CONFIG(cfg) + KC_act0)
#define SPRING_STATE(st) (BLOCK_STATE(st) + KS_anchor0)

static void compliant_grip_before(const int64_t *cfg, double *st) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  const mjtNum *qpos = DATA(cfg)->qpos, *qvel = DATA(cfg)->qvel;
  for (int i = 0; i < 2; i++) {
    double c = qpos[g[KC_c_q0 + i]];
    double roll = qpos[g[KC_x_q0 + i]] - c;
    compliant_before(cfg, SPRING_CONFIG(cfg), SPRING_STATE(st), i, roll, qvel[g[KC_x_v0 + i]] - qvel[g[KC_c_v0 + i]]);
    carriage_ratchet(cfg, st, i, c);
  }
}

/* CompliantGrip.after_step: the dampers' work at the roll's speed */
static int compliant_grip_after(const int64_t *cfg, double *st) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  const mjtNum *qvel = DATA(cfg)->qvel;
  const double speed[2] = {qvel[g[KC_x_v0]] - qvel[g[KC_c_v0]], qvel[g[KC_x_v1]] - qvel[g[KC_c_v1]]};
  compliant_after(cfg, st, SPRING_CONFIG(cfg), SPRING_STATE(st), speed);
  return STEPS_DONE;
}

/* CompliantGrip.wheels; its forces come from the deferred values, as the compliant's */
static int compliant_grip_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const mjtNum *qvel = d->qvel;
  if (d->nf != g[KC_count]) return MISSING_FRICTION_ROWS;
  out[0] = out[1] = out[2] = out[3] = 0.0;
  for (int i = 0; i < 2; i++) {
    const double vc = qvel[g[KC_c_v0 + i]];
    if (grip_skids(cfg, st, i)) {
      out[4 + i] = -1.0;
    } else if (s[KS_tracking0 + i] != 0.0 && qvel[g[KC_x_v0 + i]] - vc > s[KS_rest_speed]) {
      out[4 + i] = 1.0;
    } else {
      out[4 + i] = 0.0;
    }
  }
  return STEPS_DONE;
}

static void compliant_grip_deferred(const int64_t *cfg, const double *st, double *out) {
  compliant_deferred(cfg, st, SPRING_CONFIG(cfg), SPRING_STATE(st), out);
}

const Controller COMPLIANT_GRIP = {"compliant_grip",
                                   BLOCK_NAMES(COMPLIANT_GRIP_CONFIG, KC, COMPLIANT_GRIP_STATE, KS),
                                   .before_step = compliant_grip_before, .after_step = compliant_grip_after,
                                   .work = grip_work, .reactions = compliant_grip_reactions,
                                   .deferred = compliant_grip_deferred};
