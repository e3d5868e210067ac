"""The goal as the ``grounded`` planner works through it: literals in the oracle's order, and those it skips."""

from __future__ import annotations

from dataclasses import dataclass

from more_agent.goal import Literal, TaskGoal
from more_agent.planners.goal_order import ORACLE_PREDICATES, as_placed, order_literals


@dataclass(frozen=True)
class Agenda:
    """The goal (its scopes, what the description names) and the literals of its first option."""

    goal: TaskGoal
    literals: tuple[Literal, ...]
    """The literals a subpolicy can achieve, in execution order (``goal_order.order_literals``)."""
    skipped: tuple[Literal, ...] = ()
    """Literals no subpolicy can achieve (named when the planner calls done)."""


def agenda_of(goal: TaskGoal) -> Agenda:
    """The agenda of ``goal``'s first option, its ``attached`` literals as the placements that attach."""
    option = [as_placed(lit) for lit in goal.options[0]]
    skipped = [lit for lit in option if lit.predicate not in ORACLE_PREDICATES]
    literals = order_literals([lit for lit in option if lit not in skipped])
    return Agenda(goal, tuple(literals), tuple(skipped))
