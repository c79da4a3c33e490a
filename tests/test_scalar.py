import math

import mpmath
import pytest

from fenics_nl.solvers import scalar

GOLDEN = (1 + 5**0.5) / 2
EQUATIONS = [  # r, u0: each root is simple and each start within Newton's basin
    (lambda u: mpmath.tanh(u) + 0.2 * u - 1, 0),
    (lambda u: u**3 - 2 * u - 5, 2),
    (lambda u: u - mpmath.cos(u), 1),
    (lambda u: mpmath.atan(u) - 0.5, 0),
]


@pytest.mark.parametrize("r,u0", EQUATIONS)
@pytest.mark.parametrize("method,order", [("newton", 2.0), ("modified", 1.0), ("secant", GOLDEN)])
def test_observed_orders(r, u0, method, order):
    # 60 digits leave enough iterates above round-off for the order to settle.
    mpmath.mp.dps = 60
    res = scalar.solve(r, mpmath.mpf(u0), method, tol=mpmath.mpf(10) ** -55, max_it=500)
    assert res.converged
    assert abs(r(res.root)) < 1e-50
    assert abs(res.orders[-1] - order) < 0.15


def test_float_newton_matches_closed_form():
    res = scalar.solve(lambda u: u * u - 2, 1.0, "newton", dr=lambda u: 2 * u)
    assert res.root == pytest.approx(math.sqrt(2), rel=1e-15)
    assert res.iterates[0] == 1.0 and res.iterates[1] == 1.5  # u1 = 1 - (1 - 2)/2
    assert res.orders[-1] > 1.8


def test_modified_rate_is_one_minus_slope_ratio():
    # e_{k+1} ≈ (1 − r'(u)/K) e_k: r = u² − 2, K = 4 → rate 1 − 2√2/4.
    res = scalar.solve(lambda u: u * u - 2, 1.0, "modified", k=4.0)
    e = [abs(u - math.sqrt(2)) for u in res.iterates]
    assert e[12] / e[11] == pytest.approx(1 - 2 * math.sqrt(2) / 4, rel=1e-3)


def test_errors_are_clear():
    with pytest.raises(scalar.ScalarSolveError, match="slope"):
        scalar.solve(lambda u: u * u + 1, 0.0, "newton", dr=lambda u: 2 * u)
    with pytest.raises(scalar.ScalarSolveError, match="no convergence in 2 iterations"):
        scalar.solve(lambda u: u**3 - 2 * u - 5, 2.0, "newton", max_it=2)
    with pytest.raises(scalar.ScalarSolveError, match="diverges") as err:
        scalar.solve(lambda u: u * u + 1, 1.0, "newton", max_it=20)  # no real root
    assert not err.value.result.converged and len(err.value.result.iterates) > 2
    with pytest.raises(scalar.ScalarSolveError, match="r\\(u\\) failed"):
        scalar.solve(lambda u: math.exp(u) - 2, 0.0, "modified", k=1e-300)  # exp overflows
    with pytest.raises(scalar.ScalarSolveError, match="non-finite"):
        scalar.solve(lambda u: u * u * u - 2, 0.0, "modified", k=1e-300)  # u = 2e300, r = inf
    with pytest.raises(ValueError, match="method"):
        scalar.solve(lambda u: u, 1.0, "bisection")
