"""Buckling beam: accuracy against run time, Newton variants along the path, step control.

A. Refinement (Q1/Q2, 2·2^r elements through the height): SLEPc critical load against
   Euler and the tip rotation at P = 1.5 P_cr against the elastica, with wall times.
B. Newton variants along the path to 2 P_cr (40 fixed steps): iterations per step near and
   away from the bifurcation, factorizations, time; where a variant gives up.
C. Step control: fixed steps against growing steps (with the end-state stability check).

Writes benchmarks/results/buckling.json, buckling.png (error against wall time for each
element; Newton iterations per load step for each variant) and, with --update-docs, the
tables of docs/benchmarks.md.
"""

import argparse
import json
import math
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from common import elapsed, machine, pyplot, save_figure, update_docs
from continuation_problems import BucklingBeam
from mpi4py import MPI

from fenics_nl.solvers.loading import LoadStepError
from fenics_nl.theory import elastica

HERE = Path(__file__).resolve().parent
comm = MPI.COMM_WORLD
L, H, E, NU = 1.0, 0.02, 1e3, 0.3


def say(msg):
    if comm.rank == 0:
        print(msg, flush=True)


def refinement(degrees, refines, ratio=1.5):
    rows = []
    for degree in degrees:
        for r in refines:
            t0 = time.perf_counter()
            b = BucklingBeam(L, H, E, NU, refine=r, degree=degree)
            P_cr = b.critical_loads(1)[0][0]
            t1 = time.perf_counter()
            path, _ = b.solve_path(ratio, 40)
            t2 = time.perf_counter()
            alpha = math.degrees(abs(b.tip()["rotation"]))
            rows.append({"degree": degree, "refine": r, "dofs": b.dofs,
                         "critical_load_rel_error": P_cr / b.P_euler - 1,
                         "buckling_time_s": t1 - t0,
                         "tip_rotation_error_deg": alpha - math.degrees(
                             elastica.tip_rotation(ratio)),
                         "path_time_s": t2 - t1, "newton_iterations": path.iterations})
            err = 100 * rows[-1]["critical_load_rel_error"]
            say(f"Q{degree} refine {r}: {b.dofs} dofs, P_cr {err:+.3f} %, "
                f"rotation error {rows[-1]['tip_rotation_error_deg']:+.3f} deg, "
                f"{t2 - t0:.2f} s")
    return rows


def variants(ratio=2.0, steps=40):
    out = {}
    for method in ("full", "modified", "periodic", "bfgs"):
        b = BucklingBeam(L, H, E, NU)
        per_step = []
        t0 = time.perf_counter()
        try:
            path, _ = b.solve_path(ratio, steps, method,
                                   on_step=lambda t, r, s=per_step: s.append(
                                       (t * ratio, r.iterations, r.wall_time)))
            failed_at = None
            fact = path.work.factorizations
        except (LoadStepError, RuntimeError) as err:
            failed_at = per_step[-1][0] if per_step else 0.0
            fact = None
            say(f"  {method}: {err}")
        wall = time.perf_counter() - t0
        near = [s for s in per_step if 0.95 <= s[0] <= 1.1]
        away = [s for s in per_step if s[0] < 0.8 or s[0] > 1.5]
        out[method] = {
            "wall_time_s": wall, "failed_at_load_ratio": failed_at, "factorizations": fact,
            "iterations_per_step": [[s[0], s[1]] for s in per_step],
            "mean_iterations_near": sum(s[1] for s in near) / len(near) if near else None,
            "mean_iterations_away": sum(s[1] for s in away) / len(away) if away else None,
            "time_per_step_near_s": sum(s[2] for s in near) / len(near) if near else None,
            "time_per_step_away_s": sum(s[2] for s in away) / len(away) if away else None,
        }
        near, away = out[method]["mean_iterations_near"], out[method]["mean_iterations_away"]
        say(f"{method}: {wall:.2f} s, failed at {failed_at}, near {near}, away {away}")
    return out


def step_control(ratio=2.0):
    out = {}
    for label, steps, grow in [("fixed, 40 steps", 40, False), ("fixed, 10 steps", 10, False),
                               ("growing from 10 steps", 10, True),
                               ("one step + stability check", 1, False)]:
        b = BucklingBeam(L, H, E, NU)
        t0 = time.perf_counter()
        path, switched = b.solve_path(ratio, steps, grow=grow)
        alpha = math.degrees(abs(b.tip()["rotation"]))
        out[label] = {"wall_time_s": time.perf_counter() - t0, "steps": len(path.factors),
                      "cuts": path.failures, "newton_iterations": path.iterations,
                      "branch_switched": switched,
                      "tip_rotation_error_deg": alpha - math.degrees(elastica.tip_rotation(ratio))}
        say(f"{label}: {out[label]}")
    return out


