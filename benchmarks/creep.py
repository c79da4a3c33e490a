"""Norton creep in time: steps sized by their error against equal steps, implicit against
explicit, the consistent tangent against the elastic one.

The problem is `demos/creep_vessel.py`'s default, built here from the same pieces
(`plasticity_problems.thick_vessel`, Taylor–Hood, `NortonCreep`, `solve_in_time`): a
cylinder a = 100, b = 200 (plane strain, 10 elements through the wall), E = 200e3, ν = 0.3,
A = 5e-14, n = 5, p = 30 ramped in 0.01 and held to t = 5000 (40 relaxation times
1/(E A pⁿ⁻¹)). What is measured of each run: the hoop stress at the bore (r = a, y = 0) at
ten output times (τ · 1e-3, 3e-3, ..., 10, and the end: every run's steps land on them),
against a reference run's (steps sized to a local error of 1e-6) — the largest difference,
over p ("path error"); and at the end against the stationary closed form ("end error": the mesh's
share, about 0.1 %, included). Times are the time loop's, after a run that compiled the forms.

* **equal against adaptive steps**: equal steps end/N (the steps land on the ramp's end)
  against steps sized by their local error `tolerance`; the goal is the path to 0.5 % of p
  in at most a fifth of the time equal steps take for it;
* **explicit (forward Euler)**: the viscous strain advanced from the last state's stress,
  εᵛₖ₊₁ = εᵛₖ + Δt (3/2) A qₖⁿ⁻¹ sₖ, then one linear solve (Hooke's tangent, factorized
  once), at equal steps Δt = 1, 2, 4, ... to the end, or until it diverges (the bore's
  hoop stress beyond 10 p): its largest stable step, against a material point's estimate
  2/(3μ A n qⁿ⁻¹) at Lamé's and at the stationary σ_eq of the bore;
* **the tangent**: full Newton (UFL's consistent tangent through the local Newton steps)
  against modified Newton on Hooke's tangent, factorized once, on the same adaptive steps'
  tolerance.

    python benchmarks/creep.py [--quick] [--update-docs]
"""

from __future__ import annotations

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from common import machine, options, publish
from dolfinx import fem
from mpi4py import MPI
from plasticity_problems import thick_vessel

from fenics_nl.errors import SolveError
from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.creep import NortonCreep
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.time_stepping import LoadHistory, solve_in_time
from fenics_nl.theory import vessels

A_IN, B_OUT, E, NU, A, N, P, RAMP, END = 100.0, 200.0, 200e3, 0.3, 5e-14, 5.0, 30.0, 0.01, 5000.0
TAU = 1 / (E * A * P ** (N - 1))
# the times where the stresses are compared (every run's steps land on them): the transient
# at the bore takes about 0.01 τ (its σ_eq is 2.3 p at first), the redistribution about τ
OUTPUT = [f * TAU for f in (1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0, 10.0)] + [END]


def say(*a):
    print(*a, flush=True)


class Vessel:
    """The creeping cylinder, its Newton solver and its bore's hoop stress."""

    def __init__(self, method: str = "full"):
        self.v = v = thick_vessel("cylinder", A_IN, B_OUT, size=(B_OUT - A_IN) / 10, mixed=True)
        self.law = law = NortonCreep(E, NU, A=A, n=N)
        law.bind(v.mesh, v.quadrature_degree)
        m = v.mixed
        residual = (mixed.internal_work(law, m.u, m.p, m.v, m.q, v.model) * v.dx
                    + v.pressure * ufl.dot(v.normal, m.v) * v.weight * v.ds_inner)
        extra = {}
        if method == "modified":
            extra = {"constant_tangent": mixed.modified_newton_tangent(law, v.unknown, v.model,
                                                                      v.dx), "max_it": 500}
        self.solver = NewtonSolver(residual, v.unknown, v.supports, method=method, rtol=1e-10,
                                   atol=1e-10, force_scale=P * A_IN, **extra)
        self.sigma = mixed.cauchy_stress(law, m.u, m.p, v.model)

    def hoop(self) -> tuple[float, float]:
        """σ_θθ at the bore and outside, on y = 0."""
        s = self.v.probes.discontinuous("hoop", self.sigma[1, 1], 2)
        return s[0], s[1]

    def load(self, f: float) -> None:
        self.v.pressure.value = f * P

    def commit(self) -> None:
        self.law.commit(self.v.mixed.u, self.v.model)


def implicit(adaptive: bool, steps: int, tolerance: float = 1e-3, method: str = "full"):
    """One backward-Euler run: its bore history, end stresses, counts and time."""
    vessel = Vessel(method)
    history = []

    def on_step(t, f, result):
        history.append((t, *vessel.hoop()))

    t0 = time.perf_counter()
    path = solve_in_time(vessel.solver, vessel.law, vessel.load,
                         LoadHistory([(0.0, 0.0), (RAMP, 1.0)]), END, steps, land_on=OUTPUT,
                         adaptive=adaptive, tolerance=tolerance, commit=vessel.commit,
                         on_step=on_step)
    seconds = time.perf_counter() - t0
    return {"history": history, "time_s": seconds, "steps": len(path.times),
            "undone": path.rejected, "cuts": path.failures,
            "newton_iterations": path.iterations,
            "factorizations": path.work.factorizations,
            "stationary_since": path.stationary_since}


