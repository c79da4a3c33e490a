"""Newton variants against SNES on a 3D power-law cantilever (>= 100k unknowns by default).

One run, one mesh, one linear solver (MUMPS): every variant starts from u = 0 at the same
load and reaches the same tolerance. Writes benchmarks/results/newton.json, the plot
newton.png (relative residual against wall time, one curve per variant) and, with
--update-docs, the table in README.md (between the `bench:newton` markers).
"""

import argparse
import json
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from common import (
    elapsed,
    machine,
    outside_kernels,
    pyplot,
    save_figure,
    timed_linear_solve,
    update_docs,
)
from dolfinx import fem
from mpi4py import MPI
from problems import cantilever_3d

from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import SnesSolver

HERE = Path(__file__).resolve().parent
VARIANTS = [  # (label, solver class, options)
    ("SNES newtonls", SnesSolver, {"method": "full"}),
    ("full", NewtonSolver, {"method": "full"}),
    ("modified", NewtonSolver, {"method": "modified"}),
    ("periodic m=2", NewtonSolver, {"method": "periodic", "period": 2}),
    ("periodic m=3", NewtonSolver, {"method": "periodic", "period": 3}),
    ("bfgs", NewtonSolver, {"method": "bfgs"}),
    ("SNES lag -2 (modified)", SnesSolver, {"method": "modified"}),
    ("SNES lag 3 (periodic)", SnesSolver, {"method": "periodic", "period": 3}),
]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--cells", type=int, nargs=3, default=[80, 20, 20],
                   help="tetrahedral box cells (x, y, z); 80 20 20 gives 107k unknowns")
    p.add_argument("--traction", type=float, default=-0.12,
                   help="end traction (E = 1000, σ0 = 1): strongly non-linear at the clamp")
    p.add_argument("--linear-solver", choices=["lu", "cholesky"], default="lu")
    p.add_argument("--repeat", type=int, default=1, help="runs per variant, the fastest kept")
    p.add_argument("--update-docs", action="store_true")
    p.add_argument("--quick", action="store_true", help="small mesh, for a smoke run")
    return p.parse_args()


MATERIAL = PowerLaw(E=1e3, nu=0.3, sigma0=1.0, n=0.3)
SIZE = (10.0, 2.5, 2.5)


def tip(problem):
    value = fem.assemble_scalar(fem.form(problem.observed))
    return problem.u.function_space.mesh.comm.allreduce(value)


def run_variant(cls, opts, cells, traction, linear_solver, prefix):
    p = cantilever_3d(MATERIAL, cells=cells, size=SIZE, traction=traction)
    solver = cls(p.residual, p.u, p.bcs, linear_solver=linear_solver, prefix=prefix,
                 rtol=1e-10, max_it=500, **opts)
    MPI.COMM_WORLD.Barrier()
    t0 = time.perf_counter()
    r = solver.solve()
    wall = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    w = r.work
    return {"wall_time_s": wall, "iterations": r.iterations, "tip_displacement": tip(p),
            "residual_assemblies": w.residual_assemblies,
            "tangent_assemblies": w.tangent_assemblies, "factorizations": w.factorizations,
            "linear_solves": w.linear_solves, "phase_time_s": dict(w.time),
            "residual_norms": r.residual_norms, "elapsed_s": r.elapsed,
            "dofs": p.u.function_space.dofmap.index_map.size_global * 3}


def linear_solve_time(cells, linear_solver):
    """One linear elastic solve (assemble K and F, factorize, solve) on the same mesh."""
    linear = LinearElastic(MATERIAL.E, MATERIAL.nu)
    p = cantilever_3d(linear, cells=cells, size=SIZE, traction=-0.12)
    V = p.u.function_space
    a = fem.form(ufl.derivative(p.residual, p.u))
    L = fem.form(-ufl.replace(p.residual, {p.u: fem.Function(V)}))
    return timed_linear_solve(a, L, p.bcs, linear_solver, "linear_", x=p.u.x.petsc_vec)


