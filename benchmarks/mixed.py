"""Near-incompressibility: the displacement formulation against Taylor–Hood (u, p).

Three problems, each at ν = 0.3, 0.49, 0.499 and 0.5 (0.5: the mixed formulation only):

* **punch** (small strain): the default axisymmetric Hertz punch (R = 1, δ = 0.01, h =
  a/40), P1 and P2 displacements against P2–P1, the force's error against Hertz; and the
  mixed punch's saddle point factorized by MUMPS LU against LDLᵀ (``cholesky``);
* **neo-Hookean cylinder** (finite strain): the thick cylinder a = 1, b = 2 in plane strain
  inflated by δ = a/2 in one step, P2 displacements against P2–P1 on the same mesh
  (h = 0.1), the inner pressure against the incompressible closed form
  p = μ ln(λ_a/λ_b) + μc/2 (1/a² − 1/b²) (exact at ν = 0.5 only: below it, the gap is also
  the material's compressibility);
* **beam** (finite strain, bending): the buckling cantilever in plane strain (L/h = 50, Q2 or
  Q2–Q1, 2·2^refine elements through the height), SLEPc's critical load against Euler's
  (P_cr is also ~0.15 % above Euler at ν → 1/2 on fine meshes: the clamp's 2D effect).

Time is the solve's (the forms compiled by a first run of each configuration).

    python benchmarks/mixed.py [--quick] [--update-docs]
"""

from __future__ import annotations

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import ufl
from common import machine, options, publish
from continuation_problems import BucklingBeam
from plasticity_problems import thick_vessel
from punch_problem import build_punch

from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, NeoHookean
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import hertz

POISSON = (0.3, 0.49, 0.499, 0.5)


def punch(nu: float, use_mixed: bool, refine: int, degree: int | None = None,
          linear_solver: str | None = None) -> dict:
    R, delta = 1.0, 0.01
    options = {"newton_options": {"linear_solver": linear_solver}} if linear_solver else {}
    p = build_punch("axisymmetric", LinearElastic(1.0, nu), R, math.sqrt(R * delta),
                    refine=refine, mixed=use_mixed, degree=degree, **options)
    t0 = time.perf_counter()
    state = p.indent(delta)
    spent = time.perf_counter() - t0
    exact = hertz.sphere_from_indentation(1.0, nu, R, delta)["force"]
    return {"dofs": p.dofs, "time_s": spent, "error": state.force / exact - 1,
            "force": state.force, "newton_iterations": state.newton_iterations,
            "active_set_iterations": state.active_set_iterations,
            "elements": "P2-P1" if use_mixed else f"P{degree or 1}"}


def punch_p2(nu: float, use_mixed: bool, refine: int) -> dict:
    """The punch with P2 displacements: is Taylor–Hood's gain just the degree?"""
    return punch(nu, False, refine, degree=2)


def punch_factorizations(nu: float, refine: int) -> list[dict]:
    """The mixed punch, its saddle point factorized by MUMPS LU and LDLᵀ."""
    rows = []
    for solver in ("lu", "cholesky"):
        punch(nu, True, refine, linear_solver=solver)  # warm-up
        r = punch(nu, True, refine, linear_solver=solver)
        r.update(nu=nu, linear=solver)
        print(r, flush=True)
        rows.append(r)
    return rows


def beam(nu: float, use_mixed: bool, refine: int) -> dict:
    b = BucklingBeam(1.0, 0.02, 1e3, nu, plane="strain", refine=refine, mixed=use_mixed)
    t0 = time.perf_counter()
    P_cr = b.critical_loads(1)[0][0]
    return {"dofs": b.dofs, "time_s": time.perf_counter() - t0,
            "error": P_cr / b.P_euler - 1, "newton_iterations": "-"}


def incompressible_cylinder_pressure(a: float, A: float, B: float, mu: float) -> float:
    c = a * a - A * A
    b = math.sqrt(B * B + c)
    return mu * math.log((a / A) / (b / B)) + 0.5 * mu * c * (1 / a**2 - 1 / b**2)


def cylinder(nu: float, use_mixed: bool, h: float) -> dict:
    A, B, E, delta = 1.0, 2.0, 3.0, 0.5
    law = NeoHookean(E, nu)
    body = thick_vessel("cylinder", A, B, size=h, mixed=use_mixed)
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
    body = thick_vessel("cylinder", A, B, size=h, mixed=True)
    m = body.mixed
    dx = kinematics.quadrature_measure("dx", body.mesh, 4)
    R = (mixed.internal_work(law, m.u, m.p, m.v, m.q, body.model) * dx
         + 1e-3 * ufl.dot(body.normal, m.v) * body.ds_inner)
    extra = ({"preconditioner": mixed.preconditioner(law, m.W, body.model, dx)}
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
                        ("punch_p2", "punch, force vs Hertz"),
                        ("cylinder", "neo-Hookean cylinder, p(a) vs incompressible"),
                        ("beam", "beam, P_cr vs Euler (plane strain)")):
        for r in out[name]:
            if r.get("failed"):
                lines.append(f"| {title} | {r['nu']} | {r['formulation']} | {r['dofs']} | "
                             f"failed: {r['failed']} | | |")
                continue
            formulation = r["formulation"] + (f" {r['elements']}" if "elements" in r else "")
            lines.append(f"| {title} | {r['nu']} | {formulation} | {r['dofs']} | "
                         f"{r['newton_iterations']} | {r['time_s']:.2f} | "
                         f"{100 * r['error']:+.3f} % |")
    lines += ["", "`python benchmarks/mixed.py`; the displacement formulation refuses ν = 0.5 "
              "(one-line error), so it has no row there. The beam's time is the critical "
              "load's (one linear solve and SLEPc), not a Newton solve."]
    if out.get("punch_factorizations"):
        lu, ldlt = out["punch_factorizations"]
        lines += ["", f"The mixed punch at ν = {lu['nu']} ({lu['dofs']} unknowns) with MUMPS LU: "
                  f"{lu['time_s']:.2f} s; with LDLᵀ: {ldlt['time_s']:.2f} s "
                  f"({ldlt['time_s'] / lu['time_s']:.2f}x), the same force to "
                  f"{abs(ldlt['force'] / lu['force'] - 1):.0e}."]
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
    args = options(__doc__, "coarse meshes, nothing written")
    refine, h = (0, 0.2) if args.quick else (1, 0.1)
    out = {"machine": machine()}
    for name, problem, size in (("punch", punch, refine), ("cylinder", cylinder, h),
                                ("beam", beam, 0)):
        out[name] = [run(problem, nu, m, size) for nu in POISSON for m in (False, True)
                     if m or nu < 0.5]
    out["punch_p2"] = [run(punch_p2, nu, False, refine) for nu in POISSON if nu < 0.5]
    out["beam_fine"] = [run(beam, 0.499, True, 2)]  # what the beam's P_cr tends to
    out["punch_factorizations"] = punch_factorizations(0.5, refine)
    sizes = [0.05] if args.quick else [0.025, 0.0125]
    linear_solvers(0.3, "lu", 0.2), linear_solvers(0.3, "gamg", 0.2)  # forms compiled
    out["linear_solvers"] = [linear_solvers(nu, s, h) for h in sizes for nu in POISSON
                             for s in ("lu", "gamg")]
    publish("mixed", out, table, args)


if __name__ == "__main__":
    main()
