"""Von Mises (J2) plasticity, small strain, linear isotropic (H) and kinematic (C) hardening.

The state of a load step is the committed plastic strain ε_pⁿ and cumulated plastic strain
pⁿ at the quadrature points. Over the step the material is the *incremental* (condensed)
energy of the course: for the current strain ε,

    ψ(ε) = min over Δε_p of  W(ε − ε_p) + H/2 p² + C/3 ε_p:ε_p + σ0 Δp,
    ε_p = ε_pⁿ + Δε_p,  p = pⁿ + Δp,  Δp = √(2/3) |Δε_p|,

with W Hooke's energy. For these hardenings the minimiser is the radial return in closed
form: trial stress σ_tr = ∂W(ε − ε_pⁿ), relative deviator ξ = dev σ_tr − X, X = (2/3) C ε_pⁿ,
f = √(3/2) |ξ| − (σ0 + H pⁿ); if f > 0, Δp = f / (3μ + H + C) along n = (3/2) ξ / |ξ|_eq.
It is written in UFL, so σ = ∂ψ/∂ε (the minimiser's own variation vanishes: σ is the
return-mapped stress) and the consistent tangent ∂²ψ/∂ε∂ε both come from UFL, not typed.

The state is updated only by `commit(u)`, when a load step has converged: a cut step leaves
it as it was, so there is nothing to restore. E, σ0, H and C may be `fem.Constant` objects (checked
at their current values): one compiled form then serves every value, and a parameter's
derivative is taken by UFL (`solvers.sensitivity`, the identification of a material).
`bind(mesh, degree)` creates the state; the residual must then integrate with
`kinematics.quadrature_measure("dx", mesh, degree)`, the same rule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import ufl

from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain, check_range

__all__ = ["J2Plasticity", "PlasticState", "QuadratureStateOutputs", "SmallStrainPlasticity",
           "cell_max",
           "hookes_tangent", "per_cell", "quadrature_spaces", "store_at_points"]

YIELD_TOLERANCE = 1e-10  # f > 1e-10 σ0 is plastic


@dataclass(eq=False)
class PlasticState:
    """J2's committed state at the quadrature points, and its compiled update.

    Empty until `bind`: the parameters of a `J2Plasticity` are frozen, its state is not.
    """

    eps_p: object = None  # the plastic strain ε_p (quadrature Function, 3x3)
    p: object = None  # the cumulated plastic strain (quadrature Function)
    points: object = None  # the quadrature points (reference cell)
    commit: tuple | None = None  # (ε_p, p) of the return map as fem.Expressions, compiled once

    def bind(self, mesh, degree: int) -> None:
        """Zero ε_p and p at the quadrature points of `degree` on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        from dolfinx import fem

        T, S = quadrature_spaces(mesh, degree)
        self.eps_p = fem.Function(T, name="plastic_strain")
        self.p = fem.Function(S, name="cumulated_plastic_strain")
        self.points, self.commit = T.element.interpolation_points, None


def hookes_tangent(material, u, model: str, dx):
    """The tangent of Hooke's law with the material's E and ν.

    What a path-dependent law keeps for modified Newton: its own K(0) would read the
    committed state.

    Args:
        material: the law (its `E` and `nu` are read).
        u: the displacement (the unknown Function).
        model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        dx: the measure of the residual.

    Returns:
        Hooke's tangent, a bilinear form (UFL) in `u`.
    """
    v = ufl.TestFunction(u.function_space)
    work = LinearElastic(material.E, material.nu).internal_work(u, v, model)
    return ufl.derivative(work * dx, u)


