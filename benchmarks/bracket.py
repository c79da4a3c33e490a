"""Bracket benchmark: Newton variants against mesh size, one linear solve, 1 vs 2 ranks.

Every number comes from `demos/bracket.py --json`, run as a separate process so that each
variant's peak memory is its own. Three parts, each on the same meshes for all methods:

* refinement (MUMPS, 1 rank): each Newton variant and one linear elastic solve on every
  mesh size; time per Newton iteration, total, peak memory, and the load-point displacement,
  whose Richardson extrapolation over the three finest meshes gives the error of each;
* parallel (MUMPS): full and quasi-Newton on 1 and 2 ranks on a mesh of >= 300k unknowns;
* large (CG + GAMG, 2 ranks): full Newton in one load step (each CG solve costs as much as
  the linear solve, so the fewest iterations win) and one linear solve at about 1M unknowns.

    python benchmarks/bracket.py [--quick] [--update-readme] [--resume]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

from common import machine, update_readme

HERE = Path(__file__).resolve().parent
DEMO = HERE.parent / "demos" / "bracket.py"
MPIEXEC = Path(sys.executable).parent / "mpiexec"
# label: demo arguments. The power law is hyperelastic (path-independent), so one load
# step is legitimate; it lets BFGS factorize once for the whole solve.
VARIANTS = {"full": ["--newton", "full"], "modified": ["--newton", "modified"],
            "periodic": ["--newton", "periodic"], "quasi-newton": ["--newton", "quasi-newton"],
            "snes": ["--newton", "snes"],
            "quasi-newton, 1 step": ["--newton", "quasi-newton", "--steps", "1"]}
GAMG = ["-bracket_pc_gamg_threshold", "0.02"]  # measured: 25 % fewer CG iterations


def parse_args():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sizes", type=float, nargs="+", default=[6.0, 4.0, 2.67],
                   help="element sizes of the refinement part [mm]")
    p.add_argument("--parallel-size", type=float, default=2.4,
                   help="element size of the 1 vs 2 ranks part (about 320k unknowns)")
    p.add_argument("--large-size", type=float, default=1.55,
                   help="element size of the iterative part (about 1M unknowns); 0 skips it")
    p.add_argument("--quick", action="store_true", help="two small meshes, nothing written")
    p.add_argument("--update-readme", action="store_true", help="rewrite the README table")
    p.add_argument("--resume", action="store_true",
                   help="keep the parts already in results/bracket.json, measure the rest")
    return p.parse_args()


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


def main():
    args = parse_args()
    sizes = [10.0, 7.0] if args.quick else args.sizes
    path = HERE / "results" / "bracket.json"
    out = {"machine": machine(),
           "force_N": 8000.0, "degree": 2, "steps": 4}
    if args.resume and path.exists():
        out = json.loads(path.read_text())  # parts measured by an interrupted run stay

    def save():  # after each part: a long run that is stopped keeps what it measured
        if not args.quick:
            path.write_text(json.dumps(out, indent=1))
            say(f"wrote {path}")

    if "refinement" not in out:
        out["refinement"] = refinement(sizes)
        out["richardson"] = richardson(out["refinement"])
        save()
    if not args.quick and "parallel" not in out:
        out["parallel"] = {}
        for v in ("full", "quasi-newton"):
            p = {str(n): record(run("--size", args.parallel_size, "--newton", v, ranks=n))
                 for n in (1, 2)}
            p["speedup"] = p["1"]["solve_time_s"] / p["2"]["solve_time_s"]
            out["parallel"][v] = p
            say(f"parallel {v}, {p['1']['dofs']} unknowns: speed-up {p['speedup']:.2f}")
        save()
    if not args.quick and args.large_size > 0 and "large" not in out:
        common = ["--size", args.large_size, "--solver", "iterative", *GAMG]
        lin = record(run(*common, "--material", "linear", "--steps", 1, ranks=2))
        full = record(run(*common, "--newton", "full", "--steps", 1, ranks=2))
        out["large"] = {"linear": lin, "full, 1 step": full,
                        "over_linear": full["solve_time_s"] / lin["solve_time_s"]}
        say(f"large {lin['dofs']} unknowns: {full['solve_time_s']:.1f} s, "
            f"{out['large']['over_linear']:.1f} linear solves")
        save()
    if not args.quick:
        plot(out, HERE / "results" / "bracket.png")
    text = table(out)
    say(text)
    if args.update_readme and not args.quick:
        update_readme("bracket", text)


def table(s) -> str:
    rich = s["richardson"]
    lines = ["| unknowns | variant | time (s) | / linear solve | iterations | s / iteration | "
             "factorizations | peak memory (MB) | |u_load| (mm) | error |",
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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rich = s["richardson"]
    if not rich:
        return
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for v in VARIANTS:
        t = [r["variants"][v]["solve_time_s"] for r in s["refinement"]]
        e = [abs(r["variants"][v]["load_point_displacement"] / rich["extrapolated"] - 1)
             for r in s["refinement"]]
        ax.loglog(t, e, "o-", label=v)
    ax.set_xlabel("wall time of the non-linear solve [s] (1 rank, MUMPS)")
    ax.set_ylabel("|u_load| error vs Richardson extrapolation")
    ax.set_title("bracket, P2, 8 kN: error against run time")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    say(f"wrote {path}")


if __name__ == "__main__":
    main()
