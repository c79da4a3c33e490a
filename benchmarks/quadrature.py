"""Quadrature degree of the bracket's P2 forms: error against time on a refinement sequence.

For element sizes 9, 6, 4 mm and quadrature degrees 2, 3, 4: |u_load| at 8 kN (4 load steps,
full Newton), the time of the tangent assemblies and of the whole solve. The error is taken
against the degree-4 value on the finest mesh extrapolated in h (Richardson with the
observed order), and against the same mesh's degree-4 value (the quadrature error alone).

    python benchmarks/quadrature.py [--sizes 9 6 4] [--json benchmarks/results/quadrature.json]
"""
import argparse
import json
import time

import fenics_nl  # noqa: F401

# isort: split
from bracket_model import build_bracket
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.materials.laws import PowerLaw
from fenics_nl.solvers.loading import solve_incrementally

p = argparse.ArgumentParser()
p.add_argument("--sizes", type=float, nargs="+", default=[9.0, 6.0, 4.0])
p.add_argument("--degrees", type=int, nargs="+", default=[2, 3, 4])
p.add_argument("--json")
args = p.parse_args()
rows = []
for size in args.sizes:
    for q in args.degrees:
        b = build_bracket(PowerLaw(200e3, 0.3, sigma0=200.0, n=0.2), size=size, degree=2,
                    force_scale=8e3, quadrature_degree=q)
        t0 = time.perf_counter()
        try:
            path = solve_incrementally(b.solver, lambda t, b=b: b.set_load(8e3 * t), 4,
                                       adaptive=False, predictor=False)
        except SolveError as err:  # recorded: a rule that breaks Newton is a finding too
            rows.append({"size_mm": size, "quadrature_degree": q, "dofs": b.dofs,
                         "failure": str(err)})
            if MPI.COMM_WORLD.rank == 0:
                print(rows[-1], flush=True)
            continue
        wall = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
        row = {"size_mm": size, "quadrature_degree": q, "dofs": b.dofs,
               "load_point_displacement": b.load_point_displacement(), "solve_time_s": wall,
               "tangent_time_s": path.work.time["tangent"],
               "residual_time_s": path.work.time["residual"],
               "newton_iterations": path.iterations}
        rows.append(row)
        if MPI.COMM_WORLD.rank == 0:
            print(row, flush=True)
if args.json and MPI.COMM_WORLD.rank == 0:
    json.dump({"rows": rows}, open(args.json, "w"), indent=2)
