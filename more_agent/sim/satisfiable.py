"""Whether a goal can hold at all: is bddl's evaluation of a compiled goal true for some truth value of each
of its ground atoms?

stacking_wood asks every one of its six logs to be on the table or on a log, exactly two on the table and
exactly two on a log (bddl's ``forn`` counts exactly): no world meets that, and an episode of it is lost
before it starts. :func:`satisfiable` writes the compiled goal as a 0-1 linear program, one variable per
ground atom and one per node of the goal, each node's value tied to its children's as bddl's ``evaluate``
computes it, and asks HiGHS (scipy's ``milp``) for any solution with the goal true. Every atom is free, even
one the world cannot make true (an object on itself, a predicate the world does not model): False is a
property of the goal's logic alone, never of our world.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from bddl.logic_base import AtomicFormula


def satisfiable(goal: Sequence[Any]) -> bool:
    """Whether some truth assignment of the atoms makes every head of the compiled ``goal`` true (bddl's
    ``get_goal_conditions`` output). A solver that stops without an answer (``TIME_LIMIT_S``) counts as
    satisfiable: only a proof of no solution says False."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import coo_array

    program = _Program()
    for head in goal:
        program.constrain({program.node(head): 1.0}, 1.0, 1.0)
    rows = [(r, v, w) for r, (coeffs, _, _) in enumerate(program.rows) for v, w in coeffs.items()]
    r, v, w = (np.array(column) for column in zip(*rows, strict=True))
    matrix = coo_array((w, (r, v)), shape=(len(program.rows), program.n_vars))
    low, high = (np.array([row[k] for row in program.rows]) for k in (1, 2))
    result = milp(
        c=np.zeros(program.n_vars),
        integrality=np.ones(program.n_vars),
        bounds=Bounds(0, 1),
        constraints=LinearConstraint(matrix, low, high),
        options={"time_limit": TIME_LIMIT_S},
    )
    return bool(result.status != _INFEASIBLE)


TIME_LIMIT_S = 10.0
"""The solver's limit per goal. Over the 939 activities that instantiate, solving takes 2 ms (median) and 25 ms
at most (stacking_wood's proof; 2026-12-03, scipy imported beforehand)."""

_INFEASIBLE = 2
"""scipy's ``milp`` status for a program without a solution."""


class _Program:
    """A 0-1 linear program under construction: variables by index, rows of ``low <= sum(w * x) <= high``."""

    def __init__(self) -> None:
        self.n_vars = 0
        self.rows: list[tuple[dict[int, float], float, float]] = []
        self._atoms: dict[tuple[object, ...], int] = {}

    def var(self) -> int:
        """A new 0-1 variable."""
        self.n_vars += 1
        return self.n_vars - 1

    def constrain(self, coeffs: dict[int, float], low: float, high: float) -> None:
        """Add ``low <= sum(coeffs[v] * v) <= high``."""
        self.rows.append((coeffs, low, high))

    def node(self, node: Any) -> int:
        """The variable equal to bddl's evaluation of compiled goal ``node``."""
        if isinstance(node, AtomicFormula):
            return self._atom(node)
        kind = type(node).__name__
        children = node.children
        if kind in ("Conjunction", "Universal", "HEAD"):
            return self._all([self.node(c) for c in children])
        if kind in ("Disjunction", "Existential"):
            return self._any([self.node(c) for c in children])
        if kind == "Negation":
            return self._not(self.node(children[0]))
        if kind == "Implication":
            antecedent, consequent = (self.node(c) for c in children)
            return self._any([self._not(antecedent), consequent])
        if kind == "NQuantifier":  # exactly N, as bddl's evaluate counts
            values = [self.node(c) for c in children]
            return self._all([self._at_least(values, node.N), self._not(self._at_least(values, node.N + 1))])
        if kind in ("ForPairs", "ForNPairs"):  # at least N rows and N columns with a true pair, by position
            cells = [[self.node(c) for c in row] for row in children]
            rows = [self._any(row) for row in cells]
            columns = [self._any(list(column)) for column in zip(*cells, strict=True)]
            n = node.N if kind == "ForNPairs" else min(len(rows), len(columns))
            return self._all([self._at_least(rows, n), self._at_least(columns, n)])
        raise TypeError(f"no 0-1 encoding of bddl goal node {kind}")

    def _atom(self, node: Any) -> int:
        """One variable per ground atom: the same predicate over the same scope objects is the same atom."""
        inputs = (node.input,) if hasattr(node, "input") else (node.input1, node.input2)
        key = (node.STATE_NAME, *(node.scope[i] for i in inputs))
        if key not in self._atoms:
            self._atoms[key] = self.var()
        return self._atoms[key]

    def _all(self, xs: list[int]) -> int:
        return self._at_least(xs, len(xs))

    def _any(self, xs: list[int]) -> int:
        return self._at_least(xs, 1)

    def _not(self, x: int) -> int:
        y = self.var()
        self.constrain({x: 1.0, y: 1.0}, 1.0, 1.0)
        return y

    def _at_least(self, xs: list[int], n: int) -> int:
        """y = 1 exactly when at least ``n`` of ``xs`` (a variable listed twice counts twice) are 1:
        sum >= n * y and sum <= n - 1 + (k - n + 1) * y."""
        y = self.var()
        total: dict[int, float] = {}
        for x in xs:
            total[x] = total.get(x, 0.0) + 1.0
        self.constrain({**total, y: -float(n)}, 0.0, np.inf)
        self.constrain({**total, y: -float(len(xs) - n + 1)}, -np.inf, n - 1.0)
        return y
