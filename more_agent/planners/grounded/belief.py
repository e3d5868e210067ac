"""What the ``grounded`` planner has learnt of its episode (:class:`Belief`), and how it learns.

The belief changes in three places only: :func:`learn_from_graph` after each observation, :func:`bind`
when a choice first needs a goal scope's instance (a binding stays), and :func:`learn_from_outcome`
after each executed step. Everything else reads it.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

from more_agent.goal import TaskGoal
from more_agent.planners.base import Step
from more_agent.planners.room_types import is_standing_furniture
from more_agent.planners.targets import Area
from more_agent.records import FailureReason
from more_agent.robot import XY, ActionResult
from more_agent.scene_graph import ObjectNode, SceneGraph
from more_agent.vocabulary import FLOOR

MAX_FAILURES = 2
"""An action is not tried again after failing this many times the same way."""

MAX_REACH_FAILURES = 3
"""An object is given up after this many failed approaches (the robot explores in between)."""

GROUND_M = 0.05
"""An object whose observed box reaches this low, resting on no observed object, stands on the floor."""

Relation = tuple[str, str]
"""(predicate 'inside' / 'ontop', label of the container / support, or 'floor <room>')."""

FailureKey = tuple[str, tuple[str, ...], FailureReason | None, str | None]
"""(skill, arguments, typed reason, the closed door in the way): failures counted as the same way of failing."""


@dataclass
class Belief:
    """What the planner believes of the world beyond the step's scene graph, learnt over the episode."""

    bound: dict[str, str] = field(default_factory=dict)
    """Goal scope -> the observed instance label it stands for (:func:`bind`)."""
    seen: dict[str, ObjectNode] = field(default_factory=dict)
    """Label -> the object as last observed (objects of rooms now out of reach included)."""
    found_in: dict[str, str | None] = field(default_factory=dict)
    """Label -> the region the object was first observed in."""
    relation: dict[str, Relation | None] = field(default_factory=dict)
    """Label -> where it rests as last observed or placed."""
    found_on: dict[str, str] = field(default_factory=dict)
    """Label -> the object it rested on when first observed, where it rested on one."""
    room_types: dict[str, str] = field(default_factory=dict)
    """Region id -> its room type, as the step's graph labels it."""
    looked_into: set[str] = field(default_factory=set)
    """Containers seen open or opened."""
    looked_at: set[str] = field(default_factory=set)
    """Furniture driven to in search of a missing item (``search.furniture_to_look_at``)."""
    fruitless_looks: int = 0
    """Such drives in a row that revealed no new object (the search stops them at ``FRUITLESS_EXPLORES``)."""
    dropped: set[str] = field(default_factory=set)
    """Labels given up on: no scope binds to them again."""
    out_of_reach: dict[str, int] = field(default_factory=dict)
    """Label -> trajectory length when an approach failed: skipped until the robot has moved since."""
    failures: Counter[FailureKey] = field(default_factory=Counter)
    opened_in_a_row: int = 0
    """Containers opened to look inside, one step after the other (``search.OPENS_BEFORE_EXPLORING``)."""
    fruitless: Counter[str] = field(default_factory=Counter)
    """Region id -> explore() calls in a row that revealed no new object (``search.FRUITLESS_EXPLORES``)."""
    door_in_the_way: str | None = None
    """The closed door an approach reported in its way (``ActionResult.blocking``), opened next: as the
    oracle does, and as a reader of the feedback "the way to car A is blocked by closed door C" would."""


def learn_from_graph(belief: Belief, graph: SceneGraph) -> None:
    """Remember what the step's graph shows: each object, the region it was first seen in and what it
    rested on then, where it rests and whether it was seen open; the rooms' types."""
    belief.room_types = {rid: r.room_label for rid, r in graph.regions.items() if r.room_label}
    rel = {r.subject: (r.predicate, graph.objects[r.object].label) for r in graph.relations}
    for obj in graph.objects.values():
        first = rel.get(obj.label) if obj.label not in belief.seen else None
        if first is not None and first[0] == "ontop":
            belief.found_on[obj.label] = first[1]
        belief.seen[obj.label] = obj
        belief.found_in.setdefault(obj.label, obj.region_id)
        if obj.open:
            belief.looked_into.add(obj.label)
        if obj.held:
            belief.relation[obj.label] = None
        elif obj.label in rel:
            belief.relation[obj.label] = rel[obj.label]
        elif not on_floor(belief.relation.get(obj.label)) or (obj.region_id is not None and on_ground(belief, obj)):
            # a floor it was put on stays known unless the object shows on a floor of a region, whose room
            # type is read again (the room may have been typed again: ``Embodiment.step_graph``)
            belief.relation[obj.label] = on_ground(belief, obj)


def bind(belief: Belief, goal: TaskGoal, scope: str, xy: XY) -> str | None:
    """The observed instance ``scope`` is bound to, binding it now if possible: the label the description
    names, else the unbound instance of a category that counts as the scope nearest to ``xy``."""
    if scope in belief.bound:
        return belief.bound[scope]
    named = goal.named.get(scope)
    if named is not None:
        if named in belief.seen:
            belief.bound[scope] = named
        return belief.bound.get(scope)
    candidates = _candidates(belief, goal, scope)
    if not candidates:
        return None
    best = min(candidates, key=lambda o: (math.dist(o.position[:2], xy), o.label))
    belief.bound[scope] = best.label
    return best.label


