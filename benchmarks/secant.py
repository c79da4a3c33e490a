"""Why quasi-Newton on one factorization stays above 1.5 linear solves on the bracket.

The power-law bracket (8 kN in one step, P2) on the elastic tangent, factorized once, by
the secant methods at hand: BFGS keeping 30 (the default), 60 or 100 pairs, and Anderson
acceleration of modified Newton (depth 5, 10, 20). Each iteration costs a residual assembly
and a back-solve; what decides the cost is how many iterations reach the bracket's
tolerance (1e-9 of the load), and the contraction per iteration (the geometric mean of
‖R_k+1‖/‖R_k‖ after the first iteration). One linear solve (assemble, factorize, solve) of
the same mesh is the unit.

    python benchmarks/secant.py [--size 6] [--quick] [--update-docs]
"""

from __future__ import annotations

import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from bracket_model import build_bracket
from common import options, publish, timed_linear_solve
from petsc4py import PETSc

from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.solvers.acceleration import Anderson
from fenics_nl.solvers.result import WorkCounts

FORCE = 8e3  # N
MATERIAL = PowerLaw(200e3, 0.3, sigma0=200.0, n=0.2)


def bracket(size: float, newton: str):
    b = build_bracket(MATERIAL, size=size, degree=2, force_scale=FORCE, newton=newton)
    b.set_load(FORCE)
    return b


def bfgs(size: float, memory: int) -> dict:
    """BFGS keeping `memory` pairs, from the elastic tangent."""
    b = bracket(size, "bfgs")
    b.solver.bfgs.memory = memory
    t0 = time.perf_counter()
    r = b.solver.solve()
    return record(f"bfgs, {memory} pairs", time.perf_counter() - t0, r.residual_norms, b)


def anderson(size: float, depth: int) -> dict:
    """Modified Newton u ← u − K0⁻¹R(u), accelerated by Anderson of `depth`, by the solver's
    step interface (the bracket's load is a traction: no boundary value to lift)."""
    b = bracket(size, "modified")
    s, u = b.solver, b.u
    work = WorkCounts()
    t0 = time.perf_counter()
    s.start_solve()
    bs = u.function_space.dofmap.index_map_bs
    acc = Anderson(u.function_space.mesh.comm, u.x.index_map.size_local * bs, depth=depth)
    norms = [s.residual(work)]
    # the solver's own test: ‖R‖ ≤ max(rtol ‖R₀‖, atol F)
    test = s.convergence
    threshold = test.threshold(norms[0], FORCE)
    while norms[-1] > threshold and len(norms) <= test.max_it:
        s.update_tangent(len(norms) - 1, work)
        s.solve_linear(s.b, s.du, work)
        s.du.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        with s.du.localForm() as du:
            x = u.x.array.copy()
            u.x.array[:] = acc(x, x - du.array_r)
        norms.append(s.residual(work))
    if norms[-1] > threshold:
        raise SystemExit(f"anderson, depth {depth}: no convergence in {test.max_it} iterations")
    return record(f"anderson, depth {depth}", time.perf_counter() - t0, norms, b)


def record(label: str, seconds: float, norms, b) -> dict:
    n = np.asarray(norms)
    ratios = np.log(n[2:] / n[1:-1])  # after the first iteration
    half = len(ratios) // 2
    return {"label": label, "iterations": len(n) - 1, "time_s": seconds,
            "contraction": float(np.exp(np.mean(ratios))),
            "contraction_halves": [float(np.exp(np.mean(ratios[:half]))),
                                   float(np.exp(np.mean(ratios[half:])))],
            "load_point_displacement": b.load_point_displacement(), "dofs": b.dofs}


def linear_solve(size: float) -> float:
    """One elastic solve of the bracket's mesh under the same load."""
    b = bracket(size, "full")
    V = b.u.function_space
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = ufl.derivative(LinearElastic(200e3, 0.3).internal_work(b.u, v, "3d") * b.part.dx,
                       b.u, du)
    L = ufl.dot(b.part.traction, v) * b.part.ds_load
    from dolfinx import fem

    return min(timed_linear_solve(fem.form(a), fem.form(L), b.bcs, "lu", "sec_")
               for _ in range(2))


def table(out: dict) -> str:
    rows, unit = out["rows"], out["linear_solve_s"]
    lines = [f"Power-law bracket, {rows[0]['dofs']} unknowns (size {out['size']} mm), "
             f"{FORCE / 1e3:g} kN in one step, the elastic tangent factorized once; one linear "
             f"solve {unit:.2f} s.", "",
             "| method | iterations | contraction per iteration: all, first half, second half "
             "| time (s) | / linear solve | \\|u_load\\| (mm) |", "|---|---|---|---|---|---|"]
    for r in rows:
        first, second = r["contraction_halves"]
        lines.append(f"| {r['label']} | {r['iterations']} | {r['contraction']:.2f}, "
                     f"{first:.2f}, {second:.2f} | "
                     f"{r['time_s']:.2f} | {r['time_s'] / unit:.2f} | "
                     f"{r['load_point_displacement']:.6f} |")
    bfgs = [r for r in rows if r["label"].startswith("bfgs")]
    c = [r["contraction"] for r in rows]
    # superlinear convergence would contract faster in the second half than in the first
    linear = [r["label"] for r in rows
              if r["contraction_halves"][1] >= 0.8 * r["contraction_halves"][0]]
    faster = [r["label"] for r in rows if r["label"] not in linear]
    text = f"Contraction per iteration {min(c):.2f} to {max(c):.2f}."
    if linear:
        text += (" As fast in the second half of the iterations as in the first (linear "
                 f"convergence): {'; '.join(linear)}.")
    if len({r["iterations"] for r in bfgs}) == 1 and len(bfgs) > 1:
        text += (f" BFGS takes {bfgs[0]['iterations']} iterations whatever pairs it keeps: "
                 "the elastic tangent differs from the current one over the whole softened "
                 "zone, far beyond what its rank-two updates gather.")
    if faster:
        text += f" Faster in the second half, after a slower first: {'; '.join(faster)}."
    lines += ["", text + " Each iteration costs a residual assembly and a back-solve, so 1.5 "
              "linear solves would leave half a linear solve for all of them."]
    return "\n".join(lines)


def main():
    args = options(__doc__, "a coarse mesh, one of each method")
    size = 12.0 if args.quick else 6.0
    bracket(size, "full")  # warm-up: the forms compiled
    rows = [bfgs(size, m) for m in ((30,) if args.quick else (30, 60, 100))]
    rows += [anderson(size, m) for m in ((10,) if args.quick else (5, 10, 20))]
    for r in rows:
        print(f"{r['label']}: {r['iterations']} iterations, {r['time_s']:.2f} s", flush=True)
    publish("secant", {"size": size, "rows": rows, "linear_solve_s": linear_solve(size)},
            table, args)


if __name__ == "__main__":
    main()
