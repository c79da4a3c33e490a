"""fenics-nl: non-linear solid mechanics on DOLFINx 0.11 and PETSc.

Runs on any DOLFINx 0.11 with petsc4py and slepc4py: conda-forge's, the Docker image's,
Spack's, or the PyPI wheel (`pip install fenics-nl[wheel]`, what `make` installs). The
wheel's loader `dolfinx_solver` must be imported before dolfinx, petsc4py and slepc4py so
that its MPI and PETSc libraries are loaded first: importing this package does it when the
wheel is installed, with one BLAS thread per MPI rank (`threads`). Importing it changes
nothing else: the faster kernel flags are opt-in (`tune_kernel_flags`, which the demos,
the case command, the tests and the benchmarks call).
"""

from fenics_nl.threads import one_thread_per_rank

one_thread_per_rank()  # before the BLAS library loads

try:  # the PyPI wheel's loader, where it is installed (elsewhere DOLFINx loads its own)
    import dolfinx_solver  # noqa: F401  (import-order trap: before dolfinx)
except ModuleNotFoundError as err:
    if err.name != "dolfinx_solver":
        raise

# isort: split

from fenics_nl.compile_flags import tune_kernel_flags  # noqa: E402

__all__ = ["tune_kernel_flags"]
__version__ = "0.1.0"
