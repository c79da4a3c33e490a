"""Sensitivities of a path-dependent solution to material parameters, by direct differentiation.

A load step n of a law with internal variables α (J2's ε_p and p) ends in equilibrium

    R(u_n; α_{n−1}, θ) = 0,    α_n = A(ε(u_n); α_{n−1}, θ),

R the residual written with the committed state α_{n−1} and the parameters θ, A the state
update (the return mapping); the Dirichlet values (supports, the active contact nodes) do not
depend on θ. Differentiating both along a parameter θ_i gives, at each converged step,

    K du = −(∂R/∂θ_i + ∂R/∂α · dα_{n−1}),   du = 0 on the step's Dirichlet rows,
    dα_n = ∂A/∂u · du + ∂A/∂α · dα_{n−1} + ∂A/∂θ_i,

one linear solve per parameter with the step's tangent K, reassembled at the converged u
(the Newton solver's own matrix; its solve reuses the factorization the forward solve made,
as a CG preconditioner when the solver keeps one: no new factorization), and the state's
derivative carried on to the next step. The contact nodes of the step are held, as in
Tardieu & Constantinescu's sensitivity problem of a frictionless contact whose zone does not
move with θ. The reactions' derivative (that of the contact force) is the residual's total
derivative dR = K du + ∂R/∂θ_i + ∂R/∂α · dα_{n−1}, assembled without the Dirichlet rows.

Every derivative is UFL's: of the residual and of the state update, with respect to u, to the
state Functions and to the parameters (the law's `fem.Constant` objects, each taken as a
`ufl.variable`).
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.expression import Expression
from fenics_nl.solvers.newton import ConvergenceError, LinearSolveError
from fenics_nl.solvers.result import WorkCounts

__all__ = ["PathSensitivity", "parameter_derivative"]


def parameter_derivative(form_or_expr, constant: fem.Constant, weight=1.0):
    """`weight` × ∂/∂c of a UFL form or expression in which the constant c appears.

    UFL differentiates forms with respect to Functions only: the constant is swapped for a
    `ufl.variable` of itself and each integrand differentiated with `ufl.diff`.

    Args:
        form_or_expr: a UFL form (the residual R) or expression (a state update A).
        constant: c, the parameter θ_i (a scalar `fem.Constant` of the law).
        weight: a factor of the derivative (a number or UFL: a component of a unit vector
            picks one parameter of several in one compiled form).

    Returns:
        The derivative, a UFL form for a form, else a UFL expression.
    """
    c = ufl.variable(constant)
    swapped = ufl.replace(form_or_expr, {constant: c})
    if isinstance(swapped, ufl.Form):
        return ufl.Form([i.reconstruct(integrand=weight * ufl.diff(i.integrand(), c))
                         for i in swapped.integrals()])
    return weight * ufl.diff(swapped, c)


class PathSensitivity:
    """du/dθ and dα/dθ along a load path, and each converged step's dR/dθ.

    Call `step()` after each converged step, before the law commits its state (it reads the
    committed α_{n−1}); `reset()` at the start of a new path.

    Args:
        residual: R(u; v) as the solver has it, written with the committed state.
        u: the unknown.
        newton: the `NewtonSolver` that converged the step: its Dirichlet rows and tangent.
        state: the committed internal variables by name (quadrature Functions).
        update: the state a commit would store, by the same names (UFL of u).
        parameters: the law's parameters to differentiate by, by name (`fem.Constant` objects).
    """

    def __init__(self, residual: ufl.Form, u: fem.Function, newton, state: dict,
                 update: dict, parameters: dict[str, fem.Constant]):
        if set(state) != set(update):
            raise ValueError("state and update must name the same internal variables")
        self.names = list(parameters)
        self.newton = newton
        V = u.function_space
        n = len(self.names)
        # the parameter of the current solve, as a unit vector: one compiled form for all
        self._which = fem.Constant(V.mesh, np.zeros(n))
        self._du = fem.Function(V)
        self._dstate = {k: fem.Function(f.function_space) for k, f in state.items()}
        self._new = {k: fem.Function(f.function_space) for k, f in state.items()}
        explicit = sum((parameter_derivative(residual, c, self._which[i])
                        for i, c in enumerate(parameters.values())), ufl.Form([]))
        through_state = sum((ufl.derivative(residual, state[k], self._dstate[k])
                             for k in state), ufl.Form([]))
        self._rhs = fem.form(explicit + through_state)
        self._total = fem.form(ufl.derivative(residual, u, self._du) + explicit + through_state)
        points = next(iter(state.values())).function_space.element.interpolation_points
        self._update = {}
        for k, new in update.items():
            d = ufl.derivative(new, u, self._du)
            for i, c in enumerate(parameters.values()):
                d = d + parameter_derivative(new, c, self._which[i])
            for j in state:
                d = d + ufl.derivative(new, state[j], self._dstate[j])
            self._update[k] = Expression(d, points)
        self._b = petsc.create_vector(V)
        self.work = WorkCounts()
        self.state_derivatives = [{k: np.zeros_like(f.x.array) for k, f in state.items()}
                                  for _ in self.names]

    def reset(self) -> None:
        """A new load path from the virgin state: dα/dθ = 0."""
        for d in self.state_derivatives:
            for a in d.values():
                a[:] = 0.0

    def step(self) -> list[np.ndarray]:
        """The converged step's dR/dθ_i, for each parameter: at every local dof, no rows.

        Also carries dα/dθ_i to this step. The tangent is assembled once at the converged u;
        each parameter costs one solve with it.

        Returns:
            One array per parameter, in the order of `names`, of dR/dθ_i at this rank's
            dofs, ghosts included (a copy of the local form).
        """
        self.newton.assemble_exact_tangent(self.work)
        bcs = self.newton.bcs
        derivatives, carried = [], []
        for i in range(len(self.names)):
            self._which.value[:] = np.eye(len(self.names))[i]
            for k, f in self._dstate.items():
                f.x.array[:] = self.state_derivatives[i][k]
            self._assemble(self._rhs, self._b)
            self._b.scale(-1.0)
            petsc.set_bc(self._b, bcs, alpha=0.0)  # du = 0 on the step's Dirichlet rows
            try:
                self.newton.tangent_solve(self._b, self._du.x.petsc_vec, self.work)
            except LinearSolveError as err:  # a step the caller may refuse, as a solve's
                raise ConvergenceError(f"sensitivity to {self.names[i]}: {err}") from None
            self._du.x.scatter_forward()
            self._assemble(self._total, self._b)
            self._b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
            with self._b.localForm() as loc:
                derivatives.append(loc.array_r.copy())
            for k, expr in self._update.items():  # (all read dα_{n−1}: stored after)
                self._new[k].interpolate(expr)
            carried.append({k: f.x.array.copy() for k, f in self._new.items()})
        self.state_derivatives = carried
        return derivatives

    def _assemble(self, form, b: PETSc.Vec) -> None:
        with b.localForm() as loc:
            loc.set(0.0)
        petsc.assemble_vector(b, form)
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        self.work.residual_assemblies += 1
