# # Identifying a material by indentation: J2 parameters from a load–depth curve
#
# `indentation.py` computes the curve $P(\delta)$ of a sphere pressed into a J2 block and
# lifted off. Instrumented indentation runs this backwards: from a measured curve, find the
# yield stress $\sigma_0$ and the hardening modulus $H$ of the material (the course's example,
# after Constantinescu & Tardieu, 2001). This demo fits the model's curve to a measured one by
# Levenberg–Marquardt, with the curve's derivatives with respect to the parameters computed
# through the whole load path by direct differentiation, and says how well the curve
# determines each parameter, the fit's own discretisation included.
#
# ## Problem definition
#
# The model is `indentation.py`'s: an axisymmetric block, a rigid sphere (or a cone of
# half-angle $\alpha$, `--cone-angle`; Berkovich tips are the cone of 70.3°), frictionless
# contact solved by the course's active set, J2 plasticity with linear isotropic hardening
# $\sigma_{eq} \le \sigma_0 + H p$ (optionally the kinematic modulus $C$ and $E$ as unknowns
# too). It is loaded through the measured depths $\delta_1 < \dots < \delta_L$, then unloaded
# through the rest: its force $P_k(\theta)$ at each measured depth, for the parameters
# $\theta$. The fit minimises
#
# $$ \Phi(\theta) = \tfrac12 \sum_k \big(P_k(\theta) - P_k^{measured}\big)^2, \qquad
#    \sigma_0 > 0,\ H \ge 0. $$
#
# Gauss–Newton needs $\partial P_k/\partial\theta$. At a converged step $n$, equilibrium
# $R(u_n; \alpha_{n-1}, \theta) = 0$ with the committed internal variables $\alpha_{n-1}$
# ($\varepsilon^p$, $p$) and the return map $\alpha_n = A(\varepsilon(u_n); \alpha_{n-1},
# \theta)$ differentiate to
#
# $$ K_n\, \frac{du_n}{d\theta} = -\Big(\frac{\partial R}{\partial\theta}
#    + \frac{\partial R}{\partial\alpha}\frac{d\alpha_{n-1}}{d\theta}\Big), \qquad
#    \frac{d\alpha_n}{d\theta} = \frac{\partial A}{\partial u}\frac{du_n}{d\theta}
#    + \frac{\partial A}{\partial\alpha}\frac{d\alpha_{n-1}}{d\theta}
#    + \frac{\partial A}{\partial\theta}, $$
#
# with $du/d\theta = 0$ on the supports and on the step's contact nodes (held: Tardieu &
# Constantinescu's sensitivity problem). $K_n$ is the step's converged tangent, already
# factorized by the forward solve: each parameter costs one back-solve per step, not a
# whole forward run as a finite difference would. Every derivative is UFL's.
#
# ## Implementation

# +
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from mpi4py import MPI

from fenics_nl.identification.fit import (
    MeasuredCurve,
    fit_curve,
    initial_guess,
    parse_names,
    parse_values,
    refined_estimate,
    report,
)
from fenics_nl.identification.indentation_test import IndentationTest
from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number, text
from fenics_nl.plots import indentation as indentation_pictures

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# From the command line (`python demos/indentation_identification.py --help`); in a
# notebook, the defaults: a synthetic experiment.

