"""UFL expressions compiled for evaluation at points (`fem.Expression`), reproducibly.

FFCx names an expression's kernel by its UFL signature, and that signature carries the
global count of each `ufl.variable` label in it (a form's renumbers them; an expression's
does not). A law's stress is `ufl.diff` of its energy with respect to a variable strain,
so the same return map got a new name whenever more variables had been made before it in
the process (another test first, another xdist order): 8 or 9 kernels compiled again on
every CI run, 2-3 s each. Expanding the derivatives and stripping the variables first
gives one name per expression.
"""

from __future__ import annotations

__all__ = ["point_expression", "reproducible"]


def reproducible(expr):
    """`expr` with its derivatives expanded and its variables stripped."""
    from ufl.algorithms import expand_derivatives
    from ufl.algorithms.transformer import strip_variables

    return strip_variables(expand_derivatives(expr))


def point_expression(expr, points):
    """`fem.Expression` of `reproducible(expr)` at `points`."""
    from dolfinx import fem

    return fem.Expression(reproducible(expr), points)
