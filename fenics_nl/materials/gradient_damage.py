"""Gradient damage (the variational models AT1 and AT2): an energy of (u, α) with a length ell.

    E(u, α) = ∫ a(α) ψ0(ε(u)) + (Gc / c_w) (w(α)/ell + ell |∇α|²) dx,    a(α) = (1 − α)² + k,

AT1: w(α) = α, c_w = 8/3 (an elastic phase up to σ_c = √(3 Gc E / (8 ell)));
AT2: w(α) = α², c_w = 2 (damage from the first strain). ψ0 is Hooke's energy (E, ν) and k a
residual stiffness. With `split="volumetric"` (Amor, Marigo & Maurini 2009) only
ψ0⁺ = μ dev ε : dev ε + κ/2 ⟨tr ε⟩₊² is degraded and ψ0⁻ = κ/2 ⟨tr ε⟩₋² is not: a crack does
not open, nor the damage grow, under a volumetric compression. Irreversibility is a bound,
αⁿ ≤ α ≤ 1, on the damage problem (`solvers.alternate`); the energy's derivatives in u and α,
and their tangents, are UFL's.

The uniaxial homogeneous state (ν = 0, ∇α = 0) has a closed form from the same energy:
stationarity in α gives (1 − α) E ε² = (Gc/c_w) w'(α)/ell, so

    AT1: 1 − α = ε_c²/ε² past ε_c = √(3 Gc/(8 ell E)),    AT2: α = E ε² / (E ε² + Gc/ell),

and σ = a(α) E ε (`homogeneous_stress`). With the volumetric split, in uniaxial compressive
strain (ν = 0: κ = E/3, μ = E/2) a share c = 2/3 of ψ0 = E ε²/2 is degraded: ε² becomes c ε²
in the criterion and σ = (c a(α) + 1 − c) E ε.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ufl

from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain, check_range

__all__ = ["AT1", "AT2", "DamagedElastic", "GradientDamage", "crack_tip"]

MODELS = {"at1": 8.0 / 3.0, "at2": 2.0}  # c_w
SPLITS = ("none", "volumetric")


@dataclass(frozen=True)
class GradientDamage(Isotropic):
    """AT1 or AT2 gradient damage on Hooke's law (E, ν): toughness Gc, length ell."""

    finite_strain = False  # (not a field) small strain

    Gc: float = 1.0
    ell: float = 1.0
    model: str = "at1"
    residual_stiffness: float = 0.0
    split: str = "none"

    def __post_init__(self):
        super().__post_init__()
        check_range("Gc", self.Gc, 0.0, math.inf)
        check_range("ell", self.ell, 0.0, math.inf)
        if self.model not in MODELS:
            raise ValueError(f"model must be at1 or at2, got {self.model!r}")
        if self.split not in SPLITS:
            raise ValueError(f"split must be none or volumetric, got {self.split!r}")
        if not 0 <= self.residual_stiffness < 1:
            raise ValueError(f"residual_stiffness must be in [0, 1), got "
                             f"{self.residual_stiffness!r}")

    @property
    def c_w(self) -> float:
        """The normalisation of w: ∫ √w over the optimal profile, times 4."""
        return MODELS[self.model]

    def w(self, alpha):
        """The local dissipation: α (AT1) or α² (AT2).

        Args:
            alpha: the damage α (UFL or a number).

        Returns:
            w(α), of the kind of `alpha`.
        """
        return alpha if self.model == "at1" else alpha**2

    def stiffness(self, alpha):
        """a(α) = (1 − α)² + k.

        Args:
            alpha: the damage α (UFL or a number).

        Returns:
            a(α), of the kind of `alpha`.
        """
        return (1 - alpha) ** 2 + self.residual_stiffness

    def fracture_energy(self, alpha):
        """The dissipated energy density (Gc/c_w)(w(α)/ell + ell |∇α|²).

        Over the optimal profile of a crack it integrates to Gc per unit crack area.

        Args:
            alpha: the damage field α (a Function: its gradient is taken).

        Returns:
            The density (UFL scalar).
        """
        return self.Gc / self.c_w * (self.w(alpha) / self.ell
                                     + self.ell * ufl.inner(ufl.grad(alpha), ufl.grad(alpha)))

    def energy(self, u, alpha, model: str = "3d"):
        """The energy density of (u, α) (times 2πr in the axisymmetric model).

        Args:
            u: the displacement.
            alpha: the damage field α.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").

        Returns:
            The density (UFL scalar), to be multiplied by the measure `dx`.
        """
        eps = kinematics.small_strain(u, model)
        weight = kinematics.measure_weight(kinematics.domain(u), model)
        return (self.elastic_energy(eps, alpha) + self.fracture_energy(alpha)) * weight

    def elastic_energy(self, eps, alpha):
        """a(α) ψ0(ε), or a(α) ψ0⁺ + ψ0⁻ with the volumetric split (ε: 3x3 for it).

        Args:
            eps: the small strain ε (UFL).
            alpha: the damage α (UFL).

        Returns:
            The degraded elastic energy density (UFL scalar).
        """
        hooke = LinearElastic(self.E, self.nu)
        if self.split == "none":
            return self.stiffness(alpha) * hooke.energy(eps)
        deviatoric, trace, kappa = hooke.volumetric_split(eps)
        # at tr ε = 0 the bulk stiffness goes with the opening part (max_value and min_value
        # would both give it a zero derivative there: no κ in the tangent at u = 0)
        opening = ufl.conditional(ufl.ge(trace, 0), trace, 0)
        closing = ufl.conditional(ufl.lt(trace, 0), trace, 0)
        return (self.stiffness(alpha) * (deviatoric + kappa / 2 * opening**2)
                + kappa / 2 * closing**2)

    @property
    def critical_strain(self) -> float:
        """AT1: ε_c = √(3 Gc / (8 ell E)), the end of the elastic phase (AT2 has none: 0)."""
        if self.model == "at2":
            return 0.0
        return math.sqrt(self.Gc / (self.c_w * self.ell * self.E))

    @property
    def critical_stress(self) -> float:
        """The peak of the homogeneous uniaxial response (AT1: a(0) E ε_c; AT2: its maximum)."""
        if self.model == "at1":
            return self.homogeneous_stress(self.critical_strain)
        # AT2: σ(ε) = E ε (g/(E ε² + g))², g = Gc/ell, is largest at E ε² = g/3
        g = self.Gc / self.ell
        eps = math.sqrt(g / (3 * self.E))
        return self.homogeneous_stress(eps)

    def bifurcation_strain(self, length: float) -> float:
        """The strain where the homogeneous uniaxial bar of `length` stops being stable.

        The bar: u held at both ends, ∇α·n = 0 there, ν = 0, the residual stiffness k → 0.

        Its second variation on (v, β), v condensed out, is ∫ (½a'' − a'²/a) E ε² β²
        + (Gc/c_w)(w''/ell β² + 2 ell β'²) for a β of zero mean, and ½a'' − a'²/a = 1 − 4 = −3
        whatever α: the first mode, cos(πx/L), makes it negative past
        3 E ε_b² = (Gc/c_w)(w''/ell + 2 ell π²/L²), and not before the damage starts (AT1).

        Args:
            length: the bar's length L.

        Returns:
            ε_b (float), at least the critical strain ε_c.
        """
        w2 = 0.0 if self.model == "at1" else 2.0
        eb = math.sqrt(self.Gc / self.c_w * (w2 / self.ell + 2 * self.ell * math.pi**2
                                             / length**2) / (3 * self.E))
        return max(eb, self.critical_strain)

    def degraded_share(self, strain: float) -> float:
        """c: the share of ψ0 that a(α) multiplies in uniaxial strain (ν = 0).

        Args:
            strain: the uniaxial strain ε (its sign is read).

        Returns:
            c, 2/3 in compression with the volumetric split, else 1.
        """
        return 2.0 / 3.0 if self.split == "volumetric" and strain < 0 else 1.0

    def homogeneous_damage(self, strain: float) -> float:
        """α of the homogeneous uniaxial state at `strain` (ν = 0), loading monotonically.

        With the volumetric split, in compression: uniaxial strain (laterally held); a free
        bar in compression bulges once it has lost its shear stiffness.

        Args:
            strain: the uniaxial strain ε.

        Returns:
            α (float).
        """
        E, g = self.E, self.Gc / self.ell
        e2 = self.degraded_share(strain) * strain**2
        if self.model == "at1":
            ec = self.critical_strain
            return 0.0 if e2 <= ec**2 else 1.0 - ec**2 / e2
        return E * e2 / (E * e2 + g)

    def homogeneous_stress(self, strain: float) -> float:
        """σ = (c a(α) + 1 − c) E ε of the homogeneous uniaxial state (ν = 0).

        Args:
            strain: the uniaxial strain ε.

        Returns:
            σ (float).
        """
        a = self.stiffness(self.homogeneous_damage(strain))
        c = self.degraded_share(strain)
        return (c * a + 1 - c) * self.E * strain


