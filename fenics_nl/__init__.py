"""fenics-nl: non-linear solid mechanics on DOLFINx 0.11 and PETSc.

`dolfinx_solver` must be imported before dolfinx, petsc4py and slepc4py so that the
wheel's MPI and PETSc libraries are loaded first; importing this package does it.
"""

import dolfinx_solver  # noqa: F401  (import-order trap: keep first)

__version__ = "0.1.0"
