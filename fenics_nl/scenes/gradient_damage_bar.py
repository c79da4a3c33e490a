"""A bar in tension with gradient damage (AT1, AT2): homogeneous, unstable, cracked.

The bar is `damage_bar.BarStrip` (plane strain at ν = 0, one cell high: the uniaxial bar),
with a P1 damage field α and the energy of `GradientDamage`, minimized by
`AlternateMinimization` under αⁿ ≤ α ≤ 1 at each prescribed end displacement.

* Free ends (`held_ends=False`): ∇α·n = 0 at both ends, the natural condition, so that a
  uniform bar has a homogeneous solution (the closed form) until it stops being stable
  (`stability`: the second variation on the damage's inactive set).
* Held ends (`held_ends=True`): α = 0 at both ends (the bar is gripped there, undamaged), so
  that the damage starts in the middle and a crack forms there, with its full profile on
  both sides. `held_ends="right"`: the crack forms at the free left end, half a crack on a
  node: the symmetric half of a crack centred on a line of nodes (`end_crack`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.parallel import global_max
from fenics_nl.scenes.damage_bar import BarStrip
from fenics_nl.solvers.alternate import AlternateMinimization, AlternateResult, AlternateWork
from fenics_nl.solvers.damage_stability import DamageStability

__all__ = ["GradientDamageBar", "PullRecord", "crack", "end_crack", "pull"]


class GradientDamageBar(BarStrip):
    """The bar of a `GradientDamage` law, its damage, its solver and its stability check."""

    def __init__(self, law, length: float, cells: int, *, height: float | None = None,
                 held_ends: bool = False, acceleration: str = "none",
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if law.nu != 0:
            raise ValueError("the bar is the course's 1D bar: ν = 0 (uniaxial stress)")
        super().__init__(length, cells, height=height, comm=comm)
        self.law = law
        self.A = A = fem.functionspace(self.mesh, ("Lagrange", 1))
        self.alpha = fem.Function(A, name="damage")
        self.energy = law.energy(self.u, self.alpha, self.MODEL) * ufl.dx
        self.damage_bcs = []
        if held_ends:  # True: both; "right": the right one only
            facets = self.right if held_ends == "right" else np.concatenate([self.left,
                                                                            self.right])
            ends = fem.locate_dofs_topological(A, 1, facets)
            self.damage_bcs = [fem.dirichletbc(0.0, ends, A)]
        self.solver = AlternateMinimization(
            self.energy, self.u, self.alpha, damage_bcs=self.damage_bcs,
            force_scale=law.critical_stress * self.cross_section,
            damage_scale=law.Gc / law.ell * self.h * self.cross_section,
            acceleration=acceleration)
        self._fracture = fem.form(law.fracture_energy(self.alpha) * ufl.dx)
        self._stability = None

    def stretch(self, strain: float) -> AlternateResult:
        """Minimize at the mean strain `strain` (the right end at strain · L), not committed."""
        return self.solver.solve(self.stretch_supports(strain))

    def commit(self) -> None:
        """The converged damage becomes the lower bound of the next steps."""
        self.solver.commit()

    def stress(self) -> float:
        """σ from the right end's reaction."""
        return self.reaction_stress(self.solver.residual_u)

    def dissipated_energy(self) -> float:
        """∫ (Gc/c_w)(w(α)/ell + ell |∇α|²): the energy spent in damage (per unit thickness)."""
        return self.mesh.comm.allreduce(fem.assemble_scalar(self._fracture), op=MPI.SUM)

    def largest_damage(self) -> float:
        """max α over the bar."""
        return global_max(self.mesh.comm, self.alpha.x.array)

    def damage_profile(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, α) along the bottom edge, sorted by x, gathered on every rank."""
        n = self.A.dofmap.index_map.size_local
        x = self.A.tabulate_dof_coordinates()[:n]
        bottom = np.isclose(x[:, 1], 0.0)
        pairs = self.mesh.comm.allgather(np.column_stack([x[bottom, 0],
                                                          self.alpha.x.array[:n][bottom]]))
        xa = np.concatenate(pairs)
        xa = xa[np.argsort(xa[:, 0])]
        return xa[:, 0], xa[:, 1]

    def _checker(self) -> DamageStability:
        if self._stability is None:
            self._stability = DamageStability(self.energy, self.u, self.alpha,
                                              self.solver.lower, self.stretch_supports(0.0),
                                              self.damage_bcs, density=self.law.Gc / self.law.ell)
        return self._stability

    def driving_margin(self) -> float:
        """How far the state is from the damage criterion (`DamageStability.driving_margin`)."""
        return self._checker().driving_margin()

    def stability(self) -> tuple[float, fem.Function | None]:
        """The second variation's smallest eigenvalue on the inactive set, and its mode.

        At the current state, with v = 0 where u is prescribed.
        """
        return self._checker().lowest_mode()

    def perturb(self, mode: fem.Function, amplitude: float) -> None:
        """α + amplitude · mode, kept within αⁿ ≤ α ≤ 1: the start of the next step."""
        a = self.alpha.x.array
        a[:] = np.clip(a + amplitude * mode.x.array, self.solver.lower.x.array, 1.0)


@dataclass
class PullRecord(AlternateWork):
    """A bar pulled through a list of strains: every converged step and its bifurcation.

    The solves' work is counted as `AlternateWork`'s.
    """

    strain: list[float] = field(default_factory=list)
    stress: list[float] = field(default_factory=list)
    largest_damage: list[float] = field(default_factory=list)
    lowest_eigenvalue: list[float] = field(default_factory=list)  # inf: no damage can grow
    bifurcation_strain: float | None = None
    bifurcation_step: int | None = None
    bifurcation_stress: float | None = None  # on the homogeneous branch, before leaving it
    # (strain, driving margin) of the steps where no damage could grow (elastic)
    elastic_margins: list[tuple[float, float]] = field(default_factory=list)
    damage_onset_strain: float | None = None  # where the margin reaches 0, extrapolated


def pull(bar: GradientDamageBar, strains, *, stability: bool = True,
         amplitude: float = 0.01, progress=None) -> PullRecord:
    """Pull `bar` through `strains`, committing each step.

    With `stability`, the second variation's lowest eigenvalue at each step until it turns
    negative. There the bar leaves its branch along the critical mode (α + `amplitude` · β,
    max β = 1) and the step is solved again from there. The bifurcation strain is where the
    eigenvalue crosses 0, by linear interpolation in ε² (exact for the homogeneous bar, whose
    eigenvalue is affine in ε²); if no damage could grow at the step before (AT1 unstable as
    soon as it damages), it is the damage's onset: where the driving margin of the elastic
    steps, affine in ε², reaches 0 (extrapolated from the last two; None with fewer).
    """
    record = PullRecord()
    for k, strain in enumerate(strains):
        solves = [bar.stretch(strain)]
        if stability and record.bifurcation_step is None:
            lam, mode = bar.stability()
            record.lowest_eigenvalue.append(lam)
            if not math.isfinite(lam):
                record.elastic_margins.append((float(strain), bar.driving_margin()))
            elif record.damage_onset_strain is None:
                record.damage_onset_strain = _onset(record.elastic_margins)
            if lam < 0:
                record.bifurcation_step = k
                record.bifurcation_strain = _crossing(record, strain, lam)
                record.bifurcation_stress = bar.stress()
                bar.perturb(mode, amplitude)
                solves.append(bar.stretch(strain))
        bar.commit()
        record.strain.append(float(strain))
        record.stress.append(bar.stress())
        record.largest_damage.append(bar.largest_damage())
        record.count(*solves)
        if progress:
            progress(k, record)
    return record


def _crossing(record: PullRecord, strain: float, lam: float) -> float | None:
    """Where λ crossed 0 between the last step and this one (λ affine in ε²), or the onset."""
    if len(record.strain) == 0 or not math.isfinite(record.lowest_eigenvalue[-2]):
        return record.damage_onset_strain
    e0, l0 = record.strain[-1], record.lowest_eigenvalue[-2]
    return math.sqrt(e0**2 + (strain**2 - e0**2) * l0 / (l0 - lam))


def _onset(margins: list[tuple[float, float]]) -> float | None:
    """The strain where the elastic steps' driving margin, affine in ε², reaches 0."""
    if len(margins) < 2:
        return None
    (e1, m1), (e2, m2) = margins[-2:]
    return math.sqrt(e2**2 + (e2**2 - e1**2) * m2 / (m1 - m2))


