"""Observed convergence orders from a sequence of errors or residual norms."""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["observed_orders"]


def observed_orders(errors: Sequence[float], floor: float = 0.0) -> list[float]:
    """q_k = ln(e_{k+1}/e_k) / ln(e_k/e_{k-1}) over consecutive triples above `floor`.

    Values at or below `floor` (round-off) or non-decreasing triples are skipped, since
    the ratio means nothing there.
    """
    orders = []
    for e0, e1, e2 in zip(errors, errors[1:], errors[2:], strict=False):
        if min(e0, e1, e2) <= floor or not (e0 > e1 > e2):
            continue
        orders.append(math.log(e2 / e1) / math.log(e1 / e0))
    return orders
