"""Whether a goal literal holds as far as the ``grounded`` planner knows."""

from __future__ import annotations

from more_agent.goal import Literal
from more_agent.planners.grounded.agenda import Agenda
from more_agent.planners.grounded.belief import Belief, bind, floor_beneath
from more_agent.planners.grounded.situation import Situation
from more_agent.vocabulary import FLOOR


def holds(belief: Belief, sit: Situation, agenda: Agenda, lit: Literal) -> bool | None:
    """Whether ``lit`` holds on the observed open states and relations and the planner's own placements;
    None while one of its objects is unseen (binding its scopes when it can)."""
    goal = agenda.goal
    if lit.predicate == "open":
        label = bind(belief, goal, lit.args[0], sit.xy)
        if label is None:
            return None
        return bool(belief.seen[label].open) != lit.negated
    subject, target = lit.args
    if subject == goal.robot:
        region = floor_region(belief, sit, agenda, target)
        return None if region is None else (sit.here == region) != lit.negated
    a = bind(belief, goal, subject, sit.xy)
    if a is None:
        return None
    if goal.is_floor(target):
        floor = floor_beneath(belief, a)
        if goal.stays.get(subject) == target and (floor is not None or unplaced(belief, sit, a)):
            return not lit.negated  # the description says it lies there: wherever seen, however its region is typed
        want = goal.floor_rooms.get(target)
        if want is not None:  # the floor's room as the planner knows it (a garage typed otherwise, below)
            region = floor_region(belief, sit, agenda, target)
            want = want if region is None else belief.room_types.get(region, "")
        on = floor is not None and (want is None or floor[1] == f"{FLOOR} {want}")
        return on != lit.negated
    b = bind(belief, goal, target, sit.xy)
    if b is None:
        return None
    return (belief.relation.get(a) == (lit.predicate, b)) != lit.negated


def unplaced(belief: Belief, sit: Situation, label: str) -> bool:
    """Whether ``label`` rests on nothing the robot knows of and is not in its hand: an object seen only in part
    (a bin's top above a hedge) shows no support and no ground beneath it."""
    held = sit.graph.held_object
    return belief.relation.get(label) is None and (held is None or held.label != label)


def floor_region(belief: Belief, sit: Situation, agenda: Agenda, scope: str) -> str | None:
    """A reachable region whose room type is the floor's (the robot's when the description names none); with
    none of that type, the region where an object the description says stays on that floor was last seen
    (``TaskGoal.stays``: Ihlen_0_int's garage holds a bookcase and a cabinet, no furniture of a garage). Last
    seen, not first: a carton first glimpsed through a doorway is given the room the robot looks from."""
    goal = agenda.goal
    want = goal.floor_rooms.get(scope)
    if want is None:
        return sit.here
    matches = sorted(rid for rid, kind in belief.room_types.items() if kind == want)
    if matches:
        return matches[0]
    staying = (belief.bound.get(s, "") for s, floor in sorted(goal.stays.items()) if floor == scope)
    regions = (belief.seen[label].region_id for label in staying if label in belief.seen)
    return next((rid for rid in regions if rid is not None), None)


def closes(lit: Literal) -> bool:
    """Whether ``lit`` asks for something closed."""
    return lit.predicate == "open" and lit.negated