# +
@dataclass
class Identification(Parameters):
    """Identify J2 parameters (σ0, H; optionally E, C) from an indentation curve by
    Levenberg–Marquardt with direct-differentiation sensitivities. Without --curve, a
    synthetic experiment: a finer model's curve with noise. Units are the user's."""

    EPILOG = ("PETSc options of the model's solver take the prefix "
              "-punch_axisymmetric_elim_ (the KSP of each active-set iteration).")
    OUTPUTS: ClassVar = {"plot": "the measured and identified curves, and the misfit over "
                                 "(σ0, H) with the iterates (--map² more model runs)"}

    curve: str | None = text(None, "the measured curve: a CSV file, a header line then depth, "
                             "force per line (default: a synthetic experiment)",
                             metavar="FILE.csv")
    E: float = number(1.0, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-", above=-1, at_most=0.499)
    radius: float = number(1.0, "the sphere's radius R", unit="length", above=0)
    cone_angle: float | None = number(None, "a cone of this half-angle instead of the sphere "
                                      "(Berkovich: 70.3)", unit="degree", above=0, at_most=89)
    gap: str = choice("parabola", ["parabola", "sphere"], "the sphere's shape, as in "
                      "indentation.py: Hertz's parabola, or the exact sphere (a real "
                      "indenter: give the curve's own)")
    fit: str = text("sigma0,hardening", "the parameters to fit, among sigma0, hardening, E, "
                    "kinematic", metavar="NAMES")
    initial: str | None = text(None, "their starting values, in --fit's order (default: "
                               "synthetic, σ0 and H a factor 2 off the truth, C = H/2, E "
                               "as given; a curve, Tabor's σ0 = P/(3πa²), H = 5σ0, C = H)",
                               metavar="VALUES")
    true: str = text(None, "synthetic: the true SIGMA0,H (default 0.02E,0.1E)",
                     metavar="SIGMA0,H")
    depth: float | None = number(None, "synthetic: the deepest indentation (default 0.08 R; "
                                 "cone: 0.05)", unit="length", above=0)
    steps: int | None = number(None, "synthetic: loading depths, default 6 (unloading: half "
                               "as many, to half the depth)", at_least=2)
    noise: float | None = number(None, "synthetic: the noise's standard deviation, a "
                                 "fraction of the largest force (default 0.01)", unit="-",
                                 at_least=0, at_most=0.5)
    seed: int | None = number(None, "synthetic: the noise's random seed (default 1)",
                              at_least=0)
    refine: int = number(0, "the fit's mesh: h = a/(20·2^refine) under the indenter (the "
                         "synthetic curve's: refine + 1)", at_least=0, at_most=4)
    growth: float = number(0.1, "the fit's far field: elements grow by this fraction per "
                           "element away from the indenter (its check: half)", unit="-",
                           above=0, at_most=0.5)
    max_points: int = number(12, "a denser measured curve is resampled to this many depths per "
                             "branch", at_least=3)
    map: int = number(5, "--plot: the misfit map's model runs per axis (0: no map)",
                      at_least=0, at_most=15)

    def check(self):
        self.names = parse_names(self.fit)
        synthetic_only = [f for f in ("true", "depth", "steps", "noise", "seed")
                          if getattr(self, f) is not None]
        if self.curve is not None and synthetic_only:
            raise ValueError(f"--{synthetic_only[0]} is for the synthetic experiment: drop it "
                             "or --curve")
        if self.cone_angle is not None and self.radius != 1.0:
            raise ValueError("--radius is the sphere's: a cone (--cone-angle) has none")
        if self.cone_angle is not None and self.gap == "sphere":
            raise ValueError("--gap is the sphere's shape: a cone (--cone-angle) has none")
        self.steps = 6 if self.steps is None else self.steps
        self.noise = 0.01 if self.noise is None else self.noise
        self.seed = 1 if self.seed is None else self.seed
        self.true_values = parse_values(self.true or f"{0.02 * self.E},{0.1 * self.E}",
                                        "--true", ["sigma0", "hardening"])
        self.initial_values = (parse_values(self.initial, "--initial", self.names)
                               if self.initial is not None else None)


args = cli.arguments(Identification, {"punch_axisymmetric_elim_": "KSP"})
warnings = []
# -

# ### The measured curve
#
# A user's CSV file (units as they are: the parameters come out in the force's over the
# depth's squared), or a synthetic experiment: the curve of `indentation.py`'s physics **on
# another mesh** than the fit's and than its check's (half the element size under the
# indenter, the far field graded by 7 % per element) at the true parameters, with Gaussian
# noise of `--noise` times the largest force, so that the fit does not invert its own
# discretisation.

# +
true = None
if args.curve is not None:
    measured = MeasuredCurve.read(args.curve, max_points=args.max_points)
    if measured.resampled_from is not None:
        warnings.append(f"the curve's {measured.resampled_from} points were resampled to "
                        f"{len(measured.depth)} depths (--max-points {args.max_points})")
else:
    true = args.true_values
    deepest = args.depth or (0.08 * args.radius if args.cone_angle is None else 0.05)
    n_load = args.steps
    depths = np.concatenate([np.linspace(deepest / n_load, deepest, n_load),
                             np.linspace(deepest, 0.5 * deepest, n_load // 2 + 1)[1:]])
    experiment = IndentationTest(E=args.E, nu=args.nu, sigma0=true["sigma0"],
                                 hardening=true["hardening"], max_depth=deepest,
                                 radius=args.radius, cone_angle=args.cone_angle, gap=args.gap,
                                 refine=args.refine + 1, growth=0.07, differentiate=())
    exact = experiment.run(depths, sensitivities=False).force
    noise = args.noise * exact.max() * np.random.default_rng(args.seed).standard_normal(
        len(depths))
    measured = MeasuredCurve.from_arrays(depths, exact + noise)
    cli.say(f"synthetic curve: {len(depths)} depths to {deepest:g}, {experiment.dofs} "
            f"unknowns, noise {100 * args.noise:g} % of P_max = {exact.max():.4g}")
    del experiment
# -

# ### The model
#
# `indentation.py`'s block under the indenter — the same shape of the sphere (`--gap`), a
# block of 1000 contact radii, its quadrature — with $E$, $\sigma_0$, $H$, $C$ as
# `fem.Constant`s: one set of compiled forms for every run of the fit. Only its mesh is
# coarser: $h = a/20$ under the indenter (`--refine 0`) and a far field graded by 10 % per
# element (`--growth`), 2.5 times faster than the forward demo's 5 %.

# +
measured.check_enough(len(args.names))
model = IndentationTest(E=args.E, nu=args.nu, sigma0=1.0, hardening=0.0,
                        max_depth=float(measured.depth.max()), radius=args.radius,
                        cone_angle=args.cone_angle, gap=args.gap, refine=args.refine,
                        growth=args.growth, differentiate=tuple(args.names))
initial = args.initial_values or (
    {n: (2 * true[n] if n == "sigma0" else 0.5 * true[n]) if n in true else
     {"E": args.E, "kinematic": 0.5 * true["hardening"]}[n] for n in args.names}
    if true else initial_guess(measured, args.names, E=args.E, radius=args.radius,
                               cone_angle=args.cone_angle))
cli.known(dofs=model.dofs, ranks=MPI.COMM_WORLD.size)
cli.say(f"model: {model.dofs} unknowns; fitting {', '.join(args.names)} from "
        + ", ".join(f"{n} = {v:.4g}" for n, v in initial.items()))
# -

# ### The fit
#
# Each Levenberg–Marquardt iteration runs the model once from the virgin state through the
# measured depths, with the sensitivities: the residuals $P_k - P_k^{measured}$ and their
# Jacobian together. A step that would cross a bound goes 90 % of the way to it.

fit = fit_curve(model, measured, args.names, initial, progress=cli.say)

# ### The fit's discretisation, measured
#
# The fit's mesh has an error of its own. One run of the model on a finer mesh (`finer`:
# $h$ halved, the far field graded twice as finely) at the fitted parameters $\theta$ gives
# the finer model's curve $P_f(\theta)$; with the fit's Jacobian $J$, the least-squares
# solution of $J\,\Delta\theta = P_f(\theta) - P(\theta)$ is how far the fit's model must move
# to give the finer model's curve. The finer model's parameters are then
# $\theta - \Delta\theta$ (a Gauss–Newton step of the finer model from the fit), and
# $|\Delta\theta|$ joins the noise in their standard deviations: what the finer mesh still
# leaves is smaller than what it corrected.

finer = model.finer()
refinement = refined_estimate(fit, args.names, measured, finer)
cli.say(f"finer model: {refinement.dofs} unknowns; shift "
        + ", ".join(f"{n} {100 * d / x:+.2f} %" for n, d, x in
                    zip(args.names, refinement.shift, refinement.x, strict=True)))
del finer

# ## What the fit says
#
# The parameters and their standard deviations: $s^2 (J^TJ)^{-1}$, $s$ the residual's noise,
# and the discretisation's shift, added in quadrature; their correlation: $\sigma_0$ and $H$
# trade against each other along the curve (a higher yield stress with less hardening gives
# nearly the same forces), so the correlation is close to $-1$ and $H$ is known less well than
# $\sigma_0$. The noise's part is that of the linearised problem: the valley of $\Phi$ bends,
# so read it as a scale, not as a guarantee (`benchmarks/identification.py` counts how often
# the truth lies within it over noise seeds). A parameter whose standard deviation would
# exceed half its value for a noise of 1 % of the largest force (its 95 % interval would reach
# 0) is *not identifiable* from this curve: it is reported as such, not as a number.

# +
out = report(fit, args.names, measured, refinement)
shifted = [n for i, n in enumerate(args.names)
           if abs(refinement.shift[i]) > max(out[f"{n}_noise_std"] or 0, 0)
           and out[n] is not None and abs(refinement.shift[i]) > 0.01 * abs(out[n])]
if shifted:
    warnings.append(f"the fit's mesh dominates the uncertainty of {', '.join(shifted)} (its "
                    "shift to the finer model, in the standard deviation, exceeds the noise's "
                    f"and 1 %): --refine {args.refine + 1} would narrow it")
for n in args.names:
    if out[n] is None:
        warnings.append(f"{n} is not identifiable from this curve: 1 % noise would leave it "
                        f"uncertain by {100 * out[f'{n}_spread_at_1_percent_noise']:.0f} %")
        continue
    line = f"{n} = {out[n]:.5g} ± {out[f'{n}_std']:.2g}"
    if true and n in true:
        out[f"true_{n}"] = true[n]
        out[f"{n}_rel_error"] = out[n] / true[n] - 1
        out[f"{n}_error_in_std"] = (out[n] - true[n]) / out[f"{n}_std"]
        line += (f" (true {true[n]:.5g}: {100 * out[f'{n}_rel_error']:+.2f} %, "
                 f"{out[f'{n}_error_in_std']:+.2f} standard deviations)")
    cli.say(line)
if "correlation" in out:
    cli.say(f"σ0–H correlation {out['correlation']:+.4f}")
cli.say(f"{fit.iterations} iterations, {fit.evaluations} model runs, "
        f"{fit.wall_time:.3g} s ({fit.reason})")
if not fit.converged:
    warnings.append(f"the fit did not converge: {fit.reason}")
# -

# ## Outputs
#
# The JSON, and with `--plot` the measured curve (dots) and the identified one (line), as in
# the course's figure, beside the misfit's contours over $(\sigma_0, H)$ with the iterates.

# +
out |= {"iterations": fit.iterations, "forward_solves": fit.evaluations,
        "converged": fit.converged, "misfit": fit.misfit,
        "iterates": [[float(v) for v in x] for x in fit.iterates], "misfits": fit.misfits,
        "fitted_parameters": args.names,
        "curve": {"depth": measured.depth.tolist(), "measured": measured.force.tolist(),
                  "noise_free": exact.tolist() if true else None,
                  "fitted": (measured.force + fit.residuals).tolist(),
                  "initial": (measured.force + fit.initial_residuals).tolist()},
        "synthetic": true is not None, "noise_level": args.noise if true else None,
        "sensitivity_solves": model.sensitivity.work.linear_solves,
        "finer_model_dofs": refinement.dofs,
        "stress_unit": "stress", "dofs": model.dofs, "ranks": MPI.COMM_WORLD.size,
        "warnings": warnings}


def draw():
    """The curves, and the misfit map when σ0 and H are the fitted pair (collective)."""
    pair = args.names == ["sigma0", "hardening"] and args.map > 0
    spread = [max(3 * (out[f"{n}_std"] or 0), 0.05 * abs(x)) for n, x in
              zip(args.names, fit.x, strict=True)]
    grid = (indentation_pictures.misfit_grid(model, measured, np.array(fit.iterates),
                                                np.array(spread), args.map) if pair else None)
    indentation_pictures.identification_figure(out, args.plot, grid,
                                                  labels=measured.labels)


cli.results(out, [draw] if args.plot else [])
# -
