"""PETSc KSP set-ups for the tangent systems: MUMPS LU/Cholesky, or CG + GAMG.

hypre is not in this PETSc build, so the iterative option is CG (GMRES on an indefinite
tangent) preconditioned by smoothed aggregation (GAMG) with the rigid-body modes as
near-nullspace: without them GAMG's coarse spaces miss rotations and CG stalls on elasticity.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from dolfinx import fem, la
from petsc4py import PETSc

__all__ = ["block_preconditioned_ksp", "create_ksp", "rigid_body_modes"]

KINDS = ("lu", "cholesky", "gamg")
# the spelling of the linear solver everywhere (`linear_solver=`, `--linear-solver`, TOML)
LinearSolver = Literal["lu", "cholesky", "gamg"]


def rigid_body_modes(V: fem.FunctionSpace) -> PETSc.NullSpace:
    """Orthonormal rigid-body modes (translations, rotations) of a vector P1/P2 space.

    Args:
        V: the displacement's vector function space (2D or 3D).

    Returns:
        The modes as a PETSc NullSpace, GAMG's near-nullspace.
    """
    gdim = V.mesh.geometry.dim
    x = V.tabulate_dof_coordinates()
    n_owned = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    x = x[:n_owned]
    rotations = [(0, 1)] if gdim == 2 else [(0, 1), (1, 2), (2, 0)]
    modes = [la.vector(V.dofmap.index_map, bs=bs) for _ in range(gdim + len(rotations))]
    for i in range(gdim):  # translations
        modes[i].array[i:n_owned * bs:bs] = 1.0
    for k, (i, j) in enumerate(rotations):  # rotation in the (i, j) plane: (-x_j, x_i)
        a = modes[gdim + k].array
        a[i:n_owned * bs:bs] = -x[:, j]
        a[j:n_owned * bs:bs] = x[:, i]
    la.orthonormalize(modes)
    # copies own their memory (petsc_vec borrows the dolfinx vector's array)
    return PETSc.NullSpace().create(vectors=[m.petsc_vec.copy() for m in modes],
                                    comm=V.mesh.comm)


def create_ksp(A: PETSc.Mat, kind: str = "lu", prefix: str = "",
               near_nullspace: PETSc.NullSpace | None = None, rtol: float = 1e-10,
               P: PETSc.Mat | None = None, indefinite: bool = False) -> PETSc.KSP:
    """A KSP on `A`: direct MUMPS LU/Cholesky, or CG+GAMG (needs `near_nullspace`).

    Args:
        A: the tangent K.
        kind: ``lu``, ``cholesky`` (MUMPS) or ``gamg``.
        prefix: PETSc options prefix; its options (e.g. ``-{prefix}ksp_monitor``) are read
            last, so the command line can override every choice made here.
        near_nullspace: the rigid-body modes (`rigid_body_modes`), needed by ``gamg``.
        rtol: the relative tolerance of an iterative solve.
        P: a separate preconditioning matrix: with a direct `kind`, the KSP is then CG
            preconditioned by the factorization of P. P may lag behind A (an older tangent,
            older Dirichlet rows) and the factorization is reused until it no longer pays.
        indefinite: A is indefinite. With `P` (a saddle point) the KSP is GMRES instead,
            preconditioned on the right so that it stops on the true residual: CG's energy
            norm does not exist there, and P⁻¹A = I + (a term of the rank of the changed
            rows and springs) converges in about as many iterations either way. With GAMG
            (a tangent past a limit point) GMRES too, restarted every 200 iterations: CG
            diverges on it. Its 200 Krylov vectors cost 1.6 kB per unknown (1.6 GB at a
            million, shared by the ranks); ``-{prefix}ksp_gmres_restart`` lowers it.

    Returns:
        The KSP, its options set from the command line.
    """
    if kind not in KINDS:
        raise ValueError(f"linear solver must be one of {', '.join(KINDS)}, got {kind!r}")
    ksp = PETSc.KSP().create(A.comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A, P if P is not None else A)
    pc = ksp.getPC()
    if kind in ("lu", "cholesky") and P is not None:
        if indefinite:  # no restart within max_it
            _true_residual_gmres(ksp, restart=50)
        else:
            ksp.setType("cg")
        ksp.setTolerances(rtol=rtol, atol=0.0, max_it=50)
        pc.setType(kind)
        pc.setFactorSolverType("mumps")
    elif kind in ("lu", "cholesky"):
        ksp.setType("preonly")
        pc.setType(kind)
        pc.setFactorSolverType("mumps")
        if kind == "cholesky":
            A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            A.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
    else:
        if near_nullspace is None:
            raise ValueError("the gamg solver needs the rigid-body near-nullspace")
        A.setNearNullSpace(near_nullspace)
        if indefinite:
            _true_residual_gmres(ksp, restart=200)
            _sor_smoothing(prefix)
        else:  # the true residual ‖A x − b‖ is what an inexact Newton step controls
            ksp.setType("cg")
            ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
            _forget_sor_smoothing(prefix)
        ksp.setTolerances(rtol=rtol, atol=0.0, max_it=1000)
        pc.setType("gamg")
    ksp.setFromOptions()
    _keep_mumps(ksp, A, prefix)
    return ksp


def factorized_counting_null_pivots(ksp: PETSc.KSP) -> int:
    """Factorize a direct (MUMPS) KSP with null pivots detected (ICNTL(24)): their number.

    A singular matrix (a body that nothing holds) factorizes all the same, and its solve
    adds an arbitrary motion: the count is what says so. Collective.
    """
    pc = ksp.getPC()
    pc.setFactorSetUpSolverType()
    pc.getFactorMatrix().setMumpsIcntl(24, 1)
    ksp.setUp()
    return pc.getFactorMatrix().getMumpsInfog(28)


def allow_unsymmetric(ksp: PETSc.KSP) -> bool:
    """Let `ksp` solve a tangent that is not symmetric: CG becomes GMRES; whether it can.

    A reused factorization or GAMG preconditions GMRES (right, restarted as for an indefinite
    tangent); LU needs nothing; Cholesky cannot.

    Returns:
        False with Cholesky (the tangent must stay symmetric), else True.
    """
    pc = ksp.getPC()
    if pc.getType() == "cholesky":
        return False
    if ksp.getType() == "cg":
        _true_residual_gmres(ksp, restart=200 if pc.getType() == "gamg" else 50)
        if pc.getType() == "gamg":
            _sor_smoothing(ksp.getOptionsPrefix() or "")
    return True


_SOR_SMOOTHING = (("mg_levels_ksp_type", "richardson"), ("mg_levels_pc_type", "sor"))
_SOR_SET: set[str] = set()  # the options `_sor_smoothing` put in the database, not the user


def _sor_smoothing(prefix: str) -> None:
    """GAMG's levels smoothed by SOR sweeps (Richardson), unless the options chose others.

    PETSc's default smoother, Chebyshev on Jacobi, is built on bounds of a real positive
    spectrum, which a non-symmetric (friction) or indefinite tangent does not have. On the
    3D forging's friction tangent (19632 unknowns, 2 ranks, its first 23 Newton iterations)
    GMRES took 472 iterations with SOR against 694 with Chebyshev, 2.9 s against 3.6 s
    (benchmarks/forging.py, its smoother table).
    Set in the options database (the levels exist only when GAMG sets up): the prefix's.
    """
    opts = PETSc.Options()
    for name, value in _SOR_SMOOTHING:
        if not opts.hasName(f"{prefix}{name}"):
            opts[f"{prefix}{name}"] = value
            _SOR_SET.add(f"{prefix}{name}")


def _forget_sor_smoothing(prefix: str) -> None:
    """A CG + GAMG solver: the options `_sor_smoothing` set under `prefix`, removed.

    The database outlives the solver: a later CG solver with the same prefix (a
    frictionless run after a frictional one) would otherwise take them for the user's.
    """
    for name, _ in _SOR_SMOOTHING:
        if f"{prefix}{name}" in _SOR_SET:
            PETSc.Options().delValue(f"{prefix}{name}")
            _SOR_SET.discard(f"{prefix}{name}")


def _true_residual_gmres(ksp: PETSc.KSP, restart: int) -> None:
    """GMRES preconditioned on the right: it stops on ‖A x − b‖, what Newton needs."""
    ksp.setType("gmres")
    ksp.setGMRESRestart(restart)
    ksp.setPCSide(PETSc.PC.Side.RIGHT)


def _keep_mumps(ksp: PETSc.KSP, A: PETSc.Mat, prefix: str) -> None:
    """MUMPS for a factorization the options chose, and symmetry flags for Cholesky.

    `-{prefix}pc_type cholesky` resets the factorization package to PETSc's own sequential
    one (far slower than MUMPS LU on the bracket, while MUMPS's LDLᵀ is faster than its LU
    and needs less memory: measured by benchmarks/cholesky.py, table in docs/benchmarks.md,
    section "Direct solver: MUMPS LDLᵀ against LU", which records the PETSc trial too).
    """
    pc = ksp.getPC()
    if pc.getType() not in ("lu", "cholesky"):
        return
    if not PETSc.Options().hasName(f"{prefix}pc_factor_mat_solver_type"):
        pc.setFactorSolverType("mumps")
    if pc.getType() == "cholesky":  # an energy's tangent: symmetric (not always definite)
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        A.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)


def block_preconditioned_ksp(A: PETSc.Mat, M: PETSc.Mat, W: fem.FunctionSpace,
                             prefix: str = "", rtol: float = 1e-10) -> PETSc.KSP:
    """MINRES on a symmetric saddle-point tangent (u, p), preconditioned block-diagonally.

    The displacement block of `M` by GAMG (with the rigid-body near-nullspace), its pressure
    block by Jacobi on the mass matrix, which is spectrally
    equivalent to the Schur complement whatever the bulk modulus: the iteration count does
    not grow as ν → 1/2 (Silvester–Wathen).

    Args:
        A: the tangent K of the mixed unknown (u, p).
        M: the block preconditioner's matrix, diag(2μ ε:ε, (1/μ + 1/k) mass).
        W: the mixed space; its sub-spaces 0 and 1 are the fields u and p.
        prefix: PETSc options prefix (a block's: ``-{prefix}fieldsplit_u_...``,
            ``-{prefix}fieldsplit_p_...``).
        rtol: MINRES's relative tolerance.

    Returns:
        The KSP, its options set from the command line.
    """
    from fenics_nl.materials.mixed import collapsed

    comm = W.mesh.comm
    imap = W.dofmap.index_map
    owned = imap.size_local * W.dofmap.index_map_bs
    fields = []
    for i in (0, 1):
        Vi, dofs = collapsed(W.sub(i))
        dofs = dofs[: Vi.dofmap.index_map.size_local * Vi.dofmap.index_map_bs]
        if not np.all(dofs < owned):  # a collapsed space lists its owned dofs first
            raise RuntimeError("collapsed sub-space with a ghost among its owned dofs")
        fields.append((Vi, PETSc.IS().createGeneral(
            imap.local_to_global(dofs).astype(PETSc.IntType), comm=comm)))
    fields[0][1].compose("nearnullspace", rigid_body_modes(fields[0][0]))
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A, M)
    ksp.setType("minres")
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=2000)
    pc = ksp.getPC()
    pc.setType("fieldsplit")
    pc.setFieldSplitIS(("u", fields[0][1]), ("p", fields[1][1]))
    pc.setFieldSplitType(PETSc.PC.CompositeType.ADDITIVE)
    opts = PETSc.Options()
    for field, pc_type in (("u", "gamg"), ("p", "jacobi")):
        for name, value in (("ksp_type", "preonly"), ("pc_type", pc_type)):
            if not opts.hasName(f"{prefix}fieldsplit_{field}_{name}"):
                opts[f"{prefix}fieldsplit_{field}_{name}"] = value
    ksp.setFromOptions()
    return ksp
