"""Identification by indentation: direct-differentiation Levenberg–Marquardt against a
finite-difference peer, and what the fit's model and noise do to the answer.

The demo's synthetic experiment (`demos/indentation_identification.py`): a rigid sphere
(R = 1) pressed to δ = 0.05 into a J2 block (E = 1, ν = 0.3, σ0 = 0.02, H = 0.1) in 6 steps
and unloaded half-way in 3, the curve computed on a finer mesh (refine 1) than the fit's
(refine 0, the demo's), with no noise and with 1 % noise (seed 1); both fits start a factor 2
off (σ0 = 0.04, H = 0.05).

* **ours**: `scenes.identification.fit_curve`, one model run per evaluation carrying dP/dθ by
  direct differentiation (a back-solve per parameter and step);
* **peer**: what a user writes around the forward model: `scipy.optimize.least_squares`
  (trust-region reflective, its default), the bounds σ0 > 0 and H >= 0, and its
  finite-difference Jacobian ('2-point') with a relative step of 1e-5, the square root of
  the forward solves' tolerance (its default, 1.5e-8, differences round-off).

Counted: model runs (each of the peer's Jacobians costs two), and wall time; their ratio is
the speed-up. Then, ours only: the spread of the fits over 8 noise seeds (how often the truth
lies within one reported standard deviation), and the model error of the fit's far field: a
curve computed with the far field graded by 5 % (not the fit's 20 %) and fitted without noise.

    python benchmarks/identification.py [--quick] [--update-docs]
"""

from __future__ import annotations

import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import scipy
from common import machine, options, publish
from scipy.optimize import least_squares

from fenics_nl.errors import SolveError
from fenics_nl.scenes.identification import MeasuredCurve, fit_curve, report
from fenics_nl.scenes.indentation_test import IndentationTest

DEEPEST = 0.05
TRUE = {"sigma0": 0.02, "hardening": 0.1}
START = {"sigma0": 0.04, "hardening": 0.05}
NAMES = ["sigma0", "hardening"]
FIT_MESH = {"block": 100.0, "growth": 0.2, "quadrature_degree": 1}  # the demo's
DEPTHS = np.concatenate([np.linspace(DEEPEST / 6, DEEPEST, 6),
                         np.linspace(DEEPEST, DEEPEST / 2, 4)[1:]])


def model(refine=0, differentiate=tuple(NAMES), mesh=FIT_MESH, **values):
    return IndentationTest(E=1.0, nu=0.3, max_depth=DEEPEST, refine=refine,
                           differentiate=differentiate, **(TRUE | values), **mesh)


def measured(exact, noise, seed=1):
    rng = np.random.default_rng(seed)
    return MeasuredCurve.from_arrays(
        DEPTHS, exact + noise * exact.max() * rng.standard_normal(len(DEPTHS)))


def ours(m, curve):
    t0 = time.perf_counter()
    solves = m.sensitivity.work.linear_solves
    fit = fit_curve(m, curve, NAMES, START)
    rep = report(fit, NAMES, curve)
    return {"method": "ours", "iterations": fit.iterations, "runs": fit.evaluations,
            "time_s": time.perf_counter() - t0, "x": fit.x.tolist(),
            "std": [rep["sigma0_std"], rep["hardening_std"]],
            "sensitivity_solves": m.sensitivity.work.linear_solves - solves}


def peer(m, curve):
    runs = 0

    def residuals(x):
        nonlocal runs
        runs += 1
        m.set(sigma0=float(x[0]), hardening=float(x[1]))
        try:
            return m.run(curve.depth, sensitivities=False).force - curve.force
        except SolveError:  # what a user would do: a large residual, the step refused
            return np.full(len(curve.depth), 1e3 * curve.largest_force)

    x0 = np.array([START[n] for n in NAMES])
    t0 = time.perf_counter()
    res = least_squares(residuals, x0, jac="2-point", diff_step=1e-5,
                        bounds=([1e-6 * x0[0], 0.0], [np.inf, np.inf]))
    return {"method": "peer", "iterations": int(res.nfev), "runs": runs,
            "time_s": time.perf_counter() - t0, "x": res.x.tolist(), "status": int(res.status)}


def forward_time(m, sensitivities, repeat=3):
    m.set(**TRUE)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        m.run(DEPTHS, sensitivities=sensitivities)
        times.append(time.perf_counter() - t0)
    return min(times)


