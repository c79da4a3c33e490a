"""Materials as free-energy densities in UFL; stress and tangent are derived, never typed.

Small strain (HPP): `φ(ε)`, `σ = ∂φ/∂ε`, `A = ∂²φ/∂ε∂ε`.
Finite strain: `φ(e)` in the Green–Lagrange strain `e`, `S = ∂φ/∂e`, `P = F·S`.

Strains are 3x3 (see `kinematics`), except plane stress, where a 2x2 strain is passed and
the materials that support it use the plane-stress Lamé constant `λ* = 2λμ/(λ + 2μ)`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import ufl

from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics

__all__ = [
    "FiniteStrain",
    "Isotropic",
    "LinearElastic",
    "Material",
    "NeoHookean",
    "PowerLaw",
    "SmallStrain",
    "StVenantKirchhoff",
    "check_range",
    "von_mises_of",
]


def check_range(name: str, value: float, low: float, high: float) -> None:
    """Raise ValueError unless low < value < high (a bound may be ±inf).

    Args:
        name: the parameter's name, for the message.
        value: its value (a number, or a scalar `fem.Constant` at its current value).
        low: the lower bound (excluded).
        high: the upper bound (excluded).
    """
    if not (low < float(value) < high):
        raise ValueError(f"{name} must be in ({low:g}, {high:g}), got {value!r}")


@dataclass(frozen=True)
class Isotropic:
    """Young's modulus E > 0 and Poisson's ratio -1 < ν ≤ 0.5.

    ν = 1/2 (incompressible: λ = κ = ∞) only in the mixed formulation
    (`fenics_nl.materials.mixed`); `energy` refuses it.
    """

    E: float
    nu: float

    def __post_init__(self):
        check_range("E", self.E, 0.0, float("inf"))
        if not -1.0 < float(self.nu) <= 0.5:
            raise ValueError(f"nu must be in (-1, 0.5], got {self.nu!r}")

    @property
    def incompressible(self) -> bool:
        """ν = 1/2: λ and κ are infinite."""
        return self.nu == 0.5

    @property
    def mu(self) -> float:
        """Shear modulus μ."""
        return self.E / (2 * (1 + self.nu))

    @property
    def lmbda(self) -> float:
        """First Lamé constant λ (∞ at ν = 1/2)."""
        if self.incompressible:
            return math.inf
        return self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))

    @property
    def kappa(self) -> float:
        """Bulk modulus κ (∞ at ν = 1/2)."""
        if self.incompressible:
            return math.inf
        return self.E / (3 * (1 - 2 * self.nu))

    @property
    def volumetric_modulus(self) -> float:
        """k of `volumetric_split` (φ = φ̃ + k/2 g²): the bulk modulus κ by default."""
        return self.kappa

    def require_compressible(self) -> None:
        """Raise ValueError at ν = 1/2: a displacement formulation cannot hold it."""
        if self.incompressible:
            raise ValueError("nu = 0.5 (incompressible) needs the mixed displacement-pressure "
                             "formulation (--mixed where a scene has it, "
                             "fenics_nl.materials.mixed): the bulk modulus is infinite")

    def lmbda_for(self, strain) -> float:
        """λ for a 3x3 strain, the plane-stress λ* = 2λμ/(λ + 2μ) for a 2x2 one.

        Args:
            strain: the strain (UFL); only its shape is read.

        Returns:
            λ, or λ* (2μ at ν = 1/2).
        """
        if strain.ufl_shape[0] == 2:
            if self.incompressible:
                return 2 * self.mu  # the limit λ → ∞
            return 2 * self.lmbda * self.mu / (self.lmbda + 2 * self.mu)
        return self.lmbda

    def require_3x3(self, strain) -> None:
        """Raise ValueError for a plane-stress (2x2) strain this energy does not support.

        Args:
            strain: the strain (UFL); only its shape is read.
        """
        if strain.ufl_shape[0] != 3:
            raise ValueError(f"{type(self).__name__} does not support the plane-stress model")


def von_mises_of(sigma):
    """σ_eq = √(3/2) ‖dev σ‖ of a 3x3 stress, or of a 2x2 one embedded with σ_zz = 0 (UFL).

    Args:
        sigma: the Cauchy stress (UFL, 3x3 or 2x2).

    Returns:
        σ_eq (UFL scalar).
    """
    if sigma.ufl_shape[0] == 2:
        sigma = ufl.as_tensor([[sigma[0, 0], sigma[0, 1], 0],
                               [sigma[1, 0], sigma[1, 1], 0], [0, 0, 0]])
    s = ufl.dev(sigma)
    return ufl.sqrt(1.5 * ufl.inner(s, s))


class Material(ABC):
    """A material law: a free energy, and the internal virtual work derived from it.

    `is_linear`: the residual is linear in u (Newton converges in one step, no line
    search needed). `finite_strain`: the energy is written in the Green–Lagrange strain.
    `path_dependent`: the law has internal variables (`state_functions`, `commit` after a
    converged step, `output_fields`), as J2 plasticity.
    """

    finite_strain: bool = False
    is_linear: bool = False
    path_dependent: bool = False

    def modified_newton_tangent(self, u, model: str, dx):
        """The tangent modified Newton and BFGS keep: for an elastic law, "initial".

        `NewtonSolver`'s `constant_tangent`: the tangent at the start of each solve.

        Args:
            u: the displacement (the unknown Function).
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").
            dx: the measure of the residual.

        Returns:
            "initial"; a law may return a bilinear form (UFL) instead (J2 gives Hooke's), which
            the solver factorizes once for its life.
        """
        return "initial"

    @abstractmethod
    def energy(self, strain):
        """Free-energy density of the strain (ε in small strain, e in finite strain).

        Args:
            strain: ε or e (UFL, 3x3; 2x2 in plane stress, where the law supports it).

        Returns:
            φ (UFL scalar).
        """

    def volumetric_split(self, strain):
        """(φ̃, g, k) with φ = φ̃ + k/2 g², for the mixed formulation (`materials.mixed`).

        g is the volumetric measure (tr ε, tr e or ln J), k the modulus that tends to ∞ as
        ν → 1/2 (κ or λ). This default raises ValueError: the law has no split.

        Args:
            strain: ε or e (UFL, 3x3).

        Returns:
            (φ̃ (UFL), g (UFL), k (∞ at ν = 1/2)).
        """
        raise ValueError(f"{type(self).__name__} has no volumetric split: no mixed "
                         "displacement-pressure formulation")

    @abstractmethod
    def internal_work(self, u, v, model: str = "3d"):
        """Integrand of the internal virtual work of `u` in the direction `v`.

        Args:
            u: the displacement.
            v: the test function (virtual displacement).
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The integrand (UFL scalar), to be multiplied by the measure `dx`.
        """

    @abstractmethod
    def cauchy_stress(self, u, model: str = "3d"):
        """The Cauchy stress of the displacement `u` (3x3; 2x2 in plane stress).

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            σ (UFL).
        """

    def von_mises_expression(self, u, model: str = "3d"):
        """σ_eq = √(3/2) ‖dev σ‖ of the displacement `u` (UFL).

        Plane stress: σ is embedded in 3D with σ_zz = 0 (the deviator is the 3D one).

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            σ_eq (UFL scalar).
        """
        return von_mises_of(self.cauchy_stress(u, model))

    def von_mises(self, u, model: str = "3d"):
        """σ_eq of the displacement `u`, one value per cell (DG0 Function, at the centroid).

        Args:
            u: the displacement (a Function: its mesh carries the DG0 space).
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            σ_eq, a DG0 Function named "von_mises".
        """
        from dolfinx import fem

        Q = fem.functionspace(u.function_space.mesh, ("DG", 0))
        f = fem.Function(Q, name="von_mises")
        f.interpolate(Expression(self.von_mises_expression(u, model),
                                 Q.element.interpolation_points))
        return f


class SmallStrain(Material):
    """Stress, tangent and virtual work derived from `energy(ε)`."""

    finite_strain = False

    def stress(self, eps):
        """Cauchy stress σ = ∂φ/∂ε.

        Args:
            eps: the small strain ε (UFL, 3x3; 2x2 in plane stress).

        Returns:
            σ (UFL, the shape of ε).
        """
        eps = ufl.variable(eps)
        return ufl.diff(self.energy(eps), eps)

    def tangent(self, eps):
        """Tangent moduli A = ∂²φ/∂ε∂ε = ∂σ/∂ε (fourth-order tensor).

        Args:
            eps: the small strain ε (UFL, 3x3; 2x2 in plane stress).

        Returns:
            A (UFL).
        """
        eps = ufl.variable(eps)
        return ufl.diff(self.stress(eps), eps)

    def internal_work(self, u, v, model: str = "3d"):
        """Integrand of the internal virtual work σ(ε(u)) : ε(v) (times 2πr if axisymmetric).

        Args:
            u: the displacement.
            v: the test function (virtual displacement).
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The integrand (UFL scalar), to be multiplied by the measure `dx`.
        """
        mesh = kinematics.domain(u)
        eps_u = kinematics.small_strain(u, model)
        eps_v = kinematics.small_strain(v, model)
        return ufl.inner(self.stress(eps_u), eps_v) * kinematics.measure_weight(mesh, model)

    def cauchy_stress(self, u, model: str = "3d"):
        """σ(ε(u)): in small strain the Cauchy stress is the energy's derivative.

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            σ (UFL, 3x3; 2x2 in plane stress).
        """
        return self.stress(kinematics.small_strain(u, model))


class FiniteStrain(Material):
    """Second and first Piola stresses and virtual work derived from `energy(e)`."""

    finite_strain = True

    def second_piola(self, e):
        """S = ∂φ/∂e.

        Args:
            e: the Green–Lagrange strain (UFL, 3x3; 2x2 in plane stress).

        Returns:
            The second Piola–Kirchhoff stress S (UFL, the shape of e).
        """
        e = ufl.variable(e)
        return ufl.diff(self.energy(e), e)

    def first_piola(self, u, model: str = "3d"):
        """P = F·S(e(u)).

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The first Piola–Kirchhoff stress P (UFL).
        """
        F = kinematics.deformation_gradient(u, model)
        return F * self.second_piola(kinematics.green_lagrange(u, model))

    def cauchy_stress(self, u, model: str = "3d"):
        """σ = F S Fᵀ / det F (plane stress: det of the in-plane F, thickness change ignored).

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            σ (UFL).
        """
        F = kinematics.deformation_gradient(u, model)
        return F * self.second_piola(kinematics.green_lagrange(u, model)) * F.T / ufl.det(F)

    def internal_work(self, u, v, model: str = "3d"):
        """Integrand of P(u) : ∇v over the reference configuration (times 2πR if axisymmetric).

        Args:
            u: the displacement.
            v: the test function (virtual displacement).
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The integrand (UFL scalar), to be multiplied by the reference measure `dx`.
        """
        mesh = kinematics.domain(u)
        H_v = kinematics.displacement_gradient(v, model)
        return ufl.inner(self.first_piola(u, model), H_v) * kinematics.measure_weight(mesh, model)


@dataclass(frozen=True)
class LinearElastic(Isotropic, SmallStrain):
    """Hooke's law: φ(ε) = λ/2 (tr ε)² + μ ε:ε."""

    is_linear = True

    def energy(self, eps):
        """φ(ε).

        Args:
            eps: the small strain ε (UFL, 3x3; 2x2 in plane stress, with λ*).

        Returns:
            φ (UFL scalar).
        """
        if eps.ufl_shape[0] == 3:  # plane stress keeps a finite λ* at ν = 1/2
            self.require_compressible()
        return 0.5 * self.lmbda_for(eps) * ufl.tr(eps) ** 2 + self.mu * ufl.inner(eps, eps)

    def volumetric_split(self, eps):
        """φ = μ dev ε : dev ε + κ/2 (tr ε)².

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (μ |dev ε|², tr ε, κ).
        """
        self.require_3x3(eps)
        d = ufl.dev(eps)
        return self.mu * ufl.inner(d, d), ufl.tr(eps), self.kappa


@dataclass(frozen=True)
class PowerLaw(Isotropic, SmallStrain):
    """Deformation-theory power-law elasticity, linear at small strain.

    φ(ε) = κ/2 (tr ε)² + σ0 ε0/(n+1) [(1 + (ε_eq/ε0)²)^((n+1)/2) − 1],
    with ε_eq² = ⅔ dev ε : dev ε and ε0 = σ0/(3μ). The energy depends on ε_eq only through
    ε_eq², so it is smooth at zero strain (this is the regularisation): there the tangent is
    Hooke's (E, ν); for ε_eq ≫ ε0, σ_eq ≈ σ0 (ε_eq/ε0)^n. n = 1 is exactly Hooke's law,
    n < 1 softens (hardening plasticity-like), n > 1 stiffens. Convex for every n > 0.
    """

    sigma0: float = 1.0
    n: float = 1.0

    def __post_init__(self):
        super().__post_init__()
        check_range("sigma0", self.sigma0, 0.0, float("inf"))
        check_range("n", self.n, 0.0, float("inf"))

    @property
    def eps0(self) -> float:
        """Reference strain ε0 = σ0 / (3μ), where the law turns non-linear."""
        return self.sigma0 / (3 * self.mu)

    def strain_ratio(self, sigma_eq: float) -> float:
        """ε_eq/ε0 at the equivalent stress σ_eq, inverting σ_eq/σ0 = x (1 + x²)^((n−1)/2).

        The strain a computed peak stress means (a number, not UFL).

        Args:
            sigma_eq: the equivalent (von Mises) stress.

        Returns:
            ε_eq/ε0 (float; 0 for σ_eq ≤ 0).
        """
        from scipy.optimize import brentq

        s, n = sigma_eq / self.sigma0, self.n
        return brentq(lambda x: x * (1 + x * x) ** ((n - 1) / 2) - s, 0.0, 1e9) if s > 0 else 0.0

    def energy(self, eps):
        """φ(ε).

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            φ (UFL scalar).
        """
        self.require_compressible()
        rest, g, k = self.volumetric_split(eps)
        return 0.5 * k * g**2 + rest

    def volumetric_split(self, eps):
        """φ = σ0 ε0/(n+1) [...] + κ/2 (tr ε)²: the deviatoric part is the power law.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (σ0 ε0/(n+1) [...], tr ε, κ).
        """
        self.require_3x3(eps)
        d = ufl.dev(eps)
        x2 = (2.0 / 3.0) * ufl.inner(d, d) / self.eps0**2
        n = self.n
        return (self.sigma0 * self.eps0 / (n + 1) * ((1 + x2) ** ((n + 1) / 2) - 1),
                ufl.tr(eps), self.kappa)


@dataclass(frozen=True)
class StVenantKirchhoff(Isotropic, FiniteStrain):
    """St Venant–Kirchhoff: φ(e) = λ/2 (tr e)² + μ e:e (the course's finite-strain law)."""

    def energy(self, e):
        """φ(e).

        Args:
            e: the Green–Lagrange strain (UFL, 3x3; 2x2 in plane stress, with λ*).

        Returns:
            φ (UFL scalar).
        """
        if e.ufl_shape[0] == 3:
            self.require_compressible()
        return 0.5 * self.lmbda_for(e) * ufl.tr(e) ** 2 + self.mu * ufl.inner(e, e)

    def volumetric_split(self, e):
        """φ = μ dev e : dev e + κ/2 (tr e)² (at κ = ∞: tr e = 0, not J = 1).

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            (μ |dev e|², tr e, κ).
        """
        self.require_3x3(e)
        d = ufl.dev(e)
        return self.mu * ufl.inner(d, d), ufl.tr(e), self.kappa


@dataclass(frozen=True)
class NeoHookean(Isotropic, FiniteStrain):
    """Compressible neo-Hookean: φ = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)², C = I + 2e."""

    def energy(self, e):
        """φ(e).

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            φ (UFL scalar).
        """
        self.require_3x3(e)
        self.require_compressible()
        C = ufl.Identity(3) + 2 * e
        lnJ = 0.5 * ufl.ln(ufl.det(C))
        return 0.5 * self.mu * (ufl.tr(C) - 3) - self.mu * lnJ + 0.5 * self.lmbda * lnJ**2

    @property
    def volumetric_modulus(self) -> float:
        """λ where it is positive (ν > 0), else κ: see `volumetric_split`."""
        return self.lmbda if self.lmbda > 0 else self.kappa

    def volumetric_split(self, e):
        """φ = [μ/2 (tr C − 3) − μ ln J] + λ/2 (ln J)² for ν > 0 (k = λ, ∞ at ν = 1/2).

        φ̃ must not be concave in ln J: the P1 pressure holds ln J only in the mean over
        each vertex patch, and the part of ln J it leaves free is held by φ̃ alone. The
        split by the bulk modulus, φ̃ = [μ/2 (tr C − 3) − μ ln J − μ/3 (ln J)²] + κ/2 (ln J)²,
        gives it −2μ/3 of stiffness there: an inflated incompressible sphere then lost
        Newton's convergence near its pressure maximum and bifurcated onto mesh-scale modes
        on a fine mesh (`cases/inflated_sphere.toml`, coarse and fine: the stress cases of
        docs/validation.md). For ν ≤ 0 (λ ≤ 0) that split is the only one with k > 0; there
        the mixed form is not needed.

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            (φ̃, ln J, k), k being `volumetric_modulus`.
        """
        self.require_3x3(e)
        C = ufl.Identity(3) + 2 * e
        lnJ = 0.5 * ufl.ln(ufl.det(C))
        rest = 0.5 * self.mu * (ufl.tr(C) - 3) - self.mu * lnJ
        k = self.volumetric_modulus
        if k != self.lmbda:  # κ: the rest of λ/2 (ln J)², (λ − κ)/2 = −μ/3
            rest -= self.mu / 3 * lnJ**2
        return rest, lnJ, k
