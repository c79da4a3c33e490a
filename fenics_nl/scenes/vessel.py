"""A thick pressure vessel: a hollow sphere (axisymmetric) or cylinder (plane strain).

The quarter a < |x| < b of the (r, z) or (x, y) plane, P2 on curved edges. Supports: the
symmetry lines (x = 0: u_x = 0, the axis of the sphere; y = 0: u_y = 0). The inner surface
carries the pressure p (a Constant) or, for displacement control, a prescribed radial motion
(`inner_motion`), whose reaction gives back the pressure.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import quarter_annulus
from fenics_nl.domain.probes import Probes
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.parallel import global_max

SHAPES = ("sphere", "cylinder")


class VesselBody:
    """Mesh, space, supports, the inner surface and the points the checks read."""

    def __init__(self, shape: str, a: float, b: float, *, size: float | None = None,
                 degree: int = 2, comm: MPI.Comm = MPI.COMM_WORLD):
        if shape not in SHAPES:
            raise ValueError(f"shape must be sphere or cylinder, got {shape!r}")
        if not 0 < a < b:
            raise ValueError(f"radii must satisfy 0 < inner < outer, got {a}, {b}")
        self.shape, self.a, self.b, self.degree = shape, a, b, degree
        self.model = "axisymmetric" if shape == "sphere" else "plane_strain"
        self.h = size or (b - a) / 16
        data = quarter_annulus(comm, a, b, self.h)
        self.mesh = msh = data.mesh
        self.V = fem.functionspace(msh, ("Lagrange", degree, (2,)))
        self.u = fem.Function(self.V, name="displacement")

        def facets(name):
            return data.facet_tags.find(data.physical_groups[name].tag)

        self.inner = facets("inner")
        self.supports = [boundary.component(self.V, 0, facets("x0")),
                         boundary.component(self.V, 1, facets("y0"))]
        self.quadrature_degree = 2 * degree
        self.dx = kinematics.quadrature_measure("dx", msh, self.quadrature_degree)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=data.facet_tags)
        self.ds_inner = ds(data.physical_groups["inner"].tag)
        self.weight = kinematics.measure_weight(msh, self.model)
        self.normal = ufl.FacetNormal(msh)
        self.pressure = fem.Constant(msh, 0.0)
        self._motion = fem.Function(self.V)
        self.inner_motion = fem.dirichletbc(
            self._motion, fem.locate_dofs_topological(self.V, 1, self.inner))
        # the inner and outer points on y = 0 (r = a and b; z = 0 for the sphere)
        self.probes = Probes(msh, [[a, 0.0], [b, 0.0]])

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns."""
        return output.dofs(self.V)

    def move_inner(self, delta: float) -> None:
        """Prescribe the radial displacement δ of the inner surface (tangential 0)."""
        self._motion.interpolate(lambda x: delta * x[:2] / np.hypot(x[0], x[1]))

    def pressure_from(self, residual) -> float:
        """The pressure the inner support exerts, from its reaction (displacement control).

        Sphere: the axial resultant on the half sphere, p π a²; cylinder: the x resultant on
        the quarter, p a per unit length.
        """
        force = boundary.reactions(residual, self.u, {"inner": self.inner})["inner"]
        if self.shape == "sphere":
            return force[1] / (math.pi * self.a**2)
        return force[0] / self.a

    def inner_displacement(self) -> float:
        """Radial displacement of the inner surface (at y = 0)."""
        return self.probes.continuous(self.u)[0][0]

    def stresses_at_inner(self, material) -> tuple[float, float]:
        """(σ_eq, hoop σ_θ) at the inner surface (the point on y = 0)."""
        sigma = material.cauchy_stress(self.u, self.model)
        vm = self.probes.discontinuous("vm", material.von_mises_expression(self.u, self.model),
                                       self.degree)
        hoop = self.probes.discontinuous("hoop", sigma[1, 1], self.degree)
        return vm[0], hoop[0]

    def plastic_radius(self, material) -> float:
        """Largest |x| of a quadrature point where p > 0 (the plastic zone's edge), or a."""
        p = material.cumulated_plastic_strain
        Q = p.function_space
        x = ufl.SpatialCoordinate(self.mesh)
        r = fem.Function(Q)
        r.interpolate(fem.Expression(ufl.sqrt(ufl.inner(x, x)),
                                     Q.element.interpolation_points))
        n = Q.dofmap.index_map.size_local
        plastic = p.x.array[:n] > 0
        return max(self.a, global_max(self.mesh.comm, r.x.array[:n][plastic]))
