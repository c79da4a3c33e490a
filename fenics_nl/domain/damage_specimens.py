"""The damage demos' specimens: a bar strip, Miehe's notched square, the surfing strip.

Each factory returns DOLFINx's mesh of P1 quadrilaterals with its facet tags (and the
notched square's cell tag, its pre-crack), the tag values being this module's constants:

    LEFT (x = 0), RIGHT (x = L), BOTTOM (y = 0), TOP (y = H): the sides;
    PRECRACK: the surfing strip's pre-cracked part of y = 0 (the rest of it is BOTTOM);
    NOTCH: the notched square's cells drawn as its pre-crack (a cell tag).

The cracked plates are fine (square cells of h) where the crack goes and graded away from
it (`graded_grid`), with a line of nodes where the crack is drawn.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from dolfinx import mesh
from mpi4py import MPI

from fenics_nl.domain.boundary import tags_where
from fenics_nl.domain.graded_grid import graded_axis, graded_rectangle

__all__ = ["BOTTOM", "LEFT", "NOTCH", "PRECRACK", "RIGHT", "TESTS", "TOP", "bar_strip",
           "notched_square", "surfing_strip"]

LEFT, RIGHT, BOTTOM, TOP, PRECRACK = 1, 2, 3, 4, 5  # facet tags
NOTCH = 1  # cell tag
TESTS = ("tension", "shear")  # the notched square's


def _sides(length: float, height: float, extra: dict[int, Callable] | None = None
           ) -> dict[int, Callable]:
    """The markers of a rectangle's sides (`extra` first: its tags win)."""
    return {**(extra or {}), LEFT: lambda x: np.isclose(x[0], 0.0),
            RIGHT: lambda x: np.isclose(x[0], length),
            BOTTOM: lambda x: np.isclose(x[1], 0.0), TOP: lambda x: np.isclose(x[1], height)}


def bar_strip(comm: MPI.Comm, length: float, cells: int, *, height: float | None = None
              ) -> tuple[mesh.Mesh, mesh.MeshTags]:
    """The strip [0, L] x [0, H], `cells` quadrilaterals along it and one across.

    One cell high in plane strain at ν = 0, it is the course's 1D bar (a uniaxial stress
    state); keep H when refining, so that the cross-section stays.

    Args:
        comm: the communicator.
        length: L.
        cells: cells along the bar (h = L/cells), at least 2.
        height: H (default one cell's length, L/cells).

    Returns:
        (the mesh, its facet tags LEFT, RIGHT, BOTTOM, TOP).
    """
    if cells < 2:
        raise ValueError(f"a bar needs at least 2 cells, got {cells}")
    H = height or length / cells
    msh = mesh.create_rectangle(comm, [[0.0, 0.0], [length, H]], [cells, 1],
                                mesh.CellType.quadrilateral)
    return msh, tags_where(msh, 1, _sides(length, H))


def notched_square(comm: MPI.Comm, h: float, test: str = "tension", *, width: float,
                   side: float = 1.0) -> tuple[mesh.Mesh, mesh.MeshTags, mesh.MeshTags]:
    """Miehe's single-edge-notched square [0, L]², its notch along y = L/2 up to the centre.

    Square cells of h where the crack can go: within `width` of the notch's line to the right
    of the notch (``tension``), and also the lower right quarter (``shear``, where the
    crack turns down); the cells grow geometrically (ratio 1.3) away from it. The rows of
    nodes are at L/2 ± h/2: the notch is the band of one cell between them, x ≤ L/2, which
    is what a crack of the mesh is (a line of nodes at α = 1 alone would still carry stress
    through its neighbouring cells).

    Args:
        comm: the communicator.
        h: the cells' size where the crack can go.
        test: ``tension`` or ``shear`` (which part is fine).
        width: the fine band's half-width around the notch's line.
        side: L.

    Returns:
        (the mesh, its cell tags NOTCH, its facet tags LEFT, RIGHT, BOTTOM, TOP).
    """
    if test not in TESTS:
        raise ValueError(f"test must be tension or shear, got {test!r}")
    a = side / 2
    xs = graded_axis(side, h, (a - width, side), through=a)
    low = a - width if test == "tension" else 0.0
    ys = graded_axis(side, h, (low, a + width), through=a - h / 2)  # rows at a ± h/2
    msh = graded_rectangle(comm, xs, ys)
    notch = {NOTCH: lambda x: (np.abs(x[1] - a) <= 0.5001 * h) & (x[0] <= a + 1e-9 * side)}
    return msh, tags_where(msh, 2, notch, boundary=False), tags_where(msh, 1, _sides(side, side))


def surfing_strip(comm: MPI.Comm, h: float, cells: int, *, height: float, notch: float,
                  fine: float) -> tuple[mesh.Mesh, mesh.MeshTags]:
    """The strip [0, cells h] x [0, H]: the upper half of a plate cracked along y = 0.

    Columns of h (a field moved by whole cells meets the same mesh at every step); rows of h
    up to `fine` above the crack's line, then growing geometrically (ratio 1.3) up to H.

    Args:
        comm: the communicator.
        h: the cells' size along the crack's path.
        cells: the cells along the strip (its length cells · h).
        height: H.
        notch: the pre-crack's length on y = 0 (a whole number of cells).
        fine: the height of the uniform rows.

    Returns:
        (the mesh, its facet tags PRECRACK (y = 0, x ≤ notch), BOTTOM (the rest of y = 0),
        LEFT, RIGHT, TOP).
    """
    xs = h * np.arange(cells + 1)
    ys = graded_axis(height, h, (0.0, fine), through=0.0)
    msh = graded_rectangle(comm, xs, ys)

    def precrack(x):
        return np.isclose(x[1], 0.0) & (x[0] <= notch + 1e-9 * xs[-1])

    return msh, tags_where(msh, 1, _sides(xs[-1], height, {PRECRACK: precrack}))
