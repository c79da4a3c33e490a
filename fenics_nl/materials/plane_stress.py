"""Plane stress for a law written in the whole strain (J2): ε_zz an unknown at the points.

The law's energy ψ(ε) needs the 3x3 strain ε₃ = [[ε_xx, ε_xy, 0], [ε_xy, ε_yy, 0],
[0, 0, ε_zz]], and in plane stress ε_zz is what makes σ_zz = 0. For an elastic law that is
a closed form (the plane-stress λ* of `laws`); for J2 it is not (the return mapping is the
3D one), so ε_zz joins the displacement in one unknown w = (u, ε_zz), and the residual is the
variation of ∫ ψ(ε₃) dx over both:

    R(w; v, ζ) = ∫ σ(ε₃) : ε₃(v, 0) dx + ∫ σ_zz(ε₃) ζ dx.

ε_zz lives in a discontinuous space with as many functions per cell as the residual's rule
has points (DG1 for the 3 points of degree 2 on a triangle, DG2 for the 6 of degree 4,
DQ1/DQ2 on quadrilaterals): the second row, Σ_q w_q σ_zz(x_q) ζ_i(x_q) = 0 for every ζ_i, has
an invertible matrix [w_q ζ_i(x_q)], so σ_zz = 0 at every quadrature point exactly, where
the law is evaluated. (A quadrature element would say the same, but FFCx cannot tabulate
one on the facets where the loads act.) The tangent, UFL's derivative of R, is the
consistent one (symmetric: R is a gradient). `bind` the law and integrate with the same
quadrature degree as the unknown's (`kinematics.quadrature_measure("dx", mesh, degree)`).
"""

from __future__ import annotations

import basix
import basix.ufl
import ufl
from dolfinx import fem

from fenics_nl.materials.laws import LinearElastic
from fenics_nl.materials.mixed import collapsed

__all__ = [
    "PlaneStressUnknown",
    "elastic_tangent",
    "internal_work",
    "pointwise_element",
    "stress",
    "whole_strain",
]


def whole_strain(u, ez):
    """ε₃ of the in-plane displacement `u` and the out-of-plane strain `ez` (UFL).

    Args:
        u: the in-plane displacement (2 components; or its test function).
        ez: the out-of-plane strain ε_zz (UFL, or 0).

    Returns:
        ε₃ (UFL, 3x3).
    """
    e = ufl.sym(ufl.grad(u))
    return ufl.as_tensor([[e[0, 0], e[0, 1], 0], [e[1, 0], e[1, 1], 0], [0, 0, ez]])


