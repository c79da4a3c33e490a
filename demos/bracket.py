# # A 3D bracket in a non-linear material: Newton variants side by side
#
# An L-shaped steel-like bracket (gmsh geometry in `meshes/bracket.py`) is bolted through its
# base and pulled at a hole in its arm. The material is the power law of `fenics_nl`:
# linear (E, ν) at small strain, $\sigma_{eq} \approx \sigma_0 (\varepsilon_{eq}/\varepsilon_0)^n$
# beyond $\varepsilon_0 = \sigma_0/(3\mu)$. The default 8 kN is about 1.3 times the load at
# which a perfectly plastic base plate would hinge ($M_p = \sigma_0 b t^2/4$ against
# $F \times 50$ mm): the whole plate between the arm and the bolts is past $\sigma_0$, and
# beside the bolt holes (the net section) $\sigma_{eq} \approx 1.7\,\sigma_0$, i.e.
# $\varepsilon_{eq} \approx 14\,\varepsilon_0$, where the tangent shear stiffness is
# ~2.5 % of the elastic one. Quadratic (P2) tetrahedra by default: at these strains the
# secant shear modulus is a fraction of the bulk modulus and P1 tetrahedra, two through
# the plate, lock (half the displacement; see the README's mesh-convergence table).
#
# ## Problem definition
#
# $$ \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\, dx = \int_{S_{load}} t \cdot v\, ds,
#    \qquad \sigma = \frac{\partial \varphi}{\partial \varepsilon}, $$
#
# solved in load steps by Newton's method: full (tangent every iteration), modified (the
# tangent of the step's start, factorized once per step), periodic (every 3 iterations),
# quasi-Newton (BFGS on the step's first factorization) or PETSc SNES. Supports:
# `clamped` (bolt holes fixed) or `contact` (bolts fixed and the base on a rigid floor,
# frictionless, free to lift off: the course's combination of non-linearities).
#
# ## Implementation

# +
import argparse
import json
import resource
import sys
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from mpi4py import MPI

from fenics_nl.bracket import Bracket
from fenics_nl.cli import parse_with_petsc_options
from fenics_nl.contact import ContactError
from fenics_nl.materials import LinearElastic, PowerLaw
from fenics_nl.newton import ConvergenceError, stalled_at_round_off

comm = MPI.COMM_WORLD
VARIANTS = ("full", "modified", "periodic", "quasi-newton", "snes")


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)
# -


def parse_args(argv=None):
    p = argparse.ArgumentParser(
        description="3D bracket, power-law material, Newton variants side by side.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
        epilog="PETSc options (-bracket_ksp_view, ...) are passed through.")
    p.add_argument("--support", choices=["clamped", "contact"], default="clamped",
                   help="bolt holes fixed, or also the base on a rigid floor (unilateral)")
    p.add_argument("--newton", choices=VARIANTS, default="full", help="non-linear solver")
    p.add_argument("--compare", action="store_true",
                   help="run every variant on the same mesh and print one table")
    p.add_argument("--force", type=float, default=8e3, help="total load on the arm's hole [N]")
    p.add_argument("--steps", type=int, default=4, help="equal load steps")
    p.add_argument("--tolerance", type=float, default=1e-9,
                   help="Newton stops at |R| <= tolerance x force (or 1e-10 |R0|)")
    p.add_argument("--size", type=float, default=6.0, help="largest element size [mm]")
    p.add_argument("--degree", type=int, choices=[1, 2], default=2,
                   help="Lagrange degree (P1 is far too stiff here: see the README)")
    p.add_argument("--mesh", metavar="MSH", help="a .msh file with groups bolts, load, base")
    p.add_argument("--solver", choices=["direct", "iterative"], default="direct",
                   help="MUMPS LU, or CG + GAMG with rigid-body near-nullspace")
    p.add_argument("--material", choices=["power-law", "linear"], default="power-law",
                   help="the power law below, or linear elasticity (E, nu): one solve")
    p.add_argument("--E", type=float, default=200e3, help="Young's modulus [MPa]")
    p.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio [-]")
    p.add_argument("--sigma0", type=float, default=200.0, help="power law: reference stress [MPa]")
    p.add_argument("--n", type=float, default=0.2, help="power law exponent [-]")
    p.add_argument("--json", metavar="PATH", help="write the quantities of interest as JSON")
    p.add_argument("--output", metavar="DIR", help="displacement and von Mises stress (VTX)")
    p.add_argument("--png", metavar="PATH", help="deformed bracket coloured by von Mises stress")
    p.add_argument("--plot", metavar="PATH", help="load against load-point displacement")
    args, petsc_args = parse_with_petsc_options(p, argv)
    if args.steps < 1:
        p.error(f"--steps must be >= 1, got {args.steps}")
    if not args.size > 0:
        p.error(f"--size must be > 0, got {args.size}")
    if not args.force > 0:
        p.error(f"--force must be > 0, got {args.force}")
    return args, petsc_args