def tables(r):
    a = ["| element | refine | unknowns | P_cr error | α error at 1.5 P_cr | SLEPc (s) | "
         "path (s) |",
         "|---|---|---|---|---|---|---|"]
    for x in r["refinement"]:
        a.append(f"| Q{x['degree']} | {x['refine']} | {x['dofs']} | "
                 f"{100 * x['critical_load_rel_error']:+.3f} % | "
                 f"{x['tip_rotation_error_deg']:+.3f}° | "
                 f"{x['buckling_time_s']:.2f} | {x['path_time_s']:.2f} |")
    b = ["| Newton | time (s) | factorizations | mean its/step away (r < 0.8 or > 1.5) | "
         "near (0.95-1.1) | outcome |", "|---|---|---|---|---|---|"]
    for m, x in r["variants"].items():
        outcome = ("reached 2 P_cr" if x["failed_at_load_ratio"] is None
                   else f"gave up after P = {x['failed_at_load_ratio']:.3f} P_cr")
        near = "-" if x["mean_iterations_near"] is None else f"{x['mean_iterations_near']:.1f}"
        away = "-" if x["mean_iterations_away"] is None else f"{x['mean_iterations_away']:.1f}"
        b.append(f"| {m} | {x['wall_time_s']:.2f} | {x['factorizations'] or '-'} | {away} | "
                 f"{near} | {outcome} |")
    c = ["| steps to 2 P_cr | time (s) | steps | cuts | Newton its | branch switched | α error |",
         "|---|---|---|---|---|---|---|"]
    for label, x in r["step_control"].items():
        c.append(f"| {label} | {x['wall_time_s']:.2f} | {x['steps']} | {x['cuts']} | "
                 f"{x['newton_iterations']} | {x['branch_switched']} | "
                 f"{x['tip_rotation_error_deg']:+.3f}° |")
    return "\n".join([f"Cantilever L/h = {L / H:g}, E = {E:g}, ν = {NU}, plane stress, SVK.", "",
                      *a, "", *b, "", *c])


def plot(r, path):
    plt = pyplot()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4))
    for degree in sorted({x["degree"] for x in r["refinement"]}):
        rows = [x for x in r["refinement"] if x["degree"] == degree]
        ax.loglog([x["buckling_time_s"] for x in rows],
                  [abs(x["critical_load_rel_error"]) for x in rows], "o-",
                  label=f"Q{degree}: |P_cr / P_Euler - 1| (SLEPc time)")
        ax.loglog([x["path_time_s"] for x in rows],
                  [abs(math.radians(x["tip_rotation_error_deg"])) for x in rows], "s--",
                  label=f"Q{degree}: |α - α_elastica| [rad] at 1.5 P_cr (path time)")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("error")
    ax.set_title("accuracy against run time (refinements)", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    for method, x in r["variants"].items():
        steps = x["iterations_per_step"]
        end = ("" if x["failed_at_load_ratio"] is None
               else f", gave up after {x['failed_at_load_ratio']:.3f} P_cr")
        bx.plot([s[0] for s in steps], [s[1] for s in steps], "o-", ms=3, label=method + end)
    bx.axvline(1.0, color="k", lw=0.8, ls=":")
    bx.set_xlabel("load P / P_cr at the end of the step")
    bx.set_ylabel("Newton iterations in the step")
    bx.set_yscale("log")
    bx.set_title("Newton variants along the path (40 fixed steps)", fontsize=9)
    bx.grid(alpha=0.3, which="both")
    bx.legend(fontsize=7)
    save_figure(fig, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--update-docs", action="store_true")
    args = ap.parse_args()
    BucklingBeam(L, H, E, NU).solve_path(1.5, 10)  # warm-up: JIT
    BucklingBeam(L, H, E, NU, degree=1).critical_loads(1)
    result = {
        "refinement": refinement([2] if args.quick else [1, 2], [0] if args.quick else [0, 1, 2]),
        "variants": variants(),
        "step_control": step_control(),
        "ranks": comm.size,
        "machine": machine(comm.size),
        "benchmark_time_s": elapsed(),
    }
    if comm.rank == 0:
        text = tables(result)
        print(text)
        if not args.quick:
            (HERE / "results" / "buckling.json").write_text(json.dumps(result, indent=1))
            plot(result, HERE / "results" / "buckling.png")
            if args.update_docs:
                update_docs("buckling", text)


if __name__ == "__main__":
    main()
