"""Forming at finite strain: the upsetting's Newton variants and size, the necking bar's mesh.

A. The upsetting (`demos/upsetting.py`'s problem written again from the same pieces, 50 %,
   20 steps), frictionless and f = 0.2,
   with full Newton, modified Newton (the elastic tangent of the configuration each solve
   starts from: the course's choice at finite strain, refactorized per solve) and BFGS on
   it: Newton iterations, factorizations, active-set iterations, time, the time per step
   in linear solves of the same mesh (one MUMPS factorization and solve of the elastic
   tangent), the force and its difference from full Newton's.
B. The size: the f = 0.2 upsetting on a fine mesh, 1 rank and 2 ranks (mpiexec of the
   demo), its wall time and unknowns.
C. Simo's necking bar (`NeckingBar` below, each end pulled 7 mm in 50 steps, radially
   free as in ANSYS VM318) on meshes of 4, 8, 16 and 32 cells across the radius, and 8
   gripped: the peak force against Considère's for the neck section, the neck radius r/r0
   at 4, 5, 6 and 7 mm a end against the published ones (Simo & Hughes 1998 as digitized in
   syadegari/fe_solver verification/j2_formulation_study/circular_necking_reference.csv,
   ±0.1 mm; ANSYS VM318: u_r = −3.740 mm at 7 mm), time.

Writes benchmarks/results/forming.json and, with --update-docs, its section of
docs/benchmarks.md.
"""

import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from common import machine, options, publish
from dolfinx import fem
from mpi4py import MPI
from scipy.optimize import brentq

from fenics_nl.contact import ActiveSetContact, FrictionalContact
from fenics_nl.domain import boundary
from fenics_nl.domain.axisymmetric import billet, narrowed_bar
from fenics_nl.domain.probes import Probes
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.materials.mixed import unknowns
from fenics_nl.solvers.form_matrix import FormMatrix
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

ROOT = Path(__file__).resolve().parents[1]
MODEL = "axisymmetric"
# ("consistent": friction's slip forces in Newton's iteration, `FrictionalContact`; False:
# point forces from the last solve's normal forces, the loop of issue 60's "before")
VARIANTS = {"full": {"method": "full"},
            "full, no sense at touchdown": {"method": "full", "sense_at_touchdown": False},
            "full, point forces": {"method": "full", "consistent": False},
            "modified": {"method": "modified", "max_it": 300},
            "bfgs": {"method": "bfgs", "max_it": 300}}


def say(msg):
    if MPI.COMM_WORLD.rank == 0:
        print(msg, flush=True)


def linear_solve_time(residual, u, bcs) -> float:
    """One assembly, factorization and solve of the elastic tangent at rest (MUMPS)."""
    from petsc4py import PETSc

    K = fem.form(ufl.derivative(residual, u))
    t0 = time.perf_counter()
    matrix = FormMatrix(K)  # the solvers' own assembly
    matrix.assemble(K, bcs)
    A = matrix.mat
    ksp = PETSc.KSP().create(u.function_space.mesh.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    x, rhs = A.createVecs()
    rhs.set(1.0)
    ksp.solve(rhs, x)
    return time.perf_counter() - t0


def upset(cells, friction, variant):
    """The billet R0 = 10, h0 = 20 of demos/upsetting.py (P2, its defaults' material and die)
    to 50 % in 20 steps, with the Newton `variant` in the active set's solves."""
    R0, h0 = 10.0, 20.0
    mesh_data = billet(MPI.COMM_WORLD, R0, h0, cells=cells)
    msh = mesh_data.mesh

    def tagged(name):
        return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)

    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    supports = [boundary.component(V, 0, tagged("axis")),
                boundary.component(V, 1, tagged("mid"))]
    law = FiniteJ2Plasticity(200e3, 0.3, sigma0=400.0, H=1000.0)
    law.bind(msh, 4)
    residual = law.internal_work(u, ufl.TestFunction(V), MODEL) * kinematics.quadrature_measure(
        "dx", msh, 4)

    def die_gap(reduction):  # the die's height above each node
        return lambda x: 0.5 * h0 * (1.0 - reduction) - x[1]

    newton = {"method": "full", "rtol": 1e-10, "atol": 1e-10, "force_scale": law.sigma0 * R0**2,
              "max_it": 30, "divergence_tol": 100.0, "line_search": True,
              "reuse_factorization": False, **VARIANTS[variant]}
    rule = {"consistent": newton.pop("consistent", None),
            "sense_at_touchdown": newton.pop("sense_at_touchdown", True)}
    on_die = {"normal_axis": 1, "initial": "penetrating", "newton_options": newton,
              "prefix": "upsetting_"}
    S_C = np.union1d(tagged("top"), tagged("side"))
    if friction > 0:
        contact = FrictionalContact(residual, u, supports, S_C, die_gap(0.0), friction=friction,
                                    **rule, **on_die)
    else:
        contact = ActiveSetContact(residual, u, supports, S_C, die_gap(0.0), **on_die)

    def commit():
        law.commit(u, MODEL)
        if friction > 0:
            contact.commit()

    one_solve = linear_solve_time(residual, u, supports)
    dofs = output.dofs(V)
    t0 = time.perf_counter()
    try:
        path = solve_incrementally(contact, lambda t: contact.set_gap(die_gap(0.5 * t)), 20,
                                   max_step=0.05, easy_iterations=10**9, commit=commit,
                                   restore=contact.restore if friction > 0 else None)
    except LoadStepError as err:  # a variant that cannot do it: said in the table
        return {"problem": f"upsetting f = {friction:g}", "variant": variant,
                "dofs": dofs, "failed": str(err).split(";")[0]}
    elapsed = time.perf_counter() - t0
    steps = len(path.results)
    return {"problem": f"upsetting f = {friction:g}", "variant": variant,
            "dofs": dofs, "time_s": elapsed, "steps": steps,
            "step_cuts": path.failures, "newton_iterations": path.iterations,
            "factorizations": path.work.factorizations,
            "status_iterations": sum(r.active_set_iterations for r in path.results),
            "linear_solves": path.work.linear_solves,
            "point_force_steps": getattr(contact, "fallbacks", 0),
            "linear_solve_s": one_solve,
            "step_in_linear_solves": elapsed / steps / one_solve, "force": contact.force}


