"""What an ideal reader of a task knows before seeing the world: the goal in BDDL form and the description.

:func:`task_goal` turns a task instance into a :class:`~more_agent.goal.TaskGoal` (the runner hands it to
a planner that reads the goal, in its :class:`~more_agent.goal.GoalSpec`): bddl's ground goal options as
literals over *scope* names (``apple.n.01_1``, never world object names), the object categories each
scope may be, the instance labels the description names (``apple A``), the room type of each floor
scope the description names ("the kitchen floor") and which scopes the goal moves. Nothing here
reads world state: scopes are matched to scene-graph objects by the planner, through what the robot
observes.

The goal is read as its author meant it (:func:`intended_goal`): eight bddl activities have a
``forall`` over a variable its body never uses, e.g. recycling_office_papers ``(forall (?legal_document.n.01 -
legal_document.n.01) (inside ?legal_document.n.01_1 ?recycling_bin.n.01_1))``, which bddl checks as
"legal_document.n.01_1 is in the bin", one document no reader can tell from the others ("throw all
legal documents in the recycling bin"). Read as written by intent, every document goes in the bin,
which satisfies the goal whichever one bddl means. Not so where the typo sits in an implication:
buying_groceries' ``(forall (?sack.n.01 ...) (imply (inside ?carton__of__milk.n.01_1 ?sack.n.01_1)
(not (inside ?banana.n.02_1 ?sack.n.01))))`` means "milk and banana not in one bag", which the
intended reading keeps, but bddl checks "the milk is not in sack_1", which no reader of "one bag
... another bag" can tell from sack_2: a coin flip (seed 2 of the ceiling benchmark lost it).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from more_agent.goal import ROBOT_NAME, Literal, TaskGoal
from more_agent.sim import catalog
from more_agent.sim.ambiguity import described_scopes, scope_categories
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import TaskInstance
from more_agent.vocabulary import FLOOR_SYNSETS, scope_synset

_FLOOR = re.compile(r"^the (.+) floor$")


def task_goal(instance: TaskInstance, goals: GoalChecker) -> TaskGoal:
    """The task's goal as an ideal language reader knows it (module docstring).

    The ground options come from ``goals`` (bddl's expansion of the goal's quantifiers over the
    task's scopes); world names in them are mapped back to scope names, so the planner sees the goal
    as written, not which world object a scope is.
    """
    intended = intended_goal(instance.definition.goal)
    to_scope = scopes_of_world_names(instance.scope, {t.lstrip("?") for t in _terms(intended)})
    if intended != instance.definition.goal:
        goals = GoalChecker(instance, goal=intended)
    options = tuple(
        tuple(
            Literal(lit.predicate, tuple(to_scope.get(a, a) for a in lit.args), lit.negated)
            for lit in goals.ground_literals(i)
        )
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
        categories[scope] = frozenset(
            c
            for c in scope_categories(scope)
            if catalog.has_model(c) and (scope not in moved or c == own or not catalog.is_scene_fixture(c))
        )
        if scope in described:
            named[scope] = instance.label(scope)
    return TaskGoal(
        options=options,
        categories=categories,
        named=named,
        floor_rooms=floors,
        robot=robot,
        moved=frozenset(moved),
        stays=staying(options, floors, set(named), instance.definition.init),
        leaves=leaving(options, floors, instance.definition.init),
        activity=instance.definition.name,
    )


def scopes_of_world_names(scope: dict[str, str], in_goal: set[str]) -> dict[str, str]:
    """World name -> the scope a goal literal over it is read as. Scopes may share a world object: a garden's
    ``lawn.n.01_1``, ``floor.n.01_1`` and ``driveway.n.01_1`` are all its one ground. The scope the goal
    names wins (cleaning_parks' "leave the recycling bin on the lawn" read as on a ``floor.n.01_1`` of no
    named room lost that the bin stays on the lawn); otherwise the first."""
    to_scope: dict[str, str] = {}
    for name, world in scope.items():
        if world not in to_scope or (name in in_goal and to_scope[world] not in in_goal):
            to_scope[world] = name
    return to_scope


def staying(
    options: tuple[tuple[Literal, ...], ...], floors: dict[str, str | None], named: set[str], init: list[Any]
) -> dict[str, str]:
    """Scope -> the scope it stays on, for each goal literal ``(ontop scope support)`` that the task's init
    already states, over a floor whose room the description names or a ``named`` support: the description
    says it stays there (``TaskGoal.stays``)."""
    return {
        lit.args[0]: lit.args[1]
        for lit in _ontop_from_the_start(options, init)
        if not lit.negated and (floors.get(lit.args[1]) is not None or lit.args[1] in named)
    }


def leaving(options: tuple[tuple[Literal, ...], ...], floors: dict[str, str | None], init: list[Any]) -> dict[str, str]:
    """Scope -> the floor it must leave, for each goal literal ``(not (ontop scope floor))`` that the task's init
    states, over a floor whose room the description names: the description says it lies there now
    (``TaskGoal.leaves``)."""
    return {
        lit.args[0]: lit.args[1]
        for lit in _ontop_from_the_start(options, init)
        if lit.negated and floors.get(lit.args[1]) is not None
    }


def _ontop_from_the_start(options: tuple[tuple[Literal, ...], ...], init: list[Any]) -> list[Literal]:
    """The goal's ``ontop`` literals, either sign, whose atom the task's init states."""
    initial = {tuple(lit) for lit in init if isinstance(lit, list) and all(isinstance(t, str) for t in lit)}
    return [lit for option in options for lit in option if lit.predicate == "ontop" and ("ontop", *lit.args) in initial]


def intended_goal(parsed: list[Any]) -> list[Any]:
    """``parsed`` (bddl's goal parse) with every ``forall`` whose body names a scope of the quantified
    synset (``?legal_document.n.01_1``) but never its variable (``?legal_document.n.01``) made to
    range over its variable: the typo of eight bddl activities (module docstring)."""
    if not isinstance(parsed, list):
        return parsed
    if len(parsed) == 3 and parsed[0] == "forall":
        variable = parsed[1][0]
        body = parsed[2]
        if variable not in _terms(body):
            own_scope = re.compile(rf"{re.escape(variable)}_\d+")
            body = _renamed(body, lambda a: variable if own_scope.fullmatch(a) else a)
        return ["forall", parsed[1], intended_goal(body)]
    return [intended_goal(p) for p in parsed]


def _terms(parsed: Any) -> set[str]:
    """Every string anywhere in a parse tree."""
    return {parsed} if isinstance(parsed, str) else set().union(*(_terms(p) for p in parsed))


def _renamed(parsed: Any, rename: Callable[[str], str]) -> Any:
    return rename(parsed) if isinstance(parsed, str) else [_renamed(p, rename) for p in parsed]
