"""`fem.Expression` under a name that depends on the expression alone.

FFCx names a compiled expression after a hash of its UFL graph, and a `ufl.variable` enters
that hash by its label's number, which is a process-wide counter: the same law's stress,
built after another test's laws or after a different number of them, gets a new name and
is compiled again (a form renumbers its labels; an expression does not). The free energies
here differentiate through `ufl.variable`, so every quadrature-state update and stress
probe was recompiled in each new process order: 8-13 kernels per test run, a few seconds
each. Numbering the labels in the order they appear in the expression makes the name
reproducible; the graph is mapped node by node with sharing kept (a tree copy of a law's
derivative graph would be many times its size).
"""

from __future__ import annotations

import ufl
from ufl.corealg.map_dag import map_expr_dag
from ufl.corealg.multifunction import MultiFunction
from ufl.variable import Label

__all__ = ["Expression", "renumber_labels"]


class _LabelsInOrder(MultiFunction):
    def __init__(self):
        super().__init__()
        self.labels: dict[Label, Label] = {}

    expr = MultiFunction.reuse_if_untouched

    def label(self, o):
        return self.labels.setdefault(o, Label(len(self.labels)))


def renumber_labels(expr: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """`expr` with its variables' labels numbered 0, 1, ... in the order they appear."""
    return map_expr_dag(_LabelsInOrder(), expr)


def Expression(expr: ufl.core.expr.Expr, points, **kwargs):
    """`dolfinx.fem.Expression(expr, points, ...)`, compiled once for all processes."""
    from dolfinx import fem

    return fem.Expression(renumber_labels(expr), points, **kwargs)
