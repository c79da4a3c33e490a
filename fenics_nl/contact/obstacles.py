"""Rigid obstacles above a flat contact surface: where they are, hence the gap γ.

The course writes the contact condition on S_C as u_n ≤ γ, γ the distance along the normal
from the undeformed surface to the obstacle. A rigid punch of revolution about the vertical
axis through the origin (a cylinder in plane strain) pressed by δ has γ(x) = h(r) − δ, h the
height of its surface above the flat one at the distance r from its axis.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fenics_nl.parallel import global_max

__all__ = ["BERKOVICH", "SHAPES", "Indentation", "RigidPunch", "Traction"]

SHAPES = ("parabola", "sphere", "cone")
BERKOVICH = 70.3  # the half-angle of the cone of the Berkovich tip's area function (degrees)


@dataclass(frozen=True)
class RigidPunch:
    """A rigid punch whose axis is the vertical through the origin.

    Args:
        radius: the sphere's (or the cylinder's) radius R.
        dim: the mesh's dimension: 3 (the axis is z), or 2 (the axis is x = 0: the
            axisymmetric model's, or a cylinder's in plane strain).
        shape: ``parabola`` (Hertz's r²/(2R)), ``sphere`` (the exact R − √(R² − r²)) or
            ``cone`` (r cot α, of half-angle `cone_angle`; the radius then unused).
        cone_angle: the cone's half-angle α in degrees.
    """

    radius: float
    dim: int
    shape: str = "parabola"
    cone_angle: float = BERKOVICH

    def __post_init__(self):
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0, got {self.radius}")
        if self.shape not in SHAPES:
            raise ValueError(f"the punch's shape (--gap) must be one of {', '.join(SHAPES)}, "
                             f"got {self.shape!r}")
        if self.shape == "cone" and not (0 < self.cone_angle < 90):
            raise ValueError(f"cone_angle must be in (0, 90) degrees, got {self.cone_angle!r}")

    def distance(self, x: np.ndarray) -> np.ndarray:
        """The distance r of points from the axis.

        Args:
            x: the points, n × 3.

        Returns:
            r of each point.
        """
        return np.hypot(x[:, 0], x[:, 1]) if self.dim == 3 else np.abs(x[:, 0])

    def height(self, r) -> np.ndarray:
        """The height of the punch's surface above the flat surface.

        Args:
            r: distances from the axis.

        Returns:
            h(r), the punch touching the flat surface at r = 0.
        """
        r, R = np.asarray(r, dtype=float), self.radius
        if self.shape == "cone":
            return r / math.tan(math.radians(self.cone_angle))
        if self.shape == "parabola":
            return r**2 / (2 * R)
        return np.where(r < R, R - np.sqrt(np.clip(R * R - r * r, 0, None)), R)

    def gap(self, delta: float) -> Callable[[np.ndarray], np.ndarray]:
        """The gap of the punch pressed by δ, as DOLFINx interpolates it.

        Args:
            delta: the indentation δ (negative: the punch stays clear).

        Returns:
            γ(x) = h(r) − δ for points x given as 3 × n.
        """
        return lambda x: self.height(self.distance(np.asarray(x).T)) - delta

    def press(self, contact, delta: float, *, weight=1.0, symmetry: float = 1.0
              ) -> Indentation:
        """The converged state of the punch pressed by δ: the contact's active-set loop.

        From the last state's set and every node that penetrates now (a warm start).

        Args:
            contact: the active-set loop on S_C (`ActiveSetContact`, `FrictionalContact`).
            delta: the indentation δ.
            weight: the measure's weight (2πr in the axisymmetric model).
            symmetry: the whole body's force over the modelled part's.

        Returns:
            The state, with its force, the outermost active node's distance from the axis,
            the largest nodal pressure and the work (collective).
        """
        contact.set_gap(self.gap(delta))
        contact.add_penetrating()
        comm = contact.comm
        with contact.reusing_residual():  # the forces below read the loop's last R(u)
            res = contact.solve()
            radius = global_max(comm, self.distance(contact.x[contact.active]))
            p_max = global_max(comm, contact.pressure(weight)[contact.active])
        return Indentation(delta, symmetry * contact.force, radius, p_max,
                           res.active_set_iterations, res.iterations, res.work.factorizations)


@dataclass
class Indentation:
    """One converged state of a punch pressed into a body (the whole body's force)."""

    indentation: float
    force: float  # total (axisymmetric, 3D) or per unit length (plane strain)
    contact_radius: float  # radius (half-width in plane strain) of the last active node
    max_pressure: float
    active_set_iterations: int
    newton_iterations: int
    factorizations: int

    def plus_work_of(self, others) -> Indentation:
        """This state with the work of `others` added (the states tried before it).

        Args:
            others: states whose work led to this one (force control's positions).

        Returns:
            A copy of this state whose iteration and factorization counts are the sums.
        """
        others = list(others)
        return dataclasses.replace(self, **{k: getattr(self, k) + sum(getattr(o, k)
                                                                     for o in others)
                                            for k in ("active_set_iterations",
                                                      "newton_iterations", "factorizations")})


@dataclass
class Traction:
    """One converged state of a punch moved along x after pressing it (with friction)."""

    tangential_displacement: float  # the punch's, since the unloaded state
    tangential_force: float  # Q, total (3D) or per unit length (plane strain)
    normal_force: float  # P, the same way
    stick_radius: float  # the outermost sticking node's distance from the axis
    stick_nodes: int
    slip_nodes: int
    status_iterations: int
    newton_iterations: int
    factorizations: int