def run_variant(args, newton):
    """Load steps with one Newton variant; returns the bracket and a record per step."""
    material = (PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n)
                if args.material == "power-law" else LinearElastic(args.E, args.nu))
    b = Bracket(material, size=args.size, mesh_file=args.mesh, support=args.support,
                degree=args.degree, newton=newton, force_scale=args.force,
                tolerance=args.tolerance,
                linear_solver="lu" if args.solver == "direct" else "gamg")
    steps = []
    t0 = time.perf_counter()
    for k in range(1, args.steps + 1):
        force = args.force * k / args.steps
        b.set_load(force)
        try:
            r = b.solver.solve()
        except ConvergenceError as err:
            # a stall at round-off needs a looser tolerance, not smaller steps
            stalled = stalled_at_round_off(err.result.residual_norms)
            advice = "raise --tolerance" if stalled else "take more --steps"
            raise ConvergenceError(f"load step {k}/{args.steps} (F = {force:.4g} N), {newton} "
                                   f"Newton: {err}; {advice}", err.result) from err
        its = getattr(r, "newton_iterations", r.iterations)
        steps.append({"force": force, "load_point_displacement": b.load_point_displacement(),
                      "newton_iterations": its, "factorizations": r.work.factorizations,
                      "tangent_assemblies": r.work.tangent_assemblies,
                      "krylov_iterations": r.work.krylov_iterations,
                      "residual_norms": list(r.residual_norms)})
        say(f"  {newton}: step {k}/{args.steps}, F = {force:.4g} N, {its} iterations, "
            f"|u_load| = {steps[-1]['load_point_displacement']:.6g} mm")
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return b, steps, wall


def summary(b, steps, wall, args):
    vm = b.von_mises()
    vm_max = comm.allreduce(float(np.max(vm.x.array, initial=0.0)), op=MPI.MAX)
    mat = b.material
    out = {
        "support": args.support, "force": args.force,
        "load_point_displacement": steps[-1]["load_point_displacement"],
        "max_von_mises": vm_max,
        "newton_iterations": sum(s["newton_iterations"] for s in steps),
        "factorizations": sum(s["factorizations"] for s in steps),
        "tangent_assemblies": sum(s["tangent_assemblies"] for s in steps),
        "krylov_iterations": sum(s["krylov_iterations"] for s in steps),
        "residual_norms": steps[-1]["residual_norms"],
        "steps": [{k: v for k, v in s.items() if k != "residual_norms"} for s in steps],
        "dofs": b.dofs, "ranks": comm.size, "solve_time_s": wall,
        "peak_memory_mb": comm.allreduce(
            resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.MAX),
    }
    if isinstance(mat, PowerLaw):
        # σ_eq = σ0 x (1 + x²)^((n−1)/2), x = ε_eq/ε0: invert for the peak strain
        out["max_eps_eq_over_eps0"] = _strain_ratio(vm_max / mat.sigma0, mat.n)
    if args.support == "contact":
        out["lifted_off_area"] = b.lifted_off_area()
    return out, vm


def _strain_ratio(s, n):
    from scipy.optimize import brentq

    return brentq(lambda x: x * (1 + x * x) ** ((n - 1) / 2) - s, 0.0, 1e9) if s > 0 else 0.0


