"""Bracket benchmark: Newton variants against mesh size, one linear solve, 1 vs 2 ranks.

Every number comes from `demos/bracket.py --json`, run as a separate process so that each
variant's peak memory is its own. Three parts, each on the same meshes for all methods:

* refinement (MUMPS, 1 rank): each Newton variant and one linear elastic solve on every
  mesh size; time per Newton iteration, total, peak memory, iterations per load step and
  the load-point displacement, whose Richardson extrapolation over the three finest meshes
  gives the error of each;
* parallel (MUMPS): full and quasi-Newton on 1 and 2 ranks on the same mesh;
* large (CG + GAMG, 2 ranks): full Newton in one load step (each CG solve costs as much as
  the linear solve, so the fewest iterations win) and one linear solve at about 1M unknowns.

Two profiles. The default one fits `make bench` (about 12 min on 2 cores: meshes of 22k,
31k and 81k unknowns, 1 vs 2 ranks at 81k, no large part) and writes results/bracket.json;
`--large` (`make bench-large`, about 75 min) measures 31k, 81k and 234k, 1 vs 2 ranks at
300k and the ~1M iterative part, into results/bracket_large.json.

    python benchmarks/bracket.py [--large] [--quick] [--update-docs] [--resume]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

from common import elapsed, machine, pyplot, save_figure, update_docs

HERE = Path(__file__).resolve().parent
DEMO = HERE.parent / "demos" / "bracket.py"
MPIEXEC = Path(sys.executable).parent / "mpiexec"
# label: demo arguments. The power law is hyperelastic (path-independent), so one load
# step is legitimate; it lets BFGS factorize once for the whole solve.
VARIANTS = {"full": ["--newton", "full"], "modified": ["--newton", "modified"],
            "periodic": ["--newton", "periodic"], "bfgs": ["--newton", "bfgs"],
            "snes": ["--newton", "snes"],
            "bfgs, 1 step": ["--newton", "bfgs", "--steps", "1"]}
GAMG = ["-bracket_pc_gamg_threshold", "0.02"]  # measured: 25 % fewer CG iterations


PROFILES = {  # sizes of the refinement [mm], of the 1 vs 2 ranks part, of the large part
    "standard": {"sizes": [9.0, 6.0, 4.0], "parallel_size": 4.0, "large_size": 0.0,
                 "iterative_size": 9.0},
    "large": {"sizes": [6.0, 4.0, 2.67], "parallel_size": 2.4, "large_size": 1.55,
              "iterative_size": 0.0},
}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--large", action="store_true",
                   help="the large profile: 234k refinement, 300k in parallel, ~1M with GAMG")
    p.add_argument("--sizes", type=float, nargs="+", help="element sizes of the refinement [mm]")
    p.add_argument("--parallel-size", type=float, help="element size of the 1 vs 2 ranks part")
    p.add_argument("--large-size", type=float,
                   help="element size of the large part (CG + GAMG, 2 ranks; 1.55: about 1M "
                   "unknowns); 0 skips it")
    p.add_argument("--iterative-size", type=float,
                   help="element size of the Newton variants with CG + GAMG; 0 skips them")
    p.add_argument("--quick", action="store_true",
                   help="one small mesh (17k unknowns), nothing written")
    p.add_argument("--update-docs", action="store_true",
                   help="rewrite its table in docs/benchmarks.md")
    p.add_argument("--resume", action="store_true",
                   help="keep the parts already in the results file, measure the rest")
    args = p.parse_args()
    args.profile = "large" if args.large else "standard"
    for key, value in PROFILES[args.profile].items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    return args


def run(*args, ranks=1) -> dict:
    """One demo run; its --json output."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        cmd = [sys.executable, str(DEMO), *map(str, args), "--json", str(out)]
        if ranks > 1:
            cmd = [str(MPIEXEC), "-n", str(ranks), *cmd]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr}")
        return json.loads(out.read_text())


def record(d: dict) -> dict:
    keys = ("dofs", "ranks", "load_point_displacement", "newton_iterations", "factorizations",
            "tangent_assemblies", "krylov_iterations", "solve_time_s", "peak_memory_mb")
    r = {k: d[k] for k in keys}
    r["time_per_iteration_s"] = d["solve_time_s"] / max(d["newton_iterations"], 1)
    r["iterations_per_step"] = [s["newton_iterations"] for s in d["steps"]]
    return r


def say(*a):
    print(*a, flush=True)


