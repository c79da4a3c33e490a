"""The necking of a circular bar in tension (Simo 1988, 1992): J2 at finite strain.

A bar of radius r0 = 6.413 mm and length L0 = 53.334 mm, the radius narrowed linearly to
0.982 r0 at mid-length (the imperfection that fixes where the neck forms), is pulled at
both ends by `elongation`/2 each. By symmetry the quarter 0 < r < R(z), 0 < z < L0/2 of the
(r, z) plane is computed: the axis (u_r = 0), the mid-plane (u_z = 0), the end z = L0/2
moved along z, radially free as in ANSYS VM318 (`gripped`: held radially too).
Steel-like, Voce hardening with a linear part: E = 206.9 GPa, ν = 0.29,
σ_y = 450 + 129.24 p + (715 − 450)(1 − exp(−16.93 p)) MPa. Units: N, mm, MPa.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.probes import Probes
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.materials.mixed import unknowns
from fenics_nl.solvers.newton import NewtonSolver

__all__ = ["NeckingBar", "simo_material"]

MODEL = "axisymmetric"
RADIUS, LENGTH, NARROWING = 6.413, 53.334, 0.982


def simo_material(nu: float = 0.29) -> FiniteJ2Plasticity:
    """The benchmark's law (N, mm, MPa)."""
    return FiniteJ2Plasticity(206.9e3, nu, sigma0=450.0, H=129.24, saturation=715.0,
                              delta=16.93)


class NeckingBar:
    """Mesh, unknown, material, supports, the end's motion and its solver.

    `cells` across the radius and about 4.2 times as many along the half length, graded
    towards the neck: z = (L0/2) s^a, a = 1 + ln(grading)/ln(rows), so that the cells at
    mid-length are about `grading` times shorter than the mean (1: uniform).
    """

    def __init__(self, cells: int = 4, *, grading: float = 3.0, mixed: bool = True,
                 nu: float = 0.29, gripped: bool = False, comm: MPI.Comm = MPI.COMM_WORLD):
        half = LENGTH / 2
        rows = max(2, round(cells * half / RADIUS))
        self.mesh = msh = mesh.create_rectangle(comm, [[0.0, 0.0], [1.0, 1.0]],
                                                [cells, rows], mesh.CellType.quadrilateral)
        x = msh.geometry.x
        # z = half · s^a, a = 1 + ln(grading)/ln(rows): cells shorter towards the neck (about
        # `grading` times the mean at the end); r follows the narrowed radius R(z) linearly
        a = np.log(grading) / np.log(rows) + 1.0 if grading > 1 else 1.0
        x[:, 1] = half * x[:, 1] ** a
        x[:, 0] *= RADIUS * (NARROWING + (1 - NARROWING) * x[:, 1] / half)
        self.h = RADIUS / cells
        self.fields = f = unknowns(msh, 2, mixed)
        self.V, self.unknown, self.u = f.V, f.w, f.u
        fdim = msh.topology.dim - 1

        def where(test):
            return mesh.locate_entities_boundary(msh, fdim, test)

        axis = where(lambda p: np.isclose(p[0], 0.0))
        self.mid = where(lambda p: np.isclose(p[1], 0.0))
        self.end = where(lambda p: np.isclose(p[1], half))
        self.pull = boundary.component(self.V, 1, self.end, 0.0)
        self.bcs = [boundary.component(self.V, 0, axis), boundary.component(self.V, 1, self.mid),
                    self.pull]
        if gripped:  # the end held radially too (else only pulled along z, as VM318)
            self.bcs.append(boundary.component(self.V, 0, self.end))
        self.material = simo_material(nu)
        self.quadrature_degree = 4
        self.material.bind(msh, self.quadrature_degree)
        self.dx = kinematics.quadrature_measure("dx", msh, self.quadrature_degree)
        self.residual = f.internal_work(self.material, MODEL) * self.dx
        self._residual_form = fem.form(self.residual)
        self.solver = NewtonSolver(self.residual, self.unknown, self.bcs, rtol=1e-10,
                                   atol=1e-10, force_scale=450.0 * RADIUS**2, max_it=25,
                                   line_search=True, prefix="necking_")
        self.probes = Probes(msh, [[RADIUS * NARROWING, 0.0]])  # the neck's surface

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns."""
        return output.dofs(self.unknown.function_space)

    def set_elongation(self, elongation: float) -> None:
        """Move the end by half the total `elongation` (both ends pulled)."""
        self.pull.g.x.array[:] = 0.5 * elongation

    def commit(self) -> None:
        """The material's state after a converged step."""
        self.material.commit(self.u, MODEL)

    def force(self) -> float:
        """The bar's tension: the mid-plane's reaction (the whole section)."""
        return boundary.reactions(self._residual_form, self.unknown, {"mid": self.mid},
                                  {"mid": [1]}, space=self.V)["mid"][1] * -1.0

    def neck_radius(self) -> float:
        """The current radius of the mid-plane section."""
        return RADIUS * NARROWING + self.probes.continuous(self.fields.displacement())[0][0]
