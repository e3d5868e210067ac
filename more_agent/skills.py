"""The skill table: every high-level action a planner may take, in one place (paper Sec. III-C).

Each :class:`Skill` says what it is called, which parameters it takes, which subpolicy runs it,
which magic action of the world carries it out (an action type of the Gymnasium env,
:data:`more_agent.sim.env.ACTION_TYPES`) and how the LLM and the VLM read it in their prompts.
The env builds its action types from it, the parsers check answers against it, the prompts list
it, and the planners dispatch through it: the binding of a subpolicy name to the function that
runs it lives in :data:`more_agent.planners.policies.SUBPOLICIES`, and that of a world action to
the function that changes the world in :data:`more_agent.sim.actions.MANIPULATIONS`. A new skill
is one row here plus, when it needs a new subpolicy or world action, one binding there.

This module is data only, at the bottom of the package, so that ``sim`` and ``llm`` can read it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

ParamKind = Literal["room", "object"]
"""What a skill argument names: a room of the scene text, or an object in it."""

Subpolicy = Literal["explore", "navigate", "go_to_and", "done"]
"""The subpolicy that runs a skill: frontier exploration, driving to an object, driving there and
acting on it (the skill's world action), or ending the episode."""


@dataclass(frozen=True)
class Skill:
    """One row of the skill table."""

    name: str
    """What the planners call it, e.g. ``go_to_and_grasp``."""
    params: tuple[ParamKind, ...]
    """Argument kinds in order, as the LLM passes them."""
    subpolicy: Subpolicy
    world_action: str | None
    """The env action type that carries it out in the world; None when it only moves on the agent's map."""
    description: str
    """How the LLM's skill list describes it."""
    vlm_description: str
    """How the VLM's skill list describes it (the VLM names a skill without arguments)."""

    @property
    def signature(self) -> str:
        """E.g. ``navigate(room, object)``."""
        return f"{self.name}({', '.join(self.params)})"

    @property
    def changes_world(self) -> bool:
        """Whether its success changes the world until undone (grasp, place, open, close)."""
        return self.subpolicy == "go_to_and"


def _go_to_and(verb: str, what: str) -> Skill:
    return Skill(
        f"go_to_and_{verb}",
        ("room", "object"),
        "go_to_and",
        verb,
        f"go to the object and {what}",
        f"go to the object and {what}",
    )


SKILLS: tuple[Skill, ...] = (
    Skill(
        "explore",
        ("room",),
        "explore",
        None,
        "explore the closest unexplored area (frontier) in the room",
        "explore the closest unexplored area (frontier)",
    ),
    Skill("navigate", ("room", "object"), "navigate", "navigate_to", "go to the object", "go to the object"),
    _go_to_and("open", "open it"),
    _go_to_and("close", "close it"),
    _go_to_and("grasp", "pick it up (the hand must be empty)"),
    _go_to_and("place_inside", "put the held object inside it"),
    _go_to_and("place_ontop", "put the held object on top of it"),
    Skill(
        "done",
        (),
        "done",
        "done",
        "end the episode because the task is complete",
        "end the episode because the task is complete",
    ),
)
"""The paper's subpolicies, in the order the prompts list them."""

SKILLS_BY_NAME: dict[str, Skill] = {s.name: s for s in SKILLS}

INVALID = "invalid"
"""Not a skill: the action name planners record when their model gave no usable answer after the re-asks
(its reason is ``FailureReason.INVALID_ANSWER``)."""

MANIPULATION_VERBS: tuple[str, ...] = tuple(s.world_action for s in SKILLS if s.changes_world and s.world_action)
"""The world actions of the go-to-and-act skills: open, close, grasp, place_inside, place_ontop."""


def skill_named(name: str) -> Skill:
    """The table row of ``name``; a ValueError names the known skills."""
    if name not in SKILLS_BY_NAME:
        raise ValueError(f"unknown skill {name!r}; known: {', '.join(SKILLS_BY_NAME)}")
    return SKILLS_BY_NAME[name]
