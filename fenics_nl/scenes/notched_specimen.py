"""Miehe's single-edge-notched square (plane strain), pulled or sheared until it breaks.

The square [0, L]², its notch from the left side to the centre along y = L/2 drawn as a
pre-crack: α = 1 (a Dirichlet condition of the damage) on a band of one cell centred on that
line, which is what a crack of the mesh is (a line of nodes at α = 1 alone would still carry
stress through its neighbouring cells, at α ≈ 0.56 and a(α) up to 0.2). Its bottom side is
clamped and its top side moved rigidly:

* ``tension``: the top moves up by U (u_x = 0 there): a straight crack from the notch;
* ``shear``: the top moves right by U (u_y = 0 there, and on the left and right sides):
  the crack turns down towards the bottom right corner (with a split that keeps the
  compressed side from damaging).

The mesh (`graded_grid`) has square cells of h = ell/`resolution` where the crack can go
(``band`` ell around y = L/2 to the right of the notch in tension, the lower right quarter
and that band in shear) and grows away from it. Each step is minimized by alternate
minimization and committed (irreversibility).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.graded_grid import graded_axis, graded_rectangle
from fenics_nl.scenes.cracked_plate import CrackedPlate, CrackRecord

__all__ = ["TESTS", "NotchedSpecimen", "SpecimenRecord"]

TESTS = ("tension", "shear")


@dataclass
class SpecimenRecord(CrackRecord):
    """Every converged step: the top's displacement and force, the tip.

    And `CrackRecord`'s: the dissipated energy, the damage, the work.
    """

    displacement: list[float] = field(default_factory=list)
    force: list[float] = field(default_factory=list)  # per unit thickness, along the motion
    tip: list[list[float]] = field(default_factory=list)

    def crack_extension(self) -> list[float]:
        """The length of the tip's path from the first step, step by step (a polyline)."""
        tips = np.array(self.tip)
        steps = np.linalg.norm(np.diff(tips, axis=0), axis=1) if len(tips) > 1 else []
        return [0.0, *np.cumsum(steps).tolist()][: len(tips)]

    def release_rate(self) -> float | None:
        """(D at the last step − D at the first) over the crack's extension between them.

        None if the crack did not grow.
        """
        extension = self.crack_extension()
        if not extension or extension[-1] <= 0:
            return None
        return (self.dissipated_energy[-1] - self.dissipated_energy[0]) / extension[-1]


class NotchedSpecimen(CrackedPlate):
    """The notched square of a `GradientDamage` law, its supports, crack and solver.

    Args:
        law: the gradient damage law (E, ν, Gc, ell; its split).
        test: ``tension`` or ``shear``.
        side: L, the square's side (the notch is L/2 long).
        resolution: ell/h where the crack can go.
        band: half-width of the fine band around the crack's line, in units of ell.
        acceleration: the alternate minimization's (``none``, ``overrelaxed``, ``anderson``).
        tol: its stop, on max |Δα| (1e-6: the plain iteration crawls when a crack grows,
            its last digits changing the dissipated energy by less than 1e-5 relative).
    """

    def __init__(self, law, test: str = "tension", *, side: float = 1.0,
                 resolution: float = 2.0, band: float = 3.0, acceleration: str = "anderson",
                 tol: float = 1e-6, comm: MPI.Comm = MPI.COMM_WORLD):
        if test not in TESTS:
            raise ValueError(f"test must be tension or shear, got {test!r}")
        self.test, self.side = test, side
        self.h = h = law.ell / resolution
        a, width = side / 2, band * law.ell
        self.notch_tip = np.array([a, a])
        xs = graded_axis(side, h, (a - width, side), through=a)
        low = a - width if test == "tension" else 0.0
        ys = graded_axis(side, h, (low, a + width), through=a - h / 2)  # rows at a ± h/2
        self._plate(law, graded_rectangle(comm, xs, ys),
                    lambda x: (np.abs(x[1] - a) <= 0.5001 * h) & (x[0] <= a + 1e-9 * side))
        self._solver(self._supports(), law.critical_stress * h, tol=tol, max_it=2000,
                     acceleration=acceleration)
        self._residual = fem.form(self.solver.residual_u)
        A = self.A
        n = A.dofmap.index_map.size_local
        self._x = A.tabulate_dof_coordinates()[:n, :2]
        self._ahead = self._x[:, 0] > a + 1e-9 * side  # the tip is looked for off the notch

    def _supports(self) -> list[fem.DirichletBC]:
        """Bottom clamped; top moved along x (shear) or y (tension); sides held in y (shear)."""
        msh, V, L = self.mesh, self.V, self.side

        def side(where):
            return mesh.locate_entities_boundary(msh, 1, where)

        self.top = side(lambda x: np.isclose(x[1], L))
        self.bottom = side(lambda x: np.isclose(x[1], 0.0))
        self.moving = 0 if self.test == "shear" else 1  # the top's moving component
        self._top_bc = boundary.component(V, self.moving, self.top)
        bcs = [boundary.fixed(V, self.bottom), self._top_bc,
               boundary.component(V, 1 - self.moving, self.top)]
        if self.test == "shear":
            self.sides = side(lambda x: np.isclose(x[0], 0.0) | np.isclose(x[0], L))
            bcs.append(boundary.component(V, 1, self.sides))
        return bcs

    def load(self, displacements, progress=None) -> SpecimenRecord:
        """Move the top through `displacements`, minimizing and committing each step."""
        record = SpecimenRecord()
        g = self._top_bc.g
        for k, U in enumerate(displacements):
            g.x.array[:] = U
            self._step(record)
            record.displacement.append(float(U))
            record.force.append(self.force())
            record.tip.append(self.tip())
            if progress:
                progress(k, record)
        return record

    def force(self) -> float:
        """The top's reaction along its motion, per unit thickness (collective)."""
        return boundary.reactions(self._residual, self.u, {"top": self.top})["top"][self.moving]

    def tip(self, level: float = 0.9) -> list[float]:
        """The crack tip: the broken node (α >= `level`) farthest from the notch's tip.

        Of the nodes ahead of the notch (the notch's tip itself if there is none). Collective.

        A crack of the mesh is a band of cells at α = 1 whose neighbours' nodes are at most
        (1 − h/(2 ell))² (AT1): 0.56 at ell/h = 2, below the level.
        """
        a = self.alpha.x.array[: len(self._ahead)]
        cracked = self._x[self._ahead & (a >= level)]
        d = np.linalg.norm(cracked - self.notch_tip, axis=1)
        local = (float(d.max()), *cracked[d.argmax()]) if len(d) else (0.0, *self.notch_tip)
        best = max(self.mesh.comm.allgather(local))
        return [float(best[1]), float(best[2])]

    def broken(self) -> bool:
        """Whether the crack's tip has reached the square's right side or its bottom."""
        x, y = self.tip()
        return x >= self.side * (1 - 1e-9) or y <= 1e-9 * self.side

    def reactions(self) -> dict[str, list[float]]:
        """The supports' forces (x, y) per unit thickness: top, bottom (and sides in shear)."""
        groups = {"top": self.top, "bottom": self.bottom} | (
            {"sides": self.sides} if self.test == "shear" else {})
        return boundary.reactions(self._residual, self.u, groups)

