"""Linear buckling: (K + λ K_G) φ = 0 around a pre-stressed state, by SLEPc shift-and-invert.

K is the tangent at the undeformed state, K_G the geometric stiffness of the stress σ₀ of a
reference load: a_G(du, v) = ∫ σ₀ : (∇duᵀ·∇v) dx, the second variation of the Green–Lagrange
strain. The critical loads are λ_i times the reference load; SLEPc solves K φ = λ (−K_G) φ
for the λ nearest 0 (shift-and-invert with MUMPS). Dirichlet rows carry 1 in K and 0 in K_G,
so they only add infinite eigenvalues, far from the target.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

__all__ = [
    "critical_loads",
    "geometric_stiffness",
    "lowest_tangent_mode",
    "mode_nearest_zero",
    "negative_eigenvalues",
    "unstable_directions",
]


def geometric_stiffness(stress, du, v, gradient=ufl.grad):
    """Integrand of a_G(du, v) = σ₀ : (∇duᵀ·∇v) for a (linear) pre-stress σ₀.

    Args:
        stress: σ₀, the stress of the reference load's linear solution (UFL).
        du: the trial function (or its displacement part).
        v: the test function (or its displacement part).
        gradient: ∇, applied to du and v (e.g. an embedded 3×3 gradient for a 3×3 σ₀).

    Returns:
        The UFL integrand; times dx it is a_G.
    """
    return ufl.inner(stress, gradient(du).T * gradient(v))


def _compiled(a: ufl.Form | fem.Form) -> fem.Form:
    """`a` compiled (a caller that asks at every step compiles it once and passes it)."""
    return a if isinstance(a, fem.Form) else fem.form(a)


def _stiffness(a: ufl.Form, bcs) -> PETSc.Mat:
    """K with its Dirichlet rows scaled to its largest diagonal entry.

    A diagonal of 1 would put their (spurious) eigenvalues anywhere, depending on the units;
    at the stiffness's own scale they stay away from the target, in any unit system.
    """
    form = _compiled(a)
    K = petsc.assemble_matrix(form, bcs=bcs, diag=1.0)
    K.assemble()
    diagonal = K.getDiagonal()
    dmax = diagonal.max()[1]
    diagonal.destroy()  # not left to the garbage collector (MPI: same order on every rank)
    K.zeroEntries()
    petsc.assemble_matrix(K, form, bcs=bcs, diag=dmax)
    K.assemble()
    return K


def _nearest_zero(comm, prefix: str, n: int, A: PETSc.Mat, B: PETSc.Mat | None = None,
                  tol: float | None = None, target: float = 0.0) -> SLEPc.EPS:
    """An EPS for the `n` eigenvalues of A x = λ B x (or A x = λ x) nearest `target` (0).

    Shift-and-invert with MUMPS LU; `-{prefix}eps_...` options are read last.
    """
    eps = SLEPc.EPS().create(comm)
    eps.setOptionsPrefix(prefix)
    if B is not None:
        eps.setOperators(A, B)
    else:
        eps.setOperators(A)
    if tol is not None:
        eps.setTolerances(tol, 200)
    eps.setProblemType(SLEPc.EPS.ProblemType.GNHEP if B is not None
                       else SLEPc.EPS.ProblemType.HEP)
    eps.setDimensions(n)
    eps.setTarget(target)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    st = eps.getST()
    st.setType("sinvert")
    st.setShift(target)
    ksp = st.getKSP()
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    eps.setFromOptions()
    return eps


def critical_loads(a_K: ufl.Form, a_G: ufl.Form, bcs, V: fem.FunctionSpace, n: int = 3,
                   prefix: str = "buckling_", scale_dofs: np.ndarray | None = None
                   ) -> tuple[list[float], list[fem.Function]]:
    """The `n` smallest positive load factors λ and their modes.

    Args:
        a_K: the bilinear form of K, the tangent at the undeformed state.
        a_G: that of K_G, the geometric stiffness of the reference load's stress σ₀.
        bcs: the Dirichlet conditions (their rows: K's largest diagonal entry in K, 0 in K_G).
        V: the function space of the modes.
        n: how many load factors.
        prefix: PETSc options prefix of the SLEPc eigensolver (``-{prefix}eps_...``).
        scale_dofs: local indices over which modes are normalised to max |φ| = 1 (all by
            default: a mixed space gives its displacement's, so that the pressure's units do
            not count).

    Returns:
        The load factors λ in increasing order (at most `n`, the converged real positive
        ones) and their modes, as two lists.
    """
    K = _stiffness(a_K, bcs)
    G = petsc.assemble_matrix(fem.form(-a_G), bcs=bcs, diag=0.0)
    G.assemble()
    eps = _nearest_zero(V.mesh.comm, prefix, n, K, G, tol=1e-12)
    eps.solve()
    values, modes = [], []
    vr = K.createVecRight()
    for i in range(eps.getConverged()):
        lam = eps.getEigenpair(i, vr)
        if abs(lam.imag) > 1e-8 * abs(lam.real) or lam.real <= 0:
            continue
        phi = fem.Function(V, name=f"mode_{len(modes) + 1}")
        vr.copy(phi.x.petsc_vec)
        phi.x.scatter_forward()
        values_ = phi.x.array if scale_dofs is None else phi.x.array[scale_dofs]
        scale = V.mesh.comm.allreduce(float(np.max(np.abs(values_), initial=0.0)),
                                      op=MPI.MAX)
        phi.x.array[:] /= scale or 1.0
        values.append(lam.real)
        modes.append(phi)
    order = np.argsort(values)
    for obj in (eps, K, G, vr):
        obj.destroy()
    return [values[i] for i in order][:n], [modes[i] for i in order][:n]


def negative_eigenvalues(A: PETSc.Mat, prefix: str, rhs: PETSc.Vec | None = None,
                         solution: PETSc.Vec | None = None) -> int:
    """The number of negative eigenvalues of the symmetric matrix A, from its inertia.

    Sylvester's law: A = L D Lᵀ (MUMPS) has as many negative eigenvalues as D has negative
    pivots. One factorization, no eigensolver.

    Args:
        A: the assembled symmetric matrix.
        prefix: PETSc options prefix of the factorization's KSP (``-{prefix}...``).
        rhs: if given, a right-hand side to solve for: one back-solve on the same
            factorization.
        solution: receives A⁻¹ rhs (needed with `rhs`).

    Returns:
        The number of negative eigenvalues of A.
    """
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    factor = pc.getFactorMatrix()
    factor.setMumpsIcntl(13, 1)  # the inertia of the whole matrix in parallel (MUMPS)
    factor.setMumpsIcntl(24, 1)  # null pivots detected, as MUMPS requires for the inertia
    ksp.setFromOptions()
    ksp.setUp()
    negative = factor.getInertia()[0]
    if rhs is not None:
        ksp.solve(rhs, solution)
    ksp.destroy()
    return negative


def unstable_directions(a_T: ufl.Form, bcs, prefix: str = "stability_",
                        multipliers: int = 0, rhs: PETSc.Vec | None = None,
                        solution: PETSc.Vec | None = None, margin: float = 0.0,
                        rows: PETSc.Vec | None = None) -> int:
    """The number of eigenvalues of K_T below −margin·max diag K_T, less `multipliers`.

    0 on a stable equilibrium; it changes by one where the path crosses a limit point or a
    bifurcation. One assembly and one LDLᵀ factorization (`negative_eigenvalues`).

    Args:
        a_T: the bilinear form of the tangent K_T.
        bcs: the Dirichlet conditions (identity rows scaled to K_T's largest diagonal entry).
        prefix: the factorization's PETSc options are ``-{prefix}inertia_...``.
        multipliers: negative eigenvalues a saddle-point tangent always has (its pressure
            or multiplier dofs), not counted.
        rhs: if given (zero on the Dirichlet rows), a right-hand side to solve for.
        solution: receives (K_T + margin·max diag)⁻¹ rhs (needed with `rhs`).
        margin: a small shift that counts an eigenvalue that round-off puts on either side
            of 0 as 0, relative to K_T's largest diagonal entry.
        rows: 1 where the margin is added (a mixed unknown's displacement dofs: a pressure
            block scales otherwise, and would change sign in some units); everywhere by
            default.

    Returns:
        The count of unstable directions, 0 on a stable equilibrium.
    """
    K = _stiffness(a_T, bcs)
    if margin:
        diagonal = K.getDiagonal()
        shift = margin * diagonal.max()[1]
        if rows is None:
            K.shift(shift)
        else:
            rows.copy(diagonal)
            diagonal.scale(shift)
            K.setDiagonal(diagonal, addv=PETSc.InsertMode.ADD_VALUES)
        diagonal.destroy()
    count = negative_eigenvalues(K, f"{prefix}inertia_", rhs, solution) - multipliers
    K.destroy()
    return count


def lowest_tangent_mode(a_T: ufl.Form, bcs, V: fem.FunctionSpace, prefix: str = "stability_",
                        mass: ufl.Form | None = None, multipliers: int = 0
                        ) -> tuple[float, fem.Function]:
    """Whether the tangent K_T is positive definite, told by a negative eigenvalue.

    The count of negative eigenvalues is the inertia of K_T (`negative_eigenvalues`), less
    `multipliers`: a saddle point [[A, Bᵀ], [B, −C]] with C ≥ 0 and B of full rank m has m
    negative eigenvalues for the constraint, and the others are those of A condensed on
    it (Haynsworth's inertia additivity; Gould's for C = 0). The count matters: an
    equilibrium on a higher branch has a negative eigenvalue far from 0, where a search
    nearest 0 finds a positive one. A mass that vanishes on part of the unknown (a mixed
    formulation's pressure) condenses that part out of the pencil: infinite eigenvalues.
    Dirichlet rows are identity rows scaled to the largest diagonal entry (and zero in M).

    Args:
        a_T: the bilinear form of the tangent K_T (UFL, or compiled by a caller that asks
            at every step).
        bcs: the Dirichlet conditions.
        V: the function space of the unknown (the mode's).
        prefix: PETSc options prefix of the eigensolver (``-{prefix}eps_...``); the inertia
            factorizations' is ``{prefix}inertia_``.
        mass: the bilinear form of M (None: the identity; UFL or compiled).
        multipliers: m, the negative eigenvalues of the constraint, not counted.

    Returns:
        The smallest eigenvalue of K_T φ = λ M φ and its mode if there is a negative one
        (unstable), else the eigenvalue nearest 0 and its mode.
    """
    comm = V.mesh.comm
    K = _stiffness(a_T, bcs)
    M = None
    if mass is not None:
        M = petsc.assemble_matrix(_compiled(mass), bcs=bcs, diag=0.0)
        M.assemble()
    unstable = negative_eigenvalues(K, f"{prefix}inertia_") > multipliers
    lam, mode = _eigenpair_nearest(comm, prefix, K, M, 0.0, V)
    if unstable:  # shift below the smallest eigenvalue (counted), then find it there
        shift = -1.01 * max(abs(lam), 1e-12 * K.norm(PETSc.NormType.INFINITY))
        eye = _identity(K) if M is None else None
        for _ in range(60):
            shifted = K.duplicate(copy=True)
            shifted.axpy(-shift, M if M is not None else eye,
                         PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            below = negative_eigenvalues(shifted, f"{prefix}inertia_") - multipliers
            shifted.destroy()
            if below == 0:  # no eigenvalue below the shift: the nearest is the smallest
                break
            shift *= 4
        if eye is not None:
            eye.destroy()
        lam, mode = _eigenpair_nearest(comm, prefix, K, M, shift, V)
    for obj in (K, M):
        if obj is not None:
            obj.destroy()
    return lam, mode


def mode_nearest_zero(a_T: ufl.Form, bcs, V: fem.FunctionSpace, prefix: str = "stability_",
                      mass: ufl.Form | None = None) -> PETSc.Vec:
    """The eigenvector of K_T φ = λ M φ (or K_T φ = λ φ) with λ nearest 0 (SLEPc).

    Args:
        a_T: the bilinear form of the tangent K_T.
        bcs: the Dirichlet conditions (identity rows scaled to K_T's largest diagonal entry,
            zero in M).
        V: the function space of the unknown.
        prefix: PETSc options prefix of the eigensolver (``-{prefix}eps_...``).
        mass: the bilinear form of M (None: the identity).

    Returns:
        The eigenvector, a new PETSc Vec (the caller destroys it).
    """
    K = _stiffness(a_T, bcs)
    M = None
    if mass is not None:
        M = petsc.assemble_matrix(_compiled(mass), bcs=bcs, diag=0.0)
        M.assemble()
    _, mode = _eigenpair_nearest(V.mesh.comm, prefix, K, M, 0.0, V)
    vector = mode.x.petsc_vec.copy()
    for obj in (K, M):
        if obj is not None:
            obj.destroy()
    return vector


def _identity(K: PETSc.Mat) -> PETSc.Mat:
    """The identity with K's layout."""
    eye = K.duplicate()
    eye.zeroEntries()
    eye.shift(1.0)
    return eye


def _eigenpair_nearest(comm, prefix: str, K: PETSc.Mat, M: PETSc.Mat | None, target: float,
                       V: fem.FunctionSpace) -> tuple[float, fem.Function]:
    """The eigenpair of K φ = λ M φ (or K φ = λ φ) nearest `target`."""
    eps = _nearest_zero(comm, prefix, 1, K, M, target=target)
    eps.solve()
    if eps.getConverged() < 1:
        raise RuntimeError(f"SLEPc found no eigenvalue of the tangent (-{prefix}eps_...)")
    vr = K.createVecRight()
    lam = eps.getEigenpair(0, vr).real
    mode = fem.Function(V, name="lowest_mode")
    vr.copy(mode.x.petsc_vec)
    mode.x.scatter_forward()
    eps.destroy()
    vr.destroy()
    return lam, mode
