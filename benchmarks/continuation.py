"""Path following: arc-length continuation against load control with cut-back.

A. The shallow arch (snap-through at a limit point, `arch_model.py`, the closed form of
   `theory.arch`): to 1.5 times the limit load, on the inverted branch. Arc-length with
   each Newton variant; load control with step cut-back, which has no state beyond the
   limit point to go to.
B. The buckling beam (`continuation_problems.py`), perfect (no imperfection): to 1.5
   P_cr. Arc-length with each variant (the bifurcation is found by the tangent's inertia
   and left along its mode); load control with cut-back as the buckling demo does it (the
   end state checked and, if unstable, kicked along its mode by the elastica's deflection:
   a closed form).

Per run: steps, iterations, factorizations (and the stability checks' own), wall time and
the error against the reference. Writes benchmarks/results/continuation.json and, with
--update-docs, the README table.
"""

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from arch_model import ShallowArch
from common import machine, options, publish
from continuation_problems import BucklingBeam
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import arch as arch_theory
from fenics_nl.theory import elastica

comm = MPI.COMM_WORLD
VARIANTS = ("full", "periodic", "bfgs", "modified")
RISE, TARGET = 3.0, 1.5  # the arch's e/r; the target, in limit loads (arch) or P_cr (beam)


def say(msg):
    if comm.rank == 0:
        print(msg, flush=True)


def row(problem, control, method, t0, path=None, end_error=None, unstable=0, note=""):
    """One table row from a path (ContinuationPath or LoadPath): its work, the critical
    points it found, its states on unstable branches and its end state's error."""
    r = {"problem": problem, "control": control, "newton": method,
         "time_s": time.perf_counter() - t0, "end_error": end_error, "unstable_states": unstable,
         "note": note}
    if path is not None:
        r.update(steps=len(path.factors), iterations=path.iterations,
                 factorizations=path.work.factorizations, cuts=path.failures,
                 inertia=getattr(path, "inertia_factorizations", 0),
                 critical=[(c.kind, round(c.factor, 4))
                           for c in getattr(path, "critical_points", [])])
    say(f"{problem:5s} {control:10s} {method:8s} {r['time_s']:7.2f} s "
        + (f"{r['steps']} steps, {r['iterations']} its, {r['factorizations']} fact. "
           if path is not None else "") + f"end error {end_error} {note}")
    return r


def arch_runs(slenderness):
    """The arch to 1.5 limit loads; errors in limit loads (closed form)."""
    rows = []
    q_lim, a_lim = arch_theory.limit_load(RISE), arch_theory.limit_rise(RISE)
    for control in ("arc-length", "load"):
        for method in VARIANTS:
            a = ShallowArch(1.0, 1.0 / slenderness, RISE, 1e3, 0.3)
            solver = NewtonSolver(a.residual, a.u, a.bcs, method=method, rtol=1e-8, atol=1e-8,
                                  max_it=30 if method == "full" else 300,
                                  prefix=f"b_{method}_")
            rises = []

            def record(lam, result, a=a, rises=rises):
                rises.append(a.midspan_rise())

            t0 = time.perf_counter()
            try:
                if control == "arc-length":
                    path = ArcLength(solver, a.set_load, arc_length=0.2, max_arc_length=1.0,
                                     prefix="b_arc_").run(TARGET * q_lim, 500, on_step=record)
                else:
                    path = solve_incrementally(
                        solver, lambda t, a=a: a.set_load(t * TARGET * q_lim), 20,
                        on_step=record)
            except SolveError as err:
                rows.append(row("arch", control, method, t0, note=f"stopped: {str(err)[:90]}"))
                continue
            end = (arch_theory.load(rises[-1], RISE) - TARGET * q_lim) / q_lim
            on_unstable = sum(abs(x) < a_lim for x in rises)
            rows.append(row("arch", control, method, t0, path, end, on_unstable))
    return rows


def beam_runs():
    """The perfect beam to 1.5 P_cr; the end state's tip rotation error [deg]."""
    rows = []
    for control in ("arc-length", "load"):
        for method in VARIANTS:
            b = BucklingBeam(1.0, 0.02, 1e3, 0.3, imperfection=0.0)
            t0 = time.perf_counter()
            try:
                if control == "arc-length":
                    path = b.solve_arc_length(TARGET, method)
                    note = ("left the bifurcation along its mode" if path.switched
                            else "met no bifurcation")
                else:
                    path, switched = b.solve_path(TARGET, 40, method)
                    note = "kicked by the elastica's deflection" if switched else "no kick"
            except SolveError as err:
                rows.append(row("beam", control, method, t0, note=f"stopped: {str(err)[:90]}"))
                continue
            error = math.degrees(abs(b.tip()["rotation"]) - elastica.tip_rotation(TARGET))
            rows.append(row("beam", control, method, t0, path, error, note=note))
    return rows


def table(out):
    lines = [f"Shallow arch e/r = {out['rise']:g}, L/h = {out['slenderness']:g} (Q2, plane "
             f"stress), to {out['target']:g} limit loads (closed form: "
             f"{arch_theory.limit_load(out['rise']):.4f} EI k⁴ r); end error: the closed "
             "form's load at the computed end rise, less the target, in limit loads. Perfect "
             "beam L/h = "
             f"50 (Q2) to {out['target']:g} P_cr; end error: tip rotation less the "
             "elastica's [deg]. Unstable states: converged states between the arch's limit "
             "points.", "",
             "| problem | control | Newton | steps (cuts) | iterations | factorizations "
             "(+ inertia checks) | time (s) | critical points found | unstable states | "
             "end error | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        if "steps" not in r:
            lines.append(f"| {r['problem']} | {r['control']} | {r['newton']} | — | — | — | "
                         f"{r['time_s']:.2f} | — | — | — | {r['note']} |")
            continue
        crit = ", ".join(f"{k} {f:g}" for k, f in r["critical"]) or "—"
        unstable = r["unstable_states"] if r["problem"] == "arch" else "—"
        lines.append(f"| {r['problem']} | {r['control']} | {r['newton']} | {r['steps']} "
                     f"({r['cuts']}) | {r['iterations']} | {r['factorizations']} "
                     f"(+{r['inertia']}) | {r['time_s']:.2f} | {crit} | {unstable} | "
                     f"{r['end_error']:+.2e} | {r['note']} |")
    return "\n".join(lines)


def main():
    args = options(__doc__, "a coarse arch (L/h = 100) and the beam, fewer variants")
    global VARIANTS
    if args.quick:
        VARIANTS = ("full", "bfgs")
    slenderness = 100 if args.quick else 200
    out = {"machine": machine(comm.size), "rise": RISE, "target": TARGET,
           "slenderness": slenderness}
    out["rows"] = arch_runs(slenderness) + beam_runs()
    publish("continuation", out, table, args, say)


if __name__ == "__main__":
    main()
