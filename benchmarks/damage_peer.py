"""Gradient damage against a peer: phasefieldx 0.4.1 on Miehe's notched square in tension.

The same specimen, mesh, pre-crack and load steps (`demos/crack.py`'s tension test: the square
[0, 1]² mm, E = 210 kN/mm², ν = 0.3, Gc = 2.7e-3 kN/mm, plane strain, the notch a band of one
cell at α = 1, h = ell/2 where the crack goes, the top moved up in equal steps), AT2 with no
split (the one model both have: phasefieldx's history solver is AT2 only), residual
stiffness 1e-6:

* **ours**: `AlternateMinimization` (as the demo builds it: `Specimen` below),
  irreversibility as a bound αⁿ ≤ α ≤ 1 (SNES
  `vinewtonrsls`), plain and Anderson-accelerated, stopped at max |Δα| < 1e-6;
* **peer**: phasefieldx's staggered solver with Miehe's history field
  (`Element.Phase_Field_Fracture.solver.solver_history.solve`, `irreversibility="miehe"`):
  the damage equation is driven by H = max over the past of ψ0⁺, not bounded; its loop stops
  when the relative L2 increments of u and of the damage are both below 1e-6.

The two are different irreversibility models, so they are compared on what a user reads: the
peak force and where it is, the crack's path (the tip at each step) and the energy
dissipated at the end. Every quantity of both is measured by our functionals on the same
spaces (the peer's u and damage are read at each converged step through a wrapper of its
per-step energy routine; our residual at its state gives its top force), and times are of the
load loop only, after a warm-up run of each that compiles the forms.

Needs the bench extra (`make bench` installs it): `pip install -e ".[bench]"` and
`pip install --no-deps phasefieldx==0.4.1`. phasefieldx imports `scifem`, a compiled extension
that does not build here, only for its two energy-minimizing solvers: the history solver used
here runs without it, so an empty module stands in for it at import time.

    python benchmarks/damage_peer.py [--quick] [--update-docs]
"""

from __future__ import annotations

import contextlib
import io
import sys
import tempfile
import time
import types
from importlib.metadata import version
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from common import machine, options, publish
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.damage_specimens import BOTTOM, NOTCH, TOP, notched_square
from fenics_nl.materials.gradient_damage import GradientDamage, crack_tip
from fenics_nl.solvers.alternate import AlternateMinimization, AlternateWork

sys.modules.setdefault("scifem", types.ModuleType("scifem"))  # see the docstring
try:
    import dolfinx.log
    from phasefieldx.Element.Phase_Field_Fracture.Input import Input as PeerInput
    from phasefieldx.Element.Phase_Field_Fracture.solver import solver_history as peer
except ImportError as err:
    raise SystemExit("benchmarks/damage_peer.py needs the bench extra: pip install -e "
                     "'.[bench]' && pip install --no-deps phasefieldx==0.4.1") from err

E, NU, GC, K = 210.0, 0.3, 2.7e-3, 1e-6
TOL = 1e-6


def law(ell):
    return GradientDamage(E, NU, Gc=GC, ell=ell, model="at2", residual_stiffness=K)


def say(msg):
    if MPI.COMM_WORLD.rank == 0:
        print(msg, flush=True)


