"""The displacement–pressure (u, p) formulation of every energy of the library.

Each energy splits as φ = φ̃ + k/2 g² (`Material.volumetric_split`): g the volumetric
measure (tr ε in small strain, tr e or ln J in finite strain) and k the modulus that tends
to ∞ as ν → 1/2 (κ, or λ for the neo-Hookean law). With p an unknown field, the perturbed
Lagrangian

    Π(u, p) = ∫ φ̃(u) + p g(u) − p²/(2k) dΩ

is stationary in p where p = k g: for a finite k the solution is the displacement
formulation's, and at k = ∞ (ν = 1/2 exactly) the term p²/(2k) vanishes, g = 0 is a
constraint and p its multiplier. The residual δΠ is written as the laws write their
stresses (`ufl.variable` + `ufl.diff` of φ̃ + p g), and the tangent is its UFL derivative:
nothing is typed. For the small-strain laws p = κ tr ε is the mean stress.

The spaces are Taylor–Hood, P2 displacement and P1 pressure on the same mesh: inf-sup
stable on meshes where no cell has all its vertices on the boundary (gmsh's meshes here), so
neither locking nor a checkerboard pressure, in 2D, 3D and the axisymmetric model. A J2
material keeps its state at the quadrature points of the residual's rule, as in the
displacement formulation (its plastic flow is isochoric: tr ε_p = 0).
"""

from __future__ import annotations

import math

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem

from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import von_mises_of

__all__ = [
    "DisplacementUnknown",
    "MixedUnknown",
    "cauchy_stress",
    "collapsed",
    "internal_work",
    "modified_newton_tangent",
    "preconditioner",
    "taylor_hood",
    "unknown_of",
    "unknowns",
    "von_mises",
    "von_mises_expression",
]


def collapsed(V: fem.FunctionSpace):
    """(the collapsed space of the sub-space V, the parent dof of each of its dofs).

    DOLFINx returns the map as a list holding one array; this gives the array (int32,
    owned dofs first, unrolled for a vector space).

    Args:
        V: a sub-space (`W.sub(i)`).

    Returns:
        (the collapsed FunctionSpace, the parent dof of each of its dofs).
    """
    Vc, parent = V.collapse()
    parent = parent[0] if isinstance(parent, list | tuple) else parent
    return Vc, np.ascontiguousarray(parent, dtype=np.int32)


def taylor_hood(mesh, degree: int = 2) -> fem.FunctionSpace:
    """The mixed space (P`degree` vector displacement, P`degree − 1` pressure).

    Args:
        mesh: the mesh.
        degree: the displacement's degree, >= 2.

    Returns:
        The Taylor–Hood FunctionSpace.
    """
    if degree < 2:
        raise ValueError(f"Taylor–Hood needs a displacement degree >= 2, got {degree}")
    cell, gdim = mesh.basix_cell(), mesh.geometry.dim
    dtype = mesh.geometry.x.dtype
    Pu = basix.ufl.element("Lagrange", cell, degree, shape=(gdim,), dtype=dtype)
    Pp = basix.ufl.element("Lagrange", cell, degree - 1, dtype=dtype)
    return fem.functionspace(mesh, basix.ufl.mixed_element([Pu, Pp]))


