"""Rectangles of quadrilaterals, fine where a crack goes and graded away from it.

A crack's damage band needs h a fraction of ell along its path only. Each axis is uniform
(step h, through a given coordinate, so that a line of nodes lies where a pre-crack is
drawn) over a fine interval, and its steps grow geometrically outward up to the rectangle's
sides; the mesh is their tensor product (DOLFINx's `create_rectangle`, its nodes moved).
"""

from __future__ import annotations

import math

import numpy as np
from dolfinx import mesh
from mpi4py import MPI

__all__ = ["graded_axis", "graded_rectangle"]


def _grow(start: float, end: float, h: float, ratio: float) -> list[float]:
    """Points after `start` towards `end` (either way), each step `ratio` times the last."""
    sign = 1.0 if end > start else -1.0
    points, step = [start], h
    while sign * (end - points[-1]) > 1e-12 * abs(end - start):
        step *= ratio
        points.append(end if sign * (end - points[-1]) <= step else points[-1] + sign * step)
    if len(points) > 2 and abs(points[-1] - points[-2]) < 0.5 * step:  # no sliver at the end
        points.pop(-2)
    return points[1:]


def graded_axis(length: float, h: float, fine: tuple[float, float], through: float,
                ratio: float = 1.3) -> np.ndarray:
    """Node coordinates on [0, length]: step h over `fine`, growing by `ratio` beyond.

    The fine nodes are `through` + k h: a line of nodes at `through`.
    """
    lo, hi = max(fine[0], 0.0), min(fine[1], length)
    tol = 1e-9 * length
    k0 = math.ceil((lo - through - tol) / h)
    k1 = math.floor((hi - through + tol) / h)
    xs = list(through + h * np.arange(k0, k1 + 1))
    if xs[0] < tol:
        xs[0] = 0.0
    if length - xs[-1] < tol:
        xs[-1] = length
    left = _grow(xs[0], 0.0, h, ratio)[::-1] if xs[0] > 0 else []
    right = _grow(xs[-1], length, h, ratio) if xs[-1] < length else []
    return np.array(left + xs + right)


def graded_rectangle(comm: MPI.Comm, xs: np.ndarray, ys: np.ndarray) -> mesh.Mesh:
    """The quadrilaterals of the grid xs × ys (increasing node coordinates)."""
    msh = mesh.create_rectangle(comm, [[0.0, 0.0], [1.0, 1.0]], [len(xs) - 1, len(ys) - 1],
                                mesh.CellType.quadrilateral)
    x = msh.geometry.x
    for axis, nodes in enumerate((xs, ys)):
        index = np.rint(x[:, axis] * (len(nodes) - 1)).astype(int)
        x[:, axis] = nodes[index]  # the unit grid's lines mapped onto the graded ones
    return msh
