"""The thick vessel that the plasticity and mixed-formulation tests and benchmarks share.

`thick_vessel` builds the quarter a < |x| < b of `demos/pressure_vessel.py` (a sphere in the
axisymmetric model, a cylinder in plane strain) from the public pieces the demo's cells use:
`domain.meshes.quarter_annulus` and its tags, the unknown of `materials.mixed` (P2, or
Taylor–Hood), the symmetry lines' supports (`domain.boundary`), the inner surface's
pressure (a `fem.Constant`) or its prescribed radial motion, and what the checks read:
u(a) and the pressure from the wall's reaction. Each test or benchmark writes its material
and residual on it. (benchmarks/ is on the tests' path: `from plasticity_problems import
thick_vessel`.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.io.gmsh import MeshData
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import quarter_annulus
from fenics_nl.domain.probes import Probes
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.mixed import DisplacementUnknown, MixedUnknown, unknowns

__all__ = ["ThickVessel", "thick_vessel"]

SHAPES = {"sphere": "axisymmetric", "cylinder": "plane_strain"}  # shape: its model


@dataclass
class ThickVessel:
    """The quarter a < |x| < b, its unknown, supports and inner surface (`thick_vessel`).

    `fields` is the unknown of either formulation (`mixed`: the same when Taylor–Hood, else
    None); `unknown` its Function (what a solver updates), `u` the displacement in forms, `V`
    the displacement (sub-)space. `dx` has degree 4 (P2's 2 × 2, `quadrature_degree`);
    `ds_inner`, `weight` (2πr for the sphere) and `normal` write the pressure's work,
    ``pressure * ufl.dot(normal, v) * weight * ds_inner``; `inner_motion` is the Dirichlet
    condition of `move_inner`.
    """

    shape: str
    a: float
    b: float
    h: float
    model: str
    mesh_data: MeshData
    fields: DisplacementUnknown | MixedUnknown
    supports: list
    symmetry: dict
    dx: ufl.Measure
    ds_inner: ufl.Measure
    weight: object
    normal: object
    pressure: fem.Constant
    inner_motion: fem.DirichletBC
    motion: fem.Function
    probes: Probes
    quadrature_degree: int = 4

    @property
    def mesh(self):
        """The mesh."""
        return self.mesh_data.mesh

    @property
    def mixed(self) -> MixedUnknown | None:
        """The Taylor–Hood unknown, or None (displacement formulation)."""
        return self.fields if self.fields.mixed else None

    @property
    def V(self):
        """The displacement (sub-)space: Dirichlet conditions, reactions."""
        return self.fields.V

    @property
    def unknown(self) -> fem.Function:
        """The Function a solver updates (u, or (u, p))."""
        return self.fields.w

    @property
    def u(self):
        """The displacement in forms."""
        return self.fields.u

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.unknown.function_space)

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()

    def move_inner(self, delta: float) -> None:
        """Prescribe the radial displacement of the inner surface (tangential 0).

        Args:
            delta: δ, outwards.
        """
        self.motion.interpolate(lambda x: delta * x[:2] / np.hypot(x[0], x[1]))

    def inner_displacement(self) -> float:
        """The radial displacement of the inner surface (at y = 0)."""
        return self.probes.continuous(self.displacement())[0][0]

    def pressure_from(self, residual, inner_radius: float | None = None) -> float:
        """The pressure the inner support exerts (displacement control).

        Read where the wall carries it: the symmetry plane across the wall holds the
        pressure's resultant (sphere: the plane z = 0 the axial p π a²; cylinder: the plane
        x = 0 the x resultant p a per unit length of the quarter). The inner support's own
        reaction would also hold the corner node it shares with that plane: an O(h) error
        (−2.4 % at h = a/10, measured on the neo-Hookean cylinder).

        Args:
            residual: the residual (a form, or its UFL).
            inner_radius: the deformed inner radius (finite strain; default a).

        Returns:
            p.
        """
        a = inner_radius or self.a
        plane, axis = ("y0", 1) if self.shape == "sphere" else ("x0", 0)
        held = boundary.reactions(residual, self.unknown, {plane: self.symmetry[plane]},
                                  {plane: [axis]}, space=self.V)[plane][axis]
        return -held / (math.pi * a * a if self.shape == "sphere" else a)


def thick_vessel(shape: str, a: float, b: float, *, size: float | None = None,
                 mixed: bool = False, comm: MPI.Comm = MPI.COMM_WORLD) -> ThickVessel:
    """The quarter of a thick sphere or cylinder, as `demos/pressure_vessel.py` builds it.

    Args:
        shape: ``sphere`` (axisymmetric, x = r, y = z) or ``cylinder`` (plane strain).
        a: the inner radius.
        b: the outer radius.
        size: the element size (default (b − a)/16).
        mixed: Taylor–Hood (u, p) instead of P2 displacements.
        comm: the communicator.

    Returns:
        The vessel, P2 on the curved quarter, the symmetry lines held (x = 0 along x, the
        sphere's axis; y = 0 along y), the inner pressure at 0 and its motion at rest.
    """
    if shape not in SHAPES:
        raise ValueError(f"shape must be sphere or cylinder, got {shape!r}")
    if not 0 < a < b:
        raise ValueError(f"radii must satisfy 0 < inner < outer, got {a}, {b}")
    h = size or (b - a) / 16
    data = quarter_annulus(comm, a, b, h)
    msh = data.mesh

    def tagged(name):
        return data.facet_tags.find(data.physical_groups[name].tag)

    fields = unknowns(msh, 2, mixed)
    V = fields.V
    motion = fem.Function(fields.displacement_space)
    inner = tagged("inner")
    if mixed:  # dofs in the mixed numbering, values from the collapsed space
        dofs = fem.locate_dofs_topological((V, fields.displacement_space), 1, inner)
        inner_motion = fem.dirichletbc(motion, dofs, V)
    else:
        inner_motion = fem.dirichletbc(motion, fem.locate_dofs_topological(V, 1, inner))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=data.facet_tags)
    model = SHAPES[shape]
    return ThickVessel(
        shape, a, b, h, model, data, fields,
        supports=[boundary.component(V, 0, tagged("x0")), boundary.component(V, 1, tagged("y0"))],
        symmetry={"x0": tagged("x0"), "y0": tagged("y0")},
        dx=kinematics.quadrature_measure("dx", msh, 4),
        ds_inner=ds(data.physical_groups["inner"].tag),
        weight=kinematics.measure_weight(msh, model), normal=ufl.FacetNormal(msh),
        pressure=fem.Constant(msh, 0.0), inner_motion=inner_motion, motion=motion,
        # the inner and outer points on y = 0 (r = a and b; z = 0 for the sphere)
        probes=Probes(msh, [[a, 0.0], [b, 0.0]]))
