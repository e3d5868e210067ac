"""The shapes of the three LLM answers (room label, scene filter, next action); the skills they
name are those of the table in :mod:`more_agent.skills`.

The pydantic answer models double as JSON schemas for structured output: every field is required
and extra keys are forbidden, as OpenAI's strict mode wants. The validated results the planners
consume are the frozen :class:`PlannedAction` and :class:`FilterResult`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field


class _Answer(BaseModel):
    model_config = ConfigDict(extra="forbid")


class RoomLabelAnswer(_Answer):
    """Answer to room classification."""

    room: str = Field(description="The room type, one of the offered labels.")


class RoomObjects(_Answer):
    """One room kept by the filter and its relevant objects."""

    room: str = Field(description="Room name exactly as in the scene description.")
    objects: list[str] = Field(description="Relevant object names in this room, exactly as in the scene description.")


class FilterAnswer(_Answer):
    """Answer to scene filtering: the task-relevant rooms and their relevant objects."""

    rooms: list[RoomObjects] = Field(description="Relevant rooms, each with its relevant objects (possibly none).")


class PlanAnswer(_Answer):
    """Answer to planning: free reasoning first, then one skill call."""

    reasoning: str = Field(description="The model's reasoning towards this action, at any length.")
    skill: str = Field(description="Name of the skill to call.")
    arguments: list[str] = Field(description="Arguments in order: room and/or object names; empty for done().")


class MomaPlanAnswer(_Answer):
    """Answer to MoMa-LLM's planning prompt: Analysis, Reasoning, Command (its answer format), the
    command written as skill and arguments so that a schema can hold it."""

    analysis: str = Field(description="Where the objects of interest could be and which actions lead there.")
    reasoning: str = Field(description="Why the next action matters for the task.")
    skill: str = Field(description="Name of the skill to call.")
    arguments: list[str] = Field(description="Arguments in order: room and/or object names; empty for done().")


@dataclass(frozen=True)
class PlannedAction:
    """A validated skill call; names are the canonical scene names."""

    skill: str
    arguments: tuple[str, ...]
    room: str | None
    """The room argument, if the skill takes one."""
    object: str | None
    """The object argument, if the skill takes one."""
    reasoning: str = ""

    @property
    def call(self) -> str:
        """E.g. ``go_to_and_grasp(kitchen_0, apple_a)``, as shown in the action history."""
        return f"{self.skill}({', '.join(self.arguments)})"


@dataclass(frozen=True)
class FilterResult:
    """The filtered scene: kept rooms -> kept objects (known names only), plus what was dropped."""

    rooms: Mapping[str, tuple[str, ...]]
    unknown_rooms: tuple[str, ...]
    unknown_objects: tuple[str, ...]

    @property
    def objects(self) -> tuple[str, ...]:
        """All kept objects, room by room."""
        return tuple(o for objs in self.rooms.values() for o in objs)
