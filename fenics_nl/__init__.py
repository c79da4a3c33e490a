"""fenics-nl: non-linear solid mechanics on DOLFINx 0.11 and PETSc.

`dolfinx_solver` must be imported before dolfinx, petsc4py and slepc4py so that the
wheel's MPI and PETSc libraries are loaded first; importing this package does it. It also
compiles the forms' kernels with the CPU's vector units (`compile_flags`).
"""

import dolfinx_solver  # noqa: F401  (import-order trap: keep first)

# isort: split

from fenics_nl.compile_flags import tune_kernel_flags

tune_kernel_flags()

__version__ = "0.1.0"
