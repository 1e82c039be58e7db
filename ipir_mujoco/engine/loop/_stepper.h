/* The compiled stepping loop's shared declarations (see _stepper.c and ipir_mujoco/engine/loop/stepper.py).
 *
 * Layout: two arrays owned by Python, one int64 per CONFIG field (addresses, indices, flags) and one double per
 * STATE field (what the loop reads and writes). Each array holds the loop's own block (LOOP_CONFIG, LOOP_STATE)
 * followed by the clutch controller's block: every controller declares its own fields (a list such as
 * RATCHET_CONFIG(X, P) in controllers/_clutch_slides.c) and its table entry (Controller: its functions and its fields'
 * names), so a new controller adds a block and an entry and edits nothing shared. The module exports the loop's
 * names and each controller's, and stepper.py builds its indices from them.
 *
 * A block is a list of fields X(P, name); FIELDS(LIST, P) makes the enum P_name (the field's index in the block)
 * and P_COUNT, NAMES(LIST) its names. A block may start with, or contain, a shared sub-block (the grip's rows,
 * the compliant clutch's spring): the sub-block's functions take a pointer to where it starts.
 */
#ifndef IPIR_MUJOCO_STEPPER_H
#define IPIR_MUJOCO_STEPPER_H

#include <mujoco/mujoco.h>

#include <math.h>
#include <stdint.h>

/* the loop's block: the run's model and data, the drive, the slides' resistance rows (the loop option
 * friction_dofs), the recorder's arrays and what a sample reads; the controller's index in CONTROLLERS */
#define LOOP_CONFIG(X)                                                                                    \
  X(model) X(data) X(qvel_before) X(eq_rows) X(controller) X(motor) X(crank_q) X(crank_v) X(nfric)        \
  X(fric_a) X(fric_b) X(rod_site) X(front_body) X(loop_eq) X(rec_t) X(rec_qpos) X(rec_qvel) X(rec_scalars) \
  X(rec_deferred) X(rec_excursion)
/* the loop's works, the controller's common outputs (excursion, damper_work), the sample's constants and
 * counters */
#define LOOP_STATE(X)                                                                                     \
  X(dt) X(slope) X(torque) X(motor_work) X(friction_work) X(skid_work) X(damper_work) X(omega_prev)        \
  X(excursion) X(pin_x) X(pin_y) X(pin_z) X(total_mass) X(count) X(steps_done)

#define AS_ENUM(name) C_##name,
enum { LOOP_CONFIG(AS_ENUM) N_CONFIG };
#undef AS_ENUM
#define AS_ENUM(name) S_##name,
enum { LOOP_STATE(AS_ENUM) N_STATE };
#undef AS_ENUM

/* a controller's block: FIELDS(LIST, P) -> enum { P_a, P_b, ..., P_COUNT }; NAMES(LIST) -> "a", "b", ... */
#define FIELD_ENUM(P, name) P##_##name,
#define FIELD_NAME(P, name) #name,
#define FIELDS(LIST, P) enum { LIST(FIELD_ENUM, P) P##_COUNT };
#define NAMES(LIST) LIST(FIELD_NAME, _)

/* the controller's block, after the loop's */
#define BLOCK_CONFIG(cfg) ((cfg) + N_CONFIG)
#define BLOCK_STATE(st) ((st) + N_STATE)

#define PTR(type, field) ((type)(intptr_t)cfg[C_##field])
#define MODEL(cfg) ((mjModel *)(intptr_t)(cfg)[C_model])
#define DATA(cfg) ((mjData *)(intptr_t)(cfg)[C_data])
#define ARRAY(type, address) ((type)(intptr_t)(address)) /* an array of the controller's, by its address */

/* what the loop's and a controller's functions return: done, or which constraint rows they were to read are
 * absent after a step (the Python loop raises for the same two: rows.MISSING_ROWS holds the same order) */
enum { STEPS_DONE = 0, MISSING_LOCK_ROW = 1, MISSING_FRICTION_ROWS = 2 };

/* reactions() writes, per sample: rear held, front held (1.0 / 0.0), rear and front reaction [N], the wheels'
 * states (+1.0 rolling, 0.0 standing, -1.0 skidding; 0.0 without wheels) */
enum { N_REACTIONS = 6 };

