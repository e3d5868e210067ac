"""What a decided skill acts on, typed: the arguments of a :class:`~more_agent.planners.base.Step`.

A planner resolves the names it decided on (a room, an object label) when it decides, and hands the
result to ``execute`` with the action: a scene-graph :class:`~more_agent.scene_graph.ObjectNode`, an
:class:`Area` (a region's frontiers or floor), :class:`Unresolved` when a name matched nothing (the
skill then fails with its reason and runs nothing), or None (done). ``execute`` runs the skill on it
as it is, reading nothing ``decide`` left behind.
"""

from __future__ import annotations

from dataclasses import dataclass

from more_agent.records import FailureReason
from more_agent.robot import XY
from more_agent.scene_graph import ObjectNode


@dataclass(frozen=True)
class Area:
    """What an area skill acts on: a region's frontiers (explore) or floor (placing on it)."""

    name: str
    """How feedback names it: the room name the planner used."""
    region_id: str | None = None
    """The region; None for the floor where the robot stands."""
    frontiers: tuple[XY, ...] | None = None
    """The frontiers to explore instead of the region's own (BUMBLE explores those a chosen frame shows)."""


@dataclass(frozen=True)
class Unresolved:
    """A decided argument that names nothing the skill can act on: the step fails with this reason."""

    reason: FailureReason
    feedback: str


Target = ObjectNode | Area | Unresolved | None
"""What a skill acts on: a scene-graph object, an area, a name that matched nothing, or nothing (done)."""
