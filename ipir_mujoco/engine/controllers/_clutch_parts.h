/* Parts several compiled clutch controllers share: each a sub-block of fields and its functions, which take a
 * pointer to where the sub-block starts in the controller's block (see _stepper.h).
 *
 * COMPLIANT_PART: the compliant clutch's spring, damper and ratcheting anchor on a coordinate (compliant.py's
 * CompliantClutches; on the slide x_i, or with finite grip on the roll x_i - c_i).
 * GRIP_PART: the finite-grip model's carriages (builders/grip_model.py): their rows (the loop option grip), their
 * running bound (the wall) and grips G_i; a grip controller's block starts with it.
 */
#ifndef IPIR_MUJOCO_CLUTCH_PARTS_H
#define IPIR_MUJOCO_CLUTCH_PARTS_H

#include "../loop/_stepper.h"

/* ---- the compliant clutch ---- */
#define COMPLIANT_CONFIG(X, P) X(P, act0) X(P, act1) X(P, implicit)
#define COMPLIANT_STATE(X, P)                                                                                     \
  X(P, anchor0) X(P, anchor1) X(P, overlap0) X(P, overlap1) X(P, v_before0) X(P, v_before1) X(P, damped0)       \
  X(P, damped1) X(P, tracking0) X(P, tracking1) X(P, k) X(P, c) X(P, backlash)
FIELDS(COMPLIANT_CONFIG, CPC)
FIELDS(COMPLIANT_STATE, CPS)

/* CompliantClutches.before_step for module i at ``coord`` [m] moving at ``speed`` [m/s]: raise its anchor to
 * coord - backlash if it went further, note the overlap and speed, switch the damper on while d > 0 */
static inline void compliant_before(const int64_t *cfg, const int64_t *p, double *ps, int i, double coord,
                                    double speed) {
  mjtNum *ctrl = DATA(cfg)->ctrl, *biasprm = MODEL(cfg)->actuator_biasprm;
  const int64_t act = p[CPC_act0 + i];
  const int tracking = follow(&ps[CPS_anchor0 + i], coord - ps[CPS_backlash], 0) < 0.0; /* the anchor's running max */
  ps[CPS_tracking0 + i] = tracking ? 1.0 : 0.0;
  if (tracking) ctrl[act] = ps[CPS_anchor0 + i];
  const double d = ps[CPS_anchor0 + i] - coord;
  ps[CPS_overlap0 + i] = d;
  ps[CPS_v_before0 + i] = speed;
  if ((d > 0.0) != (ps[CPS_damped0 + i] != 0.0)) {
    ps[CPS_damped0 + i] = d > 0.0 ? 1.0 : 0.0;
    biasprm[act * mjNBIAS + 2] = d > 0.0 ? -ps[CPS_c] : 0.0;
  }
}

/* CompliantClutches.after_step: the dampers' work over the step just taken, the modules' coordinates moving at
 * ``speed`` [m/s] after it, added to the loop's damper_work */
static inline void compliant_after(const int64_t *cfg, double *st, const int64_t *p, const double *ps,
                                   const double speed[2]) {
  const mjtNum *force = DATA(cfg)->actuator_force;
  double work = 0.0;
  for (int i = 0; i < 2; i++) {
    double d = ps[CPS_overlap0 + i], applied = force[p[CPC_act0 + i]];
    if (d <= 0.0 && applied == 0.0) continue;
    if (applied > 0.0 && ps[CPS_damped0 + i] != 0.0 && p[CPC_implicit]) {
      applied -= ps[CPS_c] * (speed[i] - ps[CPS_v_before0 + i]);
    }
    work += ((d > 0.0 ? ps[CPS_k] * d : 0.0) - applied) * speed[i];
  }
  st[S_damper_work] += work * st[S_dt];
}

/* Recorder.fill_deferred's clutch part: the clutch forces, the overlaps their before_step set for this state and
 * CompliantClutches.stepped_spring_energy, into out[0..4] */
