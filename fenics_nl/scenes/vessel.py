"""A thick pressure vessel: a hollow sphere (axisymmetric) or cylinder (plane strain).

The quarter a < |x| < b of the (r, z) or (x, y) plane, P2 on curved edges. Supports: the
symmetry lines (x = 0: u_x = 0, the axis of the sphere; y = 0: u_y = 0). The inner surface
carries the pressure p (a Constant) or, for displacement control, a prescribed radial motion
(`inner_motion`), whose reaction gives back the pressure.

`mixed=True` makes the unknown the Taylor–Hood pair (u, p) of `materials.mixed`: `unknown`
is what a solver updates, `u` the displacement in forms, `displacement()` a Function of it.
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
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.mixed import unknowns

__all__ = ["VesselBody"]

SHAPES = ("sphere", "cylinder")


class VesselBody:
    """Mesh, space, supports, the inner surface and the points the checks read."""

    def __init__(self, shape: str, a: float, b: float, *, size: float | None = None,
                 degree: int = 2, mixed: bool = False, comm: MPI.Comm = MPI.COMM_WORLD):
        if shape not in SHAPES:
            raise ValueError(f"shape must be sphere or cylinder, got {shape!r}")
        if not 0 < a < b:
            raise ValueError(f"radii must satisfy 0 < inner < outer, got {a}, {b}")
        self.shape, self.a, self.b, self.degree = shape, a, b, degree
        self.model = "axisymmetric" if shape == "sphere" else "plane_strain"
        self.h = size or (b - a) / 16
        data = quarter_annulus(comm, a, b, self.h)
        self.mesh = msh = data.mesh
        self.fields = f = unknowns(msh, degree, mixed)
        self.mixed = f if mixed else None
        self.V, self.unknown, self.u = f.V, f.w, f.u
        motion_space = f.displacement_space

        def facets(name):
            return data.facet_tags.find(data.physical_groups[name].tag)

        self.inner = facets("inner")
        self.symmetry = {"x0": facets("x0"), "y0": facets("y0")}
        self.supports = [boundary.component(self.V, 0, facets("x0")),
                         boundary.component(self.V, 1, facets("y0"))]
        self.quadrature_degree = 2 * degree
        self.dx = kinematics.quadrature_measure("dx", msh, self.quadrature_degree)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=data.facet_tags)
        self.ds_inner = ds(data.physical_groups["inner"].tag)
        self.weight = kinematics.measure_weight(msh, self.model)
        self.normal = ufl.FacetNormal(msh)
        self.pressure = fem.Constant(msh, 0.0)
        self._motion = fem.Function(motion_space)
        if mixed:  # dofs in the mixed numbering, values from the collapsed space
            dofs = fem.locate_dofs_topological((self.V, motion_space), 1, self.inner)
            self.inner_motion = fem.dirichletbc(self._motion, dofs, self.V)
        else:
            self.inner_motion = fem.dirichletbc(
                self._motion, fem.locate_dofs_topological(self.V, 1, self.inner))
        # the inner and outer points on y = 0 (r = a and b; z = 0 for the sphere)
        self.probes = Probes(msh, [[a, 0.0], [b, 0.0]])

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.unknown.function_space)

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()

    def move_inner(self, delta: float) -> None:
        """Prescribe the radial displacement δ of the inner surface (tangential 0)."""
        self._motion.interpolate(lambda x: delta * x[:2] / np.hypot(x[0], x[1]))

    def pressure_from(self, residual, inner_radius: float | None = None) -> float:
        """The pressure the inner support exerts (displacement control).

        Small strain; in finite strain give the deformed `inner_radius`. Read where the wall
        carries it: the symmetry plane across the wall holds the pressure's resultant
        (sphere: the plane z = 0 the axial p π a²; cylinder: the plane x = 0 the x resultant
        p a per unit length of the quarter). The inner support's own reaction would also
        hold the corner node it shares with that plane: an O(h) error (−2.4 % at h = a/10,
        measured on the neo-Hookean cylinder).
        """
        a = inner_radius or self.a
        plane, axis = ("y0", 1) if self.shape == "sphere" else ("x0", 0)
        held = boundary.reactions(residual, self.unknown, {plane: self.symmetry[plane]},
                                  {plane: [axis]}, space=self.V)[plane][axis]
        return -held / (math.pi * a * a if self.shape == "sphere" else a)

    def inner_displacement(self) -> float:
        """Radial displacement of the inner surface (at y = 0)."""
        return self.probes.continuous(self.displacement())[0][0]

    def stresses_at_inner(self, material) -> tuple[float, float]:
        """(σ_eq, hoop σ_θ) at the inner surface (the point on y = 0)."""
        if self.mixed:
            sigma = mixed.cauchy_stress(material, self.u, self.mixed.p, self.model)
        else:
            sigma = material.cauchy_stress(self.u, self.model)
        s = ufl.dev(sigma)
        vm = self.probes.discontinuous("vm", ufl.sqrt(1.5 * ufl.inner(s, s)), self.degree)
        hoop = self.probes.discontinuous("hoop", sigma[1, 1], self.degree)
        return vm[0], hoop[0]

    def yield_onset(self, residual, material, trial: float, force: float) -> float:
        """The pressure at which the inner surface yields, from one elastic solve.

        σ_eq grows in proportion to an elastic load: solved at the pressure `trial` (which
        must leave the body elastic, else a SolveError), σ_eq(a) per unit pressure gives
        the onset σ0 / (σ_eq(a)/trial). The body is left unloaded. `force`: the force scale
        of Newton's absolute tolerance.
        """
        from fenics_nl.errors import SolveError
        from fenics_nl.solvers.newton import NewtonSolver

        self.pressure.value = trial
        NewtonSolver(residual, self.unknown, self.supports, rtol=1e-10, atol=1e-10,
                     force_scale=force, prefix="vessel_onset_").solve()
        vm_a, _ = self.stresses_at_inner(material)
        if vm_a >= material.sigma0:
            raise SolveError(f"the onset step yielded (σ_eq(a) = {vm_a:.4g} >= σ0): it must "
                             "be elastic")
        self.unknown.x.array[:] = 0.0
        self.pressure.value = 0.0
        return trial * material.sigma0 / vm_a

    def plastic_radius(self, material) -> float:
        """Largest |x| of a quadrature point where p > 0 (the plastic zone's edge), or a."""
        return material.plastic_radius(self.a)
