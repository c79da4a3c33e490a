"""The von Mises truss as a finite-element model: two P1 bars in the plane, one apex load.

Each bar is one interval element of a mesh embedded in 2D; its free energy is EA/2 e² per
unit reference length, e = (|t + ∂u/∂S|² − 1)/2 the Green–Lagrange strain along the bar (t
its unit tangent, S its arc length). P1 is exact here: the strain of a straight two-node bar
is uniform. The supports are pinned; the apex carries the dead load λ P downwards, a nodal
force (`NewtonSolver.nodal`). `theory.truss` has the exact curve.
"""

from __future__ import annotations

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.solvers.newton import NewtonSolver

__all__ = ["VonMisesTruss"]


class VonMisesTruss:
    """Half-span `a`, rise `h`, axial stiffness `EA`, reference apex load `P` (downwards)."""

    def __init__(self, a: float, h: float, EA: float, P: float,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if not (a > 0 and h > 0 and EA > 0 and P > 0):
            raise ValueError(f"a, h, EA and P must be > 0, got {a}, {h}, {EA}, {P}")
        self.a, self.h, self.EA, self.P = a, h, EA, P
        points = np.array([[-a, 0.0], [0.0, h], [a, 0.0]]) if comm.rank == 0 else np.zeros((0, 2))
        cells = (np.array([[0, 1], [1, 2]], dtype=np.int64) if comm.rank == 0
                 else np.zeros((0, 2), dtype=np.int64))
        line = ufl.Mesh(basix.ufl.element("Lagrange", "interval", 1, shape=(2,)))
        self.mesh = mesh.create_mesh(comm, cells, line, points)
        self.V = fem.functionspace(self.mesh, ("Lagrange", 1, (2,)))
        self.u = fem.Function(self.V, name="displacement")
        J = ufl.Jacobian(self.mesh)
        t = ufl.as_vector([J[0, 0], J[1, 0]])
        t = t / ufl.sqrt(ufl.dot(t, t))
        stretched = t + ufl.grad(self.u) * t  # ∂x/∂S: the deformed bar's tangent
        e = (ufl.dot(stretched, stretched) - 1) / 2
        energy = EA / 2 * e**2 * ufl.dx
        self.residual = ufl.derivative(energy, self.u, ufl.TestFunction(self.V))
        supports = mesh.locate_entities_boundary(self.mesh, 0, lambda x: np.isclose(x[1], 0))
        self.bcs = [boundary.fixed(self.V, supports)]
        X = self.V.tabulate_dof_coordinates()[: self.V.dofmap.index_map.size_local]
        apex = np.flatnonzero(np.isclose(X[:, 1], h) & np.isclose(X[:, 0], 0))
        self._apex_dof = (2 * apex + 1).astype(np.int32)  # its vertical component
        self.solver: NewtonSolver | None = None

    def newton(self, **options) -> NewtonSolver:
        """The Newton solver of the truss (its nodal load is set by `set_load`)."""
        self.solver = NewtonSolver(self.residual, self.u, self.bcs, **options)
        return self.solver

    def set_load(self, lam: float) -> None:
        """The apex load λ P, downwards."""
        self.solver.nodal.set_load(self._apex_dof, np.full(len(self._apex_dof), -lam * self.P))

    def apex_deflection(self) -> float:
        """w: the apex's downward displacement."""
        local = -float(self.u.x.array[self._apex_dof].sum())
        return self.mesh.comm.allreduce(local)