class PlaneStressUnknown:
    """w = (u, ε_zz): P`degree` in-plane displacement, ε_zz for the rule of `quadrature`.

    The attributes of the other unknowns (`materials.mixed`): `w` the Function a solver
    updates, `u`, `ez` its parts for forms and `v`, `dz` the test functions'; `V` the
    displacement sub-space (Dirichlet conditions), `displacement()` a collapsed copy.
    """

    mixed = False
    pressure_dofs = 0

    def __init__(self, mesh, degree: int, quadrature: int):
        if mesh.geometry.dim != 2:
            raise ValueError("plane stress is a 2D model")
        cell = mesh.basix_cell()
        Pu = basix.ufl.element("Lagrange", cell, degree, shape=(2,))
        self.W = fem.functionspace(mesh, basix.ufl.mixed_element(
            [Pu, pointwise_element(cell, quadrature)]))
        self.w = fem.Function(self.W, name="displacement_out_of_plane_strain")
        self.V = self.W.sub(0)
        self.u, self.ez = ufl.split(self.w)
        self.v, self.dz = ufl.TestFunctions(self.W)
        self.displacement_space, self.displacement_dofs = collapsed(self.V)
        Qc, self._ez_dofs = collapsed(self.W.sub(1))
        self._u = fem.Function(self.displacement_space, name="displacement")
        self._ez = fem.Function(Qc, name="out_of_plane_strain")

    def strain(self):
        """ε₃ of the current unknown.

        Returns:
            ε₃ of (`u`, `ez`), UFL 3x3 (`whole_strain`).
        """
        return whole_strain(self.u, self.ez)

    def displacement(self) -> fem.Function:
        """The current displacement (a copy in the collapsed Lagrange space).

        Returns:
            The displacement part of `w`, a Function named "displacement" on
            `displacement_space`; the same Function at every call, overwritten.
        """
        self._u.x.array[:] = self.w.x.array[self.displacement_dofs]
        return self._u

    def out_of_plane_strain(self) -> fem.Function:
        """ε_zz (a copy in the collapsed discontinuous space).

        Returns:
            The ε_zz part of `w`, a Function named "out_of_plane_strain"; the same Function
            at every call, overwritten.
        """
        self._ez.x.array[:] = self.w.x.array[self._ez_dofs]
        return self._ez

    def internal_work(self, material, model: str = "plane_stress"):
        """Integrand of δ∫ψ(ε₃) (`internal_work` of this module).

        Args:
            material: the law, written in the 3x3 strain (J2).
            model: unused (plane stress), for the other unknowns' signature.

        Returns:
            The integrand (UFL scalar), to be multiplied by the measure `dx`.
        """
        return internal_work(material, self)

    def constant_tangent(self, material, model: str, dx):
        """Hooke's tangent in (u, ε_zz) (`elastic_tangent` of this module).

        Args:
            material: the law (its E and ν are read).
            model: unused (plane stress), for the other unknowns' signature.
            dx: the measure of the residual.

        Returns:
            The tangent, a bilinear form (UFL) in `w`.
        """
        return elastic_tangent(material, self, dx)


def pointwise_element(cell, quadrature: int):
    """The DG element with as many functions per cell as the rule has points (Legendre).

    Its nodal matrix at the points is then square; ValueError if no degree matches.

    Args:
        cell: the basix cell type.
        quadrature: the quadrature degree of the residual's rule.

    Returns:
        The basix.ufl DG element (Legendre variant).
    """
    points, _ = basix.make_quadrature(cell, quadrature)
    for degree in range(quadrature + 1):
        element = basix.ufl.element("DG", cell, degree,
                                    lagrange_variant=basix.LagrangeVariant.legendre)
        if element.dim == len(points):
            return element
    raise ValueError(f"no discontinuous space has {len(points)} functions per {cell.name} "
                     f"(quadrature degree {quadrature}): plane stress cannot hold σ_zz = 0 "
                     "at each point")


def internal_work(material, unknown: PlaneStressUnknown):
    """Integrand of δ∫ψ(ε₃): σ(ε₃) : ε₃(v, 0) + σ_zz(ε₃) ζ (see the module).

    Args:
        material: the law, written in the 3x3 strain (its `stress` is read: J2).
        unknown: the unknown w = (u, ε_zz) and its test functions (v, ζ).

    Returns:
        The integrand (UFL scalar), to be multiplied by the measure `dx`.
    """
    sigma = material.stress(unknown.strain())
    return ufl.inner(sigma, whole_strain(unknown.v, 0)) + sigma[2, 2] * unknown.dz


def stress(material, unknown: PlaneStressUnknown):
    """The Cauchy stress σ(ε₃), 3x3 (σ_zz = 0 at the quadrature points at equilibrium).

    Args:
        material: the law, written in the 3x3 strain (J2).
        unknown: the unknown w = (u, ε_zz).

    Returns:
        σ (UFL, 3x3).
    """
    return material.stress(unknown.strain())


def elastic_tangent(material, unknown: PlaneStressUnknown, dx):
    """Hooke's tangent (E, ν) in (u, ε_zz): the course's modified Newton for J2.

    Args:
        material: the law (its E and ν are read).
        unknown: the unknown w = (u, ε_zz).
        dx: the measure of the residual.

    Returns:
        The tangent, a bilinear form (UFL) in `unknown.w`.
    """
    work = internal_work(LinearElastic(material.E, material.nu), unknown)
    return ufl.derivative(work * dx, unknown.w)
