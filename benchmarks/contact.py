"""Contact: error against run time, and the active set against its peers on the same mesh.

A. Refinement: the axisymmetric and 3D punches at several element sizes (force, radius and
   peak-pressure errors against Hertz, wall time of the contact solve).
B. Same mesh (axisymmetric, default size): active set (elimination with and without
   factorization reuse, multipliers), SNES VI (vinewtonrsls) and penalty (several k).
C. Contact-solve time over one linear elastic solve of the same mesh.

Writes benchmarks/results/contact.json, benchmarks/results/contact.png and, with
--update-docs, the README table.
"""

import argparse
import json
import math
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import ufl
from common import elapsed, machine, pyplot, save_figure, timed_linear_solve, update_docs
from dolfinx import fem
from mpi4py import MPI
from peers import solve_penalty, solve_snes_vi
from punch_problem import build_punch

from fenics_nl.materials.laws import LinearElastic
from fenics_nl.theory import hertz

HERE = Path(__file__).resolve().parent
E, NU, R, DELTA = 1.0, 0.3, 1.0, 0.01
A = (R * DELTA) ** 0.5
REF = hertz.sphere_from_indentation(E, NU, R, DELTA)
comm = MPI.COMM_WORLD


def punch(model, refine, **kw):
    return build_punch(model, LinearElastic(E, NU), R, A, refine=refine,
                       block=100.0 if model == "3d" else 1000.0, **kw)


def timed_indent(p):
    comm.Barrier()
    t0 = time.perf_counter()
    s = p.indent(DELTA)
    return s, comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)


def linear_solve_time(p):
    """Assemble K and a surface load, factorize, solve: one linear elastic solve."""
    V = p.u.function_space
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(ufl.derivative(p.residual, p.u, du))
    ds = ufl.Measure("ds", domain=p.mesh)
    L = fem.form(-1.0 * v[p.block.vertical] * p.block.weight * ds)
    return timed_linear_solve(a, L, p.bcs, "lu", "lin_")


def errors(s):
    return {"force_rel_error": s.force / REF["force"] - 1,
            "contact_radius_error_over_h": None,
            "max_pressure_rel_error": s.max_pressure / REF["max_pressure"] - 1}


def refinement(model, refines, repeat=1):
    """Each mesh's contact solve and linear solve: the fastest of `repeat` rounds.

    A round is a new punch (nothing kept from the last: the analysis, the factorization and
    the tangent are made again) and a linear solve of its mesh.
    """
    rows = []
    for r in refines:
        t, linear = math.inf, math.inf
        for _ in range(repeat):
            p = punch(model, r)
            s, t_round = timed_indent(p)
            t, linear = min(t, t_round), min(linear, linear_solve_time(p))
        e = errors(s)
        e["contact_radius_error_over_h"] = (s.contact_radius - REF["contact_radius"]) / p.block.h
        work = p.contact.newton.total
        rows.append({"model": model, "refine": r, "h": p.block.h, "dofs": p.dofs, "wall_time_s": t,
                     "force": s.force, "active_set_iterations": s.active_set_iterations,
                     "factorizations": s.factorizations, "linear_solves": work.linear_solves,
                     "update_columns": work.update_columns, **e,
                     "linear_solve_time_s": linear, "repeat": repeat})
        say(f"{model} refine {r}: {p.dofs} dofs, {t:.2f} s, force error "
            f"{100 * e['force_rel_error']:+.3f} %, ratio to a linear solve "
            f"{t / rows[-1]['linear_solve_time_s']:.2f}")
    return rows


def peers(refine, penalties):
    out = {}
    for label, kw in [("active set, elimination (new rows on one factorization)", {}),
                      ("active set, elimination, a factorization per iteration",
                       {"newton_options": {"reuse_factorization": False}}),
                      ("active set, multipliers", {"formulation": "multiplier"})]:
        p = punch("axisymmetric", refine, **kw)
        s, t = timed_indent(p)
        out[label] = {"wall_time_s": t, "force": s.force, "iterations": s.active_set_iterations,
                      "factorizations": s.factorizations, "max_penetration": 0.0,
                      "force_rel_error": s.force / REF["force"] - 1}
    p = punch("axisymmetric", refine)
    out["linear solve"] = {"wall_time_s": linear_solve_time(p)}
    r = solve_snes_vi(p, DELTA)
    out["SNES VI (vinewtonrsls)"] = {**r, "force_rel_error": r["force"] / REF["force"] - 1}
    for k in penalties:
        r = solve_penalty(p, DELTA, k * E / p.block.h, prefix=f"pen{int(k)}_")
        out[f"penalty k = {k:g} E/h"] = {**r, "force_rel_error": r["force"] / REF["force"] - 1}
    for label, r in out.items():
        say(f"{label:36s} {r['wall_time_s']:.3f} s  "
            + (f"force {r['force']:.8e}" if "force" in r else ""))
    return out


