"""Goal evaluation: bddl evaluates a task's goal through our backend on the current world.

``GoalChecker`` compiles the goal once per task instance with ``bddl.activity.get_goal_conditions``
and expands it into bddl's ground options (``get_ground_goal_state_options``: each option is a
conjunction of ground literals that satisfies the goal; bddl keeps at most 20). bddl grounds a
quantifier's variable to every object of its category, including the one a scope in its body names, so
stacking_wood's ``(forall (?log.n.01 - log.n.01) (or (ontop ?log.n.01 ?table.n.02_1) (ontop ?log.n.01
?log.n.01_1) ...))`` offers ``(ontop log.n.01_1 log.n.01_1)``, and all 20 options it kept held such a
literal; once those are dropped, the first left put log_1 on log_2 and log_2 on log_1. :func:`ground_options`
drops, at every node of the compiled goal, the options that relate an object to itself, directly or
through a cycle of placements, before bddl's limit counts them. ``check(world)`` reports whether the whole goal holds (bddl's own evaluation, quantifiers included) and, for the
option closest to being met, each conjunct's status: that option's satisfied share is the task
progress (TP). The oracle reads the same option as structured ``Literal``s.
"""

from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import networkx as nx
from bddl.activity import evaluate_goal_conditions, get_goal_conditions, get_ground_goal_state_options
from bddl.condition_evaluation import evaluate_state

from more_agent.errors import UserError
from more_agent.goal import Literal
from more_agent.records import GoalCondition
from more_agent.sim.ambiguity import scope_groups
from more_agent.sim.bddl_backend import ScopeObject, WorldBackend
from more_agent.sim.predicates import holds
from more_agent.sim.satisfiable import satisfiable
from more_agent.sim.world import World

if TYPE_CHECKING:
    from more_agent.sim.instantiate import TaskInstance


def literal_holds(world: World, lit: Literal) -> bool:
    """Whether ``lit`` (over world names) holds in ``world``: the predicates bddl evaluates (``sim.predicates``)."""
    return holds(world, lit.predicate, lit.args) != lit.negated


@dataclass(frozen=True)
class GoalStatus:
    """The goal in one world state."""

    all_met: bool
    """The whole goal holds (bddl's evaluation of the compiled goal)."""
    progress: float
    """Satisfied share of the best ground option's conjuncts (1.0 when all_met)."""
    conditions: list[GoalCondition]
    """The best option's conjuncts with their status."""
    option_index: int
    """Index of the best option (see ``GoalChecker.ground_literals``)."""


def literal_from_parsed(parsed: list[Any], scope: dict[str, ScopeObject]) -> Literal:
    """A bddl ground literal (``['not', ['open', 'fridge.n.01_1']]``) over world names."""
    negated = parsed[0] == "not"
    atom = parsed[1] if negated else parsed
    args = tuple(scope[a.lstrip("?")].world_name for a in atom[1:])
    return Literal(predicate=atom[0], args=args, negated=negated)


def ground_options(node: Any) -> None:
    """Set the ground options of compiled goal ``node`` and of all below it, as bddl does (each node's own
    ``get_ground_options``, children first), less the options no world can meet because they relate an
    object to itself (:func:`relates_to_itself`; bddl's ``forpairs`` already skips such pairs), unless
    every option of the node does (an impossible branch stays as bddl offers it). Where no option does,
    the options are bddl's, in bddl's order."""
    for child in node.children:
        for sub in child if isinstance(child, list) else [child]:  # forpairs children are rows of pairs
            ground_options(sub)
    node.get_ground_options()
    possible = [option for option in node.flattened_condition_options if not relates_to_itself(option)]
    if possible:
        node.flattened_condition_options = possible


def relates_to_itself(option: list[list[Any]]) -> bool:
    """Whether a ground option's positive literals relate an object to itself: directly (``ontop x x``,
    ``nextto x x``) or through a cycle of placements (``ontop a b`` with ``ontop b a``, or ``inside a b``
    with ``ontop b a``), which no stack can hold. Negated literals never do."""
    positive = [parsed for parsed in option if parsed[0] != "not" and len(parsed) == 3]
    if any(parsed[1] == parsed[2] for parsed in positive):
        return True
    placements = nx.DiGraph([(parsed[1], parsed[2]) for parsed in positive if parsed[0] in _PLACEMENTS])
    return not nx.is_directed_acyclic_graph(placements)


