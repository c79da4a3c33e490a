"""The upsetting of a cylindrical billet between flat rigid dies (axisymmetric, finite strain).

The half billet 0 < r < R0, 0 < z < h0/2 (the mid-plane z = 0 a symmetry plane: u_z = 0;
the axis: u_r = 0), squares cut into four triangles by their diagonals (no triangle has all
its vertices on the boundary: Taylor–Hood P2–P1 with `mixed` is stable), P`degree`.
The die is the plane z = h0/2 − d, d = reduction · h0/2: its candidate surface S_C is the
top face and the side r = R0, whose nodes fold onto the die as the billet barrels. A node's
condition u_z ≤ γ = h0/2 − d − Z is exact at any deformation for a flat die (its current
height Z + u_z stays below the die), and so is its slip: the die does not move along r,
and a node's slip on it is its increment of u_r.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.contact.friction import FrictionalContact
from fenics_nl.domain import boundary
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.mixed import unknowns
from fenics_nl.parallel import global_max
from fenics_nl.solvers.result import SolveResult

__all__ = ["Billet", "Upsetting"]

MODEL = "axisymmetric"


class Billet:
    """Mesh, unknown, supports and the die's candidate surface of the half billet."""

    def __init__(self, radius: float, height: float, *, cells: int = 8, degree: int = 2,
                 mixed: bool = False, comm: MPI.Comm = MPI.COMM_WORLD):
        if not (radius > 0 and height > 0):
            raise ValueError(f"radius and height must be > 0, got {radius}, {height}")
        self.radius, self.height, self.degree = radius, height, degree
        half = 0.5 * height
        rows = max(1, round(cells * half / radius))  # square cells
        self.mesh = msh = mesh.create_rectangle(comm, [[0.0, 0.0], [radius, half]],
                                                [cells, rows], mesh.CellType.triangle,
                                                diagonal=mesh.DiagonalType.crossed)
        self.h = radius / cells
        self.fields = f = unknowns(msh, degree, mixed)
        self.V, self.unknown, self.u = f.V, f.w, f.u
        fdim = msh.topology.dim - 1

        def where(test):
            return mesh.locate_entities_boundary(msh, fdim, test)

        tol = 1e-9 * max(radius, half)
        self.axis = where(lambda x: np.isclose(x[0], 0.0, atol=tol))
        self.mid = where(lambda x: np.isclose(x[1], 0.0, atol=tol))
        self.top = where(lambda x: np.isclose(x[1], half, atol=tol))
        # the side above the first row of cells: the corner on the mid-plane is held by its
        # symmetry condition, whose reaction is not a contact force
        self.side = where(lambda x: np.isclose(x[0], radius, atol=tol)
                          & (x[1] > 0.99 * half / rows))
        self.candidate = np.unique(np.concatenate([self.top, self.side]))
        self.supports = [boundary.component(self.V, 0, self.axis),
                         boundary.component(self.V, 1, self.mid)]
        self.weight = kinematics.measure_weight(msh, MODEL)  # 2πr: totals per turn
        self.quadrature_degree = 2 * degree
        self.dx = kinematics.quadrature_measure("dx", msh, self.quadrature_degree)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.unknown.function_space)

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()


class Upsetting:
    """The billet pressed by the die: a load-step solver (`solve`, `u`) for the driver.

    `material` a bound `FiniteJ2Plasticity`; `friction` Coulomb's f (0: frictionless, the
    frictionless active set). `set_reduction(r)` moves the die; `commit()` after a
    converged step (the plastic state, the slip history), `restore()` after a cut one.
    """

    def __init__(self, billet: Billet, material, *, friction: float = 0.0,
                 newton_options: dict | None = None, prefix: str = "upsetting_"):
        self.billet, self.material, self.friction = billet, material, float(friction)
        self.residual = billet.fields.internal_work(material, MODEL) * billet.dx
        self.u = billet.unknown
        scale = material.sigma0 * billet.radius**2  # the force of a yielded die face / π
        opts = {"method": "full", "rtol": 1e-10, "atol": 1e-10, "force_scale": scale,
                "max_it": 30, **(newton_options or {})}
        contact = {"normal_axis": 1, "normal_sign": 1, "initial": "penetrating",
                   "newton_options": opts, "prefix": prefix,
                   "displacement_space": billet.V if billet.fields.mixed else None}
        args = (self.residual, self.u, billet.supports, billet.candidate, self._gap)
        self.reduction = 0.0
        if self.friction > 0:
            self.contact = FrictionalContact(*args, friction=self.friction, **contact)
        else:
            self.contact = ActiveSetContact(*args, **contact)
        top = billet.height / 2
        self._volume = None  # its form, compiled when first asked
        self._on_top = np.isclose(self.contact.x[:, 1], top, atol=1e-9 * top)

    def _gap(self, x: np.ndarray) -> np.ndarray:
        return 0.5 * self.billet.height * (1.0 - self.reduction) - x[1]

    def set_reduction(self, reduction: float) -> None:
        """Move the die to the height reduction 1 − h/h0 = `reduction`."""
        if not 0 <= reduction < 1:
            raise ValueError(f"the reduction must be in [0, 1), got {reduction}")
        self.reduction = reduction
        self.contact.set_gap(self._gap)

    def solve(self) -> SolveResult:
        """The active set (with Coulomb's statuses) at the current die position."""
        return self.contact.solve()

    def commit(self) -> None:
        """A converged step: the material's state and (friction) the slip history."""
        self.material.commit(self.billet.u, MODEL)
        if self.friction > 0:
            self.contact.commit()

    def restore(self) -> None:
        """After a cut step: the statuses of the last converged one."""
        if self.friction > 0:
            self.contact.restore()

    # -- what a step reports ------------------------------------------------------------

    @property
    def force(self) -> float:
        """The die's force on the billet, compressive positive (the whole revolution)."""
        return self.contact.force

    def current_radius(self) -> np.ndarray:
        """r + u_r at the S_C nodes."""
        dofs, _ = self.contact.surface.tangential(0)  # u_r, in the unknown's numbering
        return self.contact.x[:, 0] + self.u.x.array[dofs]

    def contact_radius(self) -> float:
        """The outermost current radius of a node touching the die."""
        r = self.current_radius()
        return global_max(self.billet.mesh.comm, r[self.contact.active & self.contact.owned])

    def stick_radius(self) -> float:
        """The outermost current radius of a sticking node (0: none, or frictionless)."""
        if self.friction == 0:
            return 0.0
        r = self.current_radius()
        return global_max(self.billet.mesh.comm, r[self.contact.stick & self.contact.owned])

    def folded_nodes(self) -> int:
        """Nodes of the side r = R0 now on the die (the free surface folded onto it)."""
        S = self.contact.surface
        return S.count(self.contact.active & ~self._on_top)

    def max_plastic_strain(self) -> float:
        """The largest committed cumulated plastic strain."""
        p = self.material.cumulated_plastic_strain
        n = p.function_space.dofmap.index_map.size_local * p.function_space.dofmap.bs
        return global_max(self.billet.mesh.comm, p.x.array[:n])

    def volume(self) -> float:
        """The current volume of the whole billet (2π ∫ J r dR dZ, both halves)."""
        b = self.billet
        if self._volume is None:
            F = kinematics.deformation_gradient(b.u, MODEL)
            self._volume = fem.form(ufl.det(F) * b.weight * b.dx)
        return 2 * b.mesh.comm.allreduce(fem.assemble_scalar(self._volume))

    @staticmethod
    def initial_volume(radius: float, height: float) -> float:
        """π R0² h0."""
        return math.pi * radius**2 * height