def store_at_points(targets, expressions, cells=None) -> None:
    """Evaluate every expression at the quadrature points, then store each in its target.

    All are evaluated before any is stored: each reads the committed state it replaces.

    Args:
        targets: the state's quadrature Functions.
        expressions: their new values (`fenics_nl.expression.Expression`, one per target).
        cells: only the points of these local cells (the others keep their values); None:
            every cell.
    """
    from dolfinx import fem

    values = []
    for target, expression in zip(targets, expressions, strict=True):
        new = fem.Function(target.function_space)
        if cells is None:
            new.interpolate(expression)
        else:
            new.interpolate(expression, cells0=cells)
        values.append(new.x.array)
    for target, value in zip(targets, values, strict=True):
        if cells is None:
            target.x.array[:] = value
        else:
            dofmap = target.function_space.dofmap
            dofs = (dofmap.list[cells][:, :, None] * dofmap.bs + np.arange(dofmap.bs)).ravel()
            target.x.array[dofs] = value[dofs]


def quadrature_spaces(mesh, degree: int):
    """(3x3 tensor, scalar) spaces at the quadrature points of `degree` on `mesh`.

    Args:
        mesh: the mesh.
        degree: the quadrature degree.

    Returns:
        (tensor space, scalar space), dolfinx FunctionSpaces of quadrature elements.
    """
    import basix.ufl
    from dolfinx import fem

    cell = mesh.basix_cell()
    return tuple(fem.functionspace(mesh, basix.ufl.quadrature_element(
        cell, value_shape=shape, scheme="default", degree=degree)) for shape in ((3, 3), ()))


class StateAtPoints:
    """A law whose state lives at the quadrature points: bound, committed, read there.

    J2 (small and finite strain) and the viscous laws: `bind` creates the law's `state` on
    a mesh; a small-strain law's `commit` stores the state of ε(u) by its `commit_strain`;
    σ_eq per cell is evaluated at the points, where the state is, and averaged over each
    cell.
    """

    def bind(self, mesh, degree: int) -> None:
        """Create the state (zero) at the quadrature points of `degree` on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        self.state.bind(mesh, degree)

    def commit(self, u, model: str = "3d") -> None:
        """Store the step's state of the displacement `u` (a converged step).

        The update is compiled for the first `u` given: one displacement per bound material.

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        """
        self.commit_strain(kinematics.small_strain(u, model))

    def quadrature_space(self):
        """The law's scalar quadrature space (where its state is)."""
        raise NotImplementedError

    def cell_mean(self, expression, name: str):
        """The mean of a scalar UFL expression over each cell's quadrature points (DG0).

        The state exists at the quadrature points only, so anything that reads it (σ_eq,
        the mixed formulation's stress) is evaluated there.

        Args:
            expression: the scalar UFL expression.
            name: the name of the returned Function.

        Returns:
            The means, a DG0 Function.
        """
        from dolfinx import fem

        Q = self.quadrature_space()
        at_points = fem.Function(Q)
        at_points.interpolate(Expression(expression, Q.element.interpolation_points))
        f = fem.Function(fem.functionspace(Q.mesh, ("DG", 0)), name=name)
        per_cell(at_points, f, np.mean)
        return f

    def von_mises(self, u, model: str = "3d"):
        """σ_eq per cell (DG0): the mean of its quadrature points' values.

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").

        Returns:
            σ_eq, a DG0 Function named "von_mises".
        """
        return self.cell_mean(self.von_mises_expression(u, model), "von_mises")


class QuadratureStateOutputs(StateAtPoints):
    """Per-cell outputs of a law whose state lives at the quadrature points.

    J2 at small and finite strain: the law has `cumulated_plastic_strain`, a quadrature
    Function.
    """

    def quadrature_space(self):
        """The space of `cumulated_plastic_strain`."""
        return self.cumulated_plastic_strain.function_space

    def cumulated_plastic_strain_per_cell(self):
        """The largest committed p of each cell's quadrature points (DG0 Function).

        Returns:
            The maxima, a new DG0 Function named "cumulated_plastic_strain".
        """
        return cell_max(self.cumulated_plastic_strain, "cumulated_plastic_strain")

    def plastic_radius(self, least: float = 0.0) -> float:
        """The largest distance from the origin of a quadrature point where p > 0.

        The plastic zone's edge of a body loaded from a cavity at the origin (a vessel).

        Args:
            least: what is returned if no point has yielded (the cavity's radius).

        Returns:
            That distance, the same on every rank (collective).
        """
        import ufl
        from dolfinx import fem
        from mpi4py import MPI

        p = self.cumulated_plastic_strain
        Q = p.function_space
        x = ufl.SpatialCoordinate(Q.mesh)
        r = fem.Function(Q)
        r.interpolate(Expression(ufl.sqrt(ufl.inner(x, x)), Q.element.interpolation_points))
        n = Q.dofmap.index_map.size_local
        yielded = r.x.array[:n][p.x.array[:n] > 0]
        return max(least, Q.mesh.comm.allreduce(float(yielded.max(initial=least)),
                                                op=MPI.MAX))