_PLACEMENTS = ("ontop", "inside")
"""Predicates that put their first object on or in the second: a chain of them cannot return to its start."""


class GoalError(UserError):
    """A task whose goal cannot be evaluated condition by condition."""


class GoalChecker:
    """Evaluates one task instance's goal on a world (the instance's own, or another of the same task)."""

    def __init__(self, instance: TaskInstance, goal: list[Any] | None = None) -> None:
        """``goal`` replaces the task's parsed goal (a reading of it, ``sim.task_goal``)."""
        self.backend = WorldBackend(instance.world)
        self.scope = instance.scope_objects()
        conds = instance.definition.conditions
        ranges = scope_groups(conds.parsed_goal_conditions, conds.parsed_objects)
        self._ranged = frozenset(
            self.scope[s].world_name for g in ranges if g.quantifier for s in g.scopes if s in self.scope
        )
        if goal is not None:
            conds = copy.copy(conds)
            conds.parsed_goal_conditions = goal
        goal = get_goal_conditions(conds, self.backend, dict(self.scope), generate_ground_options=False)
        if not goal:
            raise ValueError(f"task {instance.task} has an empty goal")
        self._goal = goal
        for head in goal:
            ground_options(head)
        try:
            self._options = get_ground_goal_state_options(conds, self.backend, dict(self.scope), goal)
        except AssertionError:  # bddl asserts that it found at least one option
            raise GoalError(
                f"bddl finds no ground option for the goal of {instance.task} (its nested quantifiers over the "
                "same objects have no consistent grounding within bddl's enumeration limit), so its goal "
                "conditions cannot be scored one by one"
            ) from None
        self._literals = [[literal_from_parsed(head.body, self.scope) for head in opt] for opt in self._options]

    @property
    def n_options(self) -> int:
        """Number of ground options bddl produced (at most 20)."""
        return len(self._options)

    @property
    def objects(self) -> frozenset[str]:
        """The world objects the goal may use: those some ground option names and every instance a quantifier
        ranges over (any four of the seven knives; bddl keeps 20 options, which name six of them)."""
        return self._ranged | {arg for option in self._literals for lit in option for arg in lit.args}

    @functools.cached_property
    def satisfiable(self) -> bool:
        """Whether any state at all meets the goal (:func:`~more_agent.sim.satisfiable.satisfiable`)."""
        return satisfiable(self._goal)

    def ground_literals(self, option_index: int) -> list[Literal]:
        """The conjuncts of one ground option, as structured literals over world names."""
        return list(self._literals[option_index])

    def check(self, world: World | None = None) -> GoalStatus:
        """Goal status in ``world`` (default: the world the instance was built in)."""
        if world is not None:
            self.backend.world = world
        all_met, _ = evaluate_goal_conditions(self._goal)
        best_index, best_sat = 0, []
        best_fraction = -1.0
        for i, option in enumerate(self._options):
            _, result = evaluate_state(option)
            fraction = len(result["satisfied"]) / len(option)
            if fraction > best_fraction:
                best_index, best_fraction, best_sat = i, fraction, result["satisfied"]
        satisfied = set(best_sat)
        conditions = [
            GoalCondition(text=lit.text, satisfied=j in satisfied, objects=list(lit.args))
            for j, lit in enumerate(self._literals[best_index])
        ]
        return GoalStatus(
            all_met=bool(all_met),
            progress=1.0 if all_met else best_fraction,
            conditions=conditions,
            option_index=best_index,
        )


@dataclass(frozen=True)
class PrivilegedContext:
    """What only a privileged planner (the oracle) is given, besides its robot: the episode's world and
    its goal checker. ``observed`` collects world names it counts as observed beyond what its camera
    saw (what it acted on, what opening revealed), for the rTP metric."""

    world: World
    goals: GoalChecker
    observed: set[str] = field(default_factory=set)
