"""The gradient damage problems that tests/test_damage.py and benchmarks/damage.py share.

Built as `demos/damage_bar.py` and `demos/crack.py` build theirs, from the same library
pieces (`domain.damage_specimens`, `GradientDamage.energy`, `AlternateMinimization`,
`DamageStability`, `BranchStability`):

* `GradientBar`, `pull`: the AT1/AT2 bar (plane strain at ν = 0, one cell high: the
  uniaxial bar) pulled through strain steps, its stability checked until it bifurcates;
* `crack`, `end_crack`: a bar held undamaged at both ends (its crack in the middle) or at
  its right end (the half crack at its free end, twice which is the toughness of a crack
  along a line of nodes);
* `surfing`, `release_rate`: the surfing crack dragged by Irwin's moving K-field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.damage_specimens import (
    BOTTOM,
    LEFT,
    PRECRACK,
    RIGHT,
    TOP,
    bar_strip,
    surfing_strip,
)
from fenics_nl.materials.gradient_damage import crack_tip
from fenics_nl.parallel import global_max
from fenics_nl.solvers.alternate import AlternateMinimization, AlternateWork
from fenics_nl.solvers.damage_stability import BranchStability, DamageStability

__all__ = ["GradientBar", "PullRecord", "SurfingRecord", "crack", "end_crack", "pull",
           "release_rate", "surfing"]

MODEL = "plane_strain"


class GradientBar:
    """The bar of a `GradientDamage` law (ν = 0): its fields, supports, energy and solver.

    Args:
        law: the gradient damage law.
        length: L.
        cells: cells along the bar (h = L/cells).
        height: H, the cross-section per unit thickness (default h).
        held: where α = 0 (the bar gripped, undamaged): ``none`` (∇α·n = 0 at both ends:
            the homogeneous solution), ``ends`` or ``right``.
        acceleration: the alternate minimization's.
        comm: the communicator.
    """

    def __init__(self, law, length: float, cells: int, *, height: float | None = None,
                 held: str = "none", acceleration: str = "none",
                 comm: MPI.Comm = MPI.COMM_WORLD):
        self.law, self.length, self.h = law, length, length / cells
        self.height = height or self.h
        self.mesh, self.tags = msh, tags = bar_strip(comm, length, cells, height=height)
        self.V = V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
        self.A = A = fem.functionspace(msh, ("Lagrange", 1))
        self.u = fem.Function(V, name="displacement")
        self.alpha = fem.Function(A, name="damage")
        self.end = boundary.component(V, 0, tags.find(RIGHT))
        self.bcs = [boundary.component(V, 0, tags.find(LEFT)),
                    boundary.component(V, 1, tags.find(BOTTOM)), self.end]
        gripped = {"none": [], "ends": [LEFT, RIGHT], "right": [RIGHT]}[held]
        self.damage_bcs = [fem.dirichletbc(0.0, fem.locate_dofs_topological(
            A, 1, np.concatenate([tags.find(t) for t in gripped])), A)] if gripped else []
        self.energy = law.energy(self.u, self.alpha, MODEL) * ufl.dx
        self.solver = AlternateMinimization(
            self.energy, self.u, self.alpha, damage_bcs=self.damage_bcs,
            force_scale=law.critical_stress * self.height,
            damage_scale=law.Gc / law.ell * self.h * self.height, acceleration=acceleration)
        self._fracture = fem.form(law.fracture_energy(self.alpha) * ufl.dx)
        self._stability = None

    @property
    def stability(self) -> DamageStability:
        """The second variation on the damage's inactive set (made at its first use)."""
        if self._stability is None:
            self._stability = DamageStability(self.energy, self.u, self.alpha,
                                              self.solver.lower, self.bcs, self.damage_bcs,
                                              density=self.law.Gc / self.law.ell)
        return self._stability

    def stretch(self, strain: float):
        """Minimize at the mean strain `strain` (the right end at strain · L), not committed."""
        self.end.g.x.array[:] = strain * self.length
        return self.solver.solve(self.bcs)

    def stress(self) -> float:
        """σ from the right end's reaction."""
        held = boundary.reactions(self.solver.residual_u, self.u, {"right": self.tags.find(
            RIGHT)}, {"right": [0]}, space=self.V)["right"][0]
        return held / self.height

    def dissipated_energy(self) -> float:
        """∫ (Gc/c_w)(w(α)/ell + ell |∇α|²), per unit thickness."""
        return self.mesh.comm.allreduce(fem.assemble_scalar(self._fracture), op=MPI.SUM)

    def largest_damage(self) -> float:
        """max α over the bar."""
        return global_max(self.mesh.comm, self.alpha.x.array)

    def damage_profile(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, α) along the bottom edge, sorted by x, gathered on every rank."""
        n = self.A.dofmap.index_map.size_local
        x = self.A.tabulate_dof_coordinates()[:n]
        bottom = np.isclose(x[:, 1], 0.0)
        xa = np.concatenate(self.mesh.comm.allgather(
            np.column_stack([x[bottom, 0], self.alpha.x.array[:n][bottom]])))
        xa = xa[np.argsort(xa[:, 0])]
        return xa[:, 0], xa[:, 1]

    @property
    def dofs(self) -> int:
        """Unknowns: the displacement's and the damage's."""
        return self.V.dofmap.index_map.size_global * 2 + self.A.dofmap.index_map.size_global


@dataclass
class PullRecord(AlternateWork):
    """A bar pulled through strains: each converged step, its stability, the solves' work."""

    strain: list[float] = field(default_factory=list)
    stress: list[float] = field(default_factory=list)
    largest_damage: list[float] = field(default_factory=list)
    branch: BranchStability = field(default_factory=BranchStability)
    bifurcation_stress: float | None = None  # on the branch, before leaving it

    @property
    def bifurcation_strain(self) -> float | None:
        """Where the homogeneous branch stopped being stable (`BranchStability`)."""
        return self.branch.bifurcation_load

    @property
    def bifurcation_step(self) -> int | None:
        """The step where the lowest eigenvalue turned negative."""
        return self.branch.bifurcation_step


