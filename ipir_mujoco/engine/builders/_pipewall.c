/* The round pipe's wall for MuJoCo: exact contacts between a pipe piece and a sphere, capsule or box.
 *
 * See ipir_mujoco/engine/builders/pipe_walls.py. A pipe piece is a CYLINDER geom marked by its user data
 * (geom_user[0] == PIPE_MAGIC; the model's nuser_geom >= PIPE_NUSER):
 *   user[1] = 1: a straight: the bore of radius user[2] [m] about the geom's z axis, z in [-user[3], user[3]);
 *   user[1] = 2: a bend: a torus section: the centreline the circle of radius user[3] [m] about the geom's z
 *                axis in its xy plane, from the geom's +x axis turning +user[4] [rad] about z (half-open), the
 *                bore of radius user[2] about it.
 * install() replaces MuJoCo's collision functions (the public table mjCOLLISIONFUNC, mujoco.h) for the type
 * pairs (sphere, cylinder), (capsule, cylinder), (cylinder, box): a pair with a marked pipe gets the contact
 * computed from the exact distance to the centreline (normal radial, depth D/2 - (rho + r)), one contact per
 * pair (its deepest point: a capsule's ends and middle, a box's corners); any other pair goes to MuJoCo's own
 * function, unchanged. The table is process-wide and belongs to the libmujoco this module is linked
 * against (the bindings', checked by pipe_walls.py with a probe model). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <mujoco/mujoco.h>

#include <math.h>

#define PIPE_MAGIC 7310.5
#define PIPE_NUSER 5

static mjfCollision original_sphere = NULL, original_capsule = NULL, original_box = NULL;
static int installed = 0;

/* the geom's pipe data, or NULL if it is no marked pipe */
static const mjtNum* pipe_user(const mjModel* m, int g) {
  if (m->geom_type[g] != mjGEOM_CYLINDER || m->nuser_geom < PIPE_NUSER) return NULL;
  const mjtNum* user = m->geom_user + (size_t)g * m->nuser_geom;
  return user[0] == PIPE_MAGIC ? user : NULL;
}

/* For a world point p: whether the piece covers it; if so its distance rho [m] from the centreline and the
 * unit radial direction n (world; from the centreline to the point) and the centreline point c (world). */
static int pipe_point(const mjModel* m, const mjData* d, int g, const mjtNum* user, const mjtNum p[3],
                      mjtNum* rho, mjtNum n[3], mjtNum c[3]) {
  const mjtNum* pos = d->geom_xpos + 3 * g;
  const mjtNum* mat = d->geom_xmat + 9 * g;  /* row-major: column k is the local axis k in world */
  mjtNum dif[3] = {p[0] - pos[0], p[1] - pos[1], p[2] - pos[2]};
  mjtNum loc[3], cl[3], v[3];
  for (int k = 0; k < 3; k++) loc[k] = mat[k] * dif[0] + mat[3 + k] * dif[1] + mat[6 + k] * dif[2];
  if (user[1] == 1.0) {
    if (loc[2] < -user[3] || loc[2] >= user[3]) return 0;
    cl[0] = 0.0; cl[1] = 0.0; cl[2] = loc[2];
  } else {
    mjtNum q = sqrt(loc[0] * loc[0] + loc[1] * loc[1]);
    if (q < 1e-12) return 0;
    mjtNum theta = atan2(loc[1], loc[0]);
    if (theta < 0) theta += 2 * mjPI;
    if (theta >= user[4]) return 0;
    cl[0] = user[3] * loc[0] / q; cl[1] = user[3] * loc[1] / q; cl[2] = 0.0;
  }
  for (int k = 0; k < 3; k++) v[k] = loc[k] - cl[k];
  mjtNum r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (r < 1e-12) return 0;  /* on the centreline: far from any wall */
  *rho = r;
  for (int k = 0; k < 3; k++) {
    n[k] = (mat[3 * k] * v[0] + mat[3 * k + 1] * v[1] + mat[3 * k + 2] * v[2]) / r;
    c[k] = pos[k] + mat[3 * k] * cl[0] + mat[3 * k + 1] * cl[1] + mat[3 * k + 2] * cl[2];
  }
  return 1;
}

/* The deepest of the candidate balls (centres pts, radius rad) against the pipe, as one contact; the normal
 * points from geom1 to geom2: outward (to the wall) when the part is geom1 (sign +1), inward when it is
 * geom2 (sign -1). */
static int pipe_contact(const mjModel* m, const mjData* d, mjPreContact* con, int gpipe, const mjtNum* user,
                        const mjtNum* pts, int npts, mjtNum rad, mjtNum margin, mjtNum sign) {
  mjtNum best = mjMAXVAL, bn[3] = {0}, bc[3] = {0}, brho = 0;
  for (int i = 0; i < npts; i++) {
    mjtNum rho, n[3], c[3];
    if (!pipe_point(m, d, gpipe, user, pts + 3 * i, &rho, n, c)) continue;
    mjtNum dist = user[2] - (rho + rad);
    if (dist < best) {
      best = dist; brho = rho;
      for (int k = 0; k < 3; k++) { bn[k] = n[k]; bc[k] = c[k]; }
    }
  }
  if (!(best < margin)) return 0;
  con->dist = best;
  mjtNum mid = 0.5 * (brho + rad + user[2]);  /* midway between the part's surface and the wall */
  for (int k = 0; k < 3; k++) {
    con->pos[k] = bc[k] + bn[k] * mid;
    con->normal[k] = sign * bn[k];
    con->tangent[k] = 0.0;  /* MuJoCo completes the frame */
  }
  return 1;
}

