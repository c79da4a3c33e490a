"""The J2 sphere (2D, 91k unknowns) on 2 ranks: what MUMPS's factorization allows.

The sphere's run is two thirds MUMPS numeric factorizations (`benchmarks/plasticity.py`:
25 of them in 10 steps; LDLᵀ, its tangent being symmetric). This times one numeric
refactorization of its tangent's pattern (Hooke's at the same P2 mesh: J2's has the same
sparsity), the least of `--repeat`, on 1 and 2 ranks, for MUMPS LU and LDLᵀ and the MUMPS
options that could change the parallel tree: the orderings (ICNTL(7): AMF 2, SCOTCH 3,
PORD 4, METIS 5), the root front without ScaLAPACK (ICNTL(13) = 1) and the analysis in
parallel (ICNTL(28) = 2 with PT-Scotch). Then two 1-rank factorizations at once, in two
processes (the mean of 10 rounds each, against the mean of 10 alone): if the machine's two
cores shared a bottleneck (memory bandwidth, a cache), each would slow down there too. From
the factorization's share f of the 1-rank run and its speed-up s, the run's speed-up cannot
exceed 1 / (f/s + (1 − f)/2) (Amdahl, the rest taken as perfectly parallel).

    python benchmarks/sphere_ranks.py [--size 1.5625] [--quick] [--update-docs]

Each case is a process of its own (`--case NAME`, under `mpiexec -n N` for 2 ranks).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
MPIEXEC = Path(sys.executable).parent / "mpiexec"
# name: (factorization, MUMPS ICNTL options)
CASES = {"lu": ("lu", {}), "lu-amf": ("lu", {7: 2}), "lu-scotch": ("lu", {7: 3}),
         "lu-pord": ("lu", {7: 4}), "lu-metis": ("lu", {7: 5}),
         "lu-sequential-root": ("lu", {13: 1}), "lu-parallel-analysis": ("lu", {28: 2, 29: 1}),
         "ldlt": ("cholesky", {})}
QUICK = ("lu", "ldlt")
ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}  # as `make` and the demos set
CONCURRENT_ROUNDS = 10


def factorize(case: str, size: float, repeat: int) -> dict:
    """One case in this process: the least numeric refactorization time (slowest rank)."""
    import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

    # isort: split
    import ufl
    from dolfinx import fem
    from mpi4py import MPI
    from petsc4py import PETSc
    from plasticity_problems import thick_vessel

    from fenics_nl.materials.laws import LinearElastic
    from fenics_nl.solvers.form_matrix import FormMatrix
    from fenics_nl.solvers.linear_solver import create_ksp

    comm = MPI.COMM_WORLD
    body = thick_vessel("sphere", 100.0, 200.0, size=size)
    du, v = ufl.TrialFunction(body.V), ufl.TestFunction(body.V)
    K = fem.form(ufl.derivative(LinearElastic(210e3, 0.3).internal_work(
        body.u, v, body.model) * body.dx, body.u, du))
    matrix = FormMatrix(K)
    matrix.assemble(K, body.supports)
    kind, icntl = CASES[case]
    opts = PETSc.Options()
    for k, value in icntl.items():
        opts[f"sr_mat_mumps_icntl_{k}"] = value
    ksp = create_ksp(matrix.mat, kind, prefix="sr_")
    ksp.setUp()  # the analysis and a first factorization
    times = []
    for _ in range(repeat):
        matrix.assemble(K, body.supports)  # a new state: the PC factorizes again
        comm.Barrier()
        t0 = time.perf_counter()
        ksp.getPC().setUp()
        times.append(comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
    F = ksp.getPC().getFactorMatrix()
    return {"case": case, "ranks": comm.size, "dofs": matrix.mat.getSize()[0],
            "factorization_s": min(times), "mean_s": sum(times) / len(times),
            "gflop": F.getMumpsRinfog(3) / 1e9,
            "factor_entries": F.getMumpsInfog(29)}


def run(case: str, ranks: int, size: float, repeat: int, wait: bool = True):
    """A case in a new process (on `ranks` ranks); its record, or the process if not `wait`."""
    import os

    cmd = [sys.executable, __file__, "--case", case, "--size", str(size),
           "--repeat", str(repeat)]
    cmd = [str(MPIEXEC), "-n", str(ranks), *cmd] if ranks > 1 else cmd
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env={**os.environ, **ENV})
    if not wait:
        return proc
    out, _ = proc.communicate()
    if proc.returncode:
        raise SystemExit(f"{case} on {ranks} rank(s) failed")
    return json.loads(out.strip().splitlines()[-1])


def sphere_run(ranks: int, size: float) -> dict:
    """The J2 sphere (full Newton, 0.9 p_lim in 10 steps) on `ranks` ranks: its phases."""
    import os
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        cmd = [sys.executable, str(HERE.parent / "demos" / "pressure_vessel.py"), "--size",
               str(size), "--steps", "10", "--pressure-ratio", "0.9", "--json", str(out)]
        cmd = [str(MPIEXEC), "-n", str(ranks), *cmd] if ranks > 1 else cmd
        subprocess.run(cmd, check=True, capture_output=True, env={**os.environ, **ENV})
        d = json.loads(out.read_text())
    return {"ranks": ranks, "dofs": d["dofs"], "solve_time_s": d["solve_time_s"],
            "phase_time_s": d["phase_time_s"], "factorizations": d["factorizations"]}


def table(out: dict) -> str:
    rows = out["cases"]
    lines = [f"The sphere's tangent pattern, {rows[0]['one']['dofs']} unknowns (h = "
             f"{out['size']}), one numeric MUMPS refactorization, the least of "
             f"{out['repeat']}, 1 BLAS thread a rank:", "",
             "| case | GFlop | 1 rank (s) | 2 ranks (s) | speed-up |", "|---|---|---|---|---|"]
    for r in rows:
        one, two = r["one"], r["two"]
        lines.append(f"| {r['case']} | {one['gflop']:.2f} | {one['factorization_s']:.3f} | "
                     f"{two['factorization_s']:.3f} | "
                     f"{one['factorization_s'] / two['factorization_s']:.2f} |")
    c = out["concurrent"]
    # the run factorizes by LDLᵀ (demos/pressure_vessel.py): that speed-up bounds it
    ldlt = next(r for r in rows if r["case"] == "ldlt")
    best = ldlt["one"]["factorization_s"] / ldlt["two"]["factorization_s"]
    one, two = out["runs"]
    f = one["phase_time_s"]["factorization"] / one["solve_time_s"]
    alone = out["alone"]
    slower = max(c) / alone - 1
    verdict = ("the two cores do not slow each other down (within 10 %): what the 2-rank "
               "factorization loses is MUMPS's parallel tree on a 2D mesh (small fronts, and "
               "the fronts near the root shared by both ranks)" if slower <= 0.1 else
               f"the two cores slow each other down by {100 * slower:.0f} %: the machine, "
               "not MUMPS alone, limits the 2-rank factorization")
    lines += ["", f"Two 1-rank LU factorizations at once, in two processes, the mean of "
              f"{CONCURRENT_ROUNDS} rounds each: {c[0]:.3f} s and {c[1]:.3f} s, against "
              f"{alone:.3f} s alone: {verdict}.", "",
              f"The J2 sphere itself (full Newton, 0.9 p_lim in 10 steps, "
              f"{one['factorizations']} factorizations): {one['solve_time_s']:.2f} s on 1 rank, "
              f"{two['solve_time_s']:.2f} s on 2, **{one['solve_time_s'] / two['solve_time_s']:.2f}"
              f"x**; its factorizations are {100 * f:.0f} % of the 1-rank run. With the LDLᵀ "
              f"speed-up above ({best:.2f}) and the rest perfectly parallel, the run's "
              f"speed-up is at most **{1 / (f / best + (1 - f) / 2):.2f}**.", "",
              "| phase | 1 rank (s) | 2 ranks (s) | speed-up |", "|---|---|---|---|"]
    for phase, t1 in one["phase_time_s"].items():
        t2 = two["phase_time_s"][phase]
        lines.append(f"| {phase} | {t1:.2f} | {t2:.2f} | {t1 / t2:.2f} |")
    return "\n".join(lines)


def main():
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="LU and LDLᵀ only, a coarser mesh")
    ap.add_argument("--update-docs", action="store_true")
    ap.add_argument("--size", type=float, default=1.5625, help="element size (91k unknowns)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--case", choices=list(CASES), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.case:  # a worker
        record = factorize(args.case, args.size, args.repeat)
        if record["ranks"] == 1 or __import__("mpi4py.MPI").MPI.COMM_WORLD.rank == 0:
            print(json.dumps(record), flush=True)
        return
    size = 6.25 if args.quick else args.size
    rows = []
    for case in QUICK if args.quick else CASES:
        rows.append({"case": case, "one": run(case, 1, size, args.repeat),
                     "two": run(case, 2, size, args.repeat)})
        print(f"{case}: {rows[-1]['one']['factorization_s']:.3f} s on 1 rank, "
              f"{rows[-1]['two']['factorization_s']:.3f} s on 2", flush=True)
    # the mean of many rounds, so that the two processes' loops overlap (their set-ups
    # take the same time), against the mean of as many alone
    alone = run("lu", 1, size, CONCURRENT_ROUNDS)["mean_s"]
    procs = [run("lu", 1, size, CONCURRENT_ROUNDS, wait=False) for _ in range(2)]
    concurrent = [json.loads(p.communicate()[0].strip().splitlines()[-1])["mean_s"]
                  for p in procs]
    runs = [sphere_run(ranks, size) for ranks in (1, 2)]
    out = {"size": size, "repeat": args.repeat, "cases": rows, "alone": alone,
           "concurrent": concurrent, "runs": runs}
    from common import publish

    publish("sphere_ranks", out, table, args)


if __name__ == "__main__":
    main()