def refinement(sizes) -> list[dict]:
    rows = []
    for size in sizes:
        lin = record(run("--size", size, "--material", "linear", "--steps", 1))
        row = {"size": size, "dofs": lin["dofs"], "linear": lin, "variants": {}}
        say(f"size {size}: {lin['dofs']} unknowns, linear solve {lin['solve_time_s']:.2f} s")
        for v, extra in VARIANTS.items():
            r = record(run("--size", size, *extra))
            r["over_linear"] = r["solve_time_s"] / lin["solve_time_s"]
            row["variants"][v] = r
            say(f"  {v:13s} {r['solve_time_s']:8.2f} s  {r['newton_iterations']:4d} its  "
                f"{r['factorizations']:3d} fact  {r['peak_memory_mb']:7.0f} MB  "
                f"|u| {r['load_point_displacement']:.9f}")
        rows.append(row)
    return rows


def richardson(rows) -> dict | None:
    """Extrapolated |u_load| and observed order from the three finest meshes (h ∝ size)."""
    if len(rows) < 3:
        return None
    (h1, u1), (h2, u2), (h3, u3) = [(r["size"], r["variants"]["full"]["load_point_displacement"])
                                    for r in rows[-3:]]
    if abs(h1 / h2 - h2 / h3) > 0.02 * h1 / h2:
        return None  # not a geometric sequence of sizes
    ratio = (u2 - u1) / (u3 - u2)
    if ratio <= 1:
        return None  # not converging monotonically: no extrapolation
    p = math.log(ratio) / math.log(h2 / h3)
    u_inf = u3 + (u3 - u2) / (ratio - 1)
    return {"order": p, "extrapolated": u_inf}


def parallel(size) -> dict:
    out = {}
    for v, flag in (("full", "full"), ("bfgs", "bfgs")):  # labels of the results
        p = {str(n): record(run("--size", size, "--newton", flag, ranks=n)) for n in (1, 2)}
        p["speedup"] = p["1"]["solve_time_s"] / p["2"]["solve_time_s"]
        out[v] = p
        say(f"parallel {v}, {p['1']['dofs']} unknowns: speed-up {p['speedup']:.2f}")
    return out


def iterative(size) -> dict:
    """CG + GAMG, one load step, 1 rank: which Newton variant suits a Krylov solver."""
    common = ["--size", size, "--linear-solver", "gamg", "--steps", 1, *GAMG]
    lin = record(run(*common, "--material", "linear"))
    out = {"linear": lin, "variants": {}}
    # full Newton keeps a step's first AMG hierarchy while CG needs at most twice its count
    # (the default); "AMG per tangent" sets one up for every tangent, as PETSc's SNES does
    for v, flags in (("full", ["full"]),
                     ("full, AMG per tangent", ["full", "-bracket_snes_lag_preconditioner", "1"]),
                     ("bfgs", ["bfgs"]), ("modified", ["modified"])):
        r = record(run(*common, "--newton", *flags))
        r["over_linear"] = r["solve_time_s"] / lin["solve_time_s"]
        out["variants"][v] = r
        say(f"GAMG {v}, {r['dofs']} unknowns: {r['solve_time_s']:.1f} s, "
            f"{r['newton_iterations']} its, {r['krylov_iterations']} CG its")
    return out


def large(size) -> dict:
    common = ["--size", size, "--linear-solver", "gamg", *GAMG]
    lin = record(run(*common, "--material", "linear", "--steps", 1, ranks=2))
    full = record(run(*common, "--newton", "full", "--steps", 1, ranks=2))
    out = {"linear": lin, "full, 1 step": full,
           "over_linear": full["solve_time_s"] / lin["solve_time_s"]}
    say(f"large {lin['dofs']} unknowns: {full['solve_time_s']:.1f} s, "
        f"{out['over_linear']:.1f} linear solves")
    return out


def main():
    args = parse_args()
    sizes = [14.0] if args.quick else args.sizes
    name = "bracket" if args.profile == "standard" else "bracket_large"
    path = HERE / "results" / f"{name}.json"
    out = {"machine": machine(), "profile": args.profile,
           "force_N": 8000.0, "degree": 2, "steps": 4}
    if args.resume and path.exists():
        out = json.loads(path.read_text())  # parts measured by an interrupted run stay

    spent = out.get("benchmark_time_s", 0.0)  # by the interrupted run, when resuming

    def save():  # after each part: a long run that is stopped keeps what it measured
        out["benchmark_time_s"] = spent + elapsed()
        if not args.quick:
            path.write_text(json.dumps(out, indent=1))
            say(f"wrote {path}")

    if "refinement" not in out:
        out["refinement"] = refinement(sizes)
        out["richardson"] = richardson(out["refinement"])
        save()
    if not args.quick and "parallel" not in out:
        out["parallel"] = parallel(args.parallel_size)
        save()
    if not args.quick and args.iterative_size > 0 and "iterative" not in out:
        out["iterative"] = iterative(args.iterative_size)
        save()
    if not args.quick and args.large_size > 0 and "large" not in out:
        out["large"] = large(args.large_size)
        save()
    if not args.quick:
        plot(out, HERE / "results" / f"{name}.png")
    text = table(out)
    say(text)
    if args.update_docs and not args.quick:
        update_docs(name.replace("_", "-"), text)


