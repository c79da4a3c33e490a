"""Path following: arc-length continuation against load control with cut-back.

A. The shallow arch (snap-through at a limit point, `scenes.arch`, the closed form of
   `theory.arch`): to 1.5 times the limit load, on the inverted branch. Arc-length with
   each Newton variant; load control with step cut-back, which has no state beyond the
   limit point to go to.
B. The buckling beam (`scenes.beam`), perfect (no imperfection): to 1.5 P_cr. Arc-length
   with each variant (the bifurcation is found by the tangent's inertia and left along its
   mode); load control with cut-back as the beam scene does it (the end state checked and,
   if unstable, kicked along its mode by the elastica's deflection: a closed form).

Per run: steps, iterations, factorizations (and the stability checks' own), wall time and
the error against the reference. Writes benchmarks/results/continuation.json and, with
--update-readme, the README table.
"""

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from common import machine, options, publish
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.scenes.arch import ShallowArch
from fenics_nl.scenes.beam import build_beam
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


def row(problem, control, method, t0, path=None, error=None, note=""):
    """One table row from a path (ContinuationPath or LoadPath) and its error."""
    r = {"problem": problem, "control": control, "newton": method,
         "time_s": time.perf_counter() - t0, "error": error, "note": note}
    if path is not None:
        r.update(steps=len(path.factors), iterations=path.iterations,
                 factorizations=path.work.factorizations, cuts=path.failures,
                 inertia=getattr(path, "inertia_factorizations", 0),
                 critical=[(c.kind, round(c.factor, 4))
                           for c in getattr(path, "critical_points", [])])
    say(f"{problem:5s} {control:10s} {method:8s} {r['time_s']:7.2f} s "
        + (f"{r['steps']} steps, {r['iterations']} its, {r['factorizations']} fact. "
           if path is not None else "") + f"error {error} {note}")
    return r


def arch_runs(slenderness):
    rows = []
    q_lim = arch_theory.limit_load(RISE)

    def arch():
        return ShallowArch(1.0, 1.0 / slenderness, RISE, 1e3, 0.3)

    for method in VARIANTS:
        a = arch()
        solver = NewtonSolver(a.residual, a.u, a.bcs, method=method, rtol=1e-8, atol=1e-8,
                              max_it=30 if method == "full" else 300, prefix=f"b_{method}_")
        t0 = time.perf_counter()
        try:
            path = ArcLength(solver, a.set_load, arc_length=0.2, max_arc_length=1.0,
                             prefix="b_arc_").run(TARGET * q_lim, 500)
        except SolveError as err:
            rows.append(row("arch", "arc-length", method, t0, note=str(err)[:80]))
            continue
        limit = next(c.factor for c in path.critical_points if c.kind == "limit")
        rows.append(row("arch", "arc-length", method, t0, path, limit / q_lim - 1,
                        "limit load error"))
    for method in VARIANTS:
        a = arch()
        solver = NewtonSolver(a.residual, a.u, a.bcs, method=method, rtol=1e-8, atol=1e-8,
                              max_it=30 if method == "full" else 300, prefix=f"b_{method}_")
        t0 = time.perf_counter()
        try:
            path = solve_incrementally(solver, lambda t, a=a: a.set_load(t * TARGET * q_lim),
                                       20)
            rise = a.midspan_rise()
            error = (arch_theory.load(rise, RISE) - TARGET * q_lim) / q_lim
            rows.append(row("arch", "load", method, t0, path, error,
                            "reached the target by a jump past the limit point (no path "
                            "between): error of the end state"))
        except SolveError as err:
            rows.append(row("arch", "load", method, t0, note=f"stopped: {str(err)[:90]}"))
    return rows


def beam_runs():
    rows = []
    for method in VARIANTS:
        b = build_beam(1.0, 0.02, 1e3, 0.3, imperfection=0.0)
        t0 = time.perf_counter()
        try:
            path = b.solve_arc_length(TARGET, method)
        except SolveError as err:
            rows.append(row("beam", "arc-length", method, t0, note=str(err)[:80]))
            continue
        error = math.degrees(abs(b.tip()["rotation"]) - elastica.tip_rotation(TARGET))
        switched = "switched at its bifurcation" if path.switched else "no bifurcation met"
        rows.append(row("beam", "arc-length", method, t0, path, error,
                        f"tip rotation error [deg]; {switched}"))
    for method in VARIANTS:
        b = build_beam(1.0, 0.02, 1e3, 0.3, imperfection=0.0)
        t0 = time.perf_counter()
        try:
            path, switched = b.solve_path(TARGET, 40, method)
        except SolveError as err:
            rows.append(row("beam", "load", method, t0, note=str(err)[:80]))
            continue
        error = math.degrees(abs(b.tip()["rotation"]) - elastica.tip_rotation(TARGET))
        rows.append(row("beam", "load", method, t0, path, error,
                        "tip rotation error [deg]; "
                        + ("kicked by the elastica" if switched else "no kick")))
    return rows


def table(out):
    lines = ["| problem | control | Newton | steps | iterations | factorizations (+ inertia) "
             "| time (s) | error | critical points found |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        crit = ", ".join(f"{k} {f:g}" for k, f in r.get("critical", [])) or "—"
        err = "—" if r["error"] is None else f"{r['error']:+.2e}"
        if "steps" in r:
            lines.append(f"| {r['problem']} | {r['control']} | {r['newton']} | {r['steps']} | "
                         f"{r['iterations']} | {r['factorizations']} (+{r['inertia']}) | "
                         f"{r['time_s']:.2f} | {err} | {crit} |")
        else:
            lines.append(f"| {r['problem']} | {r['control']} | {r['newton']} | — | — | — | "
                         f"{r['time_s']:.2f} | — | {r['note']} |")
    return "\n".join(lines)


def main():
    args = options(__doc__, "a coarse arch (L/h = 100) and the beam, fewer variants")
    out = {"machine": machine(comm.size), "rise": RISE, "target": TARGET}
    global VARIANTS
    if args.quick:
        VARIANTS = ("full", "bfgs")
    out["rows"] = arch_runs(100 if args.quick else 200) + beam_runs()
    publish("continuation", out, table, args, say)


if __name__ == "__main__":
    main()