def variants(quick):
    rows = []
    for friction in (0.0, 0.2):
        for variant in VARIANTS:
            if friction == 0 and variant.startswith("full, "):  # (no slip force)
                continue
            r = upset(6 if quick else 12, friction, variant)
            rows.append(r)
            if "failed" in r:
                say(f"{r['problem']:18s} {variant:9s} failed: {r['failed']}")
                continue
            say(f"{r['problem']:18s} {variant:9s} {r['dofs']:6d} dofs {r['time_s']:7.2f} s "
                f"{r['newton_iterations']:5d} Newton {r['factorizations']:4d} LU "
                f"{r['status_iterations']:4d} statuses, "
                f"{r['linear_solves'] / r['steps']:.1f} linear solves a step (its time "
                f"{r['step_in_linear_solves']:.1f} of one), F = {r['force']:.8g}")
    return rows


def demo_run(cells, ranks):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "u.json"
        cmd = [str(ROOT / ".venv" / "bin" / "mpiexec"), "-n", str(ranks), sys.executable,
               str(ROOT / "demos" / "upsetting.py"), "--cells", str(cells), "--json", str(out)]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        return json.loads(out.read_text())


def size_runs(quick):
    cells = 12 if quick else 56
    rows = []
    for ranks in (1, 2):
        d = demo_run(cells, ranks)
        rows.append({"cells": cells, "ranks": ranks, "dofs": d["dofs"],
                     "wall_time_s": d["wall_time_s"], "solve_time_s": d["solve_time_s"],
                     "newton_iterations": d["newton_iterations"],
                     "status_iterations": d["status_iterations"],
                     "linear_solves": d["linear_solves"], "step_cuts": d["step_cuts"],
                     "point_force_steps": d["point_force_steps"], "force": d["force"]})
        say(f"upsetting f = 0.2, {d['dofs']} dofs, {ranks} rank(s): {d['wall_time_s']:.1f} s, "
            f"F = {d['force']:.8g}")
    return rows


# Simo's necking bar (1988, 1992): a bar of radius r0 = 6.413 mm and length L0 = 53.334 mm,
# narrowed linearly to 0.982 r0 at mid-length (the imperfection that fixes where the neck
# forms), pulled at both ends. Units: N, mm, MPa.
RADIUS, LENGTH, NARROWING = 6.413, 53.334, 0.982


def simo_material(nu: float = 0.29) -> FiniteJ2Plasticity:
    """Steel-like, Voce hardening with a linear part: E = 206.9 GPa, σ_y = 450 + 129.24 p
    + (715 − 450)(1 − exp(−16.93 p)) MPa."""
    return FiniteJ2Plasticity(206.9e3, nu, sigma0=450.0, H=129.24, saturation=715.0,
                              delta=16.93)


