"""A slender strip of quadrilaterals with its two ends tagged: a cantilever beam in 2D.

The strip [0, L] × [−h/2, h/2] (unit width), 2·2^refine elements through the height and
twice as long as high: with Q2 displacements, 2 elements through the height already bend
like the beam theory (the buckling demo and its benchmarks). The facets of the end x = 0
are tagged CLAMPED, those of x = L tagged END.
"""

from __future__ import annotations

import numpy as np
from dolfinx import mesh
from mpi4py import MPI

from fenics_nl.domain.boundary import tags_where

__all__ = ["CLAMPED", "END", "cantilever_strip"]

CLAMPED, END = 1, 2  # the facet tags of the end x = 0 and of the end x = L


def cantilever_strip(comm: MPI.Comm, length: float, thickness: float, refine: int = 0
                     ) -> tuple[mesh.Mesh, mesh.MeshTags]:
    """The strip of length L and height h in quadrilaterals, its ends tagged.

    Args:
        comm: the communicator.
        length: L, along x from 0.
        thickness: h, centred on y = 0.
        refine: 2·2^refine elements through the height; along the length they are about
            twice as long as high (at least 4).

    Returns:
        (the mesh, its facet tags CLAMPED on x = 0 and END on x = L).
    """
    if not (length > 0 and thickness > 0):
        raise ValueError(f"length and thickness must be > 0, got {length}, {thickness}")
    if refine < 0:
        raise ValueError(f"refine must be >= 0, got {refine}")
    ny = 2 * 2**refine
    nx = max(4, round(length / thickness * ny / 2))
    msh = mesh.create_rectangle(comm, [[0, -thickness / 2], [length, thickness / 2]],
                                [nx, ny], mesh.CellType.quadrilateral)
    return msh, tags_where(msh, 1, {CLAMPED: lambda x: np.isclose(x[0], 0.0),
                                    END: lambda x: np.isclose(x[0], length)})