def say(msg):
    if comm.rank == 0:
        print(msg, flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="coarse meshes only")
    ap.add_argument("--update-docs", action="store_true")
    ap.add_argument("--repeat", type=int, default=3,
                    help="rounds per mesh in the refinement table, the fastest kept: the "
                         "ratios' two times vary by about 5 %% from one round to the next "
                         "(default: 3)")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    # warm-up: compile every form once
    punch("axisymmetric", 0).indent(DELTA)
    punch("axisymmetric", 0, formulation="multiplier").indent(DELTA)
    q = punch("axisymmetric", 0)
    solve_snes_vi(q, DELTA)
    solve_penalty(q, DELTA, 10 / q.block.h, prefix="w_")
    linear_solve_time(q)
    punch("3d", 0).indent(DELTA)

    ax = refinement("axisymmetric", [0, 1] if args.quick else [0, 1, 2, 3], args.repeat)
    d3 = refinement("3d", [0] if args.quick else [0, 1], args.repeat)
    same = peers(0 if args.quick else 1, [10, 100, 1000, 10000])
    result = {"axisymmetric": ax, "3d": d3, "same_mesh": same, "hertz": REF,
              "ranks": comm.size,
              "machine": machine(comm.size), "benchmark_time_s": elapsed()}
    if comm.rank == 0 and not args.quick:
        (HERE / "results" / "contact.json").write_text(json.dumps(result, indent=1))
        plot(result, HERE / "results" / "contact.png")
        text = table(result)
        print(text)
        if args.update_docs:
            update_docs("contact", text)


def table(r):
    lines = ["Punch, R = 1, δ = 0.01, E = 1, ν = 0.3 (Hertz P = "
             f"{r['hertz']['force']:.6e}); {r['ranks']} rank(s).", "",
             "| model | refine | unknowns | time (s) | / linear solve | force error | "
             "p0 error | radius error / h | active-set its | factorizations | "
             "update columns | solves |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in r["axisymmetric"] + r["3d"]:
        ratio = row["wall_time_s"] / row["linear_solve_time_s"]
        lines.append(f"| {row['model']} | {row['refine']} | {row['dofs']} | "
                     f"{row['wall_time_s']:.2f} | {ratio:.2f} | "
                     f"{100 * row['force_rel_error']:+.3f} % | "
                     f"{100 * row['max_pressure_rel_error']:+.2f} % | "
                     f"{row['contact_radius_error_over_h']:+.2f} | "
                     f"{row['active_set_iterations']} | {row['factorizations']} | "
                     f"{row['update_columns']} | {row['linear_solves']} |")
    lines += ["", "A linear material's later active sets are solved on the first iteration's "
              "factorization (`solvers/row_update.py`): the rows that changed are a bordered "
              "system whose columns (\"update columns\", blocked back-solves) cost at most "
              "the flops of a factorization. One linear solve = assemble, factorize, solve "
              f"on the same mesh; each time the fastest of {r['axisymmetric'][0]['repeat']} "
              "rounds.",
              "", "Same axisymmetric mesh, side by side:", "",
              "| method | time (s) | force | force error | iterations | factorizations | "
              "max penetration |",
              "|---|---|---|---|---|---|---|"]
    for label, x in r["same_mesh"].items():
        if label == "linear solve":
            lines.append(f"| one linear elastic solve | {x['wall_time_s']:.3f} | | | | 1 | |")
            continue
        lines.append(f"| {label} | {x['wall_time_s']:.3f} | {x['force']:.8e} | "
                     f"{100 * x['force_rel_error']:+.3f} % | {x['iterations']} | "
                     f"{x['factorizations']} | {x['max_penetration']:.1e} |")
    return "\n".join(lines)


def plot(r, path):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for model in ("axisymmetric", "3d"):
        rows = r[model]
        ax.loglog([x["wall_time_s"] for x in rows], [abs(x["force_rel_error"]) for x in rows],
                  "o-", label=f"active set, {model}")
    for label, x in r["same_mesh"].items():
        if "force_rel_error" in x and not label.startswith("active"):
            ax.loglog([x["wall_time_s"]], [abs(x["force_rel_error"])], "s", label=label)
    ax.set_xlabel("wall time of the contact solve [s]")
    ax.set_ylabel("|P / P_Hertz - 1|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    save_figure(fig, path)


if __name__ == "__main__":
    main()