class Specimen:
    """Miehe's notched square in tension, as `demos/crack.py` builds it (h = ell/2)."""

    def __init__(self, ell: float, acceleration: str = "anderson"):
        self.law = a = law(ell)
        h = ell / 2
        msh, cells, facets = notched_square(MPI.COMM_WORLD, h, "tension", width=3 * ell)
        self.mesh, self.notch_tip = msh, np.array([0.5, 0.5])
        self.V = V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
        self.A = A = fem.functionspace(msh, ("Lagrange", 1))
        self.u, self.alpha = fem.Function(V), fem.Function(A)
        self.top = facets.find(TOP)
        self.top_bc = boundary.component(V, 1, self.top)  # the top moved up
        self.bcs = [boundary.fixed(V, facets.find(BOTTOM)), self.top_bc,
                    boundary.component(V, 0, self.top)]
        msh.topology.create_connectivity(2, 2)  # the cells' own entities, to locate dofs
        cracked = fem.locate_dofs_topological(A, 2, cells.find(NOTCH))
        self.alpha.x.array[cracked] = 1.0
        self.precrack = fem.dirichletbc(1.0, cracked, A)
        self.solver = AlternateMinimization(
            a.energy(self.u, self.alpha, "plane_strain") * ufl.dx, self.u, self.alpha,
            self.bcs, damage_bcs=[self.precrack], force_scale=a.critical_stress * h,
            damage_scale=a.Gc / a.ell * h**2, tol=TOL, max_it=2000, acceleration=acceleration)
        self._fracture = fem.form(a.fracture_energy(self.alpha) * ufl.dx)
        self._residual = fem.form(self.solver.residual_u)
        self.dofs = V.dofmap.index_map.size_global * 2 + A.dofmap.index_map.size_global

    def load(self, loads) -> tuple[AlternateWork, list, list, list]:
        """The demo's steps: (the work, the top's force, the tip, D at each step)."""
        work, force, tips, dissipated = AlternateWork(), [], [], []
        for U in loads:
            self.top_bc.g.x.array[:] = U
            work.count(self.solver.solve())
            self.solver.commit()
            force.append(self.force())
            tips.append(self.tip())
            dissipated.append(self.dissipated_energy())
        return work, force, tips, dissipated

    def force(self) -> float:
        """The top's reaction along its motion, per unit thickness."""
        return boundary.reactions(self._residual, self.u, {"top": self.top})["top"][1]

    def tip(self) -> list[float]:
        """The broken node (α >= 0.9) ahead of the notch farthest from its tip."""
        return crack_tip(self.alpha, self.notch_tip, level=0.9,
                         where=lambda x: x[0] > 0.5 + 1e-9)

    def dissipated_energy(self) -> float:
        """∫ (Gc/c_w)(w(α)/ell + ell |∇α|²), per unit thickness."""
        return self.mesh.comm.allreduce(fem.assemble_scalar(self._fracture), op=MPI.SUM)


def crack_line(specimen: Specimen) -> np.ndarray:
    """(x, y) of the crack ahead of the notch: on each column of nodes, the most damaged."""
    n = specimen.A.dofmap.index_map.size_local
    x = specimen.A.tabulate_dof_coordinates()[:n, :2]
    xya = np.vstack(specimen.mesh.comm.allgather(
        np.column_stack([x, specimen.alpha.x.array[:n]])))
    ahead = xya[xya[:, 0] > specimen.notch_tip[0] + 1e-9]
    order = np.lexsort((-ahead[:, 2], np.round(ahead[:, 0], 12)))  # by column, most first
    columns, first = np.unique(np.round(ahead[order, 0], 12), return_index=True)
    return np.column_stack([columns, ahead[order[first], 1]])


def summary(specimen: Specimen, loads, force, tips, dissipated, seconds, **extra):
    k = int(np.argmax(force))
    line = crack_line(specimen)
    return {"time_s": seconds, "peak_force": force[k], "peak_displacement": float(loads[k]),
            "force_history": force, "crack_tip_history": tips,
            "dissipated_energy": dissipated[-1], "dissipated_energy_history": dissipated,
            "final_tip": tips[-1], "crack_line": line.tolist(),
            "crack_offset": float(np.abs(line[:, 1] - specimen.notch_tip[1]).max()),
            "dofs": specimen.dofs, **extra}


def ours(ell, loads, acceleration) -> dict:
    """`Specimen.load`: alternate minimization, the damage bounded."""
    Specimen(ell, acceleration).load(loads[:1])
    specimen = Specimen(ell, acceleration)
    t0 = time.perf_counter()
    work, force, tips, dissipated = specimen.load(loads)
    seconds = time.perf_counter() - t0
    return summary(specimen, loads, force, tips, dissipated, seconds, scheme=acceleration,
                   alternate_iterations=work.iterations,
                   newton_iterations=work.newton_iterations,
                   damage_iterations=work.damage_iterations)


def phasefieldx(ell, loads, folder: Path) -> dict:
    """phasefieldx's history solver on a fresh specimen's mesh, spaces, supports, pre-crack."""
    specimen = Specimen(ell)
    states = []  # (u, damage, the time it converged) of each step

    def move_top(bcs, t):
        specimen.top_bc.g.x.array[:] = loads[round(t)]
        return 0.0, float(loads[round(t)]), 0.0

    energies = peer.compute_total_energies

    def converged(u, phi, *args, **kwargs):  # called once per step, after its loop
        states.append((u.x.array.copy(), phi.x.array.copy(), time.perf_counter()))
        return energies(u, phi, *args, **kwargs)

    data = PeerInput(E=E, nu=NU, Gc=GC, l=ell, degradation="isotropic",
                            split_energy="no", degradation_function="quadratic",
                            irreversibility="miehe", fatigue=False, k=K,
                            save_solution_xdmf=False, save_solution_vtu=False,
                            results_folder_name=str(folder / "results"))
    peer.compute_total_energies = converged
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # its "deleted ..." lines
            peer.solve(data, specimen.mesh, float(len(loads)), specimen.V, specimen.A,
                       bc_list_u=specimen.bcs, bc_list_phi=[specimen.precrack],
                       update_boundary_conditions=move_top, dt=1.0, path=str(folder),
                       bcs_list_u_names=["bottom", "top", "top_x"],
                       max_stagger_iter=10000, stagger_error_tol=TOL)
    finally:
        peer.compute_total_energies = energies
        dolfinx.log.set_log_level(dolfinx.log.LogLevel.WARNING)  # it leaves INFO
    seconds = time.perf_counter() - t0
    force, tips, dissipated = [], [], []
    for u, phi, _ in states:  # its states, measured as ours are
        specimen.u.x.array[:] = u
        specimen.alpha.x.array[:] = phi
        force.append(specimen.force())
        tips.append(specimen.tip())
        dissipated.append(specimen.dissipated_energy())
    stagger = np.loadtxt(folder / "results" / "phasefieldx.conv", skiprows=1, ndmin=2)
    return summary(specimen, loads, force, tips, dissipated, seconds, scheme="phasefieldx",
                   staggered_iterations=stagger[:, 1].astype(int).tolist())


