"""One-to-one matching of task scopes to what a scene offers, the same in every process.

networkx's Hopcroft-Karp walks Python sets of the nodes, whose order changes with the string hash
seed, so which of two equal cabinets a scope got (and every record after it) differed between runs.
Here the largest matching is an assignment problem on the given order of rows and columns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import numpy as np

L = TypeVar("L")
R = TypeVar("R")


def maximum_matching(left: Sequence[L], right: Sequence[R], allowed: Callable[[L, R], bool]) -> dict[L, R]:
    """A largest one-to-one assignment of ``left`` items to ``right`` items over the ``allowed`` pairs.

    Deterministic for a given order of both sequences.

    >>> maximum_matching(["a", "b"], [1, 2], lambda l, r: (l, r) != ("b", 1))
    {'a': 1, 'b': 2}
    """
    if not left or not right:
        return {}
    # imported here: scipy.optimize takes 0.7 s to import, and a listing never matches
    from scipy.optimize import linear_sum_assignment

    cost = np.array([[0.0 if allowed(a, b) else 1.0 for b in right] for a in left])
    rows, cols = linear_sum_assignment(cost)
    return {left[i]: right[j] for i, j in zip(rows, cols) if cost[i, j] == 0.0}
