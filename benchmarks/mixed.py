"""Near-incompressibility: the displacement formulation against Taylor–Hood (u, p).

Two problems, each at ν = 0.3, 0.49, 0.499 and 0.5 (0.5: the mixed formulation only):

* **punch** (small strain): the default axisymmetric Hertz punch (R = 1, δ = 0.01, h =
  a/40), P1 displacements against P2–P1, the force's error against Hertz;
* **neo-Hookean cylinder** (finite strain): the thick cylinder a = 1, b = 2 in plane strain
  inflated by δ = a/2 in one step, P2 displacements against P2–P1 on the same mesh
  (h = 0.1), the inner pressure against the incompressible closed form
  p = μ ln(λ_a/λ_b) + μc/2 (1/a² − 1/b²) (exact at ν = 0.5 only: below it, the gap is also
  the material's compressibility).

Time is the solve's (the forms compiled by a first run of each configuration).

    python benchmarks/mixed.py [--quick] [--update-readme]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import ufl
from common import elapsed, machine, update_readme

from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, NeoHookean
from fenics_nl.scenes.punch import build_punch
from fenics_nl.scenes.vessel import VesselBody
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import hertz

HERE = Path(__file__).resolve().parent
POISSON = (0.3, 0.49, 0.499, 0.5)


def punch(nu: float, use_mixed: bool, refine: int) -> dict:
    R, delta = 1.0, 0.01
    p = build_punch("axisymmetric", LinearElastic(1.0, nu), R, math.sqrt(R * delta),
                    refine=refine, mixed=use_mixed)
    t0 = time.perf_counter()
    state = p.indent(delta)
    spent = time.perf_counter() - t0
    exact = hertz.sphere_from_indentation(1.0, nu, R, delta)["force"]
    return {"dofs": p.dofs, "time_s": spent, "error": state.force / exact - 1,
            "newton_iterations": state.newton_iterations,
            "active_set_iterations": state.active_set_iterations}


def incompressible_cylinder_pressure(a: float, A: float, B: float, mu: float) -> float:
    c = a * a - A * A
    b = math.sqrt(B * B + c)
    return mu * math.log((a / A) / (b / B)) + 0.5 * mu * c * (1 / a**2 - 1 / b**2)


def cylinder(nu: float, use_mixed: bool, h: float) -> dict:
    A, B, E, delta = 1.0, 2.0, 3.0, 0.5
    law = NeoHookean(E, nu)
    body = VesselBody("cylinder", A, B, size=h, mixed=use_mixed)
    dx = kinematics.quadrature_measure("dx", body.mesh, 4)
    if use_mixed:
        m = body.mixed
        R = mixed.internal_work(law, m.u, m.p, m.v, m.q, body.model) * dx
    else:
        R = law.internal_work(body.u, ufl.TestFunction(body.V), body.model) * dx
    body.move_inner(delta)
    solver = NewtonSolver(R, body.unknown, [*body.supports, body.inner_motion], rtol=1e-12,
                          atol=1e-12, force_scale=law.mu * A, max_it=30)
    t0 = time.perf_counter()
    try:
        result = solver.solve()
    except Exception as err:  # a locking or diverging run is a result
        return {"dofs": body.dofs, "failed": str(err).splitlines()[0]}
    spent = time.perf_counter() - t0
    p = body.pressure_from(R, inner_radius=A + delta)
    exact = incompressible_cylinder_pressure(A + delta, A, B, law.mu)
    return {"dofs": body.dofs, "time_s": spent, "error": p / exact - 1,
            "newton_iterations": result.iterations}


def linear_solvers(nu: float, linear: str, h: float) -> dict:
    """The incompressible Lamé cylinder (linear, mixed): MUMPS LU or MINRES + blocks."""
    A, B, E = 1.0, 2.0, 3.0
    law = LinearElastic(E, nu)
    body = VesselBody("cylinder", A, B, size=h, mixed=True)
    m = body.mixed
    dx = kinematics.quadrature_measure("dx", body.mesh, 4)
    R = (mixed.internal_work(law, m.u, m.p, m.v, m.q, body.model) * dx
         + 1e-3 * ufl.dot(body.normal, m.v) * body.ds_inner)
    extra = ({"preconditioner": mixed.preconditioner(law, m, body.model, dx)}
             if linear == "gamg" else {})
    solver = NewtonSolver(R, body.unknown, body.supports, linear_solver=linear, rtol=1e-10,
                          atol=1e-10, force_scale=law.mu * A, prefix=f"mixed_{linear}_",
                          **extra)
    t0 = time.perf_counter()
    result = solver.solve()
    return {"dofs": body.dofs, "time_s": time.perf_counter() - t0,
            "krylov_iterations": result.work.krylov_iterations, "linear": linear, "nu": nu,
            "h": h}


def run(problem, nu, use_mixed, size):
    problem(nu, use_mixed, size)  # warm-up: the forms compiled
    r = problem(nu, use_mixed, size)
    r.update(nu=nu, formulation="mixed" if use_mixed else "displacement")
    print(r, flush=True)
    return r


def table(out: dict) -> str:
    lines = ["| problem | ν | formulation | unknowns | Newton iterations | time (s) | error |",
             "|---|---|---|---|---|---|---|"]
    for name, title in (("punch", "punch, force vs Hertz"),
                        ("cylinder", "neo-Hookean cylinder, p(a) vs incompressible")):
        for r in out[name]:
            if r.get("failed"):
                lines.append(f"| {title} | {r['nu']} | {r['formulation']} | {r['dofs']} | "
                             f"failed: {r['failed']} | | |")
                continue
            lines.append(f"| {title} | {r['nu']} | {r['formulation']} | {r['dofs']} | "
                         f"{r['newton_iterations']} | {r['time_s']:.2f} | "
                         f"{100 * r['error']:+.3f} % |")
    lines += ["", "`python benchmarks/mixed.py`; the displacement formulation refuses ν = 0.5 "
              "(one-line error), so it has no row there."]
    if out.get("linear_solvers"):
        lines += ["", "Direct against iterative on the mixed Lamé cylinder (linear, one solve):",
                  "", "| h | unknowns | ν | MUMPS LU (s) | MINRES + blocks (s) | "
                  "MINRES iterations |",
                  "|---|---|---|---|---|---|"]
        rows = out["linear_solvers"]
        for d in (r for r in rows if r["linear"] == "lu"):
            it = next(r for r in rows if r["linear"] == "gamg" and r["nu"] == d["nu"]
                      and r["h"] == d["h"])
            lines.append(f"| {d['h']:g} | {d['dofs']} | {d['nu']} | {d['time_s']:.2f} | "
                         f"{it['time_s']:.2f} | {it['krylov_iterations']} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarse meshes, nothing written")
    ap.add_argument("--update-readme", action="store_true")
    args = ap.parse_args()
    refine, h = (0, 0.2) if args.quick else (1, 0.1)
    out = {"machine": machine()}
    for name, problem, size in (("punch", punch, refine), ("cylinder", cylinder, h)):
        out[name] = [run(problem, nu, m, size) for nu in POISSON for m in (False, True)
                     if m or nu < 0.5]
    sizes = [0.05] if args.quick else [0.025, 0.0125]
    linear_solvers(0.3, "lu", 0.2), linear_solvers(0.3, "gamg", 0.2)  # forms compiled
    out["linear_solvers"] = [linear_solvers(nu, s, h) for h in sizes for nu in POISSON
                             for s in ("lu", "gamg")]
    out["benchmark_time_s"] = elapsed()
    text = table(out)
    print(text)
    if not args.quick:
        (HERE / "results" / "mixed.json").write_text(json.dumps(out, indent=2))
        if args.update_readme:
            update_readme("mixed", text)


if __name__ == "__main__":
    main()
