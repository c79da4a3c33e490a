"""Arc-length on the iterative path: why the snap-through stays on MUMPS.

The shallow arch of `demos/snap_through.py` (L/h = 200, e/r = 3, Q2, plane stress), refined
through its thickness (4, 8, 16 elements, aspect 4: 7k, 27k, 106k unknowns):

* one linear solve of its tangent at rest, K₀ x = q: CG + GAMG (drop threshold 0.05, the
  rigid-body near-nullspace) against MUMPS LU. The Krylov iterations do not grow under
  refinement (h-independent), but they are in the hundreds: a thin body's bending modes are
  the tangent's softest, ~(h/L)² of its membrane stiffness, and smoothed aggregation built
  on the rigid-body modes approximates them poorly;
* the arc-length path itself, 4 elements, full Newton, limit points from the sign of Δλ (no
  LDLᵀ inertia checks: they would factorize anyway): MUMPS against GMRES + GAMG (right-
  preconditioned: past the limit point the tangent is indefinite, where CG diverges), each
  as far as it goes in STEPS steps.

    python benchmarks/arch_iterative.py [--quick] [--update-docs]

About 70 s on 1 core; --quick: 4 elements only, 8 steps, nothing written.
"""

import dataclasses
import sys
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import ufl
from arch_model import ShallowArch
from common import machine, options, publish
from dolfinx import fem
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.solvers.arclength import ArcLength, ContinuationError
from fenics_nl.solvers.linear_solver import create_ksp, rigid_body_modes
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.result import WorkCounts
from fenics_nl.theory import arch as theory

RISE, STEPS = 3.0, 20
THRESHOLD = {"pc_gamg_threshold": 0.05}  # 40-60 % fewer CG iterations than 0 here


def arch(elements: int) -> ShallowArch:
    return ShallowArch(1.0, 1 / 200, RISE, 1e3, 0.3, elements=elements, aspect=4.0)


def set_options(prefix: str, values: dict) -> None:
    for k, v in values.items():
        PETSc.Options()[f"{prefix}{k}"] = v


def linear_solve(elements: int) -> dict:
    """K₀ x = q (the load at λ = 1) by MUMPS LU and by CG + GAMG to 1e-8."""
    a = arch(elements)
    a.set_load(1.0)
    K = petsc.assemble_matrix(fem.form(ufl.derivative(a.residual, a.u)), bcs=a.bcs)
    K.assemble()
    b = petsc.assemble_vector(fem.form(a.residual))
    b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    petsc.set_bc(b, a.bcs)
    out = {"elements": elements, "dofs": a.dofs}
    set_options("lin_gamg_", THRESHOLD)
    for kind in ("lu", "gamg"):
        ksp = create_ksp(K, kind, f"lin_{kind}_", rigid_body_modes(a.V), rtol=1e-8)
        x = b.duplicate()
        t = time.perf_counter()
        ksp.solve(b, x)
        out[kind] = {"time_s": time.perf_counter() - t,
                     "iterations": ksp.getIterationNumber(),
                     "reason": ksp.getConvergedReason()}
        ksp.destroy()
        x.destroy()
    return out


def path(kind: str, steps: int) -> dict:
    """The arc-length path (4 elements) for `steps` steps or until it fails; the work of
    its converged steps (a failed step's is not kept by the error)."""
    a = arch(4)
    prefix = f"arch_{kind}_"
    if kind == "gamg":
        set_options(prefix, THRESHOLD)
    solver = NewtonSolver(a.residual, a.u, a.bcs, method="full", rtol=1e-8, atol=1e-8,
                          max_it=30, linear_solver=kind, indefinite=True, prefix=prefix)
    arc = ArcLength(solver, a.set_load, arc_length=0.2, max_arc_length=1.0, detect=False,
                    prefix=f"{prefix}continuation_")
    states, work, error = [], WorkCounts(), None

    def record(lam, result):
        states.append(lam)
        work.add(result.work)

    t = time.perf_counter()
    try:
        arc.run(1.5 * theory.limit_load(RISE), steps, on_step=record)
    except ContinuationError as err:
        error = str(err).split(";")[0] if "not reached" not in str(err) else None
    peak = max(states)
    return {"kind": kind, "dofs": a.dofs, "wall_time_s": time.perf_counter() - t,
            "steps": len(states), "largest_load_factor": peak,
            "past_the_limit_point": states[-1] < peak, "error": error,
            "work": dataclasses.asdict(work)}


def table(out: dict) -> str:
    lines = ["One solve of the arch's tangent at rest, K₀ x = q (to 1e-8):", "",
             "| elements through h | unknowns | MUMPS LU (s) | CG + GAMG its | CG + GAMG (s) |",
             "|---|---|---|---|---|"]
    for r in out["linear"]:
        lines.append(f"| {r['elements']} | {r['dofs']} | {r['lu']['time_s']:.3f} | "
                     f"{r['gamg']['iterations']} | {r['gamg']['time_s']:.2f} |")
    lines += ["", f"The arc-length path, {out['paths'][0]['dofs']} unknowns, at most "
              f"{out['steps']} steps (limit load {theory.limit_load(RISE):.4g} in the closed "
              "form; the continuum's is within about 1 % of it):", "",
              "| linear solver | steps | largest λ | linear solves | Krylov its | factorizations "
              "/ AMG set-ups | time (s) | stopped by |", "|---|---|---|---|---|---|---|---|"]
    for r in out["paths"]:
        w = r["work"]
        past = " (past it)" if r["past_the_limit_point"] else ""
        lines.append(f"| {'MUMPS LU' if r['kind'] == 'lu' else 'GMRES + GAMG'} | "
                     f"{r['steps']} | {r['largest_load_factor']:.4f}{past} | "
                     f"{w['linear_solves']} | {w['krylov_iterations']} | "
                     f"{w['factorizations']} | "
                     f"{r['wall_time_s']:.1f} | {r['error'] or 'the step limit'} |")
    return "\n".join(lines)


def main() -> int:
    args = options(__doc__, "4 elements only, 8 steps, nothing written")
    steps = 8 if args.quick else STEPS
    out = {"machine": machine(), "steps": steps,
           "linear": [linear_solve(n) for n in ((4,) if args.quick else (4, 8, 16))],
           "paths": [path(kind, steps) for kind in ("lu", "gamg")]}
    publish("arch_iterative", out, table, args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
