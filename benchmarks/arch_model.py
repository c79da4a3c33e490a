"""The shallow arch of `demos/snap_through.py` in one object, for the benchmarks.

(The demo writes the same steps out: the mesh and its tags, the space, the pins, the
residual.) The arch as a 2D continuum: a curved strip that snaps through.

The strip of span L and thickness h follows y₀ = e sin(πx/L) (each section shifted
vertically: the arch is shallow), Q2 quadrilaterals, plane stress, unit width, St
Venant–Kirchhoff in the Green–Lagrange strain. Each end is pinned at its centreline node,
free to rotate. The top face carries the dead load λ q₀ sin(πx/L) per unit span,
downwards. `theory.arch` has the shallow-arch curve it is checked against.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import StVenantKirchhoff

__all__ = ["ShallowArch"]

MODEL = "plane_stress"


class ShallowArch:
    """Span `span`, thickness `thickness`, rise e = `rise` r (r = h/√12), material E, ν.

    `elements`: Q2 elements through the thickness (even, so that a node sits on the
    centreline); along the span they are `aspect` times as long as high.
    """

    def __init__(self, span: float, thickness: float, rise: float, E: float, nu: float, *,
                 elements: int = 2, aspect: float = 4.0, comm: MPI.Comm = MPI.COMM_WORLD):
        if not (span > 0 and thickness > 0 and rise > 0):
            raise ValueError(f"span, thickness and rise must be > 0, got {span}, "
                             f"{thickness}, {rise}")
        if thickness > span / 20:
            raise ValueError(f"the arch must be slender: thickness <= span/20, got L/h = "
                             f"{span / thickness:.3g}")
        if elements < 2 or elements % 2:
            raise ValueError(f"elements through the thickness must be even and >= 2, got "
                             f"{elements}")
        self.L, self.h = span, thickness
        self.r = thickness / math.sqrt(12)  # radius of gyration of the section
        self.e = rise * self.r
        self.rise = rise
        self.material = StVenantKirchhoff(E, nu)
        self.EI = E * thickness**3 / 12
        nx = max(8, 2 * round(span / (aspect * thickness / elements) / 2))
        self.mesh = mesh.create_rectangle(comm, [[0, -thickness / 2], [span, thickness / 2]],
                                          [nx, elements], mesh.CellType.quadrilateral)
        x = self.mesh.geometry.x
        x[:, 1] += self.e * np.sin(math.pi * x[:, 0] / span)
        self.V = fem.functionspace(self.mesh, ("Lagrange", 2, (2,)))
        self.u = fem.Function(self.V, name="displacement")
        v = ufl.TestFunction(self.V)
        self._pins = {name: fem.locate_dofs_geometrical(
            self.V, lambda p, x0=x0: np.isclose(p[0], x0) & np.isclose(p[1], 0))
            for name, x0 in (("left pin", 0.0), ("right pin", span))}
        self.bcs = [fem.dirichletbc(np.zeros(2), pin, self.V) for pin in self._pins.values()]
        # the top face, and the load per unit span: q(x) dx = q(x) |n_y| ds on it
        top = mesh.locate_entities_boundary(
            self.mesh, 1, lambda p: np.isclose(p[1], thickness / 2
                                               + self.e * np.sin(math.pi * p[0] / span)))
        tags = mesh.meshtags(self.mesh, 1, top, np.ones(len(top), dtype=np.int32))
        ds_top = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)(1)
        X = ufl.SpatialCoordinate(self.mesh)
        n = ufl.FacetNormal(self.mesh)
        self.q0 = self.EI * (math.pi / span) ** 4 * self.r  # the theory's load unit
        self.factor = fem.Constant(self.mesh, 0.0)  # λ: q₀ = λ EI k⁴ r
        q = self.factor * self.q0 * ufl.sin(math.pi * X[0] / span) * abs(n[1])
        dx = kinematics.quadrature_measure("dx", self.mesh, 4)
        work = ufl.inner(self.material.first_piola(self.u, MODEL),
                         kinematics.displacement_gradient(v, MODEL))
        self.residual = work * dx + q * v[1] * ds_top
        # the midspan centreline node's vertical displacement
        owned = self.V.dofmap.index_map.size_local
        X_dofs = self.V.tabulate_dof_coordinates()[:owned]
        self._mid = np.flatnonzero(np.isclose(X_dofs[:, 0], span / 2)
                                   & np.isclose(X_dofs[:, 1], self.e))
        if comm.allreduce(len(self._mid)) != 1:
            raise ValueError("the mesh has no node at midspan on the centreline: use an "
                             "even number of elements along the span")

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns."""
        return output.dofs(self.V)

    def set_load(self, lam: float) -> None:
        """q₀ = λ EI k⁴ r: λ is the theory's dimensionless load."""
        self.factor.value = lam

    def reactions(self) -> dict[str, list[float]]:
        """The force each pin exerts on the arch (per unit width): R(u) summed there."""
        from dolfinx.fem import petsc
        from petsc4py import PETSc

        b = petsc.assemble_vector(fem.form(self.residual))
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        owned = self.V.dofmap.index_map.size_local
        out = {}
        for name, nodes in self._pins.items():
            nodes = nodes[nodes < owned]
            local = [float(b.array_r[2 * nodes + i].sum()) for i in range(2)]
            out[name] = [self.mesh.comm.allreduce(f) for f in local]
        b.destroy()
        return out

    def centreline(self) -> np.ndarray | None:
        """Deformed centreline points (x + u), gathered on rank 0 and sorted by x."""
        from fenics_nl.parallel import gather_rows

        owned = self.V.dofmap.index_map.size_local
        X = self.V.tabulate_dof_coordinates()[:owned]
        on = np.isclose(X[:, 1], self.e * np.sin(math.pi * X[:, 0] / self.L))
        u = self.u.x.array[: 2 * owned].reshape(-1, 2)[on]
        rows = gather_rows(self.mesh.comm, X[on, 0], X[on, :2] + u)
        if rows is None:
            return None
        x0, points = rows
        return points[np.argsort(x0)]

    def midspan_rise(self) -> float:
        """ā = (e + w_mid)/r: the centreline's midspan rise in radii of gyration."""
        w = float(self.u.x.array[2 * self._mid + 1].sum())
        return (self.e + self.mesh.comm.allreduce(w)) / self.r