def table(s) -> str:
    rich = s["richardson"]
    lines = ["| unknowns | variant | time (s) | / linear solve | iterations | s / iteration | "
             "factorizations | peak memory (MB) | \\|u_load\\| (mm) | error |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for row in s["refinement"]:
        lin = row["linear"]
        lines.append(f"| {row['dofs']} | linear solve | {lin['solve_time_s']:.2f} | 1 | 1 | "
                     f"{lin['solve_time_s']:.2f} | 1 | {lin['peak_memory_mb']:.0f} | | |")
        for v, r in row["variants"].items():
            err = (f"{abs(r['load_point_displacement'] / rich['extrapolated'] - 1):.1%}"
                   if rich else "")
            lines.append(
                f"| {row['dofs']} | {v} | {r['solve_time_s']:.2f} | {r['over_linear']:.1f} | "
                f"{r['newton_iterations']} | {r['time_per_iteration_s']:.3f} | "
                f"{r['factorizations']} | {r['peak_memory_mb']:.0f} | "
                f"{r['load_point_displacement']:.5f} | {err} |")
    if rich:
        lines += ["", f"Richardson extrapolation over the three meshes: |u_load| → "
                  f"{rich['extrapolated']:.4f} mm, observed order {rich['order']:.2f} in h."]
    for v, p in s.get("parallel", {}).items():
        lines += ["", f"1 vs 2 ranks ({p['1']['dofs']} unknowns, MUMPS, {v}): "
                  f"{p['1']['solve_time_s']:.1f} s vs {p['2']['solve_time_s']:.1f} s, "
                  f"speed-up **{p['speedup']:.2f}**."]
    if "iterative" in s:
        g = s["iterative"]
        lines += ["", f"CG + GAMG, 1 rank, one load step, {g['linear']['dofs']} unknowns; one "
                  f"linear solve {g['linear']['solve_time_s']:.2f} s "
                  f"({g['linear']['krylov_iterations']} CG iterations):", "",
                  "| variant | time (s) | / linear solve | Newton iterations | CG iterations "
                  "| AMG set-ups |", "|---|---|---|---|---|---|"]
        lines += [f"| {v} | {r['solve_time_s']:.2f} | {r['over_linear']:.1f} | "
                  f"{r['newton_iterations']} | {r['krylov_iterations']} | "
                  f"{r['factorizations']} |" for v, r in g["variants"].items()]
    if "large" in s:
        g = s["large"]
        best = g["full, 1 step"]
        lines += ["", f"CG + GAMG, 2 ranks, {best['dofs']} unknowns: full Newton, one step, "
                  f"{best['solve_time_s']:.0f} s ({best['newton_iterations']} iterations, "
                  f"{best['krylov_iterations']} CG iterations, "
                  f"{best['time_per_iteration_s']:.1f} s / Newton iteration, peak "
                  f"{best['peak_memory_mb']:.0f} MB per rank); one linear solve "
                  f"{g['linear']['solve_time_s']:.0f} s; ratio **{g['over_linear']:.1f}**."]
    return "\n".join(lines)


def plot(s, path):
    """Error against run time per variant; iterations per load step on the finest mesh."""
    rich = s["richardson"]
    if not rich:
        return
    plt = pyplot()
    finest = s["refinement"][-1]
    # results of earlier versions have no iterations per step: then the first panel only
    per_step = all(finest["variants"][v].get("iterations_per_step") for v in VARIANTS)
    if per_step:
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4))
    else:
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for v in VARIANTS:
        t = [r["variants"][v]["solve_time_s"] for r in s["refinement"]]
        e = [abs(r["variants"][v]["load_point_displacement"] / rich["extrapolated"] - 1)
             for r in s["refinement"]]
        style = "s--" if v == "snes" else "o-"  # SNES lies on full Newton: dashed
        ax.loglog(t, e, style, label=v)
        if per_step:
            steps = finest["variants"][v]["iterations_per_step"]
            bx.plot(range(1, len(steps) + 1), steps, style, label=v)
    ax.set_xlabel("wall time of the non-linear solve [s] (1 rank, MUMPS)")
    ax.set_ylabel("|u_load| error vs Richardson extrapolation")
    ax.set_title("bracket, P2, 8 kN: error against run time", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    if not per_step:
        save_figure(fig, path)
        return
    bx.set_xlabel("load step")
    bx.set_ylabel("Newton iterations")
    bx.set_yscale("log")
    bx.set_xticks(range(1, s["steps"] + 1))
    bx.set_title(f"iterations per load step, {finest['dofs']} unknowns", fontsize=9)
    bx.grid(alpha=0.3, which="both")
    bx.legend(fontsize=7)
    save_figure(fig, path)


if __name__ == "__main__":
    main()