class NeckingBar:
    """The quarter 0 < r < R(z), 0 < z < L0/2 of the (r, z) plane, J2 at finite strain.

    The axis (u_r = 0), the mid-plane (u_z = 0), the end z = L0/2 moved along z by half the
    elongation, radially free as in ANSYS VM318 (`gripped`: held radially too). `cells`
    across the radius and about 4.2 times as many along the half length, graded towards
    the neck (`domain.axisymmetric.narrowed_bar`; `grading` 1: uniform). P2 displacements,
    or Taylor–Hood with `mixed`; full Newton with a line search.
    """

    def __init__(self, cells: int = 4, *, grading: float = 3.0, mixed: bool = True,
                 nu: float = 0.29, gripped: bool = False, comm: MPI.Comm = MPI.COMM_WORLD):
        mesh_data = narrowed_bar(comm, RADIUS, LENGTH, NARROWING, cells, grading)
        msh = mesh_data.mesh

        def tagged(name):
            return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)

        self.fields = f = unknowns(msh, 2, mixed)
        self.unknown, self.u, V = f.w, f.u, f.V
        self.mid = tagged("mid")
        self.pull = boundary.component(V, 1, tagged("end"), 0.0)
        bcs = [boundary.component(V, 0, tagged("axis")), boundary.component(V, 1, self.mid),
               self.pull]
        if gripped:  # the end held radially too (else only pulled along z, as VM318)
            bcs.append(boundary.component(V, 0, tagged("end")))
        self.material = simo_material(nu)
        self.material.bind(msh, 4)
        self.residual = f.internal_work(self.material, MODEL) * kinematics.quadrature_measure(
            "dx", msh, 4)
        self._residual_form = fem.form(self.residual)
        self.V = V
        self.solver = NewtonSolver(self.residual, self.unknown, bcs, rtol=1e-10, atol=1e-10,
                                   force_scale=450.0 * RADIUS**2, max_it=25, line_search=True,
                                   prefix="necking_")
        self.probes = Probes(msh, [[RADIUS * NARROWING, 0.0]])  # the neck's surface
        self.dofs = output.dofs(self.unknown.function_space)

    def set_elongation(self, elongation: float) -> None:
        """Move the end by half the total `elongation` (both ends pulled)."""
        self.pull.g.x.array[:] = 0.5 * elongation

    def commit(self) -> None:
        """The material's state after a converged step."""
        self.material.commit(self.u, MODEL)

    def force(self) -> float:
        """The bar's tension: the mid-plane's reaction (the whole section)."""
        return boundary.reactions(self._residual_form, self.unknown, {"mid": self.mid},
                                  {"mid": [1]}, space=self.V)["mid"][1] * -1.0

    def neck_radius(self) -> float:
        """The current radius of the mid-plane section."""
        return RADIUS * NARROWING + self.probes.continuous(self.fields.displacement())[0][0]


# r/r0 at 4, 5, 6 mm a end (Simo & Hughes, digitized to 0.1 mm) and 7 mm (ANSYS VM318)
PUBLISHED = {4.0: 5.3 / RADIUS, 5.0: 4.6 / RADIUS, 6.0: 3.7 / RADIUS,
             7.0: (RADIUS * NARROWING - 3.740) / RADIUS}


def considere_force() -> float:
    """The neck section's largest force in uniaxial rigid plasticity: σ_y(p) A e^(−p) at
    dσ_y/dp = σ_y (Considère)."""
    law = simo_material()
    p = brentq(lambda q: (law.H + law.delta * (law.saturation - law.sigma0)
                          * math.exp(-law.delta * q)) - law.yield_stress(q),
               1e-3, 2.0)
    return law.yield_stress(p) * math.pi * (RADIUS * NARROWING) ** 2 \
        * math.exp(-p)


def necking_runs(quick):
    rows = []
    meshes = [(4, False), (8, False)] if quick else [(4, False), (8, False), (16, False),
                                                     (32, False), (8, True)]
    for cells, gripped in meshes:
        bar = NeckingBar(cells, mixed=False, gripped=gripped)
        forces, ends, radii = [], [0.0], [NARROWING]
        t0 = time.perf_counter()

        def on_step(t, result, b=bar, f=forces, e=ends, r=radii):
            f.append(b.force())
            e.append(7 * t)
            r.append(b.neck_radius() / RADIUS)

        try:
            path = solve_incrementally(bar.solver, lambda t, b=bar: b.set_elongation(14 * t),
                                       50, max_step=0.02, commit=bar.commit, on_step=on_step)
        except LoadStepError as err:  # said in the table, the other meshes still run
            rows.append({"cells": cells, "gripped": gripped, "dofs": bar.dofs,
                         "failed": str(err).split(";")[0]})
            say(f"necking bar, {cells} cells: failed: {rows[-1]['failed']}")
            continue
        r = {"cells": cells, "gripped": gripped, "dofs": bar.dofs,
             "time_s": time.perf_counter() - t0, "steps": len(path.results),
             "newton_iterations": path.iterations, "peak_force_kN": max(forces) / 1e3,
             "final_force_kN": forces[-1] / 1e3,
             "radius_ratio": {str(u): float(np.interp(u, ends, radii)) for u in PUBLISHED}}
        say(f"necking bar, {cells} cells{' gripped' if gripped else ''} ({r['dofs']} dofs): "
            f"peak {r['peak_force_kN']:.3f} kN, r/r0 {r['radius_ratio']}, "
            f"{r['time_s']:.1f} s")
        rows.append(r)
    return rows


