"""Load the dolfinx wheel's MPI/PETSc first (fenics_nl imports dolfinx_solver)."""

import fenics_nl  # noqa: F401