def crack(law, length: float, cells: int, strains, *, height: float | None = None,
          acceleration: str = "none", comm: MPI.Comm = MPI.COMM_WORLD) -> dict:
    """A crack in the middle of a bar held undamaged at its ends, pulled through `strains`.

    Its dissipated energy is compared with Gc (1 + h/(c_w ell)) per unit cross-section (AT1;
    AT2 dissipates more, in the damage it spreads before it cracks: no expected value), and
    its damage profile with the closed form.

    With an odd number of cells the middle of the bar is the middle of a cell, whose two
    nodes reach α = 1: a band one cell wide, which dissipates (Gc/c_w)(w(1)/ell) h on top of
    the two half profiles' Gc. The profile on each side, at a distance d from the band,
    is (1 − d/(2 ell))² (AT1) or exp(−d/ell) (AT2).
    """
    bar = GradientDamageBar(law, length, cells, height=height, held_ends=True,
                            acceleration=acceleration, comm=comm)
    record = pull(bar, strains, stability=False)
    x, alpha = bar.damage_profile()
    band = x[alpha >= alpha.max() - 1e-9 * max(alpha.max(), 1.0)]
    d = np.min(np.abs(x[:, None] - band[None, :]), axis=1)
    exact = (np.clip(1 - d / (2 * law.ell), 0, 1) ** 2 if law.model == "at1"
             else np.exp(-d / law.ell))
    D = bar.dissipated_energy() / bar.cross_section
    # the crack's share; AT2 also dissipates in the damage it spreads before cracking
    share = law.Gc * (1 + bar.h / (law.c_w * law.ell))
    expected = share if law.model == "at1" else None
    return {"cells": cells, "h": bar.h, "h_over_ell": bar.h / law.ell,
            "dissipated_energy": D * bar.cross_section,
            "crack_share": share * bar.cross_section,
            "dissipated_energy_expected": expected and expected * bar.cross_section,
            "dissipated_energy_rel_error": expected and D / expected - 1,
            "largest_damage": bar.largest_damage(), "band_width": float(np.ptp(band)),
            "profile_max_error": float(np.max(np.abs(alpha - exact))),
            "profile": {"x": x.tolist(), "damage": alpha.tolist(),
                        "damage_exact": exact.tolist()},
            "final_stress": record.stress[-1], "iterations": sum(record.iterations),
            "newton_iterations": record.newton_iterations,
            "damage_iterations": record.damage_iterations, "cross_section": bar.cross_section,
            "steps": len(record.strain), "dofs": bar.dofs + bar.A.dofmap.index_map.size_global}


def end_crack(law, length: float, cells: int, strains, *, comm: MPI.Comm = MPI.COMM_WORLD
              ) -> float:
    """The dissipated energy, per unit section, of a crack at the free end of a bar.

    The bar is held undamaged at its right end only: the crack forms at its left end, the
    half of a crack centred on a node. Broken, it has a band of one cell at α = 1 (a P1 bar
    carries no stress only where a whole cell is at α = 1): Gc/2 (1 + 2h/(c_w ell)) for AT1.
    Twice it is the toughness of a mesh of cells h = length/cells for a crack along a line
    of nodes (`scenes.surfing`).
    """
    bar = GradientDamageBar(law, length, cells, held_ends="right", comm=comm)
    pull(bar, strains, stability=False)
    return bar.dissipated_energy() / bar.cross_section