def explicit(dt: float, until: float = END, diverged_at: float = 10.0):
    """Forward Euler at the step dt (the ramp in one step, then dt to `until`).

    Stops early once the bore's hoop stress leaves [−diverged_at p, diverged_at p].
    """
    vessel = Vessel("modified")
    law, v = vessel.law, vessel.v
    eps = kinematics.small_strain(v.mixed.u, v.model)
    T = law.viscous_strain.function_space
    s_at = Expression(law.deviatoric_stress(eps), T.element.interpolation_points)
    s = fem.Function(T)
    law.set_time_step(0.0)  # Hooke's of the committed state: the residual is linear in u
    history, t, solves = [], 0.0, 0
    t0 = time.perf_counter()
    vessel.load(1.0)
    while t < until * (1 - 1e-12):
        s.interpolate(s_at)  # the state's deviatoric stress, the flow's direction and size
        step = RAMP if t == 0 else min(dt, next(x for x in [*OUTPUT, until]
                                                if x > t * (1 + 1e-12)) - t)
        if t > 0:
            d = s.x.array.reshape(-1, 9)
            q = np.sqrt(1.5 * np.einsum("ij,ij->i", d, d))
            rate = 1.5 * A * q[:, None] ** (N - 1) * d
            law.viscous_strain.x.array[:] += step * rate.ravel()
        try:
            result = vessel.solver.solve()
        except SolveError:
            return {"history": history, "diverged": True, "solves": solves,
                    "time_s": time.perf_counter() - t0}
        solves += result.work.linear_solves
        t = next((x for x in OUTPUT if abs(x - t - step) < 1e-9 * x), t + step)
        history.append((t, *vessel.hoop()))
        if not all(abs(x) < diverged_at * P for x in history[-1][1:]):
            return {"history": history, "diverged": True, "solves": solves,
                    "time_s": time.perf_counter() - t0}
    return {"history": history, "diverged": False, "solves": solves,
            "time_s": time.perf_counter() - t0}


def path_error(history, reference) -> float:
    """The largest |σ_θθ(a) − the reference's| at the output times, over p."""
    at = {t: s for t, s, _ in history if t in OUTPUT}
    ref = {t: s for t, s, _ in reference if t in OUTPUT}
    assert len(at) == len(ref) == len(OUTPUT), "a run missed an output time"
    return max(abs(at[t] - ref[t]) for t in OUTPUT) / P


def critical_step(state: float) -> float:
    """2/(3μ A n qⁿ⁻¹) (n = N): a material point's forward-Euler bound, linearized at q.

    q is the bore's σ_eq (√3/2 (σ_θθ − σ_rr)) in the stationary state of the exponent
    `state` (1: Lamé's, the first instant; N: the stationary state of the run).
    """
    sr, st = vessels.stationary_creep_stresses("cylinder", A_IN, B_OUT, P, state, A_IN)
    q = math.sqrt(3) / 2 * (st - sr)
    return 2 / (3 * E / (2 * (1 + NU)) * A * N * q ** (N - 1))


def summarise(run: dict, reference: list) -> dict:
    """The run's errors beside its counts (the history itself left out)."""
    _, st = vessels.stationary_creep_stresses("cylinder", A_IN, B_OUT, P, N,
                                              np.array([A_IN, B_OUT]))
    end = run["history"][-1]
    out = {k: v for k, v in run.items() if k != "history"}
    out["path_error"] = path_error(run["history"], reference)
    out["end_error"] = max(abs(end[1] - st[0]), abs(end[2] - st[1])) / P
    return out


def main():
    args = options(__doc__, "three runs of each kind, nothing written")
    implicit(True, 50, tolerance=1e-1)  # compiles the forms
    say("reference: steps sized to a local error of 1e-6 ...")
    reference = implicit(True, 50, tolerance=1e-4 if args.quick else 1e-6)
    say(f"  {reference['steps']} steps, {reference['time_s']:.1f} s")
    ref = reference["history"]
    fixed = [10, 200] if args.quick else [5, 10, 20, 50, 200, 800, 3200, 12800]
    tolerances = [1e-2, 1e-3] if args.quick else [1e-1, 1e-2, 1e-3, 3e-4, 1e-4]
    out = {"machine": machine(), "tau": TAU, "end": END, "reference_steps": reference["steps"],
           "equal": [], "adaptive": [], "modified": [], "explicit": []}
    for n in fixed:
        out["equal"].append({"n": n, **summarise(implicit(False, n), ref)})
        say("equal", out["equal"][-1])
    for tol in tolerances:
        out["adaptive"].append({"tolerance": tol, **summarise(implicit(True, 50, tol), ref)})
        say("adaptive", out["adaptive"][-1])
    for tol in () if args.quick else (1e-3,):
        out["modified"].append({"tolerance": tol,
                                **summarise(implicit(True, 50, tol, "modified"), ref)})
        say("modified", out["modified"][-1])
    out["critical_step_lame"], out["critical_step_stationary"] = critical_step(1.0), \
        critical_step(N)
    for dt in ([8.0, 32.0] if args.quick else [1.0, 2.0, 4.0, 8.0, 16.0, 32.0]):
        run = explicit(dt)
        entry = {"dt": dt, **{k: v for k, v in run.items() if k != "history"},
                 "steps": len(run["history"])}
        if not run["diverged"]:
            entry |= summarise(run, ref)
        out["explicit"].append(entry)
        say("explicit", entry)
    publish("creep", out, table, args, say=say)


