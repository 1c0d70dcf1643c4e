"""The contact loop of target ``lammps``'s pair style (``compute``: the same text for every
law), a part of ``pair_frictionrules.cpp`` (:mod:`._lammps_sources` puts it together).

The modes (setup or a step, ``history project|rotate``, ``affine``, ``dissipation``, and
whether the input script asks for the force-carrying counts ``fr_carrying``) are template
parameters, so that the loop over contacts has no branch on them. The law comes in
through ``frictionrules_law.h``: ``fr_update`` (for a law with a radial return its structured
return, compiled inline) and ``FR_ISOTROPIC`` (a law that depends on T through |T| only: the
frame along the trial's tangential displacement).
"""

__all__ = ["PAIR_LOOP"]

PAIR_LOOP = r"""void FR_CLASS::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  if (affine && domain->deform_vremap)    // the velocities carry the streaming part already
    error->all(FLERR, "pair_style " FR_STYLE ": affine yes is for fix deform remap x, not remap v");
  // setup (the forces of a run's first step) commits nothing: the force of a contact is the
  // one of its last step, as LAMMPS's granular styles do. The modes are template parameters,
  // so that the contact loop has no branch on them.
  // L = (h - h0) h^-1 / dt (upper triangular, Voigt order xx yy zz yz xz xy), with affine yes:
  // the box's change since the last committed force pass, the remap between the two passes
  double L[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  if (affine && !update->setupflag) affine_rate(L);
  int *carrying = carrying_counts();    // per-atom force-carrying contacts, if asked for
  if (tally)
    carrying ? dispatch<1, 1>(L, carrying) : dispatch<1, 0>(L, carrying);
  else
    carrying ? dispatch<0, 1>(L, carrying) : dispatch<0, 0>(L, carrying);
  if (carrying && force->newton_pair) comm->reverse_comm(this);    // ghosts' counts to owners
}

template <int TALLY, int COUNT> void FR_CLASS::dispatch(const double *L, int *carrying)
{
  if (update->setupflag)
    project ? eval<0, 1, 0, TALLY, COUNT>(L, carrying) : eval<0, 0, 0, TALLY, COUNT>(L, carrying);
  else if (project == 1)
    affine ? eval<1, 1, 1, TALLY, COUNT>(L, carrying) : eval<1, 1, 0, TALLY, COUNT>(L, carrying);
  else if (project == 2)
    affine ? eval<1, 2, 1, TALLY, COUNT>(L, carrying) : eval<1, 2, 0, TALLY, COUNT>(L, carrying);
  else
    affine ? eval<1, 0, 1, TALLY, COUNT>(L, carrying) : eval<1, 0, 0, TALLY, COUNT>(L, carrying);
}

/* The contact loop: COMMIT (not LAMMPS's setup: the history moves on), PROJECT (1 history
   project, 2 history rescale; setup reads no stored history, so it runs as 1 for both), AFFINE (affine yes: Lr the box's velocity gradient), TALLY (dissipation yes), COUNT
   (the property fr_carrying defined: each atom's contacts with N > 0 added to carrying). */
template <int COMMIT, int PROJECT, int AFFINE, int TALLY, int COUNT>
void FR_CLASS::eval(const double *Lr, int *carrying)
{
  constexpr FrLayout H(PROJECT, TALLY);
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
  // members copied to locals: the stores of the loop could alias them otherwise (reloads)
  const double *p1 = atom->ntypes == 1 ? params(1, 1) : nullptr;
  const double skin = this->skin;
  const int reach_on = skin > 0.0;
  const int at_contact = lever;    // the torques' lever r - delta/2 (pair granular's), or r
  const double axis[3] = {this->axis[0], this->axis[1], this->axis[2]};
  const int stride = H.size;
  const double L[6] = {Lr[0], Lr[1], Lr[2], Lr[3], Lr[4], Lr[5]};

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
      if (rsq >= radsum * radsum && (!touch[jj] || !reach_on || rsq > reach * reach)) {
        touch[jj] = 0;    // not touching, or opened beyond the skin: a later contact starts afresh
        continue;
      }
      double *h = allhist + static_cast<size_t>(stride) * jj;
      const int swap = tag[i] > tag[j];
      const double sg = swap ? -1.0 : 1.0;    // l = x_b - x_a = sg (x_j - x_i)
      const double dist = sqrt(rsq), gap = dist - radsum, inv = sg / dist;
      const double n[3] = {d0 * inv, d1 * inv, d2 * inv};
      const int fresh = !touch[jj];
      double g[3], Nc;    // the force on a, its normal part N (> 0 in compression)
      const double *p = p1 ? p1 : params(type[i], type[j]);
      if (!COMMIT && !fresh) {
        Nc = fr_last_force(h, H.pn, p, gap, n, g);
      } else {
        double state[FR_NSTATE], next[FR_NSTATE], inc[3] = {0.0, 0.0, gap}, frc[3];
        fr_initial_state(state);
        // the trial's elastic tangential displacement as a global vector e: the stored one
        // carried to this step's contact plane, plus the increment; the law's state holds it
        // in the frame (t1, t2), de_n = dp = 0 (the increment carries the whole normal
        // displacement, less the plastic one; the law never reads dp)
        double e[3] = {0.0, 0.0, 0.0};
        if (!fresh) {
          if (PROJECT) {    // gran/hooke/history: projected on the new plane (below), no twist
            for (int c = 0; c < 3; c++) e[c] = h[H_ET + c];
            if (PROJECT == 2) {
              // pair granular's linear_history: projected on the new plane and rescaled to its
              // length before the increment (its operations, in its order)
              const double en = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
              const double before = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
              for (int c = 0; c < 3; c++) e[c] -= en * n[c];
              const double after = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
              const double scale = after > 0.0 ? before / after : 0.0;
              for (int c = 0; c < 3; c++) e[c] *= scale;
            }
          } else {
            // the products with the branch d start before the normal n = d inv is known
            // (inv = sg/|d|): n.u = (d.u) inv, 1/(1 + n0.n) = |d|/(|d| + sg n0.d)
            const double *n0 = h + H.n0, *ue = h + H_ET;
            const double n0d = n0[0] * d0 + n0[1] * d1 + n0[2] * d2;
            const double ud = ue[0] * d0 + ue[1] * d1 + ue[2] * d2;
            const double wd = (omega[i][0] + omega[j][0]) * d0 + (omega[i][1] + omega[j][1]) * d1
                              + (omega[i][2] + omega[j][2]) * d2;
            const double m[3] = {n0[0] + n[0], n0[1] + n[1], n0[2] + n[2]};
            const double k = dist / (dist + sg * n0d);
            // the twist: an exact rotation by 2 atan(s), s = tan(theta/2) to O(theta^5)
            double s = 0.25 * dt * wd * inv;
            s += s * s * s * (1.0 / 3.0);
            const double is = 1.0 / (1.0 + s * s);
            fr_turn(ue, m, ud * inv * k, n, (1.0 - s * s) * is, 2.0 * s * is, e);
          }
          for (int q = 0; q < FR_NQ; q++) state[6 + q] = h[H.q + q];
#if FR_NORMAL_SLIP
          inc[2] = gap - h[H.pn];
#endif
        }
        if (COMMIT && (PROJECT || !fresh)) {
          // gran/hooke/history: the first step of a contact slides already
          const double W[3] = {ri * omega[i][0] + rj * omega[j][0],
                               ri * omega[i][1] + rj * omega[j][1],
                               ri * omega[i][2] + rj * omega[j][2]};
          double Ll[3] = {0.0, 0.0, 0.0};
          if (AFFINE) {    // l = sg (x_j - x_i) = sg d
            Ll[0] = sg * (L[0] * d0 + L[5] * d1 + L[4] * d2);
            Ll[1] = sg * (L[1] * d1 + L[3] * d2);
            Ll[2] = sg * L[2] * d2;
          }
          const double u[3] = FR_RELATIVE_VELOCITY;
          if (!PROJECT && FR_ISOTROPIC) {
            // the turned history lies in the contact plane already: only the increment's
            // normal part is taken off (beside the turn, not after it)
            const double un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
            for (int c = 0; c < 3; c++) e[c] += dt * (u[c] - un * n[c]);
          } else {
            for (int c = 0; c < 3; c++) e[c] += dt * u[c];
          }
        }
        double t1[3], t2[3];
#if FR_ISOTROPIC
        // the law depends on the tangential force through |T| only: t1 along e (the law sees
        // (|e|, 0)), the frame of the reference axis where e = 0; the stored vector projected
        // on the contact plane (history project|rescale, and a step's increment)
        if (PROJECT) {
          const double en = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
          for (int c = 0; c < 3; c++) e[c] -= en * n[c];
        }
        const double es = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        if (es > 0.0) {
          const double ei = 1.0 / es;
          for (int c = 0; c < 3; c++) t1[c] = e[c] * ei;
        } else {
          fr_frame(n[0], n[1], n[2], axis, t1);
        }
        state[0] = es;
#else
        fr_frame(n[0], n[1], n[2], axis, t1);
        t2[0] = n[1] * t1[2] - n[2] * t1[1];
        t2[1] = n[2] * t1[0] - n[0] * t1[2];
        t2[2] = n[0] * t1[1] - n[1] * t1[0];
        state[0] = e[0] * t1[0] + e[1] * t1[1] + e[2] * t1[2];
        state[1] = e[0] * t2[0] + e[1] * t2[1] + e[2] * t2[2];
#endif
        const int status = fr_update(p, state, inc, next, frc);
        if (status < 0)
          error->one(FLERR, "pair_style " FR_STYLE ": the return map failed at the contact of "
                            "atoms {} and {} (increment {} {} {})", swap ? tag[j] : tag[i],
                     swap ? tag[i] : tag[j], inc[0], inc[1], inc[2]);
        const double T1 = frc[0], T2 = frc[1], N = frc[2];
        Nc = N;
        double de[3];    // the new elastic tangential displacement, global
        for (int c = 0; c < 3; c++) {
          g[c] = T1 * t1[c] - N * n[c];
          de[c] = next[0] * t1[c];
        }
        if (!FR_ISOTROPIC || T2 != 0.0 || next[1] != 0.0) {
          if (FR_ISOTROPIC) {
            t2[0] = n[1] * t1[2] - n[2] * t1[1];
            t2[1] = n[2] * t1[0] - n[0] * t1[2];
            t2[2] = n[0] * t1[1] - n[1] * t1[0];
          }
          for (int c = 0; c < 3; c++) {
            g[c] += T2 * t2[c];
            de[c] += next[1] * t2[c];
          }
        }
        if (COMMIT) {
          touch[jj] = 1;
          for (int c = 0; c < 3; c++) {
            h[H_ET + c] = de[c];
            if (!PROJECT) h[H.n0 + c] = n[c];
          }
          if (TALLY) {
            const double diss = T1 * next[3] + T2 * next[4] - N * next[5];
            h[H_DISS] = fresh ? diss : h[H_DISS] + diss;
            h[H_STATUS] = status;
          }
#if FR_NORMAL_SLIP
          h[H.pn] = fresh ? next[5] : h[H.pn] + next[5];
#endif
          for (int q = 0; q < FR_NQ; q++) h[H.q + q] = next[6 + q];
        }
      }
      const double ng[3] = {n[1] * g[2] - n[2] * g[1], n[2] * g[0] - n[0] * g[2],
                            n[0] * g[1] - n[1] * g[0]};
      const double fi[3] = {sg * g[0], sg * g[1], sg * g[2]};    // g on a, -g on b
      const double li = at_contact ? ri + 0.5 * gap : ri, lj = at_contact ? rj + 0.5 * gap : rj;
      f[i][0] += fi[0];
      f[i][1] += fi[1];
      f[i][2] += fi[2];
      torque[i][0] += li * ng[0];
      torque[i][1] += li * ng[1];
      torque[i][2] += li * ng[2];
      if (newton_pair || j < nlocal) {
        f[j][0] -= fi[0];
        f[j][1] -= fi[1];
        f[j][2] -= fi[2];
        torque[j][0] += lj * ng[0];
        torque[j][1] += lj * ng[1];
        torque[j][2] += lj * ng[2];
      }
      if (evflag)
        ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, fi[0], fi[1], fi[2], -d0, -d1, -d2);
      if (COUNT && Nc > 0.0) {    // a force-carrying contact
        carrying[i]++;
        if (newton_pair || j < nlocal) carrying[j]++;
      }
    }
  }
}

"""
