"""Gradient damage: alternate minimization, plain and accelerated, side by side.

A. The AT1 bar of L = 2 ell (free damage ends): through its loss of stability (detected by the
   second variation, left along its mode) and its crack, 20 displacement steps to twice ε_c.
B. A crack in a held bar (AT1, ell = L/10) on three meshes, h = ell/5, ell/10, ell/20: the
   dissipated energy's error against Gc (1 + h/(c_w ell)).
C. The surfing test (`demos/crack.py --test surfing`): a crack dragged by a moving K-field, 15
   steps; 2 dD/da against the mesh's toughness (the 1D half bar cracked at its free end).

The problems are `damage_problems`' (built as the demos build theirs), which the tests share.

Each with the plain alternate iteration, over-relaxed (ω = 1.5) and Anderson-accelerated
(depth 5), both guarded by the energy: alternate iterations, the Newton iterations in u and
the SNES iterations in α (each a factorization and a solve: the work), wall time, and the
answer's difference from the plain iteration's. Writes benchmarks/results/damage.json and,
with --update-docs, its section of docs/benchmarks.md.
"""

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from common import machine, options, publish
from damage_problems import GradientBar, crack, end_crack, pull, release_rate, surfing
from mpi4py import MPI

from fenics_nl.materials.gradient_damage import GradientDamage

SCHEMES = ("none", "overrelaxed", "anderson")


def law(ell, nu=0.0):
    return GradientDamage(1.0, nu, Gc=1.0, ell=ell, model="at1", residual_stiffness=1e-6)


def say(msg):
    if MPI.COMM_WORLD.rank == 0:
        print(msg, flush=True)


def work(record):
    """The counts of a `PullRecord` or `SurfingRecord`."""
    return {"alternate_iterations": sum(record.iterations),
            "newton_iterations": record.newton_iterations,
            "damage_iterations": record.damage_iterations}


def row(problem, scheme, t0, counts, answer, **extra):
    r = {"problem": problem, "scheme": scheme, "time_s": time.perf_counter() - t0, **counts,
         "answer": answer, **extra}
    say(f"{problem:14s} {scheme:11s} {r['time_s']:7.2f} s  {r['alternate_iterations']:5d} "
        f"alternate, {r['newton_iterations']:5d} Newton, {r['damage_iterations']:5d} SNES VI  "
        f"answer {answer:.8g}")
    return r


def bar_runs(quick):
    rows = []
    for scheme in SCHEMES:
        t0 = time.perf_counter()
        bar = GradientBar(law(0.5), 1.0, 20 if quick else 40, acceleration=scheme)
        strains = bar.law.critical_strain * np.linspace(0, 2, 21)[1:]
        record = pull(bar, strains)
        rows.append(row("bar, unstable", scheme, t0, work(record), bar.dissipated_energy(),
                        bifurcation_strain=record.bifurcation_strain))
    return rows


def crack_runs(quick):
    rows = []
    a = law(0.1)
    strains = a.critical_strain * np.array([0.99, 1.1, 1.25, 1.5, 2.0])
    for r in (5, 10) if quick else (5, 10, 20):
        cells = 2 * math.ceil(r * 10 / 2) + 1
        for scheme in SCHEMES:
            t0 = time.perf_counter()
            c = crack(a, 1.0, cells, strains, acceleration=scheme)
            counts = {"alternate_iterations": c["iterations"],
                      "newton_iterations": c["newton_iterations"],
                      "damage_iterations": c["damage_iterations"]}
            rows.append(row(f"crack, ell/h={r}", scheme, t0, counts,
                            c["dissipated_energy"] / c["cross_section"],
                            error=c["dissipated_energy_rel_error"], cells=cells))
    return rows


def surfing_runs(quick):
    rows = []
    a = law(0.04)
    half = end_crack(a, 0.4, 40, a.critical_strain * np.array([0.99, 1.1, 1.5, 2, 3]))
    steps = 8 if quick else 15
    for scheme in SCHEMES:
        t0 = time.perf_counter()
        record = surfing(law(0.04, 0.3), steps, resolution=4, acceleration=scheme,
                         toughness=2 * half)
        G, lag = release_rate(record, skip=steps // 3)
        rows.append(row("surfing", scheme, t0, work(record), G, error=G / (2 * half) - 1,
                        lag=lag, dofs=record.dofs))
    return rows


def table(out):
    lines = ["| problem | scheme | alternate its | Newton its (u) | SNES VI its (α) | time (s) "
             "| answer | vs plain |", "|---|---|---|---|---|---|---|---|"]
    plain = {}
    for r in out["rows"]:
        if r["scheme"] == "none":
            plain[r["problem"]] = r
        p = plain[r["problem"]]
        diff = abs(r["answer"] / p["answer"] - 1)
        err = f" ({100 * r['error']:+.2f} %)" if r.get("error") is not None else ""
        lines.append(f"| {r['problem']} | {r['scheme']} | {r['alternate_iterations']} | "
                     f"{r['newton_iterations']} | {r['damage_iterations']} | "
                     f"{r['time_s']:.2f} (×{r['time_s'] / p['time_s']:.2f}) | "
                     f"{r['answer']:.6g}{err} | {diff:.1e} |")
    lines.append("")
    lines.append("Answer: the dissipated energy (bar: of the whole bar; crack: per unit section, "
                 "its error against Gc (1 + h/(c_w ℓ))), or 2 dD/da (surfing, its error "
                 "against the mesh's toughness from the 1D half bar). Each alternate iteration "
                 "is a Newton solve in u and a bound-constrained SNES solve in α; an "
                 "accelerated iterate that did not lower the energy costs one more u-solve. "
                 f"{out['machine']['cores']} cores, 1 rank.")
    return "\n".join(lines)


def main():
    args = options(__doc__, "small meshes and fewer steps, nothing written")
    out = {"machine": machine(), "rows": []}
    out["rows"] += bar_runs(args.quick)
    out["rows"] += crack_runs(args.quick)
    out["rows"] += surfing_runs(args.quick)
    publish("damage", out, table, args, say)


main()
