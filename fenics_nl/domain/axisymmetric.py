"""Sections of cylinders in the (r, z) plane, built by DOLFINx, with their facet tags.

`billet`: the half 0 < r < R0, 0 < z < h0/2 of a short cylinder pressed between flat dies
(the upsetting), squares cut into four triangles by their diagonals. `narrowed_bar`: the
quarter 0 < r < R(z), 0 < z < L/2 of a bar whose radius narrows linearly towards its
mid-length (a tension test's imperfection: where the neck forms), quadrilaterals graded
towards the neck. Both are returned as the gmsh factories of `meshes` return theirs,
`dolfinx.io.gmsh.MeshData`: the mesh, its facet tags and the groups' names
(`physical_groups[name].tag`). The thick vessels' quarter is `meshes.quarter_annulus`.
"""

from __future__ import annotations

import numpy as np
from dolfinx import mesh
from dolfinx.io.gmsh import MeshData, PhysicalGroup
from mpi4py import MPI

from fenics_nl.domain.boundary import tags_where

__all__ = ["BAR_GROUPS", "BILLET_GROUPS", "billet", "narrowed_bar"]

# facet tags: the axis r = 0 and the mid-plane z = 0 (both symmetry lines), the die's faces
BILLET_GROUPS = {"axis": 1, "mid": 2, "top": 3, "side": 4}
# the axis, the mid-plane (the neck's section) and the pulled end z = L/2
BAR_GROUPS = {"axis": 1, "mid": 2, "end": 3}


def _tagged(msh: mesh.Mesh, groups: dict[str, int], where: dict) -> MeshData:
    """The mesh with the boundary facets where `where[name](x)` holds tagged `groups[name]`."""
    fdim = msh.topology.dim - 1
    tags = tags_where(msh, fdim, {groups[name]: test for name, test in where.items()})
    return MeshData(mesh=msh, cell_tags=None, facet_tags=tags, ridge_tags=None,
                    peak_tags=None, physical_groups={name: PhysicalGroup(fdim, tag)
                                                     for name, tag in groups.items()})


def billet(comm: MPI.Comm, radius: float, height: float, cells: int = 8) -> MeshData:
    """The half section of a billet of radius R0 and height h0 (its lower half by symmetry).

    `cells` squares across the radius and as many as fit in h0/2 (at least one row), each
    cut into four triangles by its diagonals: no triangle has all its vertices on the
    boundary, so Taylor–Hood P2–P1 is stable on it.

    Args:
        comm: the communicator.
        radius: R0.
        height: h0, the whole billet's.
        cells: squares across the radius.

    Returns:
        The mesh (triangles, x = r, y = z) with its facet tags, `BILLET_GROUPS`, as
        DOLFINx's MeshData. ``axis`` (r = 0), ``mid`` (z = 0), ``top`` (z = h0/2) and
        ``side`` (r = R0 above the first row of cells: its foot, on the mid-plane, is held
        by the symmetry, and a die's reaction read there would hold the symmetry's too, so
        it is left untagged).
    """
    if not (radius > 0 and height > 0):
        raise ValueError(f"radius and height must be > 0, got {radius}, {height}")
    half = 0.5 * height
    rows = max(1, round(cells * half / radius))  # square cells
    msh = mesh.create_rectangle(comm, [[0.0, 0.0], [radius, half]], [cells, rows],
                                mesh.CellType.triangle, diagonal=mesh.DiagonalType.crossed)
    tol = 1e-9 * max(radius, half)
    return _tagged(msh, BILLET_GROUPS, {
        "axis": lambda x: np.isclose(x[0], 0.0, atol=tol),
        "mid": lambda x: np.isclose(x[1], 0.0, atol=tol),
        "top": lambda x: np.isclose(x[1], half, atol=tol),
        "side": lambda x: np.isclose(x[0], radius, atol=tol) & (x[1] > 0.99 * half / rows)})


def narrowed_bar(comm: MPI.Comm, radius: float, length: float, narrowing: float,
                 cells: int = 4, grading: float = 3.0) -> MeshData:
    """The quarter section of a round bar narrowed linearly to `narrowing` · r0 at mid-length.

    R(z) = r0 (narrowing + (1 − narrowing) z/(L/2)) for 0 < z < L/2. `cells` quadrilaterals
    across the radius and about L/(2 r0) times as many along the half length, graded
    towards the neck: z = (L/2) s^a, a = 1 + ln(grading)/ln(rows), so that the first cell
    at the neck is `grading` times shorter than the mean (1: uniform); r follows R(z).

    Args:
        comm: the communicator.
        radius: r0, the bar's radius away from the neck.
        length: L, the whole bar's.
        narrowing: R(0)/r0, the neck's radius (1: a straight bar).
        cells: quadrilaterals across the radius.
        grading: how much finer the mesh is at the neck (>= 1).

    Returns:
        The mesh (x = r, y = z) with its facet tags, `BAR_GROUPS`, as DOLFINx's MeshData.
        ``axis`` (r = 0), ``mid`` (z = 0, the neck's section) and ``end`` (z = L/2).
    """
    if not (radius > 0 and length > 0 and 0 < narrowing <= 1):
        raise ValueError(f"radius and length must be > 0 and the narrowing in (0, 1], got "
                         f"{radius}, {length}, {narrowing}")
    half = length / 2
    rows = max(2, round(cells * half / radius))
    msh = mesh.create_rectangle(comm, [[0.0, 0.0], [1.0, 1.0]], [cells, rows],
                                mesh.CellType.quadrilateral)
    x = msh.geometry.x
    a = np.log(grading) / np.log(rows) + 1.0 if grading > 1 else 1.0
    x[:, 1] = half * x[:, 1] ** a
    x[:, 0] *= radius * (narrowing + (1 - narrowing) * x[:, 1] / half)
    return _tagged(msh, BAR_GROUPS, {"axis": lambda p: np.isclose(p[0], 0.0),
                                     "mid": lambda p: np.isclose(p[1], 0.0),
                                     "end": lambda p: np.isclose(p[1], half)})
