"""Arc-length continuation: ours (`solvers.arclength.ArcLength`) against PETSc's SNESNEWTONAL.

The shallow arch (`arch_model.py`, e/r = 3, its closed form in `theory.arch`) to 1.5 times its
limit load, through the snap-through. Both walk the same residual on the same mesh with full
Newton corrections and MUMPS; both stop at |R| <= tol |q|, q the target load vector,
tol = 1e-6 and 1e-7.

* ours: Crisfield's spherical constraint on the unknowns scaled by the first step's tangent,
  an adaptive arc, the tangent's inertia counted at every converged state (one LDLᵀ each),
  the limit points bracketed to 1/32 of the arc, the last step landed on the target;
* SNESNEWTONAL (petsc4py's `setNewtonALFunction`): the tangent load Q = −∂R/∂λ given, the
  constraint |Δx|² + ψ² Δλ² = s² on the raw unknowns, a fixed arc s (halved only when the
  quadratic has no real root), the normal or the exact correction; it stops at λ = 1 and
  knows nothing of stability. Its limit loads are read off the converged states it passes
  (the largest λ before the path turns down, the smallest before it turns up), to within
  one arc.

Per run: arc-length steps, Newton iterations, wall time, the limit loads found against the
closed form, the end state's error. Writes benchmarks/results/newtonal.json and, with
--update-docs, its table in docs/benchmarks.md.
"""

import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import ufl
from arch_model import ShallowArch
from common import machine, options, publish
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import arch as arch_theory

comm = MPI.COMM_WORLD
RISE, TARGET = 3.0, 1.5  # e/r; the end, in limit loads
# |R| <= tol |q|, q the target load vector: past the snap the internal forces' round-off
# reaches about 1e-7 |q| at L/h = 200 (1.1e-8 at L/h = 100)
TOLERANCES = (1e-6, 1e-7)
MAX_IT = 30  # Newton iterations of one corrector (ours: the same)


def say(msg):
    if comm.rank == 0:
        print(msg, flush=True)


def target_load(a: ShallowArch) -> PETSc.Vec:
    """q = −R(u = 0) at the target load: the dead load vector, zero on the pins."""
    a.set_load(TARGET * arch_theory.limit_load(RISE))
    q = petsc.assemble_vector(fem.form(a.residual))
    q.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    petsc.set_bc(q, a.bcs)
    q.scale(-1.0)
    a.set_load(0.0)
    return q


def ours(slenderness: float, arc: float, tol: float) -> dict:
    """ArcLength with full Newton; its limit points are those it brackets."""
    a = ShallowArch(1.0, 1.0 / slenderness, RISE, 1e3, 0.3)
    q_lim = arch_theory.limit_load(RISE)
    solver = NewtonSolver(a.residual, a.u, a.bcs, method="full", rtol=1e-14, atol=tol,
                          force_scale=target_load(a).norm(), max_it=MAX_IT,
                          prefix="al_ours_")
    t0 = time.perf_counter()
    path = ArcLength(solver, a.set_load, arc_length=arc, max_arc_length=1.0,
                     prefix="al_ours_arc_").run(TARGET * q_lim, 500)
    limits = [c.factor / q_lim for c in path.critical_points if c.kind == "limit"]
    end = (arch_theory.load(a.midspan_rise(), RISE) - TARGET * q_lim) / q_lim
    return {"solver": "ArcLength (ours)", "tolerance": tol, "arc": arc, "steps": len(path.factors),
            "iterations": path.iterations, "factorizations": path.work.factorizations,
            "inertia_factorizations": path.inertia_factorizations,
            "time_s": time.perf_counter() - t0,
            "limit_loads": limits, "end_error": end, "dofs": a.dofs}