@dataclass(frozen=True)
class AT1(GradientDamage):
    """`GradientDamage` with w(α) = α (a case file's ``law = "at1"``)."""

    model: str = field(default="at1", init=False)


@dataclass(frozen=True)
class AT2(GradientDamage):
    """`GradientDamage` with w(α) = α² (a case file's ``law = "at2"``)."""

    model: str = field(default="at2", init=False)


class DamagedElastic(SmallStrain):
    """A `GradientDamage` law on a mesh, seen as a path-dependent small-strain material.

    Its energy is the law's elastic part at the damage field α (P1): a(α) ψ0(ε) (with the
    split, a(α) ψ0⁺ + ψ0⁻), so σ, the internal work and σ_eq are `SmallStrain`'s. Its state
    is α and its irreversibility bound, the last committed damage (`lower`); the damage
    itself is found by an alternate minimization (`solvers.alternate`, which takes `lower`
    as its bound), and `commit` moves the bound up to it after a converged step.
    """

    path_dependent = True

    def __init__(self, law: GradientDamage):
        self.law = law
        self.alpha = self.lower = None

    def bind(self, mesh, degree: int) -> None:
        """The damage field (P1, zero) and its bound on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (unused: the damage is P1).
        """
        from dolfinx import fem

        A = fem.functionspace(mesh, ("Lagrange", 1))
        self.alpha = fem.Function(A, name="damage")
        self.lower = fem.Function(A, name="committed_damage")

    def energy(self, eps):
        """a(α) ψ0(ε), or with the split a(α) ψ0⁺ + ψ0⁻ (ε: 3x3).

        Args:
            eps: the small strain ε (UFL).

        Returns:
            The energy density at the current damage field (UFL scalar).
        """
        return self.law.elastic_energy(eps, self.alpha)

    def state_functions(self) -> dict:
        """The damage and its bound (to checkpoint and restore).

        Returns:
            The damage α ("damage") and its committed lower bound ("committed_damage"), the
            P1 Functions themselves, not copies.
        """
        return {"damage": self.alpha, "committed_damage": self.lower}

    def output_fields(self) -> list:
        """What --output writes of the state: the damage.

        Returns:
            The damage α itself, the one P1 Function of the list.
        """
        return [self.alpha]

    def commit(self, u=None, model: str = "3d") -> None:
        """The converged damage becomes the bound of the next steps (irreversibility).

        Args:
            u: the displacement (unused: the damage is already converged).
            model: the kinematic model (unused).
        """
        self.lower.x.array[:] = self.alpha.x.array


