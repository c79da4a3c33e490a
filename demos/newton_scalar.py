# # Newton, modified Newton and secant on a scalar equation
#
# The course's first look at Newton-type methods: solve $r(u) = 0$ and watch how fast
# the error $e_k = u_k - u$ falls.
#
# ## Problem definition
#
# $$ \text{Newton: } u_{k+1} = u_k - \frac{r(u_k)}{r'(u_k)}, \qquad
#    \text{modified: } u_{k+1} = u_k - \frac{r(u_k)}{K}, \qquad
#    \text{secant: } u_{k+1} = u_k - r(u_k)\frac{u_k - u_{k-1}}{r(u_k) - r(u_{k-1})} $$
#
# Near the root, $|e_{k+1}| \approx C |e_k|^q$ with $q = 2$ (Newton), $q = 1$ and
# $C = |1 - r'(u)/K|$ (modified), $q = (1+\sqrt5)/2 \approx 1.618$ (secant).
# The observed order is $q_k = \ln(e_{k+1}/e_k) / \ln(e_k/e_{k-1})$.
#
# ### Where the orders come from
#
# Expand the residual about the root $u$: $r(u_k) = r'(u)\, e_k + \tfrac12 r''(u)\, e_k^2 +
# O(e_k^3)$.
#
# * **Newton** divides by the slope at $u_k$, $r'(u_k) = r'(u) + r''(u)\, e_k + \dots$, and
#   the first-order terms cancel: $e_{k+1} = \frac{r''(u)}{2 r'(u)}\, e_k^2 + O(e_k^3)$.
#   The number of correct digits doubles at each iteration.
# * **Modified Newton** divides by a fixed $K$: $e_{k+1} = (1 - r'(u)/K)\, e_k + O(e_k^2)$.
#   Each iteration gains the same number of digits, $-\log_{10}|1 - r'(u)/K|$; it converges
#   only if $0 < r'(u)/K < 2$. A $K$ stiffer than the root's slope (a softening law started
#   from its initial stiffness) converges slowly but surely; one less than half of it (a
#   hardening law started from its initial stiffness) diverges.
# * **Secant** divides by the chord through the last two iterates, and
#   $e_{k+1} \approx \frac{r''(u)}{2 r'(u)}\, e_k\, e_{k-1}$: with $|e_{k+1}| \sim |e_k|^q$
#   this needs $q^2 = q + 1$, whose root is the golden ratio.
#
# In a structure the same three choices are the full tangent (assembled and factorized at
# every iteration), the constant tangent (factorized once, then back-substitutions only)
# and the secant-type updates (quasi-Newton: BFGS on a frozen factorization). Which is
# fastest is a matter of cost per iteration against the number of iterations: the bracket
# and the vessel demos measure it.
#
# In double precision round-off arrives after three or four useful iterates, too few to
# watch an order settle, so by default the iterations run in 60-digit arithmetic (mpmath);
# `--digits 16` uses plain floats.
#
# ## Implementation

# +
import math
from dataclasses import dataclass
from typing import ClassVar

import mpmath
import numpy as np

from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.solvers import scalar

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# Each function: r(u), a starting point, and what it models.

FUNCTIONS = {
    "spring": (lambda u: mpmath.tanh(u) + 0.2 * u - 1, 0.0,
               "softening spring tanh(u) + 0.2 u = 1 (initial slope stiffer than at the root)"),
    "hardening": (lambda u: u + u**3 - 3, 0.5,
                  "hardening spring u + u^3 = 3 (modified Newton with r'(u0) diverges)"),
    "cubic": (lambda u: u**3 - 2 * u - 5, 2.0, "Newton's own example u^3 - 2u - 5 = 0"),
    "kepler": (lambda u: u - 0.5 * mpmath.sin(u) - 1.0, 1.0,
               "Kepler's equation E - e sin E = M (e = 0.5, M = 1)"),
}
EXPECTED = {"newton": 2.0, "modified": 1.0, "secant": (1 + 5**0.5) / 2}
# -

# ### Parameters
#
# From the command line (`python demos/newton_scalar.py --help`); in a notebook, the
# defaults.

# +
@dataclass
class Orders(Parameters):
    """Newton (order 2), modified Newton (order 1) and secant (order 1.618) on a scalar
    equation r(u) = 0, in many-digit arithmetic so that the orders show."""

    JSON = "orders and iteration counts"
    OUTPUTS: ClassVar = {"plot": "draw |e_k+1| against |e_k| (log-log: the slopes are the "
                                 "orders)"}

    function: str = choice("spring", list(FUNCTIONS), "equation r(u) = 0 to solve "
                           "(dimensionless): " + "; ".join(f"{k}: {v[2]}"
                                                           for k, v in FUNCTIONS.items()))
    u0: float | None = number(None, "starting point (default: the function's own)")
    slope: float | None = number(None, "constant slope K of modified Newton (default: r'(u0))")
    digits: int = number(60, "decimal digits of the arithmetic (16 = double precision "
                         "floats)", at_least=16, at_most=1000)
    max_it: int = number(500, "iteration limit per method", at_least=1)

    def check(self):
        if self.slope is not None and self.slope == 0:
            raise ValueError("--slope must be non-zero")


