"""Von Mises plasticity at finite strain: F = Fe Fp, Hencky elasticity, the exponential map.

The model (Simo 1992; Eterovic & Bathe 1990 for the logarithmic form): the elastic left
Cauchy–Green tensor be = Fe Feᵀ stores Hencky's energy in the elastic logarithmic strain
ε_e = ½ ln be,

    W = κ/2 (tr ε_e)² + μ |dev ε_e|²,

the yield function is von Mises on the Kirchhoff stress τ = ∂W/∂ε_e, the flow is isochoric
(det Fp = 1) and isotropic hardening σ_y(p) = σ0 + H p + (σ∞ − σ0)(1 − exp(−δ p)) (linear
when σ∞ = σ0, Voce's saturation otherwise). The state at the quadrature points is the
plastic metric Cp⁻¹ = (Fpᵀ Fp)⁻¹ and the cumulated plastic strain p.

Over a load step, the trial be_tr = F Cp⁻¹ⁿ Fᵀ and ε_tr = ½ ln be_tr. Integrated by the
exponential map, the flow is a return in the logarithmic strain exactly as the small-strain
radial return (`plasticity`): ε_e = ε_tr − Δp n with n = dev ε_tr / ε̄, ε̄ = √(2/3) |dev ε_tr|,
and 3μ (ε̄ − Δp) = σ_y(pⁿ + Δp). The step's condensed energy is a function of the two
invariants tr ε_tr = ln J and |dev ε_tr|² only:

    ψ = κ/2 (ln J)² + μ (|dev ε_tr| − √(3/2) Δp)² + ∫ σ_y dp  over (pⁿ, pⁿ + Δp),

so P = ∂ψ/∂F and the consistent tangent are UFL's derivatives of it, as for the small-strain
law. |dev ε_tr|² needs no eigenvector: with A = C Cp⁻¹ (similar to be_tr) and the unimodular
Ā = A / det(A)^⅓, it is a function of s = tr Ā + tr Ā⁻¹ − 6 and c = (tr Ā − tr Ā⁻¹)², whose
power series (`LOG_SERIES`) is smooth, objective and free of the 0/0 of eigenvalue formulas
where two stretches coincide (uniaxial tension, axisymmetry), and short enough for a compact
tangent kernel. Over a load step the trial deviatoric elastic strain is the elastic strain
(σ_y/E) plus the step's increment, a few per cent, where the series is exact to round-off;
`commit` measures its truncation against an eigen-decomposition and refuses a step that made
it exceed 1e-9 (a trial deviatoric strain ε̄ of about 0.35).

Voce hardening solves the scalar return equation by Newton iterations unrolled in UFL
(the equation is convex, so Newton rises monotonically to the root; `commit` checks the
root). The update of Cp⁻¹ needs the fractional power be_tr^(1 − Δp/ε̄): it is evaluated with
an eigen-decomposition at the quadrature points (numpy; never differentiated).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import ufl

from fenics_nl.errors import SolveError
from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import FiniteStrain, Isotropic, check_range
from fenics_nl.materials.plasticity import QuadratureStateOutputs, quadrature_spaces

__all__ = ["FiniteJ2Plasticity", "FiniteStrainState", "deviatoric_log_strain_squared"]

SERIES_TOLERANCE = 1e-9  # relative truncation of |dev ε_tr| a commit accepts
RETURN_ITERATIONS = 4  # Voce: Newton iterations of the scalar return (unrolled)
RETURN_TOLERANCE = 1e-10  # its residual, relative to σ0, that a commit accepts
# f > 1e-8 σ0 is plastic: a committed point starts the next step on its yield surface to the
# round-off of the invariants of C Cp⁻¹ (about 1e-16 λ⁴ of |dev ε|², 1e-10 σ0 at λ = 3),
# and must start it elastic (an unloading step with the plastic tangent overshoots)
YIELD_TOLERANCE = 1e-8

# Σ x_i² for x_i = ln λ̄_i (Σ x_i = 0) as Σ k s^i c^j, s = tr Ā + tr Ā⁻¹ − 6 and
# c = (tr Ā − tr Ā⁻¹)², every term with 2i + 6j <= 14: (i, j, k). Obtained by inverting
# s = 2 Σ (cosh x_i − 1) and tr Ā − tr Ā⁻¹ = 2 Σ sinh x_i, with the power sums of three numbers
# of zero sum written in two of their symmetric functions (Newton's identities), in exact
# rational arithmetic (sympy). Tested against eigenvalues: 1e-14 relative up to an
# equivalent strain of 0.1, 1e-12 at 0.2.
LOG_SERIES = (
    (1, 0, 1.0), (2, 0, -1 / 24), (3, 0, 1 / 360), (4, 0, -1 / 4480), (5, 0, 1 / 50400),
    (6, 0, -1 / 532224), (7, 0, 1 / 5381376),
    (0, 1, -1 / 120), (1, 1, 1 / 840), (2, 1, -1 / 6720), (3, 1, 1 / 55440),
    (4, 1, -5 / 2306304),
    (0, 2, -1 / 147840), (1, 2, 1 / 480480),
)


def deviatoric_log_strain_squared(A):
    """|dev ½ ln A|² for A similar to a symmetric positive definite 3x3 matrix (UFL).

    From two invariants of the unimodular Ā = A / det(A)^⅓: tr Ā and tr Ā⁻¹ = I₂(A) / det(A)^⅔
    (no inverse, no eigenvalue).

    Args:
        A: the 3x3 matrix (UFL), e.g. C Cp⁻¹, similar to the trial be_tr.

    Returns:
        |dev ½ ln A|² (UFL scalar), from the series `LOG_SERIES`.
    """
    det = ufl.det(A)
    I1 = ufl.tr(A)
    I2 = 0.5 * (I1**2 - ufl.tr(ufl.dot(A, A)))
    a = I1 * det ** (-1.0 / 3.0) - 3
    b = I2 * det ** (-2.0 / 3.0) - 3
    s, c = a + b, (a - b) ** 2
    total = 0
    for j in sorted({j for _, j, _ in LOG_SERIES}, reverse=True):  # Horner in s, then c
        row = {i: k for i, jj, k in LOG_SERIES if jj == j}
        in_s = 0
        for i in range(max(row), -1, -1):
            in_s = in_s * s + row.get(i, 0.0)
        total = total * c + in_s
    return 0.25 * total


@dataclass(eq=False)
class FiniteStrainState:
    """The committed plastic metric Cp⁻¹ (identity when virgin) and p, and compiled updates."""

    metric: object = None  # Cp⁻¹ (quadrature Function, 3x3)
    p: object = None  # the cumulated plastic strain (quadrature Function)
    points: object = None
    update: tuple | None = None  # (F, Δp, ε̄) as fem.Expressions, compiled at the first commit

    def bind(self, mesh, degree: int) -> None:
        """Virgin state (Cp⁻¹ = I, p = 0) at the quadrature points of `degree` on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        from dolfinx import fem

        T, S = quadrature_spaces(mesh, degree)
        self.metric = fem.Function(T, name="plastic_metric")
        self.p = fem.Function(S, name="cumulated_plastic_strain")
        self.points, self.update = T.element.interpolation_points, None
        self.reset()

    def reset(self) -> None:
        """Back to Cp⁻¹ = I, p = 0."""
        self.metric.x.array.reshape(-1, 3, 3)[:] = np.eye(3)
        self.p.x.array[:] = 0.0