def internal_work(material, u, p, v, q, model: str = "3d"):
    """Integrand of δΠ(u, p; v, q): the virtual work of φ̃ + p g, and q (g − p/k).

    Times 2πr in the axisymmetric model.

    Args:
        material: the law (its `volumetric_split` and `finite_strain` are read).
        u: the displacement part of the mixed unknown (`ufl.split`).
        p: its pressure part.
        v: the displacement part of the test function.
        q: its pressure part.
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

    Returns:
        The integrand (UFL scalar), to be multiplied by the measure `dx`.
    """
    if model == "plane_stress":
        raise ValueError("the mixed formulation is for 3D, plane-strain and axisymmetric "
                         "models (plane stress has no volumetric constraint)")
    weight = kinematics.measure_weight(kinematics.domain(u), model)
    if material.finite_strain:
        strain = ufl.variable(kinematics.green_lagrange(u, model))
    else:
        strain = ufl.variable(kinematics.small_strain(u, model))
    rest, g, k = material.volumetric_split(strain)
    stress = _split_stress(material, rest, g, p, strain)  # σ̃ (small strain) or S̃ (finite)
    if material.finite_strain:
        F = kinematics.deformation_gradient(u, model)
        work = ufl.inner(F * stress, kinematics.displacement_gradient(v, model))
    else:
        work = ufl.inner(stress, kinematics.small_strain(v, model))
    constraint = g if math.isinf(k) else g - p / k
    return (work + q * constraint) * weight


def cauchy_stress(material, u, p, model: str = "3d"):
    """σ of the mixed state: ∂(φ̃ + p g)/∂ε in small strain, F S̃ Fᵀ / J in finite strain.

    Args:
        material: the law (its `volumetric_split` and `finite_strain` are read).
        u: the displacement part of the mixed unknown.
        p: its pressure part.
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

    Returns:
        σ (UFL, 3x3).
    """
    if material.finite_strain:
        e = ufl.variable(kinematics.green_lagrange(u, model))
        rest, g, _ = material.volumetric_split(e)
        F = kinematics.deformation_gradient(u, model)
        return F * ufl.diff(rest + p * g, e) * F.T / ufl.det(F)
    eps = ufl.variable(kinematics.small_strain(u, model))
    rest, g, _ = material.volumetric_split(eps)
    return _split_stress(material, rest, g, p, eps)


def _split_stress(material, rest, g, p, strain):
    """∂(φ̃ + p g)/∂strain; from the law's own deviatoric stress where it gives one.

    A law whose state comes out of a local iteration written in UFL (Norton creep) gives
    `deviatoric_stress` (its g is tr ε, so ∂(p g)/∂ε = p I): differentiating φ̃ through
    the iteration and then again for the tangent would multiply the expression (and its
    compilation) many times over.
    """
    if hasattr(material, "deviatoric_stress") and not material.finite_strain:
        return material.deviatoric_stress(strain) + p * ufl.Identity(3)
    return ufl.diff(rest + p * g, strain)


def von_mises_expression(material, u, p, model: str = "3d"):
    """σ_eq = √(3/2) ‖dev σ‖ of the mixed state (UFL).

    Args:
        material: the law.
        u: the displacement part of the mixed unknown.
        p: its pressure part.
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

    Returns:
        σ_eq (UFL scalar).
    """
    return von_mises_of(cauchy_stress(material, u, p, model))


def von_mises(material, u, p, model: str, mesh) -> fem.Function:
    """σ_eq per cell (DG0) of the mixed state on `mesh`.

    At the centroid, or the mean over the quadrature points for a law whose state lives
    there (J2).

    Args:
        material: the law.
        u: the displacement part of the mixed unknown.
        p: its pressure part.
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        mesh: the mesh of the DG0 space.

    Returns:
        σ_eq, a DG0 Function named "von_mises".
    """
    if hasattr(material, "cell_mean"):
        return material.cell_mean(von_mises_expression(material, u, p, model), "von_mises")
    Q = fem.functionspace(mesh, ("DG", 0))
    f = fem.Function(Q, name="von_mises")
    f.interpolate(Expression(von_mises_expression(material, u, p, model),
                             Q.element.interpolation_points))
    return f


