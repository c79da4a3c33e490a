"""Two bodies touching at a point: a sphere (or a cylinder) on a block, or on another one.

The section of an axisymmetric model (x = r, y = z) or of a plane-strain one: the upper
body is the quarter disc of radius R1 whose lowest point is the origin (centre (0, R1)),
cut at its equator; the lower body is the quarter disc of radius R2 whose highest point is
the origin, cut at its equator, or a block [0, width] × [−depth, 0] (R2 = None). The two
share no node: they touch at the origin only, and the gap between them opens as
r²/(2R) there (1/R = 1/R1 + 1/R2). Triangles of size h within 1.5 a of the origin (a the
contact radius the mesh is made for), growing by `growth` per unit distance.

Cell tags ``upper``, ``lower``; facet tags ``upper_contact`` (the upper body's arc),
``upper_top`` (its equator, where it is pushed), ``upper_axis``, ``lower_contact`` (the
lower arc or the block's top), ``lower_bottom`` (the equator or the block's bottom),
``lower_axis``, and ``lower_side`` (the block's).
"""

from __future__ import annotations

import gmsh
from dolfinx.io import gmsh as gmshio
from mpi4py import MPI

from fenics_nl.domain.meshes import _graded_size_field, start_model

__all__ = ["TWO_BODY_TAGS", "sphere_on_body"]

TWO_BODY_TAGS = ("upper_contact", "upper_top", "upper_axis", "lower_contact", "lower_bottom",
                 "lower_axis", "lower_side")


def sphere_on_body(comm: MPI.Comm, R1: float, a: float, *, R2: float | None = None,
                   block: float = 4.0, fine: float = 20.0, growth: float = 0.05
                   ) -> gmshio.MeshData:
    """The upper quarter disc on the lower one (or on a block), touching at the origin.

    Args:
        comm: the communicator.
        R1: the upper body's radius.
        a: the contact radius (half-width) the mesh is made for.
        R2: the lower body's radius (None: a block, width and depth `block` R1).
        block: the block's size in R1.
        fine: a/h near the origin.
        growth: the elements' growth per unit distance beyond 1.5 a.

    Returns:
        The mesh with its cell tags (``upper`` 1, ``lower`` 2) and facet tags (module).
    """
    unit = a  # gmsh's tolerances are absolute: it works in units of a
    r1, r2 = R1 / unit, None if R2 is None else R2 / unit
    width = depth = block * r1
    if comm.rank == 0:
        start_model("two_bodies")
        occ = gmsh.model.occ
        upper = occ.intersect([(2, occ.addDisk(0, r1, 0, r1, r1))],
                              [(2, occ.addRectangle(0, 0, 0, r1, r1))])[0]
        if r2 is None:
            lower = [(2, occ.addRectangle(0, -depth, 0, width, depth))]
        else:
            lower = occ.intersect([(2, occ.addDisk(0, -r2, 0, r2, r2))],
                                  [(2, occ.addRectangle(0, -r2, 0, r2, r2))])[0]
        occ.synchronize()
        tol = 1e-6
        groups = {name: [] for name in TWO_BODY_TAGS}
        for body, (dim, surface) in (("upper", upper[0]), ("lower", lower[0])):
            _, curves = gmsh.model.getAdjacencies(dim, surface)
            for c in curves:
                x, y, _ = occ.getCenterOfMass(1, c)
                if abs(x) < tol:
                    groups[f"{body}_axis"].append(c)
                elif body == "upper":
                    groups["upper_top" if abs(y - r1) < tol else "upper_contact"].append(c)
                elif r2 is None:
                    groups["lower_contact" if abs(y) < tol else "lower_bottom"
                           if abs(y + depth) < tol else "lower_side"].append(c)
                else:
                    groups["lower_bottom" if abs(y + r2) < tol else "lower_contact"].append(c)
        for i, (name, tags) in enumerate(groups.items(), start=1):
            if tags:
                gmsh.model.addPhysicalGroup(1, tags, i, name=name)
        gmsh.model.addPhysicalGroup(2, [upper[0][1]], 1, name="upper")
        gmsh.model.addPhysicalGroup(2, [lower[0][1]], 2, name="lower")
        far = max(width, depth, r1, r2 or 0.0)
        _graded_size_field(a / fine / unit, 1.5, a / fine / unit + growth * far, far)
        gmsh.model.mesh.generate(2)
    data = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=2)
    if comm.rank == 0:
        gmsh.model.remove()
    data.mesh.geometry.x[:] *= unit
    return data
