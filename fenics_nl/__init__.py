"""fenics-nl: non-linear solid mechanics on DOLFINx 0.11 and PETSc.

`dolfinx_solver` must be imported before dolfinx, petsc4py and slepc4py so that the
wheel's MPI and PETSc libraries are loaded first; importing this package does it, with one
BLAS thread per MPI rank (`threads`). It also compiles the forms' kernels with the CPU's
vector units (`compile_flags`).
"""

from fenics_nl.threads import one_thread_per_rank

one_thread_per_rank()  # before the BLAS library loads

import dolfinx_solver  # noqa: E402, F401  (import-order trap: before dolfinx)

# isort: split

from fenics_nl.compile_flags import tune_kernel_flags  # noqa: E402

tune_kernel_flags()

__version__ = "0.1.0"
