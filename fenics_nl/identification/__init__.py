"""Identifying a law's parameters from an indentation curve.

`indentation_test` is the forward model (an axisymmetric J2 block under a rigid indenter,
with the curve's derivatives by direct differentiation), `fit` the measured curve, the
Levenberg–Marquardt fit and its report.
"""