def compare(ell, steps, final):
    loads = np.linspace(0.0, final, steps + 1)[1:]
    rows = [ours(ell, loads, "none"), ours(ell, loads, "anderson")]
    with tempfile.TemporaryDirectory() as warm, tempfile.TemporaryDirectory() as run:
        phasefieldx(ell, loads[:1], Path(warm))
        rows.append(phasefieldx(ell, loads, Path(run)))
    peer_run = rows[-1]
    for r in rows:  # the peer's path against each: force and tip at every step
        df = np.abs(np.array(r["force_history"]) - peer_run["force_history"])
        dtip = np.abs(np.array(r["crack_tip_history"])[:, 0]
                      - np.array(peer_run["crack_tip_history"])[:, 0])
        r["force_difference"] = float(df.max() / peer_run["peak_force"])
        r["tip_distance"] = float(dtip.max())  # along the ligament: the crack's length
    for r in rows:
        r["ell"], r["steps"] = ell, steps
        say(f"ell = {ell}: {r['scheme']:11s} {r['time_s']:7.2f} s, {iterations(r):>15s}, peak "
            f"{r['peak_force']:.4f} kN at {r['peak_displacement']:.4g} mm, tip "
            f"({r['final_tip'][0]:.3f}, {r['final_tip'][1]:.3f}), D {r['dissipated_energy']:.5g}")
    return rows


def iterations(r) -> str:
    """A row's iterations over the steps: ours alternate, the peer's staggered."""
    if "alternate_iterations" in r:
        return f"{sum(r['alternate_iterations'])} alternate"
    return f"{sum(r['staggered_iterations'])} staggered"


def table(out):
    lines = ["| ell (mm) | solver | iterations | time (s) | peak force (kN) | at U (mm) "
             "| crack's offset (mm) | dissipated (kN mm/mm) | vs phasefieldx: force, tip |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        name = {"none": "ours, plain", "anderson": "ours, Anderson"}.get(r["scheme"],
                                                                         "phasefieldx")
        lines.append(f"| {r['ell']:g} | {name} | {iterations(r)} | {r['time_s']:.1f} | "
                     f"{r['peak_force']:.4f} | {r['peak_displacement']:.4g} | "
                     f"{r['crack_offset']:.3f} | "
                     f"{r['dissipated_energy']:.5g} | {100 * r['force_difference']:.1f} %, "
                     f"{r['tip_distance']:.3f} mm |")
    lines.append("")
    lines.append(f"Miehe's notched square in tension, AT2 without split, the same mesh "
                 f"(h = ell/2 where the crack goes), pre-crack and {out['rows'][0]['steps']} "
                 f"equal steps; phasefieldx {out['peer_version']} (its history field) against "
                 f"ours (the damage bounded); times of the load loop, "
                 f"{out['machine']['cores']} cores, 1 rank. The crack's offset: how far from "
                 f"the notch's line the most damaged node of each column ahead of the notch "
                 f"is, at the last step (0: a straight crack). The last column: the largest "
                 f"difference over the steps of the top force (of the peer's peak) and of the "
                 f"crack's length (its tip's x, the tip the broken node, α >= 0.9, farthest "
                 f"from the notch's).")
    return "\n".join(lines)


def main():
    args = options(__doc__, "ell = 0.05 mm only, nothing written")
    out = {"machine": machine(), "peer_version": version("phasefieldx"), "rows": []}
    for ell in (0.05,) if args.quick else (0.05, 0.03, 0.015):
        out["rows"] += compare(ell, 13, 6.5e-3)
    publish("damage_peer", out, table, args, say)


main()