def _candidates(belief: Belief, goal: TaskGoal, scope: str) -> list[ObjectNode]:
    """Observed objects of a category that counts as the (unnamed) ``scope``, not bound to another scope."""
    taken = set(belief.bound.values()) | set(goal.named.values()) | belief.dropped
    cats = goal.categories.get(scope, frozenset())
    return [o for o in belief.seen.values() if o.category in cats and o.label not in taken]


def unseen(belief: Belief, goal: TaskGoal, scope: str) -> bool:
    """Whether no observed object could be bound to ``scope`` yet (:func:`bind` without binding)."""
    if scope in belief.bound:
        return False
    named = goal.named.get(scope)
    return named not in belief.seen if named is not None else not _candidates(belief, goal, scope)


def on_ground(belief: Belief, obj: ObjectNode) -> Relation | None:
    """The floor of its room when the object's box reaches the ground (``GROUND_M``): the scene graph
    relates objects to objects only, and without this an item lying on a lawn would be believed off it."""
    return None if obj.bbox.min[2] > GROUND_M else on_floor_of(belief, obj.region_id)


def on_floor_of(belief: Belief, region: str | None) -> Relation:
    """The relation of an object resting on the floor of ``region``, named by its room type."""
    return ("ontop", f"{FLOOR} {belief.room_types.get(region or '', '')}")


def floor_beneath(belief: Belief, label: str) -> Relation | None:
    """The floor ``label`` rests on, directly or through a stack of 'ontop' links over loose items: a sod
    on a pillow lying on the lawn is on the lawn (docs/tasks.md, predicate semantics). None when it rests
    on standing furniture (which has no floor beneath it in that sense), inside something, or is held."""
    rel, visited = belief.relation.get(label), {label}
    while rel is not None and not on_floor(rel):
        support = belief.seen.get(rel[1])
        if rel[0] != "ontop" or support is None or rel[1] in visited or is_standing_furniture(support.category):
            return None
        visited.add(rel[1])
        rel = belief.relation.get(rel[1])
    return rel


def on_floor(rel: Relation | None) -> bool:
    """Whether ``rel`` rests something on a floor."""
    return rel is not None and rel[1].startswith(f"{FLOOR} ")


NEW_FLOOR_M2 = 10.0
"""A step that maps this much floor not mapped before revealed something (``StepOutcome.news``)."""


@dataclass(frozen=True)
class StepOutcome:
    """What executing one step showed, beyond its result: read from the robot around the skill."""

    result: ActionResult
    held: str | None
    """The label the hand held before the step."""
    region: str | None
    """The robot's region before the step."""
    news: bool
    """Whether the step revealed an object not observed before, or ``NEW_FLOOR_M2`` of floor not mapped before
    (a garden's explores show lawn and few objects: two without an object left its driveway unseen)."""
    path_length: int
    """Length of the robot's trajectory after the step."""


def learn_from_outcome(belief: Belief, goal: TaskGoal, action: Step, outcome: StepOutcome) -> None:
    """Learn from an executed step: explores that revealed nothing, floor placements, containers looked
    into, furniture driven to, and failures (:func:`count_failure`)."""
    target, result = action.target, outcome.result
    if isinstance(target, Area):
        if action.name == "explore":
            assert target.region_id is not None
            belief.fruitless[target.region_id] = 0 if outcome.news else belief.fruitless[target.region_id] + 1
        elif result.ok and outcome.held is not None:  # put on a floor
            belief.relation[outcome.held] = on_floor_of(belief, target.region_id or outcome.region)
    elif isinstance(target, ObjectNode):
        if result.ok and action.name == "go_to_and_open":
            belief.looked_into.add(target.label)
        if action.name == "navigate":
            belief.looked_at.add(target.label)
            if outcome.news:  # its room shows more: explore it again
                belief.fruitless[target.region_id or ""] = 0
    belief.fruitless_looks = 0 if outcome.news else belief.fruitless_looks + (action.name == "navigate")
    if result.reason is FailureReason.PATH_BLOCKED_BY_DOOR and result.blocking is not None:
        belief.door_in_the_way = result.blocking
    if not result.ok and isinstance(target, ObjectNode):
        count_failure(belief, goal, action, target.label, outcome)


def count_failure(belief: Belief, goal: TaskGoal, action: Step, label: str, outcome: StepOutcome) -> None:
    """Count a failure on the object ``label``; an action failing twice the same way (its typed reason, and
    the door in the way: another door is progress) drops it from the bindings (an approach: three times;
    what cannot be picked up: at once). No feedback text is compared."""
    result = outcome.result
    key = (action.name, action.arguments, result.reason, result.blocking)
    if result.reason is FailureReason.NOT_REACHABLE:
        belief.out_of_reach[label] = outcome.path_length
        limit = MAX_REACH_FAILURES
    else:  # furniture cannot be picked up however often the robot tries
        limit = 1 if result.reason is FailureReason.NOT_GRASPABLE else MAX_FAILURES
    belief.failures[key] += 1
    if belief.failures[key] < limit:
        return
    belief.dropped.add(label)
    for scope, bound in list(belief.bound.items()):
        if bound == label and scope not in goal.named:
            del belief.bound[scope]
