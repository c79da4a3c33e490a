"""The bracket of `demos/bracket.py` in one call, for the benchmarks that time its solves.

(The demo writes the same steps out: the mesh and tags, the space, the residual, a solver
per Newton variant.)

The mesh comes from `domain.bracket` (built on rank 0, distributed) or from a user's
.msh file with the physical groups ``bolts``, ``load`` and ``base``. The loaded hole carries
a uniform traction of total force F along +x; the bolt holes are clamped, and with
``support="contact"`` the base also rests on a rigid floor (may lift off; frictionless, or
with Coulomb friction).
"""

from __future__ import annotations

from functools import partial

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.contact.friction import FrictionalContact
from fenics_nl.domain import boundary
from fenics_nl.domain.bracket import THICK, bracket_mesh
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials import mixed as mixed_form
from fenics_nl.materials.mixed import unknowns
from fenics_nl.parallel import global_max
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import SnesSolver

__all__ = ["Bracket", "BracketPart", "build_bracket"]

THICKNESS_MM = THICK  # the base plate's thickness


# Newton iterations allowed in one load step. Full Newton that has not converged in 50 is
# lost (a step too large): stop early and say so. A stale tangent converges linearly, so
# modified and quasi-Newton get many cheap iterations (measured: 367 for one step to 8 kN).
MAX_IT = {"full": 50, "periodic": 150, "modified": 800, "bfgs": 800}


class BracketPart:
    """The bracket's mesh and conditions: bolt holes clamped, a traction on the loaded hole.

    Lagrange P`degree` tetrahedra. Everything a residual is written with is public: `u`,
    `V`, `dx` (degree 2 × degree by default: exact for the linear part of the power law,
    docs/benchmarks.md's table), `traction` (set by `set_load`) and `ds_load`. With
    ``support="contact"`` the base is the candidate contact surface on a rigid floor.
    """

    def __init__(self, *, size: float = 5.0, mesh_file: str | None = None,
                 support: str = "clamped", degree: int = 1, length_scale: float = 1.0,
                 quadrature_degree: int | None = None, mixed: bool = False,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if support not in ("clamped", "contact"):
            raise ValueError(f"support must be clamped or contact, got {support!r}")
        self.support = support
        data = bracket_mesh(comm, size, mesh_file, length_scale)
        self.mesh = data.mesh
        tags = data.facet_tags

        def facets(name):
            return tags.find(data.physical_groups[name].tag)

        tdim = self.mesh.topology.dim
        cells = np.arange(self.mesh.topology.index_map(tdim).size_local, dtype=np.int32)
        self.largest_cell = global_max(comm, self.mesh.h(tdim, cells))
        self.groups = {"bolts": facets("bolts")}
        self.load_facets, self.base_facets = facets("load"), facets("base")
        if support == "contact":
            self.groups["base"] = self.base_facets
        if mixed and degree < 2:
            raise ValueError("--mixed is Taylor–Hood: P2 displacements (--degree 2)")
        # `unknown` is what a solver updates, `u` the displacement in forms
        self.fields = f = unknowns(self.mesh, degree, mixed)
        self.mixed = f if mixed else None
        self.V, self.unknown, self.u, self.p = f.V, f.w, f.u, f.p
        ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)
        self.ds_load = ds(data.physical_groups["load"].tag)
        self.load_area = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * self.ds_load)))
        self.traction = fem.Constant(self.mesh, np.zeros(3))
        q = quadrature_degree if quadrature_degree is not None else 2 * degree
        self.quadrature_degree = q
        self.dx = kinematics.quadrature_measure("dx", self.mesh, q)
        self.bcs = [boundary.fixed(self.V, facets("bolts"))]
        self._mean_u = [fem.form(self.u[i] * self.ds_load) for i in range(3)]

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.unknown.function_space)

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()

    def set_load(self, force: float) -> None:
        """Total force `force` [N] along +x, spread uniformly over the loaded hole."""
        self.traction.value[:] = [force / self.load_area, 0.0, 0.0]

    def load_point_motion(self) -> np.ndarray:
        """Mean displacement vector of the loaded hole."""
        comm = self.mesh.comm
        return np.array([comm.allreduce(fem.assemble_scalar(f)) / self.load_area
                         for f in self._mean_u])

    def load_point_displacement(self) -> float:
        """|mean displacement of the loaded hole| (in the mesh's length unit)."""
        return float(np.linalg.norm(self.load_point_motion()))


def build_bracket(material, *, size: float = 5.0, mesh_file: str | None = None,
                  support: str = "clamped", degree: int = 1, length_scale: float = 1.0,
                  quadrature_degree: int | None = None, mixed: bool = False,
                  comm: MPI.Comm = MPI.COMM_WORLD, **options) -> Bracket:
    """The bracket scene in one call (as `demos/bracket.py` composes it).

    `options` go to `Bracket` (newton, linear_solver, period, force_scale, tolerance).
    """
    part = BracketPart(size=size, mesh_file=mesh_file, support=support, degree=degree,
                       length_scale=length_scale, quadrature_degree=quadrature_degree,
                       mixed=mixed, comm=comm)
    f = part.fields
    residual = (f.internal_work(material, "3d") * part.dx
                - ufl.dot(part.traction, f.v) * part.ds_load)
    return Bracket(part, material, residual, **options)


