"""What a planner is told of its task: the :class:`GoalSpec` the runner computes from the task instance.

Every planner gets the task's text (written as ``descriptions`` says). A planner that reads the goal
(``grounded``) also gets it in BDDL form over *scope* names (:class:`TaskGoal`): the literals of bddl's
ground options, the categories each scope may be, the labels the description names. Neither says
which world object a scope is, nor where anything stands: the planner finds that out through its
:class:`~more_agent.robot.Robot`. Goal state (whether a literal holds now) is privileged: only the
oracle gets it (``more_agent.sim.goals.PrivilegedContext``).

This module is data only, at the bottom of the package, so that the simulator, the planners and the
runner share the types.
"""

from __future__ import annotations

from dataclasses import dataclass, field

ROBOT_NAME = "robot"
"""The agent's name in goal literals over world names."""

REARRANGE_PREDICATES = frozenset({"inside", "ontop", "open"})
"""The goal predicates of a rearrangement: what the skills can make true."""


@dataclass(frozen=True)
class Literal:
    """One ground goal literal over object names (world or scope names; 'robot' for the agent)."""

    predicate: str
    args: tuple[str, ...]
    negated: bool = False

    @property
    def text(self) -> str:
        """BDDL form, e.g. '(inside apple_1 fridge_0)' or '(not (open fridge_0))'."""
        atom = f"({' '.join((self.predicate, *self.args))})"
        return f"(not {atom})" if self.negated else atom


@dataclass(frozen=True)
class TaskGoal:
    """The goal of one task as literals over scope names, with what the description says about the scopes."""

    options: tuple[tuple[Literal, ...], ...]
    """bddl's ground options (each a conjunction that satisfies the goal), literals over scope names."""
    categories: dict[str, frozenset[str]]
    """Scope -> object categories that count as it (the synset's own and its descendants'; for a scope the
    goal moves, no descendant that is a scene fixture: a car is a container, but none to put in a car), of
    those a world can hold: one some model is of. checkout.n.03's 'checkout' and the fridge scope's
    'electric_refrigerator' are none, so a checkout is a checkout_counter, which is furniture (a search for
    one opened a store's microwaves, fridges and ovens while 'checkout' made it an item)."""
    named: dict[str, str]
    """Scope -> instance label the description names it by (``apple A``)."""
    floor_rooms: dict[str, str | None]
    """Floor scope -> the room type the description names ('kitchen'), None when it names none."""
    robot: str
    """The agent's scope name."""
    moved: frozenset[str] = frozenset()
    """Scopes the goal moves (subjects of placement literals): only things that can be picked up are them."""
    stays: dict[str, str] = field(default_factory=dict)
    """Scope -> the scope the description says it stays on ("every carton stays on the garage floor",
    "leave toolbox A on countertop A"): a goal literal ``ontop`` a floor whose room the description names,
    or a support it names, that holds from the start. Where the robot finds an object staying on a floor is
    that room, whatever its furniture; one staying on a support shows from close by that support."""
    leaves: dict[str, str] = field(default_factory=dict)
    """Scope -> the floor the description says it must leave ("no sod may remain on the garden floor"): a
    negated goal literal ``ontop`` a floor whose room the description names, that holds from the start. The
    object lies there when the robot starts looking."""
    activity: str = ""
    """The bddl activity the goal is of: the commonsense priors read from the activity corpus leave it out
    (:mod:`more_agent.planners.whereabouts`)."""

    def is_floor(self, scope: str) -> bool:
        return scope in self.floor_rooms


@dataclass(frozen=True)
class GoalSpec:
    """What a planner is told of its task (module docstring)."""

    text: str
    """The task description in words, as the LLM planners read it."""
    class_text: str = ""
    """The description naming instances by class ('the fridge') rather than label ('fridge A'), for a
    planner whose scene text shows classes (MoMa-LLM's encoding); '' when there is none."""
    descriptions: str = "named"
    """How ``text`` was written: 'named' (the paper's text naming the instances the world makes
    ambiguous) or 'paper' (verbatim)."""
    goal: TaskGoal | None = None
    """The goal in BDDL form over scope names; only for a planner that reads it (``reads_goal``)."""