static int collide_sphere(const mjModel* m, mjData* d, mjPreContact* con, int g1, int g2, mjtNum margin) {
  const mjtNum* user = pipe_user(m, g2);
  if (!user) return original_sphere(m, d, con, g1, g2, margin);
  return pipe_contact(m, d, con, g2, user, d->geom_xpos + 3 * g1, 1, m->geom_size[3 * g1], margin, 1.0);
}

static int collide_capsule(const mjModel* m, mjData* d, mjPreContact* con, int g1, int g2, mjtNum margin) {
  const mjtNum* user = pipe_user(m, g2);
  if (!user) return original_capsule(m, d, con, g1, g2, margin);
  const mjtNum* pos = d->geom_xpos + 3 * g1;
  const mjtNum* mat = d->geom_xmat + 9 * g1;
  mjtNum half = m->geom_size[3 * g1 + 1], pts[9];
  for (int k = 0; k < 3; k++) {
    pts[k] = pos[k] - half * mat[3 * k + 2];
    pts[3 + k] = pos[k];
    pts[6 + k] = pos[k] + half * mat[3 * k + 2];
  }
  return pipe_contact(m, d, con, g2, user, pts, 3, m->geom_size[3 * g1], margin, 1.0);
}

static int collide_box(const mjModel* m, mjData* d, mjPreContact* con, int g1, int g2, mjtNum margin) {
  const mjtNum* user = pipe_user(m, g1);
  if (!user) return original_box(m, d, con, g1, g2, margin);
  const mjtNum* pos = d->geom_xpos + 3 * g2;
  const mjtNum* mat = d->geom_xmat + 9 * g2;
  const mjtNum* size = m->geom_size + 3 * g2;
  mjtNum pts[24];
  for (int i = 0; i < 8; i++) {
    mjtNum l[3] = {(i & 1 ? 1 : -1) * size[0], (i & 2 ? 1 : -1) * size[1], (i & 4 ? 1 : -1) * size[2]};
    for (int k = 0; k < 3; k++) pts[3 * i + k] = pos[k] + mat[3 * k] * l[0] + mat[3 * k + 1] * l[1] + mat[3 * k + 2] * l[2];
  }
  return pipe_contact(m, d, con, g1, user, pts, 8, 0.0, margin, -1.0);
}

static PyObject* py_install(PyObject* self, PyObject* args) {
  if (!installed) {
    original_sphere = mjCOLLISIONFUNC[mjGEOM_SPHERE][mjGEOM_CYLINDER];
    original_capsule = mjCOLLISIONFUNC[mjGEOM_CAPSULE][mjGEOM_CYLINDER];
    original_box = mjCOLLISIONFUNC[mjGEOM_CYLINDER][mjGEOM_BOX];
    if (!original_sphere || !original_capsule || !original_box) {
      PyErr_SetString(PyExc_RuntimeError, "MuJoCo's collision table lacks a cylinder pair");
      return NULL;
    }
    mjCOLLISIONFUNC[mjGEOM_SPHERE][mjGEOM_CYLINDER] = collide_sphere;
    mjCOLLISIONFUNC[mjGEOM_CAPSULE][mjGEOM_CYLINDER] = collide_capsule;
    mjCOLLISIONFUNC[mjGEOM_CYLINDER][mjGEOM_BOX] = collide_box;
    installed = 1;
  }
  Py_RETURN_NONE;
}

static PyObject* py_installed(PyObject* self, PyObject* args) {
  return PyBool_FromLong(installed && mjCOLLISIONFUNC[mjGEOM_SPHERE][mjGEOM_CYLINDER] == collide_sphere &&
                         mjCOLLISIONFUNC[mjGEOM_CAPSULE][mjGEOM_CYLINDER] == collide_capsule &&
                         mjCOLLISIONFUNC[mjGEOM_CYLINDER][mjGEOM_BOX] == collide_box);
}

static PyMethodDef methods[] = {
    {"install", py_install, METH_NOARGS, "Put the pipe's contact functions in MuJoCo's collision table (idempotent)."},
    {"installed", py_installed, METH_NOARGS, "Whether the pipe's contact functions are in the table."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_pipewall", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__pipewall(void) {
  PyObject* mod = PyModule_Create(&module);
  if (mod == NULL) return NULL;
  if (PyModule_AddIntConstant(mod, "MJVERSION_HEADER", mjVERSION_HEADER) < 0 ||
      PyModule_AddObject(mod, "PIPE_MAGIC", PyFloat_FromDouble(PIPE_MAGIC)) < 0 ||
      PyModule_AddIntConstant(mod, "PIPE_NUSER", PIPE_NUSER) < 0) {
    Py_DECREF(mod);
    return NULL;
  }
  return mod;
}