class Bracket:
    """The non-linear solver of a bracket's residual.

    A Newton variant, SNES, or the active-set loop when the base rests on the floor.

    Args:
        part: mesh, space and conditions (`BracketPart`).
        material: the small-strain law of the residual (for σ_eq).
        residual: R(u; v) of the part under its traction (UFL form).
        newton: full | modified | periodic | bfgs | snes.
        linear_solver: ``lu`` (MUMPS) or ``gamg`` (CG + GAMG).
        period: tangent rebuilt every `period` iterations (``periodic``).
        force_scale: the force of the absolute tolerance (default: the first residual).
        tolerance: ‖R‖ ≤ tolerance × force_scale ends Newton.
        friction: Coulomb's coefficient between the base and the floor (support
            ``contact``); None: frictionless.
    """

    def __init__(self, part: BracketPart, material, residual, *, newton: str = "full",
                 linear_solver: str = "lu", period: int = 3, force_scale: float | None = None,
                 tolerance: float = 1e-9, friction: float | None = None):
        if not 0 < tolerance < 1:
            raise ValueError(f"tolerance must be in (0, 1), got {tolerance!r}")
        if friction is not None and part.support != "contact":
            raise ValueError("friction acts on the floor: it needs --support contact")
        if newton == "snes" and part.support == "contact":
            raise ValueError("--newton snes works with --support clamped only")
        self.part, self.material, self.residual = part, material, residual
        self.mesh, self.V, self.bcs = part.mesh, part.V, part.bcs
        self.u = part.unknown  # what the solver updates (u, or (u, p) if mixed)
        self.support, self.largest_cell = part.support, part.largest_cell
        self.set_load, self.load_point_motion = part.set_load, part.load_point_motion
        self.load_point_displacement = part.load_point_displacement
        # atol = tolerance × the load: ‖R‖ cannot go below the round-off of the internal
        # forces, which reaches 1e-10 of the load at ε_eq ~ 800 ε0 (measured: 20 kN in 10
        # steps on P2, 17k unknowns), hence 1e-9; and an active-set iteration restarts
        # Newton close to equilibrium, where rtol ‖R₀‖ means little
        method = newton
        opts = {"method": method, "rtol": 1e-10, "atol": tolerance, "force_scale": force_scale,
                "max_it": MAX_IT.get(method, 50),
                "linear_solver": linear_solver, "period": period}
        if linear_solver == "gamg" and part.mixed:  # MINRES, block preconditioner
            opts["preconditioner"] = mixed_form.preconditioner(material, part.mixed.W, "3d",
                                                               part.dx)
        if method in ("modified", "bfgs"):  # J2: the course's elastic tangent, once
            opts["constant_tangent"] = part.fields.constant_tangent(material, "3d", part.dx)
        if part.support == "contact":
            # the floor z = 0 under the base: outward normal −e_z, gap 0
            # with friction each base node is open, sticking or slipping on the floor
            contact = (ActiveSetContact if friction is None else
                       partial(FrictionalContact, friction=friction))
            self.solver = contact(
                residual, self.u, self.bcs, part.base_facets, lambda x: np.zeros(x.shape[1]),
                normal_axis=2, normal_sign=-1, initial="none", prefix="bracket_",
                newton_options=opts,
                displacement_space=part.V if part.mixed else None)
        elif newton == "snes":
            self.solver = SnesSolver(residual, self.u, self.bcs, prefix="bracket_snes_",
                                     rtol=1e-10, atol=tolerance, force_scale=force_scale,
                                     max_it=MAX_IT["full"], linear_solver=linear_solver)
        else:
            self.solver = NewtonSolver(residual, self.u, self.bcs, prefix="bracket_", **opts)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns."""
        return self.part.dofs

    def commit(self) -> None:
        """A converged load step: the start of the next one's slip increments (friction)."""
        if isinstance(self.solver, FrictionalContact):
            self.solver.commit()

    def contact_fields(self) -> list[fem.Function]:
        """Nodal floor pressure and active set (1/0) on the base (contact support only)."""
        return self.solver.fields()

    def reactions(self) -> dict[str, list[float]]:
        """Resultant force on the bolts (and on the base from the floor), see `boundary`."""
        return boundary.reactions(self.residual, self.u, self.part.groups, space=self.V)

    def floor_areas(self) -> tuple[float, float]:
        """Areas of the base lifted off the floor and in contact with it [mm²].

        Contact support only; a facet is in contact when all its vertices are active. Their
        sum is the meshed base's area (polygonal bolt holes: a little more than the exact).
        """
        ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=self.solver.active_facets())
        return tuple(self.mesh.comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds(tag))))
                     for tag in (0, 1))
