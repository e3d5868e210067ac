"""The order goal literals are achieved in, shared by the planners that read the goal (oracle, grounded).

A planner is not a library for another: what both goal-reading planners need lives here, so that
neither imports the other.
"""

from __future__ import annotations

from more_agent.goal import REARRANGE_PREDICATES, ROBOT_NAME, Literal

ORACLE_PREDICATES = REARRANGE_PREDICATES
"""Goal predicates the oracle knows how to achieve: those of a rearrangement."""

PLACED_AS = {"attached": "ontop"}
"""Goal predicates that a placement makes true, and the placement: ``attached(a, b)`` holds once a rests on b
(``sim.predicates.is_attached``)."""

PUT_DOWN_MAX_TOP_M = 1.5
"""Furniture taller than this (trees, wardrobes) is not used to put things down on."""


def as_placed(lit: Literal) -> Literal:
    """``lit`` as the skills achieve it: an ``attached`` literal becomes the ``ontop`` placement that attaches."""
    placement = PLACED_AS.get(lit.predicate)
    return lit if placement is None else Literal(placement, lit.args, lit.negated)


def _group(lit: Literal) -> int:
    """Order of literal kinds: open, removals, placements, closing, robot position."""
    if lit.predicate == "open":
        return 3 if lit.negated else 0
    if lit.args[0] == ROBOT_NAME:
        return 4
    return 1 if lit.negated else 2


def order_literals(literals: list[Literal]) -> list[Literal]:
    """Literals in execution order: by kind, and placements so that what goes into / onto X comes before X moves."""
    ordered = sorted(literals, key=_group)
    placements = [lit for lit in ordered if _group(lit) == 2]
    done: list[Literal] = []
    todo = list(placements)
    while todo:
        # First literal none of whose subject's contents-to-be are still waiting; cycles fall back to order.
        pick = next((lit for lit in todo if not any(o.args[1] == lit.args[0] for o in todo if o is not lit)), todo[0])
        done.append(pick)
        todo.remove(pick)
    rest = iter(done)
    return [next(rest) if _group(lit) == 2 else lit for lit in ordered]