/* A clutch controller's compiled form: what the loop calls, and its block's names; every function is given (the
 * loop tests none of them: no_before_step, no_after_step and no_deferred below stand for nothing to do).
 *
 * before_step: the clutch update before each mj_step. after_step: its bookkeeping after the step. work: the work
 * rates after the step [W] (the loop's option power: its load_compiled checks that it is the one this counts), the
 * resistances' (rolling) and the grips' or contacts' against skidding (skidding). reactions: the sample's
 * N_REACTIONS values. deferred: its clutch forces, overlaps and stepped spring energy at the start of the next step
 * into the recorder's deferred row (ClutchController.deferred_values: DEFERRED_VALUES of them). The int functions
 * return STEPS_DONE or a MISSING_* code. */
typedef struct {
  const char *name;
  const char *const *config;
  int n_config;
  const char *const *state;
  int n_state;
  void (*before_step)(const int64_t *cfg, double *st);
  int (*after_step)(const int64_t *cfg, double *st);
  int (*work)(const int64_t *cfg, double *st, double *rolling, double *skidding);
  int (*reactions)(const int64_t *cfg, const double *st, double out[N_REACTIONS]);
  void (*deferred)(const int64_t *cfg, const double *st, double *out);
} Controller;

/* a table entry's names: its CONFIG list (enum prefix CP) and STATE list (prefix SP) */
#define BLOCK_NAMES(CONFIG, CP, STATE, SP)                                             \
  .config = (const char *const[]){NAMES(CONFIG) NULL}, .n_config = CP##_COUNT, \
  .state = (const char *const[]){NAMES(STATE) NULL}, .n_state = SP##_COUNT

/* the table of controllers (controllers/_clutch_table.c): a controller's index is its place there */
extern const Controller *const CONTROLLERS[];
extern const int N_CONTROLLERS;

/* what the recorder's deferred row holds after the loop's four values (_stepper.c's DEFERRED_FIELDS): the
 * controller's DEFERRED_VALUES, clutch_force1, clutch_force2, clutch_overlap1, clutch_overlap2, clutch_spring */
enum { DEFERRED_CLUTCH = 4, DEFERRED_VALUES = 5 };

/* a table entry's functions where a controller has nothing to do: before a step, after it, no deferred values */
static inline void no_before_step(const int64_t *cfg, double *st) {
  (void)cfg;
  (void)st;
}

static inline int no_after_step(const int64_t *cfg, double *st) {
  (void)cfg;
  (void)st;
  return STEPS_DONE;
}

static inline void no_deferred(const int64_t *cfg, const double *st, double *out) {
  (void)cfg;
  (void)st;
  for (int i = 0; i < DEFERRED_VALUES; i++) out[i] = 0.0;
}

/* first constraint row of equality eq (active): the active equalities' rows come first, in id order */
static inline int64_t equality_row(const int64_t *cfg, int64_t eq) {
  const mjtBool *active = DATA(cfg)->eq_active;
  const int64_t *rows = PTR(const int64_t *, eq_rows);
  int64_t row = 0;
  for (int64_t e = 0; e < eq; e++) {
    if (active[e]) row += rows[e];
  }
  return row;
}

/* rows.clutch_share: the clutch's part of a held module's total hold (Python's max and min, in order) */
static inline double clutch_share(double hold, double resistance) {
  double bounded = -resistance > hold ? -resistance : hold;
  double pushed = 0.0 < bounded ? 0.0 : bounded;
  return hold - pushed;
}

/* controller.follow: a coordinate's running maximum (upper: minimum) *extreme after its new value; returns the
 * value's give, how far it lies behind the extreme it had (> 0 where it went back), < 0 where it passed it (and
 * *extreme is value now). The one rule of every ratchet: the controllers' compiled forms all follow through it. */
static inline double follow(double *extreme, double value, int upper) {
  const double give = upper ? value - *extreme : *extreme - value;
  if (give < 0.0) *extreme = value;
  return give;
}

/* controller.lower_bound / upper_bound: one margin below (above) value, moved by ulps until MuJoCo's distance
 * to it is below the margin */
static inline double lower_bound(double value, double margin) {
  double bound = value - margin;
  while (value - bound >= margin) bound = nextafter(bound, INFINITY);
  return bound;
}

static inline double upper_bound(double value, double margin) {
  double bound = value + margin;
  while (bound - value >= margin) bound = nextafter(bound, -INFINITY);
  return bound;
}

/* rows.FrictionRows.forces: two modules' frictionloss rows at their offsets (-1: none, 0.0); the step just taken
 * has checked that the rows are there */
static inline void friction_forces(const double *efc_force, int ne, const int64_t offset[2], double out[2]) {
  for (int i = 0; i < 2; i++) out[i] = offset[i] >= 0 ? efc_force[ne + offset[i]] : 0.0;
}

#endif
