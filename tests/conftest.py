"""Load the dolfinx wheel's MPI/PETSc first (fenics_nl imports dolfinx_solver).

Under mpiexec, PETSc objects on the world communicator must be destroyed by every rank at
the same point. Python's cyclic garbage collector runs whenever one rank's allocations
cross a threshold, so it can destroy a SNES (dolfinx's NonlinearProblem lives in a
reference cycle) on rank 0 while rank 1 waits in another collective: the mpi suite hung in
3 runs out of 4 that way. So, on several ranks, collect only between tests, all together.
"""

import gc

import fenics_nl  # noqa: F401

# isort: split

import pytest
from mpi4py import MPI

if MPI.COMM_WORLD.size > 1:
    gc.disable()

    @pytest.fixture(autouse=True)
    def _collect_on_every_rank_together():
        yield
        gc.collect()