class SmallStrainPlasticity(QuadratureStateOutputs):
    """A small-strain plastic law by its return map: the state (ε_p, p) at the points.

    The subclass gives `return_map(ε)` → (ε_p, p, Δp) in UFL from the committed state (and
    has a `state: PlasticState`, E and ν); σ = Hooke's stress of ε − ε_p(ε), whose UFL
    derivative through the return map is the consistent tangent (not symmetric when the
    flow is not associated). J2 (`J2Plasticity`) and the soils' laws
    (`materials.drucker_prager`).
    """

    path_dependent = True

    def modified_newton_tangent(self, u, model: str, dx):
        """The course's choice for plasticity: Hooke's tangent (E, ν), factorized once.

        Not K(0) of this energy: that form reads the committed state, and at u = 0 after
        plastic steps the trial stress −C:ε_p is beyond yield (a plastic tangent).

        Args:
            u: the displacement (the unknown Function).
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
            dx: the measure of the residual.

        Returns:
            Hooke's tangent, a bilinear form (UFL) in `u`.
        """
        return hookes_tangent(self, u, model, dx)

    def reset(self) -> None:
        """Back to the virgin state (a new load path on the same forms)."""
        st = self._bound()
        st.eps_p.x.array[:] = 0.0
        st.p.x.array[:] = 0.0

    @property
    def plastic_strain(self):
        """The committed plastic strain ε_p (quadrature Function, 3x3)."""
        return self._bound().eps_p

    @property
    def cumulated_plastic_strain(self):
        """The committed cumulated plastic strain p (quadrature Function)."""
        return self._bound().p

    def state_functions(self) -> dict:
        """The committed state's quadrature Functions by name (to checkpoint and restore).

        Returns:
            The committed ε_p ("plastic_strain") and p ("cumulated_plastic_strain"), the
            Functions themselves, not copies.
        """
        st = self._bound()
        return {"plastic_strain": st.eps_p, "cumulated_plastic_strain": st.p}

    def state_update(self, strain) -> dict:
        """The state `commit` would store for `strain`, by the names of `state_functions` (UFL).

        What a sensitivity differentiates: the new state as a function of the strain, the
        committed state and the parameters.

        Args:
            strain: the small strain ε (UFL, 3x3).

        Returns:
            A dict of UFL expressions, the new ε_p ("plastic_strain") and p
            ("cumulated_plastic_strain").
        """
        eps_p, p, _ = self.return_map(strain)
        return {"plastic_strain": eps_p, "cumulated_plastic_strain": p}

    def plastic_zone(self, dx) -> dict:
        """The largest cumulated plastic strain, and the plastic fraction of the volume.

        Args:
            dx: the measure of the residual (the state's quadrature rule).

        Returns:
            A dict of floats, the same on every rank (collective), the largest p
            ("max_cumulated_plastic_strain") and the share of ∫ dx where p > 0
            ("plastic_volume_fraction").
        """
        from dolfinx import fem
        from mpi4py import MPI

        p = self.cumulated_plastic_strain
        comm, n = p.function_space.mesh.comm, p.function_space.dofmap.index_map.size_local
        volume, plastic = (comm.allreduce(fem.assemble_scalar(fem.form(f * dx)))
                           for f in (1.0, ufl.conditional(ufl.gt(p, 0), 1.0, 0.0)))
        return {"max_cumulated_plastic_strain": comm.allreduce(
                    float(p.x.array[:n].max(initial=0.0)), op=MPI.MAX),
                "plastic_volume_fraction": plastic / volume}

    def output_fields(self) -> list:
        """What a time series writes of the state: p (cell max) and ε_p (cell mean), DG0.

        Returns:
            The new DG0 Functions of `cumulated_plastic_strain_per_cell` and
            `plastic_strain_per_cell`, in that order.
        """
        return [self.cumulated_plastic_strain_per_cell(), self.plastic_strain_per_cell()]

    def plastic_strain_per_cell(self):
        """The mean committed plastic strain ε_p of each cell's quadrature points (DG0, 3x3).

        Returns:
            The means, a new DG0 tensor Function named "plastic_strain".
        """
        from dolfinx import fem

        eps_p = self.plastic_strain
        msh = eps_p.function_space.mesh
        f = fem.Function(fem.functionspace(msh, ("DG", 0, (3, 3))), name="plastic_strain")
        n = msh.topology.index_map(msh.topology.dim).size_local
        at_points = eps_p.x.array.reshape(-1, 9)[eps_p.function_space.dofmap.list[:n]]
        f.x.array.reshape(-1, 9)[f.function_space.dofmap.list[:n, 0]] = at_points.mean(axis=1)
        f.x.scatter_forward()
        return f

    def _bound(self) -> PlasticState:
        if self.state.eps_p is None:
            raise ValueError(f"{type(self).__name__} has no state: call bind(mesh, "
                             "quadrature degree) before writing a form with it")
        return self.state

    def stress(self, eps):
        """σ: Hooke's stress at the return-mapped state, C : (ε − ε_p(ε)).

        Its UFL derivative through the return map is the consistent tangent. With an
        associated flow (J2) it is ∂ψ/∂ε of the step's condensed energy ψ: the return map
        minimizes ψ over the state, so the state's variation
        drops out of dψ/dε (the envelope theorem): σ is ∂ψ_e/∂ε_e at ε_e = ε − ε_p(ε), the
        same stress without the terms that cancel, and its derivative through the return map
        is the consistent tangent. Against differentiating `energy` itself, the kernels
        assemble the tangent and the residual faster (compared once, on
        benchmarks/plasticity_peer.py's cylinder: no benchmark keeps that comparison); the
        answers agree to round-off.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            σ (UFL, 3x3).
        """
        eps_p, _, _ = self.return_map(eps)
        return LinearElastic(self.E, self.nu).stress(eps - eps_p)

    def commit_strain(self, strain, cells=None) -> None:
        """`commit` for a 3x3 strain expression (plane stress: `plane_stress.whole_strain`).

        Args:
            strain: the small strain ε (UFL, 3x3); the update is compiled for the first given.
            cells: only at the points of these local cells (the law's part of a body:
                `piecewise.ByGroup`); None: everywhere.
        """
        st = self._bound()
        if st.commit is None:  # compiled once
            eps_p, p, _ = self.return_map(strain)
            st.commit = (Expression(eps_p, st.points), Expression(p, st.points))
        store_at_points((st.eps_p, st.p), st.commit, cells)


