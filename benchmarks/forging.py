"""The 3D closed-die forging (`demos/forging.py`): the mesh's trend, and its size on 2 ranks.

A. The mesh: the demo's defaults (f = 0.2, 42 %) with tetrahedra of 2.0, 1.5 and 1.0 on one
   rank: the final load, die fill, flash, the Newton iterations, cuts and time, where the
   time went (assembly, factorization, solve).
   The coarse mesh again with 40 and 80 steps: the path's dependence on the step.
B. The size on 2 ranks: the 20k mesh's whole stroke with GMRES + GAMG (its Krylov
   iterations where the flash forms), in the demo's 20 steps and in 40; tetrahedra of 0.55
   (108 738 unknowns) over the first 8 % of the stroke, with GMRES + GAMG and with MUMPS
   LU: the time per Newton iteration of each, on the same mesh and steps; and the whole
   stroke there in 40 steps with GMRES + GAMG (about 11 minutes; in 20 steps it takes far
   longer, from the steps cut where the side meets the walls).
C. GAMG's smoother under GMRES on the 20k mesh's first 8 % (2 ranks): SOR, the library's
   choice for GMRES, against PETSc's Chebyshev (by option): Krylov iterations, solve time.
D. What GAMG's iterations grow with where the side meets the walls (reduction > 0.3): the
   20k mesh's whole stroke on 2 ranks (B's run) against the same stroke with the plastic
   flow 50 times stiffer (H = 50 000: the tangent far from incompressible) and with the
   penalty 10 times softer: Krylov iterations a Newton iteration of the converged steps,
   before and after reduction 0.3, and a solve in the attempts of the steps that were cut.
   (The other runs' physics differs: a diagnosis, not a variant.)

Writes benchmarks/results/forging_3d.json and, with --update-docs, its section of
docs/benchmarks.md.
"""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from common import ROOT, machine, options, publish

PHASES = ("residual", "tangent", "factorization", "solve")


def say(msg):
    print(msg, flush=True)