def table(out):
    lines = ["| problem | variant | unknowns | Newton its | linear solves a step | "
             "factorizations | status its | time (s) | a step's time, in linear solves | "
             "force | vs full |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    full = {}
    for r in out["variants"]:
        if r["variant"] == "full":
            full[r["problem"]] = r
        f = full[r["problem"]]
        if "failed" in f and "failed" not in r:  # no reference to compare with
            f = r
        if "failed" in r:
            lines.append(f"| {r['problem']} | {r['variant']} | {r['dofs']} | failed: "
                         f"{r['failed']} | | | | | | | |")
            continue
        lines.append(f"| {r['problem']} | {r['variant']} | {r['dofs']} | "
                     f"{r['newton_iterations']} | {r['linear_solves'] / r['steps']:.1f} | "
                     f"{r['factorizations']} | "
                     f"{r['status_iterations']} | {r['time_s']:.2f} (×"
                     f"{r['time_s'] / f['time_s']:.2f}) | {r['step_in_linear_solves']:.1f} | "
                     f"{r['force']:.7g} | {abs(r['force'] / f['force'] - 1):.1e} |")
    lines += ["", "| upsetting f = 0.2 (the demo) | unknowns | ranks | wall time (s) | solve (s) "
              "| Newton its | status its | linear solves a load step (of 20, cuts included) "
              "| step cuts | steps with point forces | solve time / linear solves (s) | force |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in out["size"]:
        lines.append(f"| {r['cells']} cells | {r['dofs']} | {r['ranks']} | "
                     f"{r['wall_time_s']:.1f} | {r['solve_time_s']:.1f} | "
                     f"{r['newton_iterations']} | {r['status_iterations']} | "
                     f"{r['linear_solves'] / 20:.1f} | {r['step_cuts']} | "
                     f"{r['point_force_steps']} | "
                     f"{r['solve_time_s'] / r['linear_solves']:.3f} | {r['force']:.7g} |")
    head = " | ".join(f"r/r0 at {u:g} mm" for u in PUBLISHED)
    lines += ["", f"| necking bar | unknowns | peak force (kN) | {head} | Newton its | time (s) |",
              "|---|---|---|" + "---|" * len(PUBLISHED) + "---|---|",
              f"| published | | {out['considere_force_kN']:.2f} (Considère, neck section) | "
              + " | ".join(f"{v:.3f}" for v in PUBLISHED.values()) + " | | |"]
    for r in out["necking"]:
        if "failed" in r:
            lines.append(f"| {r['cells']} cells | {r['dofs']} | failed: {r['failed']} |")
            continue
        ratios = " | ".join("" if v is None else f"{v:.3f}" for v in r["radius_ratio"].values())
        lines.append(f"| {r['cells']} cells{', gripped' if r['gripped'] else ''} | {r['dofs']} "
                     f"| {r['peak_force_kN']:.3f} | {ratios} | {r['newton_iterations']} | "
                     f"{r['time_s']:.1f} |")
    lines.append("")
    lines.append("Upsetting: R0 = 10, h0 = 20 to 50 % in 20 steps (cut when a step fails), "
                 "P2. Modified Newton keeps the elastic tangent of the configuration each "
                 "inner solve starts from. Necking bar: P2 displacement formulation, graded "
                 "mesh, 50 steps; the Taylor–Hood form does not pass the force peak yet "
                 f"(Newton stalls there). {out['machine']['cores']} cores.")
    return "\n".join(lines)


def main():
    args = options(__doc__, "small meshes, nothing written")
    out = {"machine": machine(), "considere_force_kN": considere_force() / 1e3,
           "variants": variants(args.quick),
           "size": size_runs(args.quick), "necking": necking_runs(args.quick)}
    publish("forming", out, table, args, say)


if __name__ == "__main__":
    main()