static inline void compliant_deferred(const int64_t *cfg, const double *st, const int64_t *p, const double *ps,
                                      double *out) {
  const mjtNum *force = DATA(cfg)->actuator_force;
  const double k = ps[CPS_k], dt = st[S_dt];
  double spring = 0.0;
  for (int i = 0; i < 2; i++) {
    double d = ps[CPS_overlap0 + i];
    out[i] = force[p[CPC_act0 + i]];
    out[2 + i] = d;
    if (d > 0.0) spring += 0.5 * k * d * (d + dt * ps[CPS_v_before0 + i]);
  }
  out[4] = spring;
}

/* ---- the carriages of finite grip (a grip controller's block starts with this part) ---- */
#define GRIP_CONFIG(X, P)                                                                                         \
  X(P, count) X(P, roll_off0) X(P, roll_off1) X(P, grip_off0) X(P, grip_off1) X(P, x_q0) X(P, x_q1) X(P, x_v0)  \
  X(P, x_v1) X(P, c_q0) X(P, c_q1) X(P, c_v0) X(P, c_v1) X(P, skid_j0) X(P, skid_j1) X(P, rolling_tendon)
#define GRIP_STATE(X, P) X(P, cmin0) X(P, cmin1) X(P, cmargin0) X(P, cmargin1) X(P, grip0) X(P, grip1) X(P, rest_speed)
FIELDS(GRIP_CONFIG, GPC)
FIELDS(GRIP_STATE, GPS)

/* the carriage update of both grip controllers (GripRatchet and CompliantGrip.before_step): module i's carriage
   at c may only move back, its forward bound lowered to its running minimum; a carriage pushed forward again
   counts as excursion */
static inline void carriage_ratchet(const int64_t *cfg, double *st, int i, double c) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  double *gs = BLOCK_STATE(st);
  const double give = follow(&gs[GPS_cmin0 + i], c, 1);
  if (give < 0.0) {
    MODEL(cfg)->jnt_range[2 * g[GPC_skid_j0 + i] + 1] = upper_bound(c, gs[GPS_cmargin0 + i]);
  } else if (give > st[S_excursion]) {
    st[S_excursion] = give;
  }
}

/* PythonSteps._friction_power with finite grip: the rolling resistances' rows at the roll's speed v_x - v_c
 * (on the roll tendon: rigid clutches) or the slide's v_x (compliant ones), the grips' at the carriages' v_c */
static inline int grip_work(const int64_t *cfg, double *st, double *rolling, double *skidding) {
  (void)st;
  const int64_t *g = BLOCK_CONFIG(cfg);
  const mjData *d = DATA(cfg);
  const mjtNum *efc_force = d->efc_force, *qvel = d->qvel;
  const int ne = d->ne;
  if (d->nf != g[GPC_count]) return MISSING_FRICTION_ROWS;
  const int tendon = g[GPC_rolling_tendon] != 0;
  double roll_work = 0.0, skid_work = 0.0;
  for (int i = 0; i < 2; i++) {
    const int64_t roll = g[GPC_roll_off0 + i], grip_row = g[GPC_grip_off0 + i];
    const double vx = qvel[g[GPC_x_v0 + i]], vc = qvel[g[GPC_c_v0 + i]];
    if (roll >= 0) roll_work += efc_force[ne + roll] * (tendon ? vx - vc : vx);
    if (grip_row >= 0) skid_work += efc_force[ne + grip_row] * vc;
  }
  *rolling = roll_work;
  *skidding = skid_work;
  return STEPS_DONE;
}

/* whether module i's carriage skids: its friction row at G_i, or with G_i = 0 moving back faster than rest */
static inline int grip_skids(const int64_t *cfg, const double *st, int i) {
  const int64_t *g = BLOCK_CONFIG(cfg);
  const double *gs = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const int64_t row = g[GPC_grip_off0 + i];
  const double grip_force = row >= 0 ? d->efc_force[d->ne + row] : 0.0, G = gs[GPS_grip0 + i];
  return G > 0.0 ? grip_force >= G : d->qvel[g[GPC_c_v0 + i]] < -gs[GPS_rest_speed];
}

#endif