def demo_run(ranks, *args):
    """The demo's JSON from `mpiexec -n ranks` with `args`."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "f.json"
        cmd = [str(ROOT / ".venv" / "bin" / "mpiexec"), "-n", str(ranks), sys.executable,
               str(ROOT / "demos" / "forging.py"), *map(str, args), "--json", str(out)]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        return json.loads(out.read_text())


def row(d, **given):
    keep = ("dofs", "ranks", "force", "die_fill", "flash_reach", "flash_fraction",
            "force_over_slab", "volume_change", "newton_iterations", "step_cuts",
            "linear_solves", "krylov_iterations", "solve_time_s", "wall_time_s")
    r = {**given, **{k: d[k] for k in keep}}
    r["time_by_phase_s"] = {k: d[f"{k}_phase_time_s"] for k in PHASES}
    r["per_linear_solve_s"] = d["solve_time_s"] / max(d["linear_solves"], 1)
    return r


def mesh_runs(quick):
    rows = []
    runs = [(2.0, ())] if quick else [(2.0, ()), (1.5, ()), (1.0, ()), (2.0, ("--steps", "40")),
                                      (2.0, ("--steps", "80"))]
    for size, extra in runs:
        r = row(demo_run(1, "--size", size, *extra), size=size, linear_solver="lu",
                flags=" ".join(extra) or "the demo's")
        say(f"size {size}: {r['dofs']} unknowns, F = {r['force']:.6g}, fill "
            f"{r['die_fill']:.3f}, {r['newton_iterations']} Newton, {r['step_cuts']} cuts, "
            f"{r['solve_time_s']:.1f} s")
        rows.append(r)
    return rows


def size_runs(quick):
    start, fine = ("--reduction", "0.034", "--steps", "2"), ("--steps", "40")
    small, large = (1.2, 1.2) if quick else (1.0, 0.55)
    runs = [(small, "gamg", ()), (small, "gamg", fine), (large, "gamg", start),
            (large, "lu", start), (large, "gamg", fine)]
    rows, stroke = [], None
    for size, solver, extra in runs:
        d = demo_run(2, "--size", size, "--linear-solver", solver, *extra)
        stroke = stroke or d  # the first: the whole stroke, D's reference
        r = row(d, size=size, linear_solver=solver, flags=" ".join(extra) or "the demo's")
        say(f"size {size}, {solver}, {r['flags']}: {r['dofs']} unknowns on 2 ranks, "
            f"{r['linear_solves']} linear solves, {r['per_linear_solve_s']:.2f} s each, "
            f"{r['solve_time_s']:.1f} s")
        rows.append(r)
    return rows, stroke


CHEBYSHEV = ("-forging_mg_levels_ksp_type", "chebyshev", "-forging_mg_levels_pc_type",
             "jacobi")


def smoother_runs(quick):
    size = 1.2 if quick else 1.0
    rows = []
    for smoother, extra in (("SOR (the library's)", ()), ("Chebyshev (PETSc's)", CHEBYSHEV)):
        d = demo_run(2, "--size", size, "--linear-solver", "gamg", "--reduction", "0.034",
                     "--steps", "2", *extra)
        r = {"smoother": smoother, "dofs": d["dofs"], "newton_iterations": d["newton_iterations"],
             "krylov_iterations": d["krylov_iterations"], "force": d["force"],
             "solve_phase_s": d["solve_phase_time_s"]}
        say(f"{smoother}: {r['krylov_iterations']} Krylov its, {r['solve_phase_s']:.2f} s")
        rows.append(r)
    return rows


WALLS = 0.3  # the reduction from which the side presses the cavity's walls (20k mesh)
CAUSES = (("the demo (B's run)", ()), ("H = 50 000 (50x)", ("--hardening", "50000")),
          ("penalty 0.3 (1/10)", ("--penalty", "0.3")))


def krylov_by_phase(d):
    """Krylov iterations a Newton iteration of the converged steps, before and after WALLS."""
    def ratio(steps):
        return (sum(s["krylov_iterations"] for s in steps)
                / max(sum(s["newton_iterations"] for s in steps), 1))
    return (ratio([s for s in d["steps"] if s["reduction"] <= WALLS]),
            ratio([s for s in d["steps"] if s["reduction"] > WALLS]))


def cause_runs(quick, demo_stroke):
    size = 1.2 if quick else 1.0
    rows = []
    for cause, extra in CAUSES:
        d = demo_stroke if not extra else demo_run(2, "--size", size, "--linear-solver",
                                                   "gamg", *extra)
        before, after = krylov_by_phase(d)
        # the attempts of the steps that were cut: the solves no converged step counts
        cut_solves = d["linear_solves"] - sum(s["newton_iterations"] for s in d["steps"])
        cut_krylov = d["krylov_iterations"] - sum(s["krylov_iterations"] for s in d["steps"])
        r = {"run": cause, "dofs": d["dofs"], "newton_iterations": d["newton_iterations"],
             "step_cuts": d["step_cuts"], "linear_solves": d["linear_solves"],
             "krylov_per_newton_before_walls": before, "krylov_per_newton_at_walls": after,
             "cut_attempt_solves": cut_solves,
             "krylov_per_cut_attempt_solve": cut_krylov / max(cut_solves, 1),
             "force": d["force"], "solve_time_s": d["solve_time_s"]}
        say(f"{cause}: {before:.1f} Krylov its a Newton iteration before the walls, "
            f"{after:.1f} at them, {r['krylov_per_cut_attempt_solve']:.1f} in the "
            f"{cut_solves} solves of cut steps; {r['linear_solves']} solves, "
            f"{r['solve_time_s']:.1f} s")
        rows.append(r)
    return rows


def table(out):
    lines = ["| tetrahedra | unknowns | ranks | linear solver | flags | F | die fill | "
             "flash reach | Newton its (cuts) | linear solves | Krylov its per solve | "
             "s per linear solve | solve time (s) |", "|" + "---|" * 13]
    for r in out["mesh"] + out["size"]:
        krylov = (f"{r['krylov_iterations'] / r['linear_solves']:.0f}"
                  if r["linear_solver"] == "gamg" else "")
        lines.append(
            f"| {r['size']:g} | {r['dofs']} | {r['ranks']} | {r['linear_solver']} | "
            f"{r['flags']} | {r['force']:.5g} | {r['die_fill']:.3f} | "
            f"{r['flash_reach']:.3g} | {r['newton_iterations']} ({r['step_cuts']}) | "
            f"{r['linear_solves']} | {krylov} | {r['per_linear_solve_s']:.2f} | "
            f"{r['solve_time_s']:.1f} |")
    lines += ["", "GMRES + GAMG on the 20k mesh's first 8 % of the stroke, 2 ranks, by the "
              "levels' smoother:", "",
              "| smoother | unknowns | Newton its | Krylov its | solve phase (s) | F |",
              "|" + "---|" * 6]
    for r in out["smoother"]:
        lines.append(f"| {r['smoother']} | {r['dofs']} | {r['newton_iterations']} | "
                     f"{r['krylov_iterations']} | {r['solve_phase_s']:.2f} | "
                     f"{r['force']:.10g} |")
    lines += ["", f"GMRES + GAMG on the 20k mesh's whole stroke, 2 ranks: Krylov iterations "
              f"a Newton iteration (converged steps) before the side meets the walls "
              f"(reduction <= {WALLS}) and after:", "",
              "| run | unknowns | Krylov its a Newton it., before | after | in the cut "
              "steps' attempts (their solves) | Newton its (cuts) | linear solves | "
              "solve time (s) | F |", "|" + "---|" * 9]
    for r in out["causes"]:
        lines.append(f"| {r['run']} | {r['dofs']} | "
                     f"{r['krylov_per_newton_before_walls']:.1f} | "
                     f"{r['krylov_per_newton_at_walls']:.1f} | "
                     f"{r['krylov_per_cut_attempt_solve']:.1f} ({r['cut_attempt_solves']}) | "
                     f"{r['newton_iterations']} "
                     f"({r['step_cuts']}) | {r['linear_solves']} | {r['solve_time_s']:.1f} | "
                     f"{r['force']:.6g} |")
    return "\n".join(lines)


def main():
    args = options(__doc__, "size 2.0 only, and the 2-rank runs at size 1.2")
    sizes, stroke = size_runs(args.quick)
    out = {"machine": machine(2), "mesh": mesh_runs(args.quick), "size": sizes,
           "smoother": smoother_runs(args.quick), "causes": cause_runs(args.quick, stroke)}
    publish("forging_3d", out, table, args, say)


if __name__ == "__main__":
    main()