def main():
    args = parse_args()
    cells = [8, 2, 2] if args.quick else args.cells
    rank0 = MPI.COMM_WORLD.rank == 0
    # Warm-up: JIT-compile every form on a tiny mesh so timings exclude compilation.
    for k, (_, cls, opts) in enumerate(VARIANTS):
        run_variant(cls, opts, [4, 1, 1], args.traction, args.linear_solver, f"w{k}_")
    linear_solve_time([4, 1, 1], args.linear_solver)

    results = {}
    t_lin = min(linear_solve_time(cells, args.linear_solver) for _ in range(args.repeat))
    for k, (label, cls, opts) in enumerate(VARIANTS):
        runs = [run_variant(cls, opts, cells, args.traction, args.linear_solver, f"b{k}_{i}_")
                for i in range(args.repeat)]
        results[label] = min(runs, key=lambda r: r["wall_time_s"])
        if rank0:
            r = results[label]
            print(f"{label:24s} {r['wall_time_s']:7.2f} s  its {r['iterations']:3d}  "
                  f"fact {r['factorizations']:2d}  tip {r['tip_displacement']:.10f}", flush=True)
    full, snes = results["full"]["wall_time_s"], results["SNES newtonls"]["wall_time_s"]
    best = min((r["wall_time_s"], k) for k, r in results.items() if not k.startswith("SNES"))
    tips = [r["tip_displacement"] for r in results.values()]
    summary = {
        "dofs": results["full"]["dofs"], "ranks": MPI.COMM_WORLD.size, "cells": cells,
        "traction": args.traction, "linear_solver": args.linear_solver,
        "linear_solve_time_s": t_lin,
        "ratio_full_over_snes": full / snes,
        "best_variant": best[1], "ratio_best_over_full": best[0] / full,
        "max_rel_tip_spread": (max(tips) - min(tips)) / abs(np.mean(tips)),
        "machine": machine(MPI.COMM_WORLD.size),
        "benchmark_time_s": elapsed(),
        "variants": results,
    }
    if rank0:
        print(table(summary))
        if not args.quick:
            out = HERE / "results" / "newton.json"
            out.write_text(json.dumps(summary, indent=1))
            print(f"wrote {out}")
            plot(summary, HERE / "results" / "newton.png")
            if args.update_docs:
                update_docs("newton", table(summary))


def table(s):
    lines = [
        f"3D power-law cantilever, {s['dofs']} unknowns, {s['ranks']} rank(s), MUMPS "
        f"{s['linear_solver'].upper()}; one linear elastic solve of the same mesh: "
        f"{s['linear_solve_time_s']:.2f} s.",
        "",
        "| variant | time (s) | / full | / linear solve | iterations | factorizations | "
        "tangent assemblies | residual assemblies | linear solves | factorization time (s) | "
        "outside the kernels (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    full = s["variants"]["full"]["wall_time_s"]
    for label, r in s["variants"].items():
        lines.append(
            f"| {label} | {r['wall_time_s']:.2f} | {r['wall_time_s'] / full:.2f} | "
            f"{r['wall_time_s'] / s['linear_solve_time_s']:.1f} | {r['iterations']} | "
            f"{r['factorizations']} | {r['tangent_assemblies']} | {r['residual_assemblies']} | "
            f"{r['linear_solves']} | {r['phase_time_s']['factorization']:.2f} | "
            f"{outside_kernels(r):.2f} |")
    lines += ["", f"Hand-written full Newton / SNES newtonls: **{s['ratio_full_over_snes']:.2f}**; "
              f"best variant ({s['best_variant']}) / full Newton: "
              f"**{s['ratio_best_over_full']:.2f}**; all variants agree on the tip displacement "
              f"to {s['max_rel_tip_spread']:.1e} (relative)."]
    return "\n".join(lines)


def plot(s, path):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for label, r in s["variants"].items():
        norms = np.asarray(r["residual_norms"])
        ax.loglog(r["elapsed_s"], norms / norms[0], ".-" if "SNES" in label else "o-",
                  ms=3, label=f"{label} ({r['iterations']} its)")
    ax.set_xlabel("wall time since the start of the solve [s]")
    ax.set_ylabel("|R| / |R0|")
    ax.set_title(f"power-law cantilever, {s['dofs']} unknowns, MUMPS, {s['ranks']} rank(s)",
                 fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    save_figure(fig, path)


if __name__ == "__main__":
    main()
