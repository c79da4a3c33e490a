"""Small ready-made problems shared by tests and benchmarks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.materials import kinematics

__all__ = ["Problem", "cantilever_3d"]


@dataclass
class Problem:
    """A displacement problem R(u; v) = 0 ready for a Newton solver."""

    u: fem.Function
    residual: ufl.Form
    bcs: list[fem.DirichletBC]
    load: fem.Constant  # scaled by load stepping
    observed: ufl.Form  # a scalar quantity of interest (integral form)


def cantilever_3d(material, cells=(12, 3, 3), size=(10.0, 1.0, 1.0), traction=-1.0,
                  comm: MPI.Comm = MPI.COMM_WORLD, degree: int = 1) -> Problem:
    """Block clamped at x = 0 with a downward traction on x = L (tetrahedra).

    The observed quantity is the mean vertical displacement of the loaded face.
    """
    L, W, H = size
    domain = mesh.create_box(comm, [np.zeros(3), np.array(size)], list(cells),
                             mesh.CellType.tetrahedron)
    V = fem.functionspace(domain, ("Lagrange", degree, (3,)))
    fdim = domain.topology.dim - 1
    clamped = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[0], 0.0))
    loaded = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[0], L))
    tags = mesh.meshtags(domain, fdim, loaded, np.full(len(loaded), 1, dtype=np.int32))
    bc = fem.dirichletbc(np.zeros(3), fem.locate_dofs_topological(V, fdim, clamped), V)
    u, v = fem.Function(V, name="u"), ufl.TestFunction(V)
    t = fem.Constant(domain, np.array([0.0, 0.0, traction]))
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    dx = kinematics.quadrature_measure("dx", domain, degree=2 * degree)
    R = material.internal_work(u, v) * dx - ufl.dot(t, v) * ds(1)
    observed = u[2] / (W * H) * ds(1)
    return Problem(u, R, [bc], t, observed)
