"""What an ideal reader of a task knows before seeing the world: the goal in BDDL form and the description.

:func:`task_goal` turns a task instance into a :class:`TaskGoal`: bddl's ground goal options as
literals over *scope* names (``apple.n.01_1``, never world object names), the object categories each
scope may be, the instance labels the description names (``apple A``), the room type of each floor
scope the description names ("the kitchen floor") and which scopes the goal moves. Nothing here
reads world state: scopes are matched to scene-graph objects by the planner, through what the robot
observes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from more_agent.sim import catalog
from more_agent.sim.ambiguity import described_scopes, scope_categories
from more_agent.sim.predicates import ROBOT_NAME
from more_agent.sim.goals import GoalChecker, Literal
from more_agent.sim.instantiate import TaskInstance
from more_agent.sim.tasks import scope_synset

_FLOOR = re.compile(r"^the (.+) floor$")

FLOOR_SYNSETS = frozenset({"floor.n.01", "lawn.n.01", "driveway.n.01", "carpet.n.01"})
"""Synsets of room grounds: their scopes are floors, placed on where the robot stands."""


@dataclass(frozen=True)
class TaskGoal:
    """The goal of one task as literals over scope names, with what the description says about the scopes."""

    options: tuple[tuple[Literal, ...], ...]
    """bddl's ground options (each a conjunction that satisfies the goal), literals over scope names."""
    categories: dict[str, frozenset[str]]
    """Scope -> object categories that count as it (the synset's own and its descendants'; for a scope the
    goal moves, no descendant that is a scene fixture: a car is a container, but none to put in a car)."""
    named: dict[str, str]
    """Scope -> instance label the description names it by (``apple A``)."""
    floor_rooms: dict[str, str | None]
    """Floor scope -> the room type the description names ('kitchen'), None when it names none."""
    robot: str
    """The agent's scope name."""
    moved: frozenset[str] = frozenset()
    """Scopes the goal moves (subjects of placement literals): only things that can be picked up are them."""

    def is_floor(self, scope: str) -> bool:
        return scope in self.floor_rooms


def task_goal(instance: TaskInstance, goals: GoalChecker) -> TaskGoal:
    """The task's goal as an ideal language reader knows it (module docstring).

    The ground options come from ``goals`` (bddl's expansion of the goal's quantifiers over the
    task's scopes); world names in them are mapped back to scope names, so the planner sees the goal
    as written, not which world object a scope is.
    """
    to_scope = {world: scope for scope, world in instance.scope.items()}
    options = tuple(
        tuple(Literal(lit.predicate, tuple(to_scope.get(a, a) for a in lit.args), lit.negated)
              for lit in goals.ground_literals(i))
        for i in range(goals.n_options)
    )
    described = described_scopes(instance)
    robot = next((s for s, w in instance.scope.items() if w == ROBOT_NAME), ROBOT_NAME)
    categories: dict[str, frozenset[str]] = {}
    named: dict[str, str] = {}
    floors: dict[str, str | None] = {}
    moved = {lit.args[0] for option in options for lit in option if len(lit.args) == 2 and lit.args[0] != robot}
    for scope in instance.scope:
        synset = scope_synset(scope)
        if scope == robot:
            continue
        if synset in FLOOR_SYNSETS:
            match = _FLOOR.match(instance.label(scope)) if scope in described else None
            floors[scope] = match.group(1).replace(" ", "_") if match else None
            continue
        own = synset.split(".")[0]
        categories[scope] = frozenset(c for c in scope_categories(scope)
                                      if scope not in moved or c == own or not catalog.is_scene_fixture(c))
        if scope in described:
            named[scope] = instance.label(scope)
    return TaskGoal(options=options, categories=categories, named=named, floor_rooms=floors, robot=robot,
                    moved=frozenset(moved))

