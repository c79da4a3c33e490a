"""What the bracket demo reports: step records, the JSON, the variants' table, pictures.

`demos/bracket.py` tells the story (the part, the material, the residual, the Newton
variant and its load steps, equilibrium); the records and outputs of a run live here.
"""

from __future__ import annotations

import math
import resource

import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.io import cli, pictures
from fenics_nl.io.cli import say
from fenics_nl.materials.laws import PowerLaw
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.parallel import global_max

__all__ = ["DEFAULT_SIZE_MM", "MM", "StepRecord", "comparison", "say_result", "summary",
           "writers"]

MM = {"mm": 1.0, "m": 1e-3}  # the length of 1 mm in the chosen unit
DEFAULT_SIZE_MM = 6.0  # P2: |u_load| 3.7 % below the extrapolated value (benchmarks page)


class StepRecord:
    """The `on_step` of `solve_incrementally` for one Newton variant: a record per step.

    Each converged step's force, load-point displacement and work, kept in `steps`, in
    the JSON's converged steps (its fields written by --output) and said in one line.
    Steps after the `loading_steps` unload: their force goes back down.
    """

    def __init__(self, bracket, newton: str, force: float, loading_steps: int,
                 total_steps: int, units: str, fields):
        self.b, self.newton, self.force, self.units = bracket, newton, force, units
        self.loading_steps, self.total_steps, self.fields = loading_steps, total_steps, fields
        self.steps: list[dict] = []

    def __call__(self, t, r) -> None:
        """Keep and say the step just converged at load factor `t` (result `r`)."""
        if len(self.steps) >= self.loading_steps:  # unloading
            t = 1.0 - t
        self.steps.append({"force": t * self.force,
                           "load_point_displacement": self.b.load_point_displacement(),
                           "newton_iterations": r.iterations,
                           "active_set_iterations": r.active_set_iterations,
                           "factorizations": r.work.factorizations,
                           "tangent_assemblies": r.work.tangent_assemblies,
                           "krylov_iterations": r.work.krylov_iterations,
                           "residual_norms": list(r.residual_norms)})
        cli.converged_step({"load_factor": t, **self.steps[-1]}, fields=self.fields)
        sets = (f" in {r.active_set_iterations} active-set iterations"
                if r.active_set_iterations else "")
        say(f"  {self.newton}: step {len(self.steps)}/{self.total_steps}, F = "
            f"{t * self.force:.4g} N, {r.iterations} Newton iterations{sets}, |u_load| = "
            f"{self.steps[-1]['load_point_displacement']:.6g} {self.units}")


def summary(b, steps: list[dict], wall: float, args) -> tuple[dict, fem.Function]:
    """The JSON of one variant's run, and its σ_eq field (for the picture)."""
    comm = b.part.mesh.comm
    vm = b.von_mises()
    vm_max = global_max(comm, vm.x.array)
    mat = b.material
    out = {
        "support": args.support, "force": args.force, "length_unit": args.units,
        "load_point_displacement": steps[args.steps - 1]["load_point_displacement"],
        "max_von_mises": vm_max,
        "newton_iterations": sum(s["newton_iterations"] for s in steps),
        "factorizations": sum(s["factorizations"] for s in steps),
        "tangent_assemblies": sum(s["tangent_assemblies"] for s in steps),
        "krylov_iterations": sum(s["krylov_iterations"] for s in steps),
        "residual_norms": steps[-1]["residual_norms"],
        "steps": [{k: v for k, v in s.items() if k != "residual_norms"} for s in steps],
        "reactions": b.reactions(),
        "largest_cell": b.largest_cell,
        "dofs": b.dofs, "ranks": comm.size, "solve_time_s": wall,
        "peak_memory_mb": comm.allreduce(
            resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.MAX),
        "warnings": resolution_warnings(args),
    }
    if isinstance(mat, PowerLaw):
        # σ_eq = σ0 x (1 + x²)^((n−1)/2), x = ε_eq/ε0: invert for the peak strain
        out["max_eps_eq_over_eps0"] = _strain_ratio(vm_max / mat.sigma0, mat.n)
    if isinstance(mat, J2Plasticity):
        out.update(plastic_zone(mat, b.part))
    if args.unload:  # what the load leaves behind
        out["permanent_load_point_displacement"] = steps[-1]["load_point_displacement"]
        out["warnings"].append("unloaded: max_von_mises and the reactions are those of the "
                               "residual state")
    if args.support == "contact":
        c = b.solver
        out["lifted_off_area"], out["contact_area"] = b.floor_areas()
        out["active_set_iterations"] = sum(s["active_set_iterations"] for s in steps)
        out["max_floor_pressure"] = global_max(comm, c.pressure()[c.active])
        if args.friction is not None:  # Coulomb on the whole floor: |T_t| <= f T_n
            fx, fy, fz = out["reactions"]["base"]
            out.update(friction=args.friction, stick_nodes=c.surface.count(c.stick),
                       slip_nodes=c.surface.count(c.slip),
                       floor_friction_ratio=math.hypot(fx, fy) / (args.friction * fz)
                       if args.friction > 0 and fz > 0 else 0.0)
    return out, vm


