"""Values at points, the same on any number of ranks.

A continuous field (the displacement) is evaluated on the lowest rank that holds the point.
A discontinuous one (a stress) is interpolated cell by cell into a Legendre DG space (its
interpolation points are inside the cells: the axisymmetric hoop strain u_r/r is never
evaluated on the axis) and averaged over the owned cells holding the point, each evaluated
at the point itself.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem, geometry
from mpi4py import MPI

from fenics_nl.expression import Expression

__all__ = ["Probes"]


class Probes:
    """Points located once in a mesh; `outside` lists the indices of points it misses."""

    def __init__(self, mesh, points):
        self.mesh, comm = mesh, mesh.comm
        tdim = mesh.topology.dim
        tree = geometry.bb_tree(mesh, tdim)
        n_owned = mesh.topology.index_map(tdim).size_local
        self.where, self.outside = [], []
        for i, point in enumerate(points):
            x = np.zeros((1, 3))
            x[0, : len(point)] = point
            cells = geometry.compute_colliding_cells(
                mesh, geometry.compute_collisions_points(tree, x), x).links(0)
            owner = comm.allreduce(comm.rank if len(cells) else comm.size, MPI.MIN)
            if owner == comm.size:
                self.outside.append(i)
            self.where.append((x, owner, np.asarray(cells, dtype=np.int32),
                               [int(c) for c in cells if c < n_owned]))
        self._fields = {}

    def continuous(self, f: fem.Function) -> list[list[float]]:
        """Values of a continuous Function at the points (collective)."""
        comm, out = self.mesh.comm, []
        for x, owner, cells, _ in self.where:
            value = f.eval(x, cells[:1]).tolist() if comm.rank == owner else None
            out.append(comm.bcast(value, root=owner))
        return out

    def discontinuous(self, name: str, expr, degree: int) -> list:
        """Values of a UFL expression at the points (collective; compiled once).

        A float per point for a scalar, nested lists of the expression's shape for a tensor.
        """
        shape = expr.ufl_shape
        if name not in self._fields:
            import basix.ufl

            el = basix.ufl.element("DG", self.mesh.basix_cell(), degree, shape=shape or None,
                                   lagrange_variant=basix.LagrangeVariant.legendre)
            Q = fem.functionspace(self.mesh, el)
            self._fields[name] = (fem.Function(Q),
                                  Expression(expr, Q.element.interpolation_points))
        f, compiled = self._fields[name]
        f.interpolate(compiled)
        comm, out = self.mesh.comm, []
        size = int(np.prod(shape)) if shape else 1
        for x, _, _, owned in self.where:
            total = sum((f.eval(x, np.array([c], dtype=np.int32))[:size] for c in owned),
                        np.zeros(size))
            mean = comm.allreduce(total) / comm.allreduce(len(owned))
            out.append(mean.reshape(shape).tolist() if shape else float(mean[0]))
        return out
