import math

import numpy as np
import pytest

from fenics_nl.theory import elastica

# formulas.md table: P/P_cr, α (deg), δ/L, x/L
TABLE = [(1.01, 16.15, 0.1779, 0.9802), (1.05, 35.61, 0.3800, 0.9053),
         (1.10, 49.53, 0.5085, 0.8203), (1.20, 67.86, 0.6488, 0.6739),
         (1.50, 98.67, 0.7886, 0.3636), (2.00, 124.55, 0.7970, 0.0709)]


@pytest.mark.parametrize("ratio,alpha,d,x", TABLE)
def test_elastica_reproduces_the_reference_table(ratio, alpha, d, x):
    assert math.degrees(elastica.tip_rotation(ratio)) == pytest.approx(alpha, abs=0.006)
    dd, xx = elastica.tip_position(ratio)
    assert dd == pytest.approx(d, abs=6e-5) and xx == pytest.approx(x, abs=6e-5)


def test_small_rotation_asymptote_and_straight_branch():
    # P/P_cr ≈ 1 + α²/8 for small α; no rotation below the Euler load
    a = 0.01
    assert elastica.load_ratio(a) == pytest.approx(1 + a * a / 8, rel=1e-8)
    assert elastica.tip_rotation(0.9) == 0.0
    assert elastica.euler_load(2.0, 3.0, 1.5) == pytest.approx(math.pi**2 * 6 / 9)


def test_shape_ends_at_the_tip_position():
    from fenics_nl.theory import elastica

    for ratio in (1.05, 1.5, 3.0):
        x, y = elastica.shape(ratio)
        d, xl = elastica.tip_position(ratio)
        assert abs(x[-1] - xl) < 1e-8 and abs(y[-1] - d) < 1e-8
        # inextensible: the centreline keeps its length
        assert np.sum(np.hypot(np.diff(x), np.diff(y))) == pytest.approx(1.0, rel=1e-4)