def resolution_warnings(args) -> list[str]:
    """What the mesh cannot promise (the convergence checks: the benchmarks page)."""
    notes = ["no closed form for this part: |u_load| is checked by mesh convergence "
             "(docs/benchmarks.md), σ_eq peaks at the singular clamped bolt-hole edges"]
    if args.mesh:
        notes.append(f"user mesh {args.mesh}: its resolution is not checked")
    elif args.size is not None and args.size / MM[args.units] > DEFAULT_SIZE_MM:
        notes.append(f"elements coarser than the default {DEFAULT_SIZE_MM:g} mm: |u_load| is "
                     f"more than 4 % below its converged value (measured: -5 % at 10 mm, "
                     f"-10 % at 20 mm)")
    if args.degree == 1:
        notes.append("P1 tetrahedra lock in this bending problem (about half the displacement)")
    return notes


def plastic_zone(mat: J2Plasticity, part) -> dict:
    """The largest cumulated plastic strain and the plastic fraction of the volume."""
    comm = part.mesh.comm
    pq = mat.cumulated_plastic_strain
    n = pq.function_space.dofmap.index_map.size_local
    volume, plastic_volume = (comm.allreduce(fem.assemble_scalar(fem.form(f * part.dx)))
                              for f in (1.0, ufl.conditional(ufl.gt(pq, 0), 1.0, 0.0)))
    return {"max_cumulated_plastic_strain": global_max(comm, pq.x.array[:n]),
            "plastic_volume_fraction": plastic_volume / volume}


def _strain_ratio(s: float, n: float) -> float:
    """x with x (1 + x²)^((n−1)/2) = s: the power law's ε_eq/ε0 at σ_eq/σ0 = s."""
    from scipy.optimize import brentq

    return brentq(lambda x: x * (1 + x * x) ** ((n - 1) / 2) - s, 0.0, 1e9) if s > 0 else 0.0


def comparison(runs: dict, args) -> dict:
    """Every variant's summary, said as one table.

    The JSON is full Newton's, with every variant's under `variants`.
    """
    rows = {n: summary(*r, args)[0] for n, r in runs.items()}
    ref = rows["full"]["load_point_displacement"]
    say(f"\n| Newton | iterations per step | factorizations | tangent assemblies | "
        f"time (s) | |u_load| ({args.units}) | rel. diff. to full |\n|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        its = ", ".join(str(s["newton_iterations"]) for s in r["steps"])
        diff = abs(r["load_point_displacement"] / ref - 1)
        say(f"| {name} | {its} | {r['factorizations']} | {r['tangent_assemblies']} | "
            f"{r['solve_time_s']:.2f} | {r['load_point_displacement']:.9g} | {diff:.1e} |")
    out = dict(rows["full"])
    out["variants"] = rows
    return out


def say_result(out: dict, b, units: str) -> None:
    """The run's figures in one line."""
    strain = (f" (ε_eq ≈ {out['max_eps_eq_over_eps0']:.3g} ε0)"
              if "max_eps_eq_over_eps0" in out else "")
    lifted = (f", lifted-off area {out['lifted_off_area']:.4g} {units}²"
              if "lifted_off_area" in out else "")
    say(f"|u_load| = {out['load_point_displacement']:.6g} {units}, max σ_eq = "
        f"{out['max_von_mises']:.4g} N/{units}²{strain}, {out['newton_iterations']} Newton "
        f"iterations, {out['factorizations']} factorizations, {b.dofs} unknowns{lifted}")


def writers(b, vm, steps: list[dict], args) -> list:
    """The outputs asked for, each run on its own after the JSON.

    (--output's fields were written at every converged step.)
    """
    todo = []
    if args.plot:
        todo.append(lambda: plot(b, steps, args))
    if args.png:
        todo.append(lambda: picture(b, vm, args))
    return todo


def plot(b, steps: list[dict], args) -> None:
    """The load against the load-point displacement, every converged step."""
    if b.part.mesh.comm.rank != 0:
        return
    plt = pictures.pyplot()
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot([0] + [s["load_point_displacement"] for s in steps],
            [0] + [s["force"] / 1e3 for s in steps], "o-")
    ax.set_xlabel(f"load-point displacement |u| [{args.units}]")
    ax.set_ylabel("force [kN]")
    ax.grid(alpha=0.3)
    ax.set_title(f"bracket, {args.support} support, {args.material}"
                 + (f" n = {args.n}" if args.material == "power-law" else ""))
    pictures.save_figure(fig, args.plot)


def picture(b, vm, args) -> None:
    """Two views of the deformed bracket, the load arrow, the bolts, the floor.

    Coloured by σ_eq; in J2 by the cumulated plastic strain.
    """
    floor = None
    if b.support == "contact":
        c = b.solver
        floor = (c.x[c.owned], c.active[c.owned])
    where = dict(clamped=b.part.groups["bolts"], loaded=b.part.load_facets,
                 load_motion=b.load_point_motion(), units=args.units, force=args.force,
                 support=b.support, floor=floor, unloaded=args.unload)
    if isinstance(b.material, J2Plasticity):  # where it yielded, and how much
        pictures.bracket_picture(b.part.displacement(),
                                 b.material.cumulated_plastic_strain_per_cell(), args.png,
                                 label="cumulated plastic strain p (largest of each cell)",
                                 **where)
    else:
        pictures.bracket_picture(b.part.displacement(), vm, args.png, **where)
    say(f"wrote {args.png}")