def newtonal(slenderness: float, step: float, psisq: float, correction: str, tol: float
             ) -> dict:
    """SNESNEWTONAL on the same residual: λ ∈ [0, 1] scales the target load."""
    a = ShallowArch(1.0, 1.0 / slenderness, RISE, 1e3, 0.3)
    q_lim = arch_theory.limit_load(RISE)
    F, J = fem.form(a.residual), fem.form(ufl.derivative(a.residual, a.u))
    x = a.u.x.petsc_vec
    b, A = petsc.create_vector(a.V), petsc.create_matrix(J)
    Q0 = target_load(a)  # Q = −∂R/∂λ: the dead load is linear in λ
    states = []  # converged (λ, ā)

    def residual(snes, X, R):
        lam = snes.getNewtonALLoadParameter()
        a.set_load(lam * TARGET * q_lim)
        X.copy(x)
        x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        with R.localForm() as r:
            r.set(0.0)
        petsc.assemble_vector(R, F)
        petsc.apply_lifting(R, [J], bcs=[a.bcs], x0=[X], alpha=-1.0)
        R.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        petsc.set_bc(R, a.bcs, X, -1.0)

    def tangent(snes, X, A_, P):
        A_.zeroEntries()
        petsc.assemble_matrix(A_, J, bcs=a.bcs)
        A_.assemble()

    def tangent_load(snes, X, Q):
        Q0.copy(Q)

    def monitor(snes, it, norm):
        if it > 0 and norm <= tol * Q0.norm():
            states.append((snes.getNewtonALLoadParameter() * TARGET, a.midspan_rise()))

    snes = PETSc.SNES().create(comm)
    snes.setType("newtonal")  # before its tangent load function, which it keeps
    snes.setOptionsPrefix("al_snes_")
    opts = PETSc.Options("al_snes_")
    for k, v in {"snes_newtonal_step_size": step,
                 "snes_newtonal_psisq": psisq, "snes_newtonal_correction_type": correction,
                 "snes_newtonal_max_continuation_steps": 2000, "snes_max_it": MAX_IT,
                 "snes_atol": tol * Q0.norm(), "snes_rtol": 0.0, "snes_stol": 0.0,
                 "ksp_type": "preonly", "pc_type": "lu",
                 "pc_factor_mat_solver_type": "mumps"}.items():
        opts[k] = v
    snes.setFunction(residual, b)
    snes.setJacobian(tangent, A)
    snes.setNewtonALFunction(tangent_load)
    snes.setMonitor(monitor)
    snes.setFromOptions()
    t0 = time.perf_counter()
    snes.solve(None, x.copy())
    wall = time.perf_counter() - t0
    for k in list(opts.getAll()):
        opts.delValue(k)
    lam = [s[0] for s in states]
    limits = [lam[i] for i in range(1, len(lam) - 1)
              if (lam[i] - lam[i - 1]) * (lam[i + 1] - lam[i]) < 0]
    reason = snes.getConvergedReason()
    say(f"  SNESNEWTONAL s = {step:g}, ψ² = {psisq:g}, {correction}: reason {reason} at "
        f"λ = {snes.getNewtonALLoadParameter() * TARGET:.4g} limit loads, {len(states)} steps")
    end = ((arch_theory.load(a.midspan_rise(), RISE) - TARGET * q_lim) / q_lim
           if reason > 0 else None)
    return {"solver": f"SNESNEWTONAL ({correction})", "tolerance": tol, "arc": step, "psisq": psisq,
            "steps": len(states), "iterations": snes.getIterationNumber(),
            # a tangent assembled and factorized at every iteration (two solves on it)
            "factorizations": snes.getIterationNumber(), "inertia_factorizations": 0,
            "time_s": wall, "limit_loads": limits, "end_error": end, "reason": reason,
            "dofs": a.dofs}


def table(out: dict) -> str:
    """The runs as a markdown table."""
    lines = [f"Shallow arch e/r = {RISE:g}, L/h = {out['slenderness']:g} (Q2, plane stress, "
             f"{out['rows'][0]['dofs']} unknowns), to {TARGET:g} limit loads; full Newton, "
             "MUMPS, |R| <= tol |q|, q the target load vector. Limit loads in units of the "
             "closed form's (1.000 is exact).", "",
             "| tol | solver | arc | steps | Newton iterations | factorizations (+ inertia) | "
             "time (s) | limit loads found | end error |", "|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        arc = f"{r['arc']:g}" + (f", ψ² = {r['psisq']:g}" if "psisq" in r else "")
        limits = ", ".join(f"{x:.4f}" for x in r["limit_loads"]) or "none"
        end = "not reached" if r["end_error"] is None else f"{r['end_error']:.1e}"
        lines.append(f"| {r['tolerance']:g} | {r['solver']} | {arc} | {r['steps']} | "
                     f"{r['iterations']} | "
                     f"{r['factorizations']} (+{r['inertia_factorizations']}) | "
                     f"{r['time_s']:.2f} | {limits} | {end} |")
    return "\n".join(lines)


def main():
    args = options(__doc__, "the stockier arch (L/h = 100)")
    slenderness = 100 if args.quick else 200
    out = {"machine": machine(comm.size), "slenderness": slenderness, "rows": []}
    for tol in TOLERANCES:
        out["rows"].append(ours(slenderness, 0.2, tol))
        for step, psisq, correction in ((0.002, 1.0, "normal"), (0.002, 0.0, "normal"),
                                        (0.002, 0.0, "exact"), (0.004, 0.0, "normal"),
                                        (0.008, 0.0, "normal")):
            out["rows"].append(newtonal(slenderness, step, psisq, correction, tol))
    publish("newtonal", out, table, args, say)


if __name__ == "__main__":
    main()
