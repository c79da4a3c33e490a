"""Inverted (folded) and degenerate cells: found before they give a silently wrong answer.

DOLFINx integrates with |det J|, so a cell turned inside out still assembles: the mesh then
overlaps itself and the solve returns a plausible but wrong field. The test used here needs
no reference orientation: across every interior facet, the two cells must lie on opposite
sides of the facet's plane (their vertex means have signed distances of opposite signs). A
cell whose vertex mean lies on the plane of one of its facets has (almost) no volume.
"""

from __future__ import annotations

import numpy as np
from dolfinx import mesh as dmesh
from mpi4py import MPI

__all__ = ["bad_cells", "check_cells"]


def _facet_plane(xf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals and a point of each facet (rows of xf: facet, vertex, coordinate)."""
    gdim = xf.shape[2]
    if gdim == 2:
        t = xf[:, 1] - xf[:, 0]
        n = np.stack([-t[:, 1], t[:, 0]], axis=1)
    else:
        n = np.cross(xf[:, 1] - xf[:, 0], xf[:, 2] - xf[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0), xf[:, 0]


def bad_cells(domain: dmesh.Mesh, rel_tol: float = 1e-8) -> dict[str, np.ndarray]:
    """Local indices of folded and of degenerate cells (straight-sided geometry)."""
    tdim, fdim = domain.topology.dim, domain.topology.dim - 1
    gdim = domain.geometry.dim
    domain.topology.create_connectivity(fdim, tdim)
    f2c = domain.topology.connectivity(fdim, tdim)
    n_facets = domain.topology.index_map(fdim).size_local + domain.topology.index_map(
        fdim).num_ghosts
    n_cells = domain.topology.index_map(tdim).size_local
    x = domain.geometry.x[:, :gdim]
    counts = np.diff(f2c.offsets)
    interior = np.flatnonzero(counts[:n_facets] == 2)
    cells = f2c.array[f2c.offsets[interior][:, None] + np.arange(2)]
    fnodes = dmesh.entities_to_geometry(domain, fdim, interior.astype(np.int32))
    n, p = _facet_plane(x[fnodes[:, :gdim]])
    cnodes = dmesh.entities_to_geometry(domain, tdim, np.arange(
        domain.topology.index_map(tdim).size_local
        + domain.topology.index_map(tdim).num_ghosts, dtype=np.int32))
    n_vertices = {"triangle": 3, "quadrilateral": 4, "tetrahedron": 4, "hexahedron": 8}[
        domain.topology.cell_name()]
    centre = x[cnodes[:, :n_vertices]].mean(axis=1)
    size = np.linalg.norm(x[cnodes[:, :n_vertices]] - centre[:, None], axis=2).max(axis=1)
    d = [np.einsum("ij,ij->i", centre[cells[:, k]] - p, n) for k in range(2)]
    h = np.minimum(size[cells[:, 0]], size[cells[:, 1]])
    flat = (np.abs(d[0]) < rel_tol * h) | (np.abs(d[1]) < rel_tol * h)
    folded = ~flat & (np.sign(d[0]) == np.sign(d[1]))
    def owned(mask):
        c = np.unique(cells[mask])
        return c[c < n_cells]

    return {"folded": owned(folded), "degenerate": owned(flat)}


def check_cells(domain: dmesh.Mesh, name: str = "mesh") -> None:
    """Raise ValueError naming the first bad cell (on any rank) of a folded/degenerate mesh."""
    bad = bad_cells(domain)
    x = domain.geometry.x
    cnodes = domain.geometry.dofmaps[0]
    for kind, cells in bad.items():
        count = domain.comm.allreduce(len(cells), op=MPI.SUM)
        if count:
            where = x[cnodes[cells[0]]].mean(axis=0) if len(cells) else None
            where = next(w for w in domain.comm.allgather(where) if w is not None)
            what = "inverted (folded over a neighbour)" if kind == "folded" else "degenerate"
            raise ValueError(f"{name}: {count} {what} cell(s), the first near "
                             f"({', '.join(f'{c:.4g}' for c in where)})")
