"""Every capability of the bracket on the iterative path (CG + GAMG), under refinement.

The bracket (`demos/bracket.py --linear-solver gamg`, 2 ranks) in the power law (full Newton, one
step), in J2 (two steps and the unloading), on its floor (frictionless active set, two
steps), on a rough floor (Coulomb, f = 0.3) and mixed (Taylor–Hood u–p, MINRES with the
block preconditioner, one step), each on meshes halved twice. Per run: Newton iterations,
Krylov iterations per Newton iteration (flat under refinement: the preconditioner is
h-independent), AMG set-ups (one per load step or active-set iteration while CG keeps up),
time, and time in linear solves of the same mesh (`--material linear`, CG + GAMG, solved to
1e-11: one such solve is the unit). At the coarsest mesh each answer is checked against the
direct solver's (MUMPS) within Newton's tolerance.

Arc-length is not here: past a limit point its tangent is indefinite, where CG breaks down
(the snap-through and the beam run on MUMPS; benchmarks/arch_iterative.py measures GMRES +
GAMG on the arch).

    python benchmarks/iterative.py [--quick] [--update-docs] [--large] [--only NAME...]

Standard: 12, 6 and 3 mm elements (18k, 31k and 169k unknowns), 14 min on 2 cores;
--large: 1.55 mm (about 1M unknowns) for `make bench-large`, the third halving; --only
NAME...: some capabilities (with --large, merged into the capabilities recorded already:
each row keeps the time of the linear solve it is divided by); --quick: 20 mm, nothing
written.
"""

import argparse
import json
import sys

from bracket import run as demo_run
from bracket import say
from common import ROOT, elapsed, machine, update_docs

# each capability: its label, flags and KSP options prefix
CAPABILITIES = {
    "power-law": ("power law", ["--steps", "1"], "bracket_"),
    "j2": ("J2, loaded and unloaded", ["--material", "j2", "--steps", "2", "--unload"],
           "bracket_"),
    "contact": ("contact", ["--support", "contact", "--steps", "2"], "bracket_elim_"),
    "friction": ("friction", ["--support", "contact", "--friction", "0.3", "--steps", "2"],
                 "bracket_elim_"),
    "mixed": ("mixed u-p (MINRES)", ["--mixed", "--steps", "1"], "bracket_fieldsplit_u_"),
}


def gamg(prefix: str) -> list[str]:
    """CG + GAMG, its drop threshold 0.02 (25 % fewer CG iterations, benchmarks/bracket.py)."""
    return ["--linear-solver", "gamg", f"-{prefix}pc_gamg_threshold", "0.02"]


KEYS = ("dofs", "newton_iterations", "krylov_iterations", "factorizations", "solve_time_s",
        "load_point_displacement", "active_set_iterations", "peak_memory_mb")


def run(*args, ranks: int) -> dict:
    """One demo run on `ranks` ranks (benchmarks/bracket.py's): the keys of its JSON kept."""
    d = demo_run(*args, ranks=ranks)
    return {k: d[k] for k in KEYS if k in d}


def mesh(size: float, ranks: int, names: list[str], check: bool) -> dict:
    """The capabilities `names` on one mesh; against MUMPS too when `check`."""
    linear = run("--size", size, "--material", "linear", "--steps", "1", *gamg("bracket_"),
                 ranks=ranks)
    out = {"size": size, "linear": linear, "capabilities": {}}
    for key in names:
        name, flags, prefix = CAPABILITIES[key]
        r = run("--size", size, *flags, *gamg(prefix), ranks=ranks)
        r["krylov_per_newton"] = r["krylov_iterations"] / r["newton_iterations"]
        r["over_linear"] = r["solve_time_s"] / linear["solve_time_s"]
        r["linear_solve_time_s"] = linear["solve_time_s"]
        if check:
            direct = run("--size", size, *flags, ranks=ranks)
            r["direct_rel_difference"] = abs(r["load_point_displacement"]
                                             / direct["load_point_displacement"] - 1)
        out["capabilities"][name] = r
        say(f"{size} mm, {r['dofs']} unknowns, {name}: {r['solve_time_s']:.1f} s, "
            f"{r['newton_iterations']} Newton its, {r['krylov_per_newton']:.0f} CG its each, "
            f"{r['factorizations']} AMG set-ups, {r['over_linear']:.1f} linear solves")
    return out


