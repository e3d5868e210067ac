"""The ``grounded`` planner's choice of the next step: a function of its belief, the step's situation and
the goal's agenda (package docstring, points 2 and 3; the search is :mod:`.search`)."""

from __future__ import annotations

from more_agent.goal import Literal
from more_agent.planners.base import DONE, Step
from more_agent.planners.grounded.agenda import Agenda
from more_agent.planners.grounded.belief import Belief
from more_agent.planners.grounded.literals import closes, floor_region, holds
from more_agent.planners.grounded.search import search
from more_agent.planners.grounded.situation import Situation
from more_agent.planners.grounded.steps import Choice, floor_step, object_step, put_down, reachable, support_for


def choose(belief: Belief, sit: Situation, agenda: Agenda) -> Choice:
    """``done`` when every goal literal holds as far as the robot knows (or a named instance was given up
    on), else a step for the first unmet literal it can act on, else a search for what is unseen."""
    status = [(lit, holds(belief, sit, agenda, lit)) for lit in agenda.literals]
    lost = sorted(label for label in belief.bound.values() if label in belief.dropped)
    if lost:
        why = f"cannot act on {', '.join(lost)}, which the description names"
        return Choice(Step(DONE, note=why, gave_up=f"grounded planner gave up: {why}"))
    pending = [(lit, h) for lit, h in status if h is not True]
    if not pending:
        why = "; ".join(lit.text for lit in agenda.skipped)
        gave_up = f"goal literals no subpolicy achieves: {why}" if why else ""
        return Choice(Step(DONE, note="every goal literal holds in the scene graph", gave_up=gave_up))
    held_node = sit.graph.held_object
    held = held_node.label if held_node is not None else None
    door = door_in_the_way(belief, sit)
    if door is not None:
        if held is not None:
            return put_down(belief, sit, agenda, held)
        return object_step(sit, "go_to_and_open", door, f"{door} blocks the way")
    if held is not None:
        choice = place_held(belief, sit, agenda, held, [lit for lit, h in pending if h is False])
        if choice is not None:
            return choice
    only_closing = all(closes(lit) for lit, _ in pending)
    for lit, h in pending:
        if closes(lit) and not only_closing:
            continue  # close last: what is inside may still be needed
        if h is False:
            choice = act_for(belief, sit, agenda, lit, held)
            if choice is not None:
                return choice
    # Nothing to act on now: find what is unseen, else what is out of reach.
    missing = next((lit for lit, h in pending if h is None), pending[0][0])
    return search(belief, sit, agenda, missing, held)


def door_in_the_way(belief: Belief, sit: Situation) -> str | None:
    """The closed door the last blocked approach reported (``Belief.door_in_the_way``) while the step's graph
    shows it closed and it is not given up; forgotten once open, unseen or given up."""
    label = belief.door_in_the_way
    door = sit.graph.objects.get(label) if label is not None else None
    if door is None or door.open is not False or door.label in belief.dropped:
        belief.door_in_the_way = None
        return None
    return door.label


def place_held(belief: Belief, sit: Situation, agenda: Agenda, held: str, unmet: list[Literal]) -> Choice | None:
    """Place the held item where an unmet literal wants it, when that target is ready."""
    for lit in unmet:
        if lit.predicate == "open" or lit.negated or belief.bound.get(lit.args[0]) != held:
            continue
        target = lit.args[1]
        if agenda.goal.is_floor(target):
            region = floor_region(belief, sit, agenda, target)
            if region is not None:
                return floor_step(sit, region, f"for {lit.text}")
            continue
        b = belief.bound[target]
        if b in reachable(belief, sit) and not must_open(belief, b, lit.predicate):
            return object_step(sit, f"go_to_and_place_{lit.predicate}", b, f"for {lit.text}")
    return None


def act_for(belief: Belief, sit: Situation, agenda: Agenda, lit: Literal, held: str | None) -> Choice | None:
    """The next step towards an unmet literal whose objects are all known, or None if it cannot act now."""
    objects = reachable(belief, sit)
    note = f"for {lit.text}"
    goal = agenda.goal
    if lit.predicate == "open":
        label = belief.bound[lit.args[0]]
        if label not in objects:
            return None
        if held is not None:
            return put_down(belief, sit, agenda, held)
        return object_step(sit, "go_to_and_close" if lit.negated else "go_to_and_open", label, note)
    subject, target = lit.args
    if subject == goal.robot:
        return _go_to_room(belief, sit, agenda, target, note)
    a = belief.bound[subject]
    if a not in objects:
        return None
    if goal.is_floor(target) and not lit.negated and floor_region(belief, sit, agenda, target) is None:
        return None  # no room of the floor's type found yet: search for it first
    if (
        goal.is_floor(target)
        and lit.negated
        and (_placed_elsewhere(agenda, subject) or support_for(belief, sit, a) is None)
    ):
        return None  # the placement the goal asks for meets it; putting it down again cannot
    if not lit.negated and not goal.is_floor(target):
        b = belief.bound[target]
        if b not in objects:
            return None
        if must_open(belief, b, lit.predicate):
            return (
                put_down(belief, sit, agenda, held) if held is not None else object_step(sit, "go_to_and_open", b, note)
            )
    if held is not None:  # another item, or this one, which a negated literal takes away from where it must not be
        return put_down(belief, sit, agenda, held)
    hider = _closed_container_of(belief, a)
    if hider is not None:
        return object_step(sit, "go_to_and_open", hider, note) if hider in objects else None
    return object_step(sit, "go_to_and_grasp", a, note)


def _go_to_room(belief: Belief, sit: Situation, agenda: Agenda, floor: str, note: str) -> Choice | None:
    """Drive to an object of the room whose floor the robot must stand on, once such a room is known."""
    region = floor_region(belief, sit, agenda, floor)
    goal_obj = next((o for o in sit.graph.objects_in(region)), None) if region else None
    return object_step(sit, "navigate", goal_obj.label, note) if goal_obj is not None else None


def _placed_elsewhere(agenda: Agenda, scope: str) -> bool:
    """Whether a goal literal places ``scope`` somewhere (which takes it off any floor it must leave)."""
    return any(not lit.negated and lit.predicate != "open" and lit.args[0] == scope for lit in agenda.literals)


def _closed_container_of(belief: Belief, label: str) -> str | None:
    """The closed container ``label`` was last seen (or put) inside, if any."""
    rel = belief.relation.get(label)
    if rel is None or rel[0] != "inside" or rel[1] not in belief.seen:
        return None
    return rel[1] if belief.seen[rel[1]].open is False else None


def must_open(belief: Belief, label: str, predicate: str) -> bool:
    """Whether placing ``inside`` ``label`` needs it opened first."""
    return predicate == "inside" and belief.seen[label].open is False