def modified_newton_tangent(material, w: fem.Function, model: str, dx):
    """The mixed counterpart of `Material.modified_newton_tangent`.

    For a path-dependent law at small strain: the tangent of the same mixed form with
    Hooke's law (E, ν); at finite strain, the tangent each solve starts from, as in the
    displacement formulation.

    Args:
        material: the law.
        w: the mixed unknown (u, p).
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        dx: the measure of the residual.

    Returns:
        "initial", or Hooke's mixed tangent, a bilinear form (UFL) in `w`.
    """
    if not material.path_dependent or material.finite_strain:
        return "initial"
    from fenics_nl.materials.laws import LinearElastic

    elastic = LinearElastic(material.E, material.nu)
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(w.function_space)
    return ufl.derivative(internal_work(elastic, u, p, v, q, model) * dx, w)


def preconditioner(material, W: fem.FunctionSpace, model: str, dx):
    """diag(2μ ε:ε, (1/μ + 1/k) mass): the block preconditioner of the mixed tangent.

    Spectrally equivalent to it for any bulk modulus (Silvester–Wathen), so MINRES needs
    about as many iterations at ν = 1/2 as at 0.3 (`NewtonSolver`, ``gamg``; measured by
    benchmarks/mixed.py, table in docs/benchmarks.md). The material's initial shear
    modulus: a softening law (plastic flow) weakens it, as it does GAMG's.

    Args:
        material: the law (its `mu` and `volumetric_modulus` are read).
        W: the Taylor–Hood space.
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        dx: the measure of the residual.

    Returns:
        The preconditioner, a bilinear form (UFL) on `W`.
    """
    (du, dp), (v, q) = ufl.TrialFunctions(W), ufl.TestFunctions(W)
    eps = kinematics.small_strain
    k = material.volumetric_modulus  # the k of every law's `volumetric_split`
    c = 1 / material.mu + (0.0 if math.isinf(k) else 1 / k)
    weight = kinematics.measure_weight(W.mesh, model)
    return (2 * material.mu * ufl.inner(eps(du, model), eps(v, model)) + c * dp * q) \
        * weight * dx


class DisplacementUnknown:
    """The displacement formulation's unknown, with `MixedUnknown`'s attributes.

    Every unknown (this one, `MixedUnknown`, `plane_stress.PlaneStressUnknown`) gives the
    internal work of a material in its formulation and the constant tangent of modified
    Newton: the one composition path from an unknown, a material and a model to a residual.

    `w` and `u` are the same Function, `V` = `W` its space; `p`, `q` are None.
    """

    mixed = False

    def __init__(self, mesh, degree: int = 2, *, function: fem.Function | None = None):
        if function is None:
            V = fem.functionspace(mesh, ("Lagrange", degree, (mesh.geometry.dim,)))
            function = fem.Function(V, name="displacement")
        self.W = self.V = function.function_space
        self.w = self.u = function
        self.v, self.p, self.q = ufl.TestFunction(self.V), None, None
        self.pressure_dofs = 0
        self.displacement_space = self.V
        self.displacement_dofs = np.arange(self.w.x.array.size, dtype=np.int32)

    def displacement(self) -> fem.Function:
        """The displacement Function itself.

        Returns:
            `w` (= `u`) itself, the Function the solver updates, not a copy.
        """
        return self.w

    def von_mises(self, material, model: str) -> fem.Function:
        """σ_eq per cell (DG0) of the current state (`Material.von_mises`).

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

        Returns:
            σ_eq, a DG0 Function named "von_mises".
        """
        return material.von_mises(self.u, model)

    def internal_work(self, material, model: str):
        """Integrand of the internal virtual work in the direction of the test function.

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The integrand (UFL scalar), to be multiplied by the measure `dx`.
        """
        return material.internal_work(self.u, self.v, model)

    def constant_tangent(self, material, model: str, dx):
        """What modified Newton and BFGS keep (`NewtonSolver`'s `constant_tangent`).

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").
            dx: the measure of the residual.

        Returns:
            The material's `modified_newton_tangent`, "initial" or a bilinear form (UFL).
        """
        return material.modified_newton_tangent(self.u, model, dx)


