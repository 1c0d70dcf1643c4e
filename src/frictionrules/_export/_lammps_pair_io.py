"""The second half of ``pair_frictionrules.cpp`` (:mod:`._lammps_sources`): the affine rate
from the box's change, the force-carrying counts per atom and their reverse communication,
the history's transfer, ``single()`` (``compute pair/local``; the layout ``FrLayout`` of
``history project|rotate`` and ``dissipation yes|no``) and the restart (the settings: the
law's sizes, ``project``, ``affine``, ``tally``, the last box and the history fix's name).
The same text for every law."""

__all__ = ["PAIR_IO_CPP"]


PAIR_IO_CPP = r"""
/* The velocity gradient L of the box's change since the last committed step's force pass (zero
   at the first one), L dt = (h - h0) h^-1: fix deform's remap x took each branch l0 to
   l = h h0^-1 l0, so l - l0 = L l dt exactly; the box of this pass kept as h0 for the next. */
void FR_CLASS::affine_rate(double *L)
{
  const double *h = domain->h;
  if (box0_set) {
    const double dt = update->dt;
    double hr[6];
    for (int k = 0; k < 6; k++) hr[k] = (h[k] - box0[k]) / dt;
    const double *hi = domain->h_inv;
    L[0] = hr[0] * hi[0];
    L[1] = hr[1] * hi[1];
    L[2] = hr[2] * hi[2];
    L[3] = hr[1] * hi[3] + hr[3] * hi[2];
    L[4] = hr[0] * hi[4] + hr[5] * hi[3] + hr[4] * hi[2];
    L[5] = hr[0] * hi[5] + hr[5] * hi[1];
  }
  for (int k = 0; k < 6; k++) box0[k] = h[k];
  box0_set = 1;
}

/* The per-atom integer property fr_carrying (fix property/atom i_fr_carrying), zeroed here and
   filled by compute() with each local atom's force-carrying contacts (N > 0, open contacts of
   the skin pushing included); none where the input script does not define it. newton off: a
   pair across two ranks is computed on both, each counting its own atom; newton on: once, the
   ghost's count sent back to its owner (reverse communication). */
int *FR_CLASS::carrying_counts()
{
  int flag = -1, cols = -1;
  const int index = atom->find_custom("fr_carrying", flag, cols);
  if (index < 0) return nullptr;
  if (flag != 0 || cols != 0)
    error->all(FLERR, "pair_style " FR_STYLE ": the property fr_carrying must be one integer "
                      "per atom (fix property/atom i_fr_carrying)");
  int *counts = atom->ivector[index];
  const int n = atom->nlocal + (force->newton_pair ? atom->nghost : 0);
  for (int i = 0; i < n; i++) counts[i] = 0;
  return counts;
}

int FR_CLASS::pack_reverse_comm(int n, int first, double *buf)
{
  int flag = -1, cols = -1;
  const int *counts = atom->ivector[atom->find_custom("fr_carrying", flag, cols)];
  for (int i = 0; i < n; i++) buf[i] = counts[first + i];
  return n;
}

void FR_CLASS::unpack_reverse_comm(int n, int *list, double *buf)
{
  int flag = -1, cols = -1;
  int *counts = atom->ivector[atom->find_custom("fr_carrying", flag, cols)];
  for (int i = 0; i < n; i++) counts[list[i]] += static_cast<int>(buf[i]);
}

/* The history is kept in the canonical orientation: the other atom of the pair gets a copy. */
void FR_CLASS::transfer_history(double *source, double *target, int, int)
{
  const int nh = nhistory();
  for (int k = 0; k < nh; k++) target[k] = source[k];
}

/* svector = N (> 0 in compression), |T|, 1 if the last update slid, accumulated dissipation
   (these two NaN with dissipation no: not kept), then the law's internal variables. */
double FR_CLASS::single(int i, int j, int, int, double rsq, double, double, double &fforce)
{
  for (int k = 0; k < 4 + FR_NQ; k++) svector[k] = 0.0;
  fforce = 0.0;
  const double radsum = atom->radius[i] + atom->radius[j];
  if (rsq >= (radsum + skin) * (radsum + skin) || fix_history == nullptr) return 0.0;
  auto view = static_cast<FR_HISTORY_FIX *>(fix_history);
  const int *jlist = list->firstneigh[i];
  const int jnum = list->numneigh[i];
  for (int jj = 0; jj < jnum; jj++) {
    if ((jlist[jj] & NEIGHMASK) != j) continue;
    if (!view->firstflag[i][jj]) return 0.0;
    const FrLayout H(project, tally);
    const double *h = view->firstvalue[i] + static_cast<size_t>(H.size) * jj;
    // N and |T| of the last step's force, from the elastic displacements
    const double dist = sqrt(rsq);
    const double *p = params(atom->type[i], atom->type[j]);
    const double N = fr_last_normal(h, H.pn, p, dist - radsum);
    svector[0] = N;
    const double *e = h + H_ET;
    svector[1] = p[0] * sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    svector[2] = tally ? (h[H_STATUS] == 1.0 ? 1.0 : 0.0) : NAN;
    svector[3] = tally ? h[H_DISS] : NAN;
    for (int q = 0; q < FR_NQ; q++) svector[4 + q] = h[H.q + q];
    fforce = N / dist;
    return 0.0;
  }
  return 0.0;
}

void FR_CLASS::write_restart(FILE *fp)
{
  write_restart_settings(fp);
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fwrite(&setflag[i][j], sizeof(int), 1, fp);
      if (setflag[i][j]) fwrite(params(i, j), sizeof(double), FR_NPARAMS, fp);
    }
}

void FR_CLASS::read_restart(FILE *fp)
{
  read_restart_settings(fp);
  allocate();
  const int me = comm->me;
  double p[FR_NPARAMS];
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (me == 0) utils::sfread(FLERR, &setflag[i][j], sizeof(int), 1, fp, nullptr, error);
      MPI_Bcast(&setflag[i][j], 1, MPI_INT, 0, world);
      if (setflag[i][j]) {
        if (me == 0) utils::sfread(FLERR, p, sizeof(double), FR_NPARAMS, fp, nullptr, error);
        MPI_Bcast(p, FR_NPARAMS, MPI_DOUBLE, 0, world);
        for (int k = 0; k < FR_NPARAMS; k++) {
          params(i, j)[k] = p[k];
          params(j, i)[k] = p[k];
        }
      }
    }
}

void FR_CLASS::write_restart_settings(FILE *fp)
{
  const int sizes[8] = {FR_NPARAMS, nhistory(), project, affine, tally, box0_set,
                        history_instance, lever};
  fwrite(sizes, sizeof(int), 8, fp);
  fwrite(axis, sizeof(double), 3, fp);
  fwrite(&skin, sizeof(double), 1, fp);
  fwrite(box0, sizeof(double), 6, fp);    // the last pass's box: the restarted L as the run's
}

void FR_CLASS::read_restart_settings(FILE *fp)
{
  int sizes[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  if (comm->me == 0) {
    utils::sfread(FLERR, sizes, sizeof(int), 8, fp, nullptr, error);
    utils::sfread(FLERR, axis, sizeof(double), 3, fp, nullptr, error);
    utils::sfread(FLERR, &skin, sizeof(double), 1, fp, nullptr, error);
    utils::sfread(FLERR, box0, sizeof(double), 6, fp, nullptr, error);
  }
  MPI_Bcast(sizes, 8, MPI_INT, 0, world);
  project = sizes[2];
  lever = sizes[7];
  affine = sizes[3];
  tally = sizes[4];
  box0_set = sizes[5];
  // the history fix keeps the writer's name, under which the restart file holds the histories
  // (another pair style may have run before this one there, and numbered it otherwise)
  if (sizes[6] != history_instance && fix_history == nullptr) {
    const std::string placeholder = history_id() + "_DUMMY";
    history_instance = sizes[6];
    if (modify->get_fix_by_id(placeholder)) {
      modify->delete_fix(placeholder);
      modify->add_fix(history_id() + "_DUMMY all DUMMY");
    }
  }
  MPI_Bcast(box0, 6, MPI_DOUBLE, 0, world);
  MPI_Bcast(axis, 3, MPI_DOUBLE, 0, world);
  MPI_Bcast(&skin, 1, MPI_DOUBLE, 0, world);
  beyond_contact = skin > 0.0 ? 1 : 0;
  if (sizes[0] != FR_NPARAMS || sizes[1] != nhistory())
    error->all(FLERR, "pair_style " FR_STYLE ": the restart file was written by another law");
}

double FR_CLASS::memory_usage()
{
  double bytes = Pair::memory_usage();
  if (allocated) bytes += static_cast<double>(stride) * stride * FR_NPARAMS * sizeof(double);
  return bytes;
}
"""