def main(argv=None) -> int:
    args, petsc_args = parse_args(argv)
    from petsc4py import PETSc

    PETSc.Options().insertString(" ".join(petsc_args))
    t0 = time.perf_counter()
    try:
        if args.compare:
            out = compare(args)
        else:
            b, steps, wall = run_variant(args, args.newton)
            out, vm = summary(b, steps, wall, args)
            strain = (f" (ε_eq ≈ {out['max_eps_eq_over_eps0']:.3g} ε0)"
                      if "max_eps_eq_over_eps0" in out else "")
            say(f"|u_load| = {out['load_point_displacement']:.6g} mm, max σ_eq = "
                f"{out['max_von_mises']:.4g} MPa{strain}, "
                f"{out['newton_iterations']} Newton iterations, {out['factorizations']} "
                f"factorizations, {b.dofs} unknowns"
                + (f", lifted-off area {out['lifted_off_area']:.4g} mm²"
                   if "lifted_off_area" in out else ""))
            outputs(b, vm, steps, args)
    except (ValueError, ConvergenceError, ContactError, RuntimeError) as err:
        if comm.rank == 0:
            print(f"error: {err}", file=sys.stderr)
        return 2
    out["wall_time_s"] = time.perf_counter() - t0
    say(f"wall time {out['wall_time_s']:.2f} s on {comm.size} rank(s)")
    if args.json and comm.rank == 0:
        Path(args.json).write_text(json.dumps(out, indent=2))
    return 0


def compare(args):
    """Every variant on the same mesh: one table, and their answers side by side."""
    rows = {}
    for newton in VARIANTS:
        if newton == "snes" and args.support == "contact":
            continue
        b, steps, wall = run_variant(args, newton)
        rows[newton], _ = summary(b, steps, wall, args)
    ref = rows["full"]["load_point_displacement"]
    say("\n| Newton | iterations per step | factorizations | tangent assemblies | "
        "time (s) | |u_load| (mm) | rel. diff. to full |\n|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        its = ", ".join(str(s["newton_iterations"]) for s in r["steps"])
        diff = abs(r["load_point_displacement"] / ref - 1)
        say(f"| {name} | {its} | {r['factorizations']} | {r['tangent_assemblies']} | "
            f"{r['solve_time_s']:.2f} | {r['load_point_displacement']:.9g} | {diff:.1e} |")
    out = dict(rows["full"])
    out["variants"] = rows
    return out


def outputs(b, vm, steps, args):
    if args.output:
        from dolfinx.io import VTXWriter

        Path(args.output).mkdir(parents=True, exist_ok=True)
        with VTXWriter(comm, Path(args.output) / "displacement.bp", [b.u]) as f:
            f.write(0.0)
        with VTXWriter(comm, Path(args.output) / "von_mises.bp", [vm]) as f:
            f.write(0.0)
        say(f"wrote {args.output}/displacement.bp and von_mises.bp (ParaView: ADIOS2 VTX)")
    if args.plot and comm.rank == 0:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 4))
        ax.plot([0] + [s["load_point_displacement"] for s in steps],
                [0] + [s["force"] / 1e3 for s in steps], "o-")
        ax.set_xlabel("load-point displacement |u| [mm]")
        ax.set_ylabel("force [kN]")
        ax.grid(alpha=0.3)
        ax.set_title(f"bracket, {args.support} support, power law n = {args.n}")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")
    if args.png:
        picture(b, vm, args.png)


def picture(b, vm, path):
    import pyvista
    from dolfinx import plot as dplot

    pyvista.OFF_SCREEN = True
    topology, cells, x = dplot.vtk_mesh(b.mesh)
    grid = pyvista.UnstructuredGrid(topology, cells, x)
    grid.cell_data["von Mises [MPa]"] = vm.x.array[: b.mesh.topology.index_map(3).size_local]
    from dolfinx import fem

    P1 = fem.functionspace(b.mesh, ("Lagrange", 1, (3,)))
    u1 = fem.Function(P1)
    u1.interpolate(b.u)
    grid.point_data["u"] = u1.x.array.reshape(-1, 3)[: len(x)]
    # true scale when the motion is visible, else the largest motion drawn as 5 mm
    scale = max(1.0, 5.0 / max(np.abs(u1.x.array).max(), 1e-300))
    warped = grid.warp_by_vector("u", factor=scale)
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 800))
    pl.add_mesh(grid, style="wireframe", color="gray", opacity=0.15)
    pl.add_mesh(warped, scalars="von Mises [MPa]", cmap="turbo", show_edges=False,
                scalar_bar_args={"vertical": True, "position_x": 0.86, "position_y": 0.25})
    pl.view_vector((1.0, -1.6, 0.9))
    pl.add_text(f"deformed x{scale:.2g} (grey: undeformed)", font_size=10)
    if comm.size > 1:
        say("--png draws rank 0's part only under MPI")
    pl.screenshot(path)
    say(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