@dataclass(frozen=True, eq=False)
class FiniteJ2Plasticity(QuadratureStateOutputs, Isotropic, FiniteStrain):
    """J2 at finite strain: σ0 > 0, linear hardening H ≥ 0, Voce saturation σ∞ ≥ σ0, δ ≥ 0.

    σ_y(p) = σ0 + H p + (σ∞ − σ0)(1 − exp(−δ p)); `saturation=None` (the default) is σ∞ = σ0,
    linear hardening (H = 0: perfect plasticity). Models: 3D, plane strain, axisymmetric.
    Modified Newton keeps the tangent each solve starts from ("initial"): at finite strain
    the elastic tangent of that configuration (its points start elastic), not Hooke's
    reference tangent, which would ignore the rotations and stretches of a forming step.
    """

    sigma0: float = 1.0
    H: float = 0.0
    saturation: float | None = None
    delta: float = 0.0
    state: FiniteStrainState = field(default_factory=FiniteStrainState, init=False,
                                     repr=False, compare=False)

    path_dependent = True

    def __post_init__(self):
        super().__post_init__()
        check_range("sigma0", self.sigma0, 0.0, math.inf)
        for name in ("H", "delta"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be >= 0 and finite, got {getattr(self, name)!r}")
        if self.saturation is not None and not (
                math.isfinite(float(self.saturation)) and self.saturation >= self.sigma0):
            raise ValueError(f"saturation must be >= sigma0 ({self.sigma0:g}) and finite, got "
                             f"{self.saturation!r}")
        saturating = self.saturation is not None and self.saturation > self.sigma0
        if saturating != (self.delta > 0):  # half a Voce law would be silently linear
            raise ValueError("saturation (> sigma0) and delta (> 0) go together: Voce's "
                             f"hardening needs both, got saturation={self.saturation!r}, "
                             f"delta={self.delta!r}")

    # the hardening law

    @property
    def voce(self) -> bool:
        """A saturating (non-linear) part: the return needs iterations."""
        return self.saturation is not None and self.saturation > self.sigma0 and self.delta > 0

    def yield_stress(self, p):
        """σ_y(p): UFL for a UFL p, numpy for a number or an array.

        Args:
            p: the cumulated plastic strain (UFL, a number or a numpy array).

        Returns:
            σ_y(p), of the kind of `p`.
        """
        exp = np.exp if isinstance(p, int | float | np.floating | np.ndarray) else ufl.exp
        s = self.sigma0 + self.H * p
        if self.voce:
            s = s + (self.saturation - self.sigma0) * (1 - exp(-self.delta * p))
        return s

    def hardening_slope(self, p):
        """dσ_y/dp (UFL).

        Args:
            p: the cumulated plastic strain (UFL).

        Returns:
            dσ_y/dp (UFL; H itself for linear hardening).
        """
        if not self.voce:
            return self.H
        return self.H + self.delta * (self.saturation - self.sigma0) * ufl.exp(-self.delta * p)

    def hardening_energy(self, p):
        """∫₀ᵖ σ_y (UFL).

        Args:
            p: the cumulated plastic strain (UFL).

        Returns:
            The hardening energy ∫₀ᵖ σ_y (UFL scalar).
        """
        w = self.sigma0 * p + 0.5 * self.H * p**2
        if self.voce:
            w = w + (self.saturation - self.sigma0) * (p + (ufl.exp(-self.delta * p) - 1)
                                                       / self.delta)
        return w

    # the step's return and energy

    def _bound(self) -> FiniteStrainState:
        if self.state.metric is None:
            raise ValueError("FiniteJ2Plasticity has no state: call bind(mesh, quadrature "
                             "degree) before writing a form with it")
        return self.state

    def trial(self, e):
        """(ln J, |dev ε_tr|²) of the Green–Lagrange strain e from the committed Cp⁻¹ (UFL).

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            (ln J, |dev ε_tr|²), UFL scalars.
        """
        self.require_3x3(e)
        A = ufl.dot(ufl.Identity(3) + 2 * e, self._bound().metric)
        return 0.5 * ufl.ln(ufl.det(A)), deviatoric_log_strain_squared(A)

    def return_map(self, Q):
        """(plastic?, ε̄, Δp) for |dev ε_tr|² = Q from the committed p (UFL).

        Args:
            Q: |dev ε_tr|² (UFL scalar, the second of `trial`).

        Returns:
            (whether it flows, a UFL condition; the trial equivalent strain ε̄; Δp, 0 where
            elastic).
        """
        p_n = self._bound().p
        eq = ufl.sqrt(2.0 / 3.0 * Q)
        f = 3 * self.mu * eq - self.yield_stress(p_n)
        plastic = ufl.gt(f, YIELD_TOLERANCE * self.sigma0)
        dp = f / (3 * self.mu + self.hardening_slope(p_n))  # exact for linear hardening
        if self.voce:  # Newton on g(Δp) = 3μ(ε̄ − Δp) − σ_y(pⁿ + Δp), convex and decreasing
            for _ in range(RETURN_ITERATIONS - 1):
                g = 3 * self.mu * (eq - dp) - self.yield_stress(p_n + dp)
                dp = dp + g / (3 * self.mu + self.hardening_slope(p_n + dp))
        return plastic, eq, ufl.conditional(plastic, dp, 0.0)

    def volumetric_split(self, e):
        """ψ = [μ |dev ε_e|² + ∫ σ_y dp] + κ/2 (ln J)²: the plastic flow keeps the volume.

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            (μ |dev ε_e|² + ∫ σ_y dp, ln J, κ).
        """
        lnJ, Q = self.trial(e)
        plastic, _, dp = self.return_map(Q)
        p_n = self._bound().p
        # every term under the conditional: √Q has no derivative at Q = 0 (elastic branch)
        rest = ufl.conditional(
            plastic,
            self.mu * (ufl.sqrt(Q) - math.sqrt(1.5) * dp) ** 2
            + self.hardening_energy(p_n + dp) - self.hardening_energy(p_n),
            self.mu * Q)
        return rest, lnJ, self.kappa

    def energy(self, e):
        """ψ(e): the step's condensed energy at the returned state.

        Args:
            e: the Green–Lagrange strain (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        self.require_compressible()
        rest, lnJ, k = self.volumetric_split(e)
        return rest + 0.5 * k * lnJ**2

    # the state

    def reset(self) -> None:
        """Back to the virgin state (a new load path on the same forms)."""
        self._bound().reset()

    @property
    def cumulated_plastic_strain(self):
        """The committed cumulated plastic strain p (quadrature Function)."""
        return self._bound().p

    @property
    def plastic_metric(self):
        """The committed Cp⁻¹ (quadrature Function, 3x3)."""
        return self._bound().metric

    def state_functions(self) -> dict:
        """The committed state's quadrature Functions by name (to checkpoint and restore).

        Returns:
            The committed Cp⁻¹ ("plastic_metric") and p ("cumulated_plastic_strain"), the
            Functions themselves, not copies.
        """
        st = self._bound()
        return {"plastic_metric": st.metric, "cumulated_plastic_strain": st.p}

    def output_fields(self) -> list:
        """What a time series writes of the state: p (cell max), DG0.

        Returns:
            The one new DG0 Function of `cumulated_plastic_strain_per_cell`.
        """
        return [self.cumulated_plastic_strain_per_cell()]

    def commit(self, u, model: str = "3d") -> None:
        """Store the returned state of the displacement `u` (a converged step).

        Cp⁻¹ ← F⁻¹ be Fᵀ⁻¹ with be = J^⅔ b̄_tr^(1 − Δp/ε̄) (the exponential map), p ← p + Δp.
        Raises SolveError, before storing anything, if the step was too large for the
        logarithm's series or the Voce return did not converge: the load driver then cuts
        the step.

        Args:
            u: the displacement; the update is compiled for the first `u` given.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        """
        from dolfinx import fem

        st = self._bound()
        if st.update is None:  # compiled once
            _, Q = self.trial(kinematics.green_lagrange(u, model))
            _, eq, dp = self.return_map(Q)
            st.update = (Expression(kinematics.deformation_gradient(u, model), st.points),
                         Expression(dp, st.points), Expression(eq, st.points))
        values = []
        for expr, like in zip(st.update, (st.metric, st.p, st.p), strict=True):
            f = fem.Function(like.function_space)
            f.interpolate(expr)
            values.append(f.x.array)
        F = values[0].reshape(-1, 3, 3)
        dp, eq = values[1], values[2]
        metric = st.metric.x.array.reshape(-1, 3, 3)
        b = F @ metric @ F.transpose(0, 2, 1)
        lam, vec = np.linalg.eigh(0.5 * (b + b.transpose(0, 2, 1)))
        volume = np.cbrt(np.prod(lam, axis=1))[:, None]  # J^⅔ (det Cp⁻¹ = 1)
        log_dev = 0.5 * np.log(lam / volume)  # dev ε_tr, eigenvalues
        eq_exact = np.sqrt(2.0 / 3.0 * np.sum(log_dev**2, axis=1))
        self._check_commit(st.p.function_space.mesh.comm, eq, 2 * log_dev, dp)
        flowed = dp > 0  # elastic points keep their Cp⁻¹ (no round trip through F⁻¹)
        # |dev ε_e| = (ε̄ − Δp) with the ε̄ of the series, the one the next step's trial
        # reads: the point then starts that step on its yield surface, to round-off
        keep = (eq[flowed] - dp[flowed]) / eq_exact[flowed]
        new = volume[flowed] * np.exp(2 * keep[:, None] * log_dev[flowed])
        be = np.einsum("pij,pj,pkj->pik", vec[flowed], new, vec[flowed])
        F_inv = np.linalg.inv(F[flowed])
        cp = F_inv @ be @ F_inv.transpose(0, 2, 1)
        cp = 0.5 * (cp + cp.transpose(0, 2, 1))
        metric[flowed] = cp / np.cbrt(np.linalg.det(cp))[:, None, None]  # det Cp⁻¹ = 1
        st.p.x.array[:] += dp

    def _check_commit(self, comm, eq, x, dp) -> None:
        """The series' truncation and (Voce) the return's residual, on every rank.

        A refusal is every rank's: the driver's cut is collective.

        `x`: the eigenvalues of ln b̄_tr. The truncation is measured on them, the series
        evaluated at s and c computed from them without cancellation (the invariants of
        C Cp⁻¹ carry a round-off that grows with the stretch, about 1e-16 λ⁴, which is not
        the step's doing); relative where the strain is at least the yield strain. A NaN
        fails both checks.
        """
        from mpi4py import MPI

        s = np.sum(4 * np.sinh(0.5 * x) ** 2, axis=1)  # Σ 2 (cosh x − 1)
        c = np.sum(2 * np.sinh(x), axis=1) ** 2
        series = sum(k * s**i * c**j for i, j, k in LOG_SERIES)
        exact = np.sum(x**2, axis=1)
        floor = 6 * (self.sigma0 / (3 * self.mu)) ** 2  # Σ x² at the yield strain
        # |dev ε| relative: half of Σ x²'s (NaN kept: np.max propagates it)
        worst = comm.allreduce(0.5 * float(np.max(np.abs(series - exact)
                                                   / np.maximum(exact, floor), initial=0.0)),
                               op=MPI.MAX)
        if not worst <= SERIES_TOLERANCE:
            raise SolveError(f"a load step too large for the logarithmic strain's series "
                             f"(|dev ε| off by {worst:.1e} relative at a point): take "
                             "smaller steps")
        residual = 0.0
        if self.voce and np.any(dp > 0):
            p = self._bound().p.x.array[dp > 0] + dp[dp > 0]
            g = 3 * self.mu * (eq[dp > 0] - dp[dp > 0]) - self.yield_stress(p)
            residual = float(np.max(np.abs(g))) / self.sigma0
        residual = comm.allreduce(residual, op=MPI.MAX)
        if not residual <= RETURN_TOLERANCE:
            raise SolveError(f"the Voce return did not converge (residual {residual:.1e} "
                             "σ0 at a point): take smaller steps")
