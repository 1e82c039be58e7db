/* The compiled clutch controllers, in one table (see _stepper.h): a controller's index is its place here, and the
 * extension exports each one's name and fields in this order (stepper.py finds a controller by its name). A new
 * controller adds its file (its block and its Controller) and one line here. */
#include "../loop/_stepper.h"

extern const Controller NO_CLUTCH, RATCHET, LOCK_KINEMATIC, LOCK_UNILATERAL, COMPLIANT, GRIP_RATCHET, COMPLIANT_GRIP,
    WHEEL_RATCHET;

const Controller *const CONTROLLERS[] = {
    &NO_CLUTCH,       /* slide_clutches.NoClutch (_clutch_slides.c) */
    &RATCHET,         /* slide_clutches.Ratchet */
    &LOCK_KINEMATIC,  /* slide_clutches.Locks, the paper's rule */
    &LOCK_UNILATERAL, /* slide_clutches.Locks, the one-way rule */
    &COMPLIANT,       /* compliant.CompliantClutches */
    &GRIP_RATCHET,    /* grip.GripRatchet (_clutch_grip.c) */
    &COMPLIANT_GRIP,  /* compliant_grip.CompliantGrip */
    &WHEEL_RATCHET,   /* wheels.WheelRatchet (_clutch_wheels.c) */
};
const int N_CONTROLLERS = (int)(sizeof(CONTROLLERS) / sizeof(CONTROLLERS[0]));