def pull(bar: GradientBar, strains, *, stability: bool = True, amplitude: float = 0.01
         ) -> PullRecord:
    """Pull `bar` through `strains`, committing each step (the demo's loop).

    With `stability`, the lowest eigenvalue at each step until it turns negative; there the
    bar leaves its branch along the critical mode (α + `amplitude` · β) and the step is
    minimized again from there.

    Args:
        bar: the bar.
        strains: the mean strains of the steps.
        stability: whether the stability is checked.
        amplitude: the critical mode's factor.

    Returns:
        Its record.
    """
    record = PullRecord()
    for strain in strains:
        solves = [bar.stretch(strain)]
        if stability and record.branch.bifurcation_step is None:
            lam, mode = bar.stability.lowest_mode()
            if record.branch.observe(strain, lam, bar.stability.driving_margin()):
                record.bifurcation_stress = bar.stress()
                bar.stability.perturb(mode, amplitude)
                solves.append(bar.solver.solve(bar.bcs))
        bar.solver.commit()
        record.strain.append(float(strain))
        record.stress.append(bar.stress())
        record.largest_damage.append(bar.largest_damage())
        record.count(*solves)
    return record


def crack(law, length: float, cells: int, strains, *, height: float | None = None,
          acceleration: str = "none", comm: MPI.Comm = MPI.COMM_WORLD) -> dict:
    """A crack in the middle of a bar held undamaged at its ends (the demo's mesh table).

    Args:
        law: the gradient damage law.
        length: L.
        cells: cells along the bar (odd: a band of one cell at α = 1 in the middle).
        strains: the mean strains of the steps.
        height: the bar's cross-section (default one cell).
        acceleration: the alternate minimization's.
        comm: the communicator.

    Returns:
        The demo's row (the dissipated energy against Gc (1 + h/(c_w ell)) (AT1), the
        profile against (1 − d/(2 ell))² (AT1) or exp(−d/ell) (AT2), the counts).
    """
    bar = GradientBar(law, length, cells, height=height, held="ends",
                      acceleration=acceleration, comm=comm)
    record = pull(bar, strains, stability=False)
    x, alpha = bar.damage_profile()
    band = x[alpha >= alpha.max() - 1e-9 * max(alpha.max(), 1.0)]
    d = np.min(np.abs(x[:, None] - band[None, :]), axis=1)
    exact = (np.clip(1 - d / (2 * law.ell), 0, 1) ** 2 if law.model == "at1"
             else np.exp(-d / law.ell))
    D = bar.dissipated_energy() / bar.height
    share = law.Gc * (1 + bar.h / (law.c_w * law.ell))
    expected = share if law.model == "at1" else None
    return {"cells": cells, "h": bar.h, "h_over_ell": bar.h / law.ell,
            "dissipated_energy": D * bar.height, "crack_share": share * bar.height,
            "dissipated_energy_expected": expected and expected * bar.height,
            "dissipated_energy_rel_error": expected and D / expected - 1,
            "largest_damage": bar.largest_damage(), "band_width": float(np.ptp(band)),
            "profile_max_error": float(np.max(np.abs(alpha - exact))),
            "profile": {"x": x.tolist(), "damage": alpha.tolist(),
                        "damage_exact": exact.tolist()},
            "final_stress": record.stress[-1], "iterations": sum(record.iterations),
            "newton_iterations": record.newton_iterations,
            "damage_iterations": record.damage_iterations, "cross_section": bar.height,
            "steps": len(record.strain), "dofs": bar.dofs}


