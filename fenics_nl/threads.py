"""One BLAS/OpenMP thread per MPI rank, unless the user says otherwise.

Under `mpiexec -n 2` on 2 cores, each rank's OpenBLAS (MUMPS's dense kernels) starts a thread
per core, and the idle ones spin: the J2 sphere at 91k unknowns took 14.7 s on 2 ranks
(its residual assembly not faster at all than on 1 rank, 0.86 s against 0.94 s) and 11.8 s
with one thread per rank (0.48 s; 18.2 s on 1 rank: 1.54x). The thread counts are read
when the BLAS library loads, so this runs before `dolfinx_solver` loads PETSc.
"""

from __future__ import annotations

import os

__all__ = ["one_thread_per_rank"]

# the launchers' size variables: MPICH/Hydra, Open MPI
RANK_COUNTS = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE")
THREAD_COUNTS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")


def one_thread_per_rank(environ=os.environ) -> bool:
    """Set the unset THREAD_COUNTS to 1 when launched on several ranks; whether it did."""
    ranks = max((int(environ[v]) for v in RANK_COUNTS if environ.get(v, "").isdigit()),
                default=1)
    if ranks <= 1:
        return False
    for name in THREAD_COUNTS:
        environ.setdefault(name, "1")
    return True