def table(out):
    t = out["forward_time_s"]
    lines = ["| noise | method | iterations | model runs | forward-run equivalents | time (s) "
             "| σ0 (error) | H (error) |", "|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        errors = [f"{x:.5f} ({100 * (x / TRUE[n] - 1):+.2f} %)"
                  for n, x in zip(NAMES, r["x"], strict=True)]
        lines.append(f"| {100 * r['noise']:g} % | {r['method']} | {r['iterations']} | "
                     f"{r['runs']} | {r['time_s'] / t:.1f} | {r['time_s']:.1f} | "
                     f"{errors[0]} | {errors[1]} |")
    lines.append("")
    speed = [(p["time_s"] / o["time_s"], p["runs"] / o["runs"]) for o, p in
             zip(out["rows"][::2], out["rows"][1::2], strict=True)]
    lines.append(
        f"Ours is {', '.join(f'{s:.1f}×' for s, _ in speed)} faster than the peer "
        f"({', '.join(f'{r:.1f}×' for _, r in speed)} fewer model runs). One forward run "
        f"of the fit's model ({out['dofs']} unknowns, {len(DEPTHS)} steps) takes "
        f"{t:.2f} s, {out['forward_sensitivities_time_s']:.2f} s with the two parameters' "
        f"sensitivities (+{100 * (out['forward_sensitivities_time_s'] / t - 1):.0f} %); "
        f"\"forward-run equivalents\" is the fit's time over the former. The peer's "
        f"iterations column is its residual evaluations (scipy's nfev; each Jacobian costs "
        f"two more runs). Scipy {out['scipy']}, {out['machine']['cores']} cores, 1 rank.")
    if "seeds" in out:
        s = out["seeds"]
        lines.append("")
        lines.append(
            f"Over {len(s['within'])} noise seeds (1 %), the truth is within one reported "
            f"standard deviation for σ0 in {sum(w[0] for w in s['within'])} fits and for H in "
            f"{sum(w[1] for w in s['within'])} (68 % expected); the largest errors are "
            f"{s['largest_in_std'][0]:.2f} and {s['largest_in_std'][1]:.2f} standard "
            f"deviations. The fit's model against a curve made with the far field graded "
            f"by 5 % instead of 20 % (no noise): σ0 {100 * out['far_field'][0]:+.2f} %, "
            f"H {100 * out['far_field'][1]:+.2f} %: the error of the fit's far field, "
            f"which a real (half-space) curve would show.")
    return "\n".join(lines)


def main():
    args = options(__doc__, "no noise only, no seeds, nothing written")
    fine = model(refine=1, differentiate=())
    exact = fine.run(DEPTHS, sensitivities=False).force
    m = model(**START)
    m.run(DEPTHS[:2])  # compiles the forms
    out = {"machine": machine(), "scipy": scipy.__version__, "dofs": m.dofs, "rows": [],
           "forward_time_s": forward_time(m, False),
           "forward_sensitivities_time_s": forward_time(m, True)}
    for noise in (0.0,) if args.quick else (0.0, 0.01):
        curve = measured(exact, noise)
        for method in (ours, peer):
            row = method(m, curve) | {"noise": noise}
            print(row, flush=True)
            out["rows"].append(row)
    if not args.quick:
        within, largest = [], np.zeros(2)
        for seed in range(1, 9):
            r = ours(m, measured(exact, 0.01, seed))
            std = np.array([v if v is not None else np.nan for v in r["std"]])
            k = np.abs(np.array(r["x"]) - [TRUE[n] for n in NAMES]) / std
            within.append([bool(v <= 1) for v in k])  # NaN: not identifiable, not within
            largest = np.fmax(largest, k)
            print(seed, r["x"], k, flush=True)
        out["seeds"] = {"within": within, "largest_in_std": largest.tolist()}
        half_space = model(refine=1, differentiate=(),
                           mesh={"block": 100.0, "growth": 0.05, "quadrature_degree": 1})
        far = half_space.run(DEPTHS, sensitivities=False).force
        r = ours(m, measured(far, 0.0))
        out["far_field"] = [x / TRUE[n] - 1 for n, x in zip(NAMES, r["x"], strict=True)]
    publish("identification", out, table, args)


main()
