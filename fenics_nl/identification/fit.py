"""Identifying J2 parameters from an indentation curve: the measured curve, the fit, its report.

The model (`indentation_test.IndentationTest`) is run through the measured depths themselves
— loading to the deepest, then unloading — so the computed P is compared with the measured
one at each measured depth, with no interpolation of either; a dense curve (more than
`max_points` per branch) is first resampled to `max_points` depths per branch by linear
interpolation of the measurement. The misfit is ½ Σ (P_model − P_measured)², minimised over
the chosen parameters by Levenberg–Marquardt (`solvers.least_squares`) with the Jacobian of
the direct differentiation: one model run per iteration gives the residuals and all their
derivatives.

The fit's mesh is a compromise between time and accuracy; its error is measured and taken
out (`refined_estimate`): one run of the same model on a finer mesh (h halved under the
indenter, the far field graded twice as finely) at the fitted parameters gives the curve
the finer model has there, and the fit's own Jacobian turns the difference into the
parameters' shift Δθ between the two models (a Gauss–Newton step of the finer model from
the fit). The reported parameters are the finer model's, θ − Δθ, and |Δθ| is added to their
noise's standard deviation: the discretisation is part of the uncertainty (`report`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fenics_nl.identification.indentation_test import (
    PARAMETERS,
    POSITIVE,
    IndentationTest,
    check_value,
)
from fenics_nl.solvers.least_squares import FitResult, levenberg_marquardt, statistics

__all__ = ["IDENTIFIABLE_SPREAD", "MeasuredCurve", "Refinement", "fit_curve", "initial_guess",
           "parse_names", "parse_values", "refined_estimate", "report"]

# a parameter whose standard deviation, for a noise of 1 % of the largest force, would exceed
# this fraction of its value is not determined by the curve: reported as not identifiable.
# At 1/2, its two-standard-deviation interval (95 % for a Gaussian) would reach 0: the curve
# could not tell it from no such parameter (H at δ = 0.02 R: 0.88-1.05, benchmarks/
# identification.py; 0.41 at 0.08 R)
IDENTIFIABLE_SPREAD = 0.5
REFERENCE_NOISE = 0.01


@dataclass
class MeasuredCurve:
    """A load–depth curve: loading to the deepest point, then (optionally) unloading.

    `depth` and `force` in the user's units, in the order measured.
    """

    depth: np.ndarray
    force: np.ndarray
    resampled_from: int | None = None  # the measured points, if resampled
    # the axes' labels: a file's header, else the quantities in the user's units
    labels: tuple[str, str] = ("depth δ (length)", "force P (force)")

    @classmethod
    def from_arrays(cls, depth, force, *, max_points: int = 12) -> MeasuredCurve:
        """The curve, checked (ValueError).

        Finite, depth >= 0 (zero depths dropped: they carry nothing), at least 3 points, one
        loading then one unloading (unless dense: then resampled).
        """
        depth, force = np.asarray(depth, dtype=float), np.asarray(force, dtype=float)
        if depth.shape != force.shape or depth.ndim != 1:
            raise ValueError("the curve needs one depth and one force per point")
        if not (np.all(np.isfinite(depth)) and np.all(np.isfinite(force))):
            raise ValueError("the curve has a value that is not a finite number")
        if np.any(depth < 0):
            k = int(np.argmax(depth < 0))
            raise ValueError(f"depth must be >= 0 (point {k + 1} has {depth[k]:g}): "
                             "indentation depths are measured into the surface")
        keep = depth > 0  # the unloaded start carries no information
        depth, force = depth[keep], force[keep]
        if len(depth) < 3:
            raise ValueError(f"the curve has {len(depth)} point(s) of non-zero depth: a fit "
                             "needs at least 3 (more than its parameters)")
        deepest = int(np.argmax(depth))
        loading, unloading = depth[: deepest + 1], depth[deepest:]
        dense = max(len(loading), len(unloading)) > max_points
        if dense:
            return cls._resampled(depth, force, deepest, max_points)
        if np.any(np.diff(loading) <= 0) or np.any(np.diff(unloading) >= 0):
            raise ValueError("depths must increase to the deepest point, then decrease (one "
                             "loading, one unloading); hold segments or reloads are not "
                             "supported")
        return cls(depth, force)

    @classmethod
    def _resampled(cls, depth, force, deepest, n) -> MeasuredCurve:
        """At most n depths per branch, by linear interpolation of the (dense) measurement."""
        parts_d, parts_f = [], []
        d_load, f_load = depth[: deepest + 1], force[: deepest + 1]
        order = np.argsort(d_load, kind="stable")
        grid = np.linspace(d_load.max() / n, d_load.max(), n)
        parts_d.append(grid)
        parts_f.append(np.interp(grid, d_load[order], f_load[order]))
        d_un, f_un = depth[deepest + 1:], force[deepest + 1:]
        if len(d_un):
            order = np.argsort(d_un, kind="stable")
            k = min(n, len(d_un))
            grid = np.linspace(d_load.max(), d_un.min(), k + 1)[1:]
            parts_d.append(grid)
            parts_f.append(np.interp(grid, d_un[order], f_un[order]))
        return cls(np.concatenate(parts_d), np.concatenate(parts_f),
                   resampled_from=len(depth))

    @classmethod
    def read(cls, path: str | Path, *, max_points: int = 12) -> MeasuredCurve:
        """A CSV file: a header line, then depth, force per line (ValueError if it is not)."""
        path = Path(path)
        if not path.is_file():
            raise ValueError(f"curve file {path} does not exist")
        lines = path.read_text().splitlines()
        if lines and _numbers(lines[0]):
            raise ValueError(f"{path}: its first line is numbers; the curve needs a header "
                             "line (e.g. depth,force) before its points")
        try:
            data = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
        except ValueError as err:
            raise ValueError(f"{path}: not a CSV of numbers after its header line ({err})"
                             ) from None
        if data.shape[1] != 2:
            raise ValueError(f"{path}: {data.shape[1]} column(s); the curve needs two, "
                             "depth and force (and a header line)")
        curve = cls.from_arrays(data[:, 0], data[:, 1], max_points=max_points)
        header = lines[0].split(",")
        if len(header) == 2:
            curve.labels = (header[0].strip(), header[1].strip())
        return curve

    def check_enough(self, parameters: int) -> None:
        """ValueError unless the curve has more points than the fit has parameters."""
        if len(self.depth) <= parameters:
            raise ValueError(f"the curve has {len(self.depth)} points of non-zero depth for "
                             f"{parameters} parameters: a fit needs more points than "
                             "parameters")

    @property
    def largest_force(self) -> float:
        """max P: the scale of the force residuals."""
        return float(np.max(np.abs(self.force)))


def _numbers(line: str) -> bool:
    """Whether a CSV line is all numbers."""
    try:
        [float(t) for t in line.split(",")]
    except ValueError:
        return False
    return True


def parse_names(text: str) -> list[str]:
    """'sigma0,hardening' -> the names, checked (ValueError naming an unknown one)."""
    names = [t.strip() for t in text.split(",") if t.strip()]
    unknown = [n for n in names if n not in PARAMETERS]
    if unknown or not names:
        raise ValueError(f"unknown parameter {', '.join(unknown) or '(none given)'}: choose "
                         f"among {', '.join(PARAMETERS)}")
    if len(set(names)) != len(names):
        raise ValueError(f"a parameter is named twice in {text!r}")
    return names


def parse_values(text: str, flag: str, names: list[str]) -> dict[str, float]:
    """'0.02,0.1' -> {name: value} in the order of `names`, each in its range (ValueError)."""
    try:
        values = [float(t) for t in text.split(",")]
    except ValueError:
        raise ValueError(f"{flag} {text!r}: give {len(names)} number(s) separated by commas "
                         f"({', '.join(names)})") from None
    if len(values) != len(names):
        raise ValueError(f"{flag} {text!r}: {len(values)} value(s) for {len(names)} "
                         f"parameter(s) ({', '.join(names)})")
    for name, value in zip(names, values, strict=True):
        try:
            check_value(name, value)
        except ValueError as err:
            raise ValueError(f"{flag}: {err}") from None
    return dict(zip(names, values, strict=True))


def initial_guess(measured: MeasuredCurve, names: list[str], *, E: float, radius: float,
                  cone_angle: float | None) -> dict[str, float]:
    """Starting values from the curve: Tabor's σ0 = P/(3πa²) at the deepest point.

    a the geometric contact radius there (sphere √(2Rδ − δ²), cone δ tan α); H = 5σ0 (a
    hardening of the order of the yield stress over a few per cent of strain), C = H, E as
    given.
    """
    k = int(np.argmax(measured.depth))
    d, P = measured.depth[k], measured.force[k]
    if cone_angle is None:
        a2 = 2 * radius * d - d * d if d < radius else radius**2
    else:
        a2 = (d * math.tan(math.radians(cone_angle))) ** 2
    sigma0 = P / (3 * math.pi * a2)
    if not sigma0 > 0:
        raise ValueError("the curve's force at its deepest point is not positive: no "
                         "indentation to identify a material from")
    guess = {"sigma0": sigma0, "hardening": 5 * sigma0, "kinematic": 5 * sigma0, "E": E}
    return {n: guess[n] for n in names}


def fit_curve(model: IndentationTest, measured: MeasuredCurve, names: list[str],
              initial: dict[str, float], *, progress=None) -> FitResult:
    """Levenberg–Marquardt on the curve's misfit over the parameters `names`.

    σ0 and E stay > 0 (bounded by 1e-6 of their start), H and C >= 0. Each evaluation is one
    model run with sensitivities: the residuals and their Jacobian together.
    """
    if tuple(names) != model.differentiate:
        raise ValueError(f"the model differentiates {model.differentiate}, not {names}")
    measured.check_enough(len(names))
    x0 = np.array([initial[n] for n in names], dtype=float)
    lower = np.array([1e-6 * x0[i] if n in POSITIVE else 0.0
                      for i, n in enumerate(names)])

    def evaluate(x):
        model.set(**dict(zip(names, x, strict=True)))
        curve = model.run(measured.depth)
        J = np.column_stack([curve.derivatives[n] for n in names])
        return curve.force - measured.force, J

    fit = levenberg_marquardt(evaluate, x0, lower, progress=progress)
    model.set(**dict(zip(names, fit.x, strict=True)))  # not a refused trial's
    return fit


@dataclass
class Refinement:
    """The fit's parameters moved to a finer model: the finer model's θ − Δθ, and Δθ."""

    x: np.ndarray  # the finer model's parameters (the fit's, less the shift)
    shift: np.ndarray  # Δθ: what the fit's model needs to give the finer model's curve
    forces: np.ndarray  # the finer model's curve at the fit's parameters
    dofs: int  # the finer model's unknowns


def refined_estimate(fit: FitResult, names: list[str], measured: MeasuredCurve,
                     finer: IndentationTest) -> Refinement:
    """The parameters of the finer model `finer`, from one run of it at the fit's.

    At θ the fit's model gives P(θ) and the finer one P_f(θ); with the fit's Jacobian J,
    J Δθ = P_f(θ) − P(θ) (least squares) is the shift of the fit's parameters that makes its
    curve the finer model's, so the finer model's fit to the same data is θ − Δθ to first
    order (a Gauss–Newton step of the finer model, on the fit's derivatives).
    """
    finer.set(**dict(zip(names, fit.x, strict=True)))
    forces = finer.run(measured.depth, sensitivities=False).force
    fitted = measured.force + fit.residuals
    shift = np.linalg.lstsq(fit.jacobian, forces - fitted, rcond=None)[0]
    # the step is a minimum's (Jᵀr = 0): a parameter the fit left on its bound (H = 0)
    # stays there, its shift still counted in its deviation
    x = np.where(fit.x - shift > 0, fit.x - shift, fit.x)
    return Refinement(x, shift, forces, finer.dofs)


def report(fit: FitResult, names: list[str], measured: MeasuredCurve,
           refinement: Refinement | None = None) -> dict:
    """The parameters, their spreads, correlations, identifiability: JSON-able.

    With a `refinement`, the parameters are the finer model's and each standard deviation
    is √(noise's² + Δθ²): the shift between the two models bounds what the finer one leaves
    of the discretisation (it halves the mesh size), and it is counted, not hidden. A
    parameter is identifiable when its standard deviation for a noise of 1 % of the largest
    force would be at most IDENTIFIABLE_SPREAD of its value (and the Jacobian has full
    rank); otherwise its value and spread are not reported, and the reason is.
    """
    stats = statistics(fit.residuals, fit.jacobian)
    reference = REFERENCE_NOISE * measured.largest_force
    ref_std = reference * np.sqrt(np.clip(np.diag(stats["unit_inverse"]), 0, None))
    x = fit.x if refinement is None else refinement.x
    shift = np.zeros_like(x) if refinement is None else refinement.shift
    std = np.hypot(stats["std"], shift)
    out = {"parameters": names, "noise": stats["noise"]}
    for i, n in enumerate(names):
        spread = ref_std[i] / abs(x[i]) if x[i] != 0 else math.inf
        ok = stats["rank"] == len(names) and spread <= IDENTIFIABLE_SPREAD
        out[n] = float(x[i]) if ok else None
        out[f"{n}_std"] = float(std[i]) if ok else None
        out[f"{n}_noise_std"] = float(stats["std"][i]) if ok else None
        out[f"{n}_identifiable"] = bool(ok)
        out[f"{n}_spread_at_1_percent_noise"] = _finite_or_none(spread)
        if refinement is not None:
            out[f"{n}_fit_model"] = float(fit.x[i])  # before the refinement
            out[f"{n}_discretisation_shift"] = float(shift[i])
        if not ok:
            out[f"{n}_estimate"] = float(x[i])  # where the fit stopped, not a result
    corr = stats["correlation"]
    out["correlation_matrix"] = [[_finite_or_none(v) for v in row] for row in corr]
    if "sigma0" in names and "hardening" in names:
        out["correlation"] = _finite_or_none(corr[names.index("sigma0"),
                                                  names.index("hardening")])
    return out


def _finite_or_none(v: float) -> float | None:
    """A JSON number, or null where there is none (no spread: no correlation; H = 0)."""
    return float(v) if math.isfinite(v) else None