args = cli.arguments(Orders, prefixes={})
r, u0_default, what = FUNCTIONS[args.function]
u0 = args.u0 if args.u0 is not None else u0_default
if args.digits > 16:
    mpmath.mp.dps = args.digits
    num, tol = mpmath.mpf, mpmath.mpf(10) ** (5 - args.digits)
else:
    num, tol = float, 1e-14
    r = (lambda f: lambda u: float(f(u)))(r)
print(f"r(u) = 0: {what}; u0 = {u0}, {args.digits} digits")
# -

# ### The three methods
#
# A method that fails (modified Newton with a slope less than half the true one diverges)
# is a result too: its iterates are shown.

# +
def table(method, res, orders, failure):
    """Iterates, residuals and observed orders of one method (long runs elided)."""
    state = f"root {mpmath.nstr(res.root, 17)}" if res.converged else "FAILED"
    print(f"\n{method}: {res.iterations} iterations, {state}")
    print("  k   u_k                     |r(u_k)|     q_k")
    q = [None, None, *orders] if len(orders) + 2 <= len(res.iterates) else orders
    for i, (u, ru) in enumerate(zip(res.iterates, res.residuals, strict=True)):
        if 12 < i < len(res.iterates) - 3:
            if i == 13:
                print("  ...")
            continue
        qi = f"{q[i]:.3f}" if i < len(q) and q[i] is not None else ""
        print(f"  {i:<3d} {mpmath.nstr(u, 20):<23s} {float(abs(ru)):<12.3e} {qi}")
    if failure:
        print(f"  {failure}")
    elif orders:
        print(f"  observed order {orders[-1]:.3f} (theory {EXPECTED[method]:.3f})")


results, failures = {}, {}
for method in scalar.METHODS:
    k = num(args.slope) if args.slope is not None else None
    try:
        results[method] = scalar.solve(r, num(u0), method, k=k, tol=tol, max_it=args.max_it)
    except scalar.ScalarSolveError as err:
        results[method], failures[method] = err.result, str(err)

summary = {}
for method, res in results.items():
    orders = [float(q) for q in res.orders]
    summary[method] = {"converged": res.converged, "iterations": res.iterations,
                       "order": orders[-1] if orders else None,
                       "expected_order": EXPECTED[method], "orders": orders,
                       "root": float(res.root) if res.converged else None}
    table(method, res, orders, failures.get(method))
    if method in failures:
        summary[method]["failure"] = failures[method]
summary["function"] = args.function
# -

# ## Outputs
#
# The JSON (orders and iteration counts) and, when asked, $e_{k+1}$ against $e_k$.


def plot(results, path, title):
    """e_{k+1} against e_k, log-log: near the root the points lie on lines of slope q."""
    from fenics_nl.plots import figures  # imports dolfinx: only when a plot is asked for

    plt = figures.pyplot()

    fig, ax = plt.subplots(figsize=(6, 5))
    lo, hi = math.inf, 0.0
    for (method, res), colour in zip(results.items(), ("C0", "C1", "C2"), strict=True):
        if not res.converged:
            ax.plot([], [], "x", color=colour, label=f"{method}: diverged")
            continue
        root = res.iterates[-1]
        e = [float(abs(u - root)) for u in res.iterates[:-1]]
        e = [x for x in e if x > 0]
        if len(e) < 2:
            continue
        ax.loglog(e[:-1], e[1:], "o-", ms=3, color=colour,
                  label=f"{method} (theory: slope {EXPECTED[method]:.3g})")
        lo, hi = min(lo, *e), max(hi, *e)
    if hi > 0:
        x = np.geomspace(lo, hi, 50)
        for q, style in ((1.0, ":"), ((1 + 5**0.5) / 2, "-."), (2.0, "--")):
            ax.loglog(x, hi * (x / hi) ** q, style, color="gray", lw=0.8)
        ax.set_xlim(lo, hi * 2)
        ax.set_ylim(lo, hi * 2)
    ax.set_xlabel("error |e_k| = |u_k - u*|")
    ax.set_ylabel("next error |e_k+1|")
    ax.set_title(f"e_k+1 against e_k (grey: slopes 1, 1.62, 2)\n{title}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    figures.save_figure(fig, path)


cli.results(summary, [lambda: plot(results, args.plot, what)] if args.plot else [])
