/* The round-pipe model's hub ratchets, compiled (see _stepper.h): WheelRatchet in wheels.py (before_step, states)
 * and the wheeled loop's work rates (wheels.WheelPower), step for step as there: the same double arithmetic in
 * the same order, the contacts' J v from MuJoCo's mj_mulJacVec in both (tests/test_mujoco_stepper.py holds the two
 * equal bit for bit). The per-hub, per-joint and per-geom arrays are compiled_wheels.py's, by their addresses. */
#include "../../loop/_stepper.h"

#define WHEELS_CONFIG(X, P)                                                                                     \
  X(P, nhub) X(P, per_module) X(P, friction_count) X(P, x_v0) X(P, x_v1) X(P, elliptic) X(P, ngeom) X(P, hub_q) \
  X(P, hub_joint) X(P, hub_row) X(P, joint_module) X(P, geom_module) X(P, work_dofs) X(P, stick) X(P, margin)  \
  X(P, bound)
#define WHEELS_STATE(X, P) X(P, radius) X(P, cone) X(P, rest_speed) X(P, skid_speed) X(P, resist0) X(P, resist1)
FIELDS(WHEELS_CONFIG, WC)
FIELDS(WHEELS_STATE, WS)

/* WheelRatchet.before_step: each hub's lower limit raised to its running maximum (RunningBound, lower_bound), or
 * its give on the wall, R (max - angle), noted as excursion */
static void wheels_before(const int64_t *cfg, double *st) {
  const int64_t *w = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjtNum *qpos = DATA(cfg)->qpos;
  mjtNum *range = MODEL(cfg)->jnt_range;
  const int64_t *hub_q = ARRAY(const int64_t *, w[WC_hub_q]), *joint = ARRAY(const int64_t *, w[WC_hub_joint]);
  const double *margin = ARRAY(const double *, w[WC_margin]);
  double *bound = ARRAY(double *, w[WC_bound]);
  const double radius = s[WS_radius];
  for (int64_t k = 0; k < w[WC_nhub]; k++) {
    const double angle = qpos[hub_q[k]];
    const double back = follow(&bound[k], angle, 0);
    if (back < 0.0) {
      range[2 * joint[k]] = lower_bound(angle, margin[k]);
    } else {
      const double give = back * radius;
      if (give > st[S_excursion]) st[S_excursion] = give;
    }
  }
}

/* WheelPower: the hubs' friction rows times the hubs' speeds; the contacts' tangential rows (all of a pyramidal
 * cone's) times their speeds J v_{n+1}, summed row by row */
static int wheels_work(const int64_t *cfg, double *st, double *rolling, double *skidding) {
  (void)st;
  const int64_t *w = BLOCK_CONFIG(cfg);
  const mjModel *m = MODEL(cfg);
  mjData *d = DATA(cfg);
  const mjtNum *force = d->efc_force, *qvel = d->qvel;
  const int64_t *dofs = ARRAY(const int64_t *, w[WC_work_dofs]);
  if (d->nf != w[WC_friction_count]) return MISSING_FRICTION_ROWS;
  const int ne = d->ne, first = d->ne + d->nf + d->nl, nefc = d->nefc;
  double hubs = 0.0, contacts = 0.0;
  for (int k = 0; k < d->nf; k++) hubs += force[ne + k] * qvel[dofs[k]];
  if (nefc > first) {
    mj_markStack(d);
    mjtNum *jv = mj_stackAllocNum(d, nefc);
    mj_mulJacVec(m, d, jv, qvel);
    const int elliptic = w[WC_elliptic] != 0;
    for (int row = first; row < nefc; row++) {
      if (elliptic && (row - first) % 3 == 0) continue; /* a contact's normal row */
      contacts += force[row] * jv[row];
    }
    mj_freeStack(d);
  }
  *rolling = hubs;
  *skidding = contacts;
  return STEPS_DONE;
}