def cheapest(runs: list[dict], bound: float, key: str) -> dict | None:
    """The fastest run whose error `key` is at most `bound`."""
    ok = [r for r in runs if r[key] <= bound]
    return min(ok, key=lambda r: r["time_s"]) if ok else None


def table(out: dict) -> str:
    """The results as Markdown."""
    lines = [f"Norton creep (n = 5) in the thick cylinder of `demos/creep_vessel.py`, to "
             f"t = {out['end']:g} = {out['end'] / out['tau']:.3g} τ (τ = 1/(E A pⁿ⁻¹)); "
             f"path error: the bore's hoop stress against a reference of "
             f"{out['reference_steps']} steps (local error 1e-6) at ten output times from "
             "0.001 τ to the end (every run lands on them), the largest difference over p; "
             "end error: against the stationary closed form (the mesh's share included).", "",
             "| steps | steps taken (undone) | Newton its | factorizations | path error | "
             "end error | time [s] |", "|---|---|---|---|---|---|---|"]
    for r in out["equal"]:
        lines.append(f"| equal, N = {r['n']} | {r['steps']} | {r['newton_iterations']} | "
                     f"{r['factorizations']} | {100 * r['path_error']:.3g} % | "
                     f"{100 * r['end_error']:.3g} % | {r['time_s']:.2f} |")
    for kind in ("adaptive", "modified"):
        for r in out[kind]:
            name = "adaptive" if kind == "adaptive" else "adaptive, modified Newton"
            lines.append(f"| {name}, tol = {r['tolerance']:g} | {r['steps']} ({r['undone']}) | "
                         f"{r['newton_iterations']} | {r['factorizations']} | "
                         f"{100 * r['path_error']:.3g} % | {100 * r['end_error']:.3g} % | "
                         f"{r['time_s']:.2f} |")
    for r in out["explicit"]:
        if r["diverged"]:
            lines.append(f"| explicit, Δt = {r['dt']:g} | diverged after {r['steps']} | — | "
                         f"1 | — | — | {r['time_s']:.2f} |")
        else:
            lines.append(f"| explicit, Δt = {r['dt']:g} | {r['steps']} | {r['solves']} solves "
                         f"| 1 | {100 * r['path_error']:.3g} % | {100 * r['end_error']:.3g} % | "
                         f"{r['time_s']:.2f} |")
    lines.append("")
    for key, what in (("path_error", "the path"), ("end_error", "the stationary state")):
        eq = cheapest(out["equal"], 5e-3, key)
        ad = cheapest(out["adaptive"], 5e-3, key)
        if eq and ad:
            lines.append(f"* {what} within 0.5 % of p: equal steps N = {eq['n']} in "
                         f"{eq['time_s']:.2f} s, adaptive (tol {ad['tolerance']:g}, "
                         f"{ad['steps']} steps) in {ad['time_s']:.2f} s: a ratio of "
                         f"{eq['time_s'] / ad['time_s']:.2g}.")
        elif ad:
            last = out["equal"][-1]
            lines.append(f"* {what} within 0.5 % of p: adaptive (tol {ad['tolerance']:g}, "
                         f"{ad['steps']} steps) in {ad['time_s']:.2f} s; no equal-step run "
                         f"reached it (N = {last['n']}: {100 * last[key]:.3g} % in "
                         f"{last['time_s']:.0f} s, {last['time_s'] / ad['time_s']:.0f} times "
                         "longer).")
    stable = [r["dt"] for r in out["explicit"] if not r["diverged"]]
    lines.append(f"* explicit: the largest stable step measured "
                 f"{max(stable) if stable else 'none':g}; a material point's bound "
                 f"2/(3μ A n qⁿ⁻¹) is {out['critical_step_lame']:.3g} at Lamé's σ_eq of the "
                 f"bore and {out['critical_step_stationary']:.3g} at the stationary one "
                 f"(τ = {out['tau']:.4g}).")
    return "\n".join(lines)


if __name__ == "__main__":
    if MPI.COMM_WORLD.size > 1:
        raise SystemExit("run on one rank")
    main()