class MixedUnknown:
    """w = (u, p) in Taylor–Hood, and what demos and drivers read of it.

    `w` is the Function a solver updates; `u`, `p` its parts for forms; `V` the displacement
    sub-space (Dirichlet conditions, contact nodes: dofs in `w`'s numbering); and
    `displacement()`, `pressure()` collapsed copies to probe, draw and write
    (`displacement_space`, and `displacement_dofs`: where its values sit in `w`).
    """

    mixed = True

    def __init__(self, mesh, degree: int = 2, *, function: fem.Function | None = None):
        self.W = taylor_hood(mesh, degree) if function is None else function.function_space
        self.w = function or fem.Function(self.W, name="displacement_pressure")
        self.V, self.Q = self.W.sub(0), self.W.sub(1)
        self.u, self.p = ufl.split(self.w)
        self.v, self.q = ufl.TestFunctions(self.W)
        self.displacement_space, self.displacement_dofs = collapsed(self.V)
        Qc, self._p_dofs = collapsed(self.Q)
        self.pressure_dofs = Qc.dofmap.index_map.size_global  # the constraints' number
        self._u = fem.Function(self.displacement_space, name="displacement")
        self._p = fem.Function(Qc, name="pressure")

    def displacement(self) -> fem.Function:
        """The current displacement (a copy in the collapsed P2 space).

        Returns:
            The displacement part of `w`, a Function named "displacement" on
            `displacement_space`; the same Function at every call, overwritten.
        """
        self._u.x.array[:] = self.w.x.array[self.displacement_dofs]
        return self._u

    def pressure(self) -> fem.Function:
        """The current pressure field p (a copy in the collapsed P1 space).

        Returns:
            The pressure part of `w`, a Function named "pressure"; the same Function at every
            call, overwritten.
        """
        self._p.x.array[:] = self.w.x.array[self._p_dofs]
        return self._p

    def von_mises(self, material, model: str) -> fem.Function:
        """σ_eq per cell (DG0) of the current state, its pressure the unknown p.

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

        Returns:
            σ_eq, a DG0 Function named "von_mises" (`von_mises` of this module).
        """
        return von_mises(material, self.u, self.p, model, self.W.mesh)

    def internal_work(self, material, model: str):
        """Integrand of δΠ(u, p; v, q) (`internal_work` of this module).

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

        Returns:
            The integrand (UFL scalar), to be multiplied by the measure `dx`.
        """
        return internal_work(material, self.u, self.p, self.v, self.q, model)

    def constant_tangent(self, material, model: str, dx):
        """What modified Newton and BFGS keep (`modified_newton_tangent` of this module).

        Args:
            material: the law.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
            dx: the measure of the residual.

        Returns:
            "initial", or a bilinear form (UFL) in `w`.
        """
        return modified_newton_tangent(material, self.w, model, dx)


def unknowns(mesh, degree: int = 2, mixed: bool = False
             ) -> DisplacementUnknown | MixedUnknown:
    """The unknown of either formulation: P`degree` displacement, or Taylor–Hood (u, p).

    Args:
        mesh: the mesh.
        degree: the displacement's degree.
        mixed: Taylor–Hood (u, p) if True.

    Returns:
        A new `MixedUnknown` or `DisplacementUnknown`.
    """
    return MixedUnknown(mesh, degree) if mixed else DisplacementUnknown(mesh, degree)


def unknown_of(w: fem.Function) -> DisplacementUnknown | MixedUnknown:
    """The unknown whose Function is `w`, made by the caller (a demo's `fem.Function`).

    Mixed if `w`'s space is (a Taylor–Hood pair, as `taylor_hood` makes).

    Args:
        w: the displacement Function, or the (u, p) one.

    Returns:
        A `MixedUnknown` or `DisplacementUnknown` around `w` itself.
    """
    mesh = w.function_space.mesh
    if w.function_space.num_sub_spaces and w.ufl_element().is_mixed:
        return MixedUnknown(mesh, function=w)
    return DisplacementUnknown(mesh, function=w)
