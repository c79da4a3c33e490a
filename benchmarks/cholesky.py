"""Why MUMPS Cholesky was 7.5x slower than LU on the bracket, and when LDLᵀ pays.

One P2 bracket tangent (power law, at the 8 kN state), factorized by MUMPS as LU, as
Cholesky unflagged, flagged symmetric (MUMPS SYM=2: symmetric indefinite, with pivoting)
and flagged SPD (SYM=1: LDLᵀ without pivoting), with MUMPS's default ordering and METIS
(ICNTL(7)=5). Times a numeric refactorization (the symbolic one is done once) and reads the
factor's size and memory (INFOG(29), INFOG(22) in MB). Then full Newton on the same mesh
with `linear_solver="lu"` and `"cholesky"`.

The 7.5x slowdown first seen with `-bracket_pc_type cholesky` was not MUMPS: changing the
PC type by option reset the factorization package to PETSc's own sequential Cholesky;
`linear_solver.create_ksp` now keeps MUMPS.

    python benchmarks/cholesky.py [--size 6] [--json benchmarks/results/cholesky.json]

On 2 ranks (`mpiexec -n 2`), the same factorizations scale differently (issue 31): the
records of 81k and 300k unknowns on 1 and 2 ranks, factorizations only at 300k:

    [mpiexec -n 2] python benchmarks/cholesky.py --size 4 \
        --json benchmarks/results/cholesky_81k_<n>ranks.json
    [mpiexec -n 2] python benchmarks/cholesky.py --size 2.4 --cases lu cholesky-symmetric \
        --repeat 2 --no-newton --load-steps 0 --json benchmarks/results/cholesky_300k_<n>ranks.json
"""
import argparse
import json
import time

import fenics_nl  # noqa: F401

# isort: split
from bracket_model import build_bracket
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.materials.laws import PowerLaw
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.result import WorkCounts

CASES = {"lu": ("lu", None, None), "cholesky": ("cholesky", None, None),
         "cholesky-symmetric": ("cholesky", "symmetric", None),
         "cholesky-spd": ("cholesky", "spd", None), "cholesky-spd-metis": ("cholesky", "spd", 5)}
# MUMPS options tried for 2 ranks (issue 31): the root front without ScaLAPACK
# (ICNTL(13) = 1), and the analysis in parallel with PT-Scotch (ICNTL(28) = 2, ICNTL(29) = 1)
ICNTL = {"lu-sequential-root": {13: 1}, "lu-parallel-analysis": {28: 2, 29: 1}}
CASES.update({name: ("lu", None, None) for name in ICNTL})
p = argparse.ArgumentParser()
p.add_argument("--size", type=float, default=6.0)
p.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
p.add_argument("--repeat", type=int, default=3, help="numeric refactorizations timed (the least)")
p.add_argument("--no-newton", action="store_true", help="the factorizations only")
p.add_argument("--load-steps", type=int, default=4,
               help="Newton steps to the 8 kN state whose tangent is factorized (0: the "
                    "unloaded state's, the same pattern and factor size)")
p.add_argument("--json")
args = p.parse_args()

b = build_bracket(PowerLaw(200e3, 0.3, sigma0=200.0, n=0.2), size=args.size, degree=2,
            force_scale=8e3)
for k in range(1, args.load_steps + 1):  # the 8 kN state: the tangent is the non-linear one
    b.set_load(8e3 * k / args.load_steps)
    b.solver.solve()
if args.load_steps == 0:
    b.solver.update_tangent(0, WorkCounts())  # the unloaded state's
A = b.solver.A  # the last assembled tangent, with identity Dirichlet rows
rows = []
for case in args.cases:
    kind, flag, ordering = CASES[case]
    spd = flag == "spd"
    M = A.copy()
    if flag:
        M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        M.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
    if spd:
        M.setOption(PETSc.Mat.Option.SPD, True)
    ksp = PETSc.KSP().create(MPI.COMM_WORLD)
    ksp.setOperators(M)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType(kind)
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    F = pc.getFactorMatrix()
    if ordering is not None:
        F.setMumpsIcntl(7, ordering)
    for key, value in ICNTL.get(case, {}).items():
        F.setMumpsIcntl(key, value)
    t0 = time.perf_counter()
    pc.setUp()  # symbolic + numeric
    first = time.perf_counter() - t0
    M.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
    times = []
    for _ in range(args.repeat):  # numeric factorizations only, as Newton does
        M.shift(1e-300)  # new values for PETSc (state bumped): a numeric refactorization
        t0 = time.perf_counter()
        ksp.setOperators(M)
        pc.setUp()
        times.append(time.perf_counter() - t0)
    F = pc.getFactorMatrix()
    row = {"case": case, "kind": kind, "matrix_flag": flag or "none",
           "ordering": "metis" if ordering == 5 else "default",
           "mumps_sym": 0 if kind == "lu" else (1 if spd else 2),
           "first_setup_s": first, "numeric_factorization_s": min(times),
           "ordering_used": F.getMumpsInfog(7), "factor_entries": F.getMumpsInfog(29),
           "factorization_gflop": F.getMumpsRinfog(3) / 1e9,
           "factor_memory_mb": F.getMumpsInfog(22)}
    rows.append(row)
    if MPI.COMM_WORLD.rank == 0:
        print(row, flush=True)
    ksp.destroy()
    M.destroy()
# the same comparison inside Newton: full Newton, 4 load steps to 8 kN, same mesh
newton = []
for kind in () if args.no_newton else ("lu", "cholesky"):
    c = build_bracket(PowerLaw(200e3, 0.3, sigma0=200.0, n=0.2), size=args.size, degree=2,
                force_scale=8e3, linear_solver=kind)
    t0 = time.perf_counter()
    path = solve_incrementally(c.solver, lambda t, c=c: c.set_load(8e3 * t), 4, adaptive=False,
                               predictor=False)
    newton.append({"linear_solver": kind, "solve_time_s": time.perf_counter() - t0,
                   "factorization_time_s": path.work.time["factorization"],
                   "factorizations": path.work.factorizations, "iterations": path.iterations,
                   "load_point_displacement": c.load_point_displacement()})
    if MPI.COMM_WORLD.rank == 0:
        print(newton[-1], flush=True)
if args.json and MPI.COMM_WORLD.rank == 0:
    json.dump({"dofs": b.dofs, "size_mm": args.size, "ranks": MPI.COMM_WORLD.size,
               "load_steps": args.load_steps,
               "factorizations": rows,
               "full_newton": newton}, open(args.json, "w"), indent=2)
