"""Our triaxial tests in LAMMPS (``engine="lammps"``): the files, the run on MPI ranks, the
result read back (``docs/assembly.md``, "LAMMPS")."""

from ._resume import lammps_triaxial, resume_lammps_triaxial
from ._runner import (LammpsFiles, check_lammps_options, read_lammps_triaxial, run_lammps,
                      write_lammps_triaxial)

__all__ = ["LammpsFiles", "write_lammps_triaxial", "read_lammps_triaxial", "run_lammps",
           "lammps_triaxial", "check_lammps_options", "resume_lammps_triaxial"]