def end_crack(law, length: float, cells: int, strains, *, comm: MPI.Comm = MPI.COMM_WORLD
              ) -> float:
    """The dissipated energy, per unit section, of a crack at the free end of a bar.

    Held undamaged at its right end only, the bar cracks at its left end: the half of a
    crack centred on a node. Broken, it has a band of one cell at α = 1 (a P1 bar carries
    no stress only where a whole cell is): Gc/2 (1 + 2h/(c_w ell)) for AT1. Twice it is the
    toughness of a mesh of cells h = length/cells for a crack along a line of nodes.

    Args:
        law: the gradient damage law.
        length: L.
        cells: cells along the bar.
        strains: the mean strains of the steps.
        comm: the communicator.

    Returns:
        D per unit section.
    """
    bar = GradientBar(law, length, cells, held="right", comm=comm)
    pull(bar, strains, stability=False)
    return bar.dissipated_energy() / bar.height


@dataclass
class SurfingRecord(AlternateWork):
    """A surfing crack's steps: the field's centre, the tip, the half strip's dissipation."""

    h: float = 0.0  # the cells' size along the crack's path
    dofs: int = 0
    centre: list[float] = field(default_factory=list)
    tip: list[float] = field(default_factory=list)
    dissipated_energy: list[float] = field(default_factory=list)


def surfing(law, steps: int, *, resolution: float = 4.0, toughness: float | None = None,
            acceleration: str = "none", comm: MPI.Comm = MPI.COMM_WORLD) -> SurfingRecord:
    """The surfing crack of `demos/crack.py`: Irwin's K-field moved by 2h, `steps` + 1 times.

    The half strip [0, 1] x [0, 0.3] cracked along y = 0 up to 0.3 (`surfing_strip`, fine up
    to 3 ell above it), u_y = 0 on y = 0, Irwin's displacement on the other sides with
    K = √(G E/(1 − ν²)).

    Args:
        law: the gradient damage law (plane strain).
        steps: the positions after the first (the notch's tip).
        resolution: ell/h along the crack's path.
        toughness: G, the K-field's release rate (default Gc (1 + h/(c_w ell)), a crack
            inside the mesh; one on the strip's symmetry line has twice its band).
        acceleration: the alternate minimization's.
        comm: the communicator.

    Returns:
        Its record.
    """
    h = law.ell / resolution
    notch, height = 0.3, 0.3
    msh, tags = surfing_strip(comm, h, round(1.0 / h), height=height, notch=notch,
                              fine=3.0 * law.ell)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    A = fem.functionspace(msh, ("Lagrange", 1))
    u, alpha = fem.Function(V), fem.Function(A)
    line = np.concatenate([tags.find(BOTTOM), tags.find(PRECRACK)])
    outer = fem.locate_dofs_topological(V, 1, np.concatenate([tags.find(t)
                                                              for t in (LEFT, TOP, RIGHT)]))
    g = fem.Function(V)
    bcs = [boundary.component(V, 1, line),
           fem.dirichletbc(g, np.setdiff1d(outer, fem.locate_dofs_topological(V, 1, line)))]
    cracked = fem.locate_dofs_topological(A, 1, tags.find(PRECRACK))
    alpha.x.array[cracked] = 1.0
    G = toughness or law.Gc * (1 + h / (law.c_w * law.ell))
    K = math.sqrt(G * law.E / (1 - law.nu**2))
    solver = AlternateMinimization(
        law.energy(u, alpha, MODEL) * ufl.dx, u, alpha, bcs,
        damage_bcs=[fem.dirichletbc(1.0, cracked, A)], force_scale=K * math.sqrt(h),
        damage_scale=law.Gc / law.ell * h**2, acceleration=acceleration)
    fracture = fem.form(law.fracture_energy(alpha) * ufl.dx)
    mu, kappa = law.E / (2 * (1 + law.nu)), 3 - 4 * law.nu
    record = SurfingRecord(h=h, dofs=V.dofmap.index_map.size_global * 2
                           + A.dofmap.index_map.size_global)
    for centre in notch + 2 * h * np.arange(steps + 1):
        def irwin(x, centre=centre):
            r, theta = np.hypot(x[0] - centre, x[1]), np.arctan2(x[1], x[0] - centre)
            amplitude = K / (2 * mu) * np.sqrt(r / (2 * np.pi)) * (kappa - np.cos(theta))
            return np.vstack([amplitude * np.cos(theta / 2), amplitude * np.sin(theta / 2)])

        g.interpolate(irwin)
        record.count(solver.solve())
        solver.commit()
        record.dissipated_energy.append(comm.allreduce(fem.assemble_scalar(fracture),
                                                       op=MPI.SUM))
        record.centre.append(float(centre))
        record.tip.append(crack_tip(alpha, (0.0, 0.0), level=0.5,
                                    where=lambda x: np.isclose(x[1], 0.0))[0])
    return record


def release_rate(record: SurfingRecord, skip: int) -> tuple[float, float]:
    """(2 dD/da, the tip's lag behind the centre): least squares over the steps after `skip`.

    Args:
        record: the surfing crack's.
        skip: the steps left out (before the propagation is steady).

    Returns:
        (2 dD/da, the mean lag).
    """
    tip = np.array(record.tip[skip:])
    slope = np.polyfit(tip, np.array(record.dissipated_energy[skip:]), 1)[0]
    return 2 * slope, float(np.mean(np.array(record.centre[skip:]) - tip))