@dataclass(frozen=True, eq=False)
class J2Plasticity(SmallStrainPlasticity, Isotropic, SmallStrain):
    """J2 plasticity: yield stress σ0 > 0, isotropic hardening H ≥ 0, kinematic C ≥ 0.

    H = C = 0 is perfect plasticity (the defaults of H and C). Models: 3D, plane strain,
    axisymmetric (3x3 strains); plane stress through `materials.plane_stress`, with the
    out-of-plane strain an unknown at the quadrature points (a 2x2 strain is refused).
    """

    sigma0: float = 1.0
    H: float = 0.0
    C: float = 0.0
    state: PlasticState = field(default_factory=PlasticState, init=False, repr=False,
                                compare=False)

    def __post_init__(self):
        super().__post_init__()
        check_range("sigma0", self.sigma0, 0.0, math.inf)
        for name in ("H", "C"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be >= 0 and finite, got {getattr(self, name)!r}")

    def return_map(self, eps):
        """(ε_p, p, Δp) at the strain ε from the committed state (UFL, radial return).

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (plastic strain ε_p, cumulated plastic strain p, its increment Δp), UFL.
        """
        self.require_3x3(eps)
        st = self._bound()
        eps_p_n, p_n = st.eps_p, st.p
        mu = self.mu
        eps_e = eps - eps_p_n
        # dev σ_tr = 2μ dev ε_e: the bulk modulus (∞ at ν = 1/2) does not enter the return
        xi = 2 * mu * ufl.dev(eps_e) - 2.0 / 3.0 * self.C * eps_p_n
        q = ufl.sqrt(1.5 * ufl.inner(xi, xi))
        f = q - (self.sigma0 + self.H * p_n)
        # a point left on the yield surface by the last step has f = 0 up to round-off: it
        # must start the next step elastic (an unloading step with the plastic tangent
        # there overshoots by E/E_t and diverges)
        plastic = ufl.gt(f, YIELD_TOLERANCE * self.sigma0)
        dp = ufl.conditional(plastic, f / (3 * mu + self.H + self.C), 0)
        # the direction only where it is defined (q > 0 there): no 0/0 in the elastic branch
        n = ufl.conditional(plastic, 1.5 * xi / q, ufl.zero(3, 3))
        return eps_p_n + dp * n, p_n + dp, dp

    def energy(self, eps):
        """ψ(ε): the step's condensed energy at the return-mapped state.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        eps_p, p, dp = self.return_map(eps)
        return (LinearElastic(self.E, self.nu).energy(eps - eps_p)
                + 0.5 * self.H * p**2 + self.C / 3.0 * ufl.inner(eps_p, eps_p)
                + self.sigma0 * dp)

    def volumetric_split(self, eps):
        """ψ = [μ |dev ε_e|² + hardening + σ0 Δp] + κ/2 (tr ε)².

        The plastic flow is isochoric (tr ε_p = 0), so the bulk term holds the total strain.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (μ |dev ε_e|² + hardening + σ0 Δp, tr ε, κ).
        """
        eps_p, p, dp = self.return_map(eps)
        d = ufl.dev(eps - eps_p)
        rest = (self.mu * ufl.inner(d, d) + 0.5 * self.H * p**2
                + self.C / 3.0 * ufl.inner(eps_p, eps_p) + self.sigma0 * dp)
        return rest, ufl.tr(eps), self.kappa


def cell_max(at_points, name: str):
    """The largest value of each cell's quadrature points of `at_points` (DG0, `name`).

    Args:
        at_points: a scalar quadrature Function (p, α).
        name: the name of the returned Function.

    Returns:
        The maxima, a DG0 Function.
    """
    from dolfinx import fem

    cells = fem.Function(fem.functionspace(at_points.function_space.mesh, ("DG", 0)),
                         name=name)
    per_cell(at_points, cells, np.max)
    return cells


def per_cell(at_points, cells, reduce) -> None:
    """DG0 `cells` = `reduce` of each owned cell's quadrature values of `at_points`.

    Read and written through both dofmaps (no assumption on dof numbering); ghosts updated.

    Args:
        at_points: a scalar quadrature Function.
        cells: the DG0 Function on the same mesh, written.
        reduce: a numpy reduction called as `reduce(values, axis=1)` (np.max, np.mean).
    """
    msh = cells.function_space.mesh
    n = msh.topology.index_map(msh.topology.dim).size_local
    values = at_points.x.array[at_points.function_space.dofmap.list[:n]]  # (cells, points)
    cells.x.array[cells.function_space.dofmap.list[:n, 0]] = reduce(values, axis=1)
    cells.x.scatter_forward()
