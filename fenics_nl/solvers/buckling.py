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


def geometric_stiffness(stress, du, v, gradient=ufl.grad):
    """Integrand of a_G(du, v) = σ₀ : (∇duᵀ·∇v) for a (linear) pre-stress σ₀."""
    return ufl.inner(stress, gradient(du).T * gradient(v))


def _stiffness(a: ufl.Form, bcs) -> PETSc.Mat:
    """K with its Dirichlet rows scaled to its largest diagonal entry.

    A diagonal of 1 would put their (spurious) eigenvalues anywhere, depending on the units;
    at the stiffness's own scale they stay away from the target, in any unit system.
    """
    form = fem.form(a)
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
                  tol: float | None = None) -> SLEPc.EPS:
    """An EPS for the `n` eigenvalues of A x = λ B x (or A x = λ x) nearest 0.

    Shift-and-invert at 0 with MUMPS LU; `-{prefix}eps_...` options are read last.
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
    eps.setTarget(0.0)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    st = eps.getST()
    st.setType("sinvert")
    st.setShift(0.0)
    ksp = st.getKSP()
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    eps.setFromOptions()
    return eps


def critical_loads(a_K: ufl.Form, a_G: ufl.Form, bcs, V: fem.FunctionSpace, n: int = 3,
                   prefix: str = "buckling_") -> tuple[list[float], list[fem.Function]]:
    """The `n` smallest positive load factors λ and their modes (normalised, max |φ| = 1)."""
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
        scale = V.mesh.comm.allreduce(float(np.max(np.abs(phi.x.array), initial=0.0)),
                                      op=MPI.MAX)
        phi.x.array[:] /= scale or 1.0
        values.append(lam.real)
        modes.append(phi)
    order = np.argsort(values)
    for obj in (eps, K, G, vr):
        obj.destroy()
    return [values[i] for i in order][:n], [modes[i] for i in order][:n]


def lowest_tangent_mode(a_T: ufl.Form, bcs, V: fem.FunctionSpace, prefix: str = "stability_"
                        ) -> tuple[float, fem.Function]:
    """Eigenvalue of the tangent K_T nearest 0 and its mode: negative means unstable.

    Dirichlet rows are identity rows (eigenvalue 1), kept away from the target by scaling
    them to the largest diagonal entry.
    """
    K = _stiffness(a_T, bcs)
    eps = _nearest_zero(V.mesh.comm, prefix, 1, K)
    eps.solve()
    vr = K.createVecRight()
    lam = eps.getEigenpair(0, vr).real
    mode = fem.Function(V, name="lowest_mode")
    vr.copy(mode.x.petsc_vec)
    mode.x.scatter_forward()
    for obj in (eps, K, vr):
        obj.destroy()
    return lam, mode
