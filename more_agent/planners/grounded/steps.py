"""The steps the ``grounded`` planner takes on objects and floors, and where it frees its hand."""

from __future__ import annotations

import math
from dataclasses import dataclass

from more_agent.planners.base import Step
from more_agent.planners.goal_order import PUT_DOWN_MAX_TOP_M
from more_agent.planners.grounded.agenda import Agenda
from more_agent.planners.grounded.belief import Belief, floor_beneath
from more_agent.planners.grounded.situation import Situation
from more_agent.planners.room_types import is_furniture, is_standing_furniture
from more_agent.planners.targets import Area
from more_agent.vocabulary import FLOOR


@dataclass(frozen=True)
class Choice:
    """A chosen step (its typed target included), and whether it opens a container to look inside
    (the search counts those in a row, ``search.OPENS_BEFORE_EXPLORING``)."""

    action: Step
    looking: bool = False


def object_step(sit: Situation, skill: str, label: str, note: str) -> Choice:
    """``skill`` on the object ``label`` of the step's graph."""
    obj = sit.graph.objects[label]
    return Choice(Step(skill, (sit.room(obj.region_id), label), obj, note=note))


def floor_step(sit: Situation, region: str, note: str) -> Choice:
    """Put what the hand holds on the floor of ``region``."""
    room = sit.room(region)
    return Choice(Step("go_to_and_place_ontop", (room, FLOOR), Area(room, region), note=note))


def reachable(belief: Belief, sit: Situation) -> set[str]:
    """Labels of objects in the step's graph, less those whose approach failed since the robot last moved."""
    moved = len(sit.path)
    return {o for o in sit.graph.objects if belief.out_of_reach.get(o, -1) != moved}


def put_down(belief: Belief, sit: Situation, agenda: Agenda, held: str) -> Choice:
    """Free the hand: on the floor where the robot stands, unless the goal wants the item off that
    floor; then on top of the nearest low furniture seen (the oracle's choice), if there is one."""
    note = f"free the hand of {held}"
    support = support_for(belief, sit, held) if off_floor(belief, agenda, held, sit.here) else None
    if support is not None:
        return object_step(sit, "go_to_and_place_ontop", support, note)
    room = sit.room(sit.here)
    return Choice(Step("go_to_and_place_ontop", (room, FLOOR), Area(room), note=note))


def off_floor(belief: Belief, agenda: Agenda, held: str, region: str | None) -> bool:
    """Whether a goal literal wants ``held`` off the floor of ``region`` (``not ontop`` a floor scope
    that names no room or names this room's type)."""
    kind = belief.room_types.get(region or "")
    goal = agenda.goal
    return any(
        lit.negated
        and lit.predicate == "ontop"
        and goal.is_floor(lit.args[1])
        and belief.bound.get(lit.args[0]) == held
        and goal.floor_rooms[lit.args[1]] in (None, kind)
        for lit in agenda.literals
    )


def support_for(belief: Belief, sit: Situation, held: str) -> str | None:
    """The nearest reachable observed furniture to put ``held`` on top of: low enough to reach
    (``PUT_DOWN_MAX_TOP_M``), not closed, not given up on, not a loose item lying on a floor (what is put
    on it rests on that floor: :func:`~.belief.floor_beneath`); in the robot's room first."""
    spots = [
        o
        for label in reachable(belief, sit)
        if label not in belief.dropped
        and label != held
        and is_furniture((o := belief.seen[label]).category)
        and o.category != "door"
        and o.bbox.max[2] <= PUT_DOWN_MAX_TOP_M
        and o.open is not False
        and (is_standing_furniture(o.category) or floor_beneath(belief, label) is None)
    ]
    if not spots:
        return None
    here = sit.here
    return min(spots, key=lambda o: (o.region_id != here, math.dist(o.position[:2], sit.xy), o.label)).label