/* WheelRatchet.states: per module its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share
 * of the hold, from its hubs' limit and friction rows and its contacts' forces; out as reactions() writes it */
static int wheels_reactions(const int64_t *cfg, const double *st, double out[N_REACTIONS]) {
  const int64_t *w = BLOCK_CONFIG(cfg);
  const double *s = BLOCK_STATE(st);
  const mjData *d = DATA(cfg);
  const mjtNum *force = d->efc_force;
  const int64_t *joint_module = ARRAY(const int64_t *, w[WC_joint_module]);
  const int64_t *geom_module = ARRAY(const int64_t *, w[WC_geom_module]);
  const int64_t *hub_row = ARRAY(const int64_t *, w[WC_hub_row]);
  const double *stick = ARRAY(const double *, w[WC_stick]);
  if (d->nf != w[WC_friction_count]) return MISSING_FRICTION_ROWS;
  const int ne = d->ne, start = d->ne + d->nf;
  double limits[2] = {0.0, 0.0}, friction[2] = {0.0, 0.0}, normal[2] = {0.0, 0.0}, tangential[2] = {0.0, 0.0};
  int sticks[2] = {0, 0};
  for (int row = start; row < start + d->nl; row++) { /* a hub's limit row (an arm's stop is no clutch) */
    if (d->efc_type[row] == mjCNSTR_LIMIT_JOINT) {
      const int64_t module = joint_module[d->efc_id[row]];
      if (module >= 0) limits[module] += force[row];
    }
  }
  for (int i = 0; i < 2; i++) {
    for (int64_t k = i * w[WC_per_module]; k < (i + 1) * w[WC_per_module]; k++) {
      if (hub_row[k] < 0) continue;
      const double f = force[ne + hub_row[k]];
      friction[i] += f;
      if (f > stick[k]) sticks[i] = 1;
    }
  }
  for (int c = 0; c < d->ncon; c++) { /* WheelRatchet.contacts: a module's wheels' and housing's */
    const mjContact *con = d->contact + c;
    const int64_t ngeom = w[WC_ngeom];
    const int g1 = con->geom[0], g2 = con->geom[1];
    const int in1 = g1 >= 0 && g1 < ngeom && geom_module[g1] >= 0;
    const int g = in1 ? g1 : g2;
    const int64_t i = g >= 0 && g < ngeom ? geom_module[g] : -1;
    const int a = con->efc_address;
    if (i < 0 || a < 0) continue;
    const double t1 = force[a + 1], t2 = force[a + 2];
    normal[i] += force[a];
    tangential[i] += sqrt(t1 * t1 + t2 * t2);
  }
  for (int i = 0; i < 2; i++) {
    double state = 1.0, share = 0.0; /* rolling */
    if (limits[i] > 0.0 || sticks[i]) {
      const double hold = (limits[i] + friction[i]) / s[WS_radius];
      int skids;
      if (normal[i] > 0.0) {
        skids = tangential[i] >= s[WS_cone] * normal[i];
      } else {
        skids = d->qvel[w[WC_x_v0 + i]] < -s[WS_rest_speed];
      }
      skids = skids || d->qvel[w[WC_x_v0 + i]] < -s[WS_skid_speed]; /* held modules stand (SKID_SPEED) */
      state = skids ? -1.0 : 0.0;
      share = clutch_share(hold, s[WS_resist0 + i]);
    }
    out[i] = state == 0.0 ? 1.0 : 0.0; /* held: standing */
    out[2 + i] = share;
    out[4 + i] = state;
  }
  return STEPS_DONE;
}

const Controller WHEEL_RATCHET = {"wheel_ratchet", BLOCK_NAMES(WHEELS_CONFIG, WC, WHEELS_STATE, WS),
                                  .before_step = wheels_before, .after_step = no_after_step, .work = wheels_work,
                                  .reactions = wheels_reactions, .deferred = no_deferred};