def merge_recorded(out: dict, path) -> None:
    """The capabilities recorded in `path` on the same mesh, under those just run."""
    if not path.exists():
        return
    before = json.loads(path.read_text())
    for m in out["meshes"]:
        for old in before["meshes"]:
            if old["size"] != m["size"]:
                continue
            for name, r in old["capabilities"].items():
                r.setdefault("linear_solve_time_s", old["linear"]["solve_time_s"])
                m["capabilities"].setdefault(name, r)


def table(out: dict) -> str:
    rows = out["meshes"]
    lines = [f"CG + GAMG on {out['ranks']} ranks; one linear solve of the same mesh is the "
             "unit of the last column. Krylov iterations per Newton iteration stay within a "
             "factor under refinement where the preconditioner is h-independent.", "",
             "| capability | unknowns | Newton its | Krylov its / Newton it | AMG set-ups | "
             "time (s) | / linear solve | vs MUMPS |", "|---|---|---|---|---|---|---|---|"]
    for name, _, _ in CAPABILITIES.values():
        for m in rows:
            if name not in m["capabilities"]:
                continue
            r = m["capabilities"][name]
            check = (f"{r['direct_rel_difference']:.0e}" if "direct_rel_difference" in r
                     else "")
            lines.append(f"| {name} | {r['dofs']} | {r['newton_iterations']} | "
                         f"{r['krylov_per_newton']:.0f} | {r['factorizations']} | "
                         f"{r['solve_time_s']:.1f} | {r['over_linear']:.1f} | {check} |")
    lines += ["", "One linear solve: " + ", ".join(linear_units(m) for m in rows) + "."]
    return "\n".join(lines)


def linear_units(m: dict) -> str:
    """The linear solve(s) a mesh's rows are divided by: this run's, and those of the
    earlier runs whose rows `merge_recorded` kept (each row records its own)."""
    lin = m["linear"]
    text = (f"{lin['dofs']} unknowns {lin['solve_time_s']:.2f} s "
            f"({lin['krylov_iterations']} CG its)")
    units: dict[float, list[str]] = {}
    for name, r in m["capabilities"].items():
        units.setdefault(r.get("linear_solve_time_s", lin["solve_time_s"]), []).append(name)
    if len(units) == 1:
        return text
    def rows_of(names):
        return ", ".join(f'"{n}"' for n in names)

    this = units.pop(lin["solve_time_s"], [])
    return (f"{text} for {rows_of(this)}; " + "; ".join(
        f"{t:.2f} s (an earlier run of the same mesh) for {rows_of(names)}"
        for t, names in units.items()))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="20 mm elements, nothing written")
    p.add_argument("--large", action="store_true",
                   help="1.55 mm (about 1M unknowns) only, no MUMPS check (it does not fit)")
    p.add_argument("--only", nargs="+", choices=list(CAPABILITIES), metavar="CAPABILITY",
                   help=f"these capabilities only: {', '.join(CAPABILITIES)}")
    p.add_argument("--update-docs", action="store_true")
    args = p.parse_args()
    sizes = [20.0] if args.quick else [1.55] if args.large else [12.0, 6.0, 3.0]
    ranks = 2
    names = args.only or list(CAPABILITIES)
    out = {"machine": machine(ranks), "ranks": ranks,
           "meshes": [mesh(s, ranks, names, check=i == 0 and not args.large)
                      for i, s in enumerate(sizes)]}
    out["benchmark_time_s"] = elapsed()
    if args.large and args.only:
        merge_recorded(out, ROOT / "benchmarks" / "results" / "iterative_large.json")
    text = table(out)
    say(text)
    if not args.quick:
        name = "iterative_large" if args.large else "iterative"
        (ROOT / "benchmarks" / "results" / f"{name}.json").write_text(json.dumps(out, indent=2))
        if args.update_docs:
            update_docs(name.replace("_", "-"), text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