def crack_tip(alpha, origin, *, level: float, where=None) -> list[float]:
    """A crack's tip: the broken node (α ≥ `level`) farthest from `origin` (collective).

    A crack of the mesh is a band of cells at α = 1, whose neighbours' nodes are at most
    (1 − h/(2 ell))² (AT1): a level above that (0.9 at ell/h = 2) finds the band's nodes only.

    Args:
        alpha: the damage (a P1 Function).
        origin: where the crack starts (a notch's tip), its coordinates.
        level: the damage of a broken node.
        where: the nodes looked at, a marker of their coordinates as DOLFINx's (x of shape
            (3, n) to a boolean array); None: all.

    Returns:
        The tip's coordinates (`origin` if no node is broken).
    """
    import numpy as np

    A = alpha.function_space
    n = A.dofmap.index_map.size_local
    x = A.tabulate_dof_coordinates()[:n]
    broken = alpha.x.array[:n] >= level
    if where is not None:
        broken &= where(x.T)
    gdim = A.mesh.geometry.dim
    cracked, origin = x[broken, :gdim], np.asarray(origin, dtype=float)
    d = np.linalg.norm(cracked - origin, axis=1)
    local = (float(d.max()), *cracked[d.argmax()]) if len(d) else (0.0, *origin)
    best = max(A.mesh.comm.allgather(local))
    return [float(v) for v in best[1:]]
