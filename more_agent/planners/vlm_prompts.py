"""The BUMBLE baselines' VLM questions: messages with images, answer shapes and their validation.

Five questions (templates ``more_agent/llm/prompts/bumble_*.txt``): the step decision (subtask and
skill, shown the annotated current view), the landmark step (which memory frame shows the object,
BUMBLE's ``goto_landmark``), the object step (which mark in the picked frame, BUMBLE's
``navigate_to_point_on_ground``), the exploration frame, and whether an exploration achieved its
subtask. Frames are numbered 1..n in a request and each image follows its caption in the user
message; a validator maps an answer back to the offered choice or raises
:class:`~more_agent.llm.errors.InvalidAnswer` with a reason the model can act on.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from more_agent.errors import unknown_name_error
from more_agent.llm.completion import ChatMessage
from more_agent.llm.errors import InvalidAnswer
from more_agent.llm.images import image_part, text_part
from more_agent.llm.prompts import render_prompt, skill_api_text
from more_agent.robot_spec import ROBOT
from more_agent.skills import SKILLS


class _Answer(BaseModel):
    """Every answer gives its reasoning first."""

    model_config = ConfigDict(extra="forbid")

    reasoning: str = Field(description="Why.")


class StepAnswer(_Answer):
    """The step decision."""

    subtask: str = Field(description="The next subtask in words, e.g. 'grasp apple A'.")
    skill: str = Field(description="Name of the skill that achieves it.")


class FrameAnswer(_Answer):
    """A frame chosen among the numbered frames of a request."""

    frame: int = Field(description="Frame number as offered.")


class MarkAnswer(_Answer):
    """A mark chosen in an annotated frame."""

    mark: int = Field(description="Mark number as listed.")


class VerifyAnswer(_Answer):
    """Whether an exploration achieved its subtask."""

    reasoning: str = Field(description="What was found or not.")
    achieved: bool = Field(description="True when the subtask was achieved.")


@dataclass(frozen=True)
class Picture:
    """One image of a request with its caption (e.g. 'Frame 2: apple A, fridge A [open]')."""

    caption: str
    png: bytes


def with_pictures(messages: list[ChatMessage], pictures: Sequence[Picture]) -> list[ChatMessage]:
    """``messages`` with the pictures appended to the last user message, each after its caption."""
    last = messages[-1]
    parts: list[dict[str, Any]] = [text_part(str(last["content"]))]
    for p in pictures:
        parts += [text_part(p.caption), image_part(p.png)]
    return [*messages[:-1], ChatMessage(role=last["role"], content=parts)]


def object_list(descriptions: Sequence[str]) -> str:
    """Objects one per line, numbered as their marks (``3: fridge A [open]``), or 'none'."""
    lines = [f"{i}: {d}" for i, d in enumerate(descriptions, start=1)]
    return "\n".join(lines) or "none"


def frame_captions(objects_per_frame: Sequence[Sequence[str]]) -> list[str]:
    """'Frame k: a, b, c' per frame, k from 1."""
    return [f"Frame {k}: {', '.join(objs) or 'no objects'}" for k, objs in enumerate(objects_per_frame, start=1)]


def step_messages(
    *,
    task: str,
    view: Picture,
    objects: Sequence[str],
    held: str | None,
    feedback: str,
    memory: Sequence[ChatMessage] = (),
) -> list[ChatMessage]:
    """The step decision: task, annotated current view and its marked objects, skills; ``memory``
    (BUMBLE's long- and short-term memory, :mod:`more_agent.planners.bumble_memory`) goes between
    the instructions and the current view."""
    system, *rest = render_prompt(
        "bumble_plan",
        task=task,
        skills=skill_api_text(SKILLS, vlm=True),
        objects=object_list(objects),
        held_object=held or "nothing",
        feedback=feedback or "none",
        reach_m=f"{ROBOT.reach_m:g}",
    )
    return [system, *memory, *with_pictures(rest, [view])]


def frames_messages(prompt: str, *, task: str, subtask: str, pictures: Sequence[Picture]) -> list[ChatMessage]:
    """A question over numbered frames (``bumble_landmark``, ``bumble_explore``, ``bumble_verify``)."""
    frames = "\n".join(p.caption for p in pictures)
    return with_pictures(render_prompt(prompt, task=task, subtask=subtask, frames=frames), pictures)


def object_messages(*, task: str, subtask: str, view: Picture, objects: Sequence[str]) -> list[ChatMessage]:
    """The object step: the annotated frame and its marked objects."""
    messages = render_prompt("bumble_object", task=task, subtask=subtask, objects=object_list(objects))
    return with_pictures(messages, [view])


def parse_step(answer: str | Mapping[str, Any]) -> tuple[str, str]:
    """(skill, subtask) of a step answer; InvalidAnswer for a missing subtask or an unknown skill."""
    if not isinstance(answer, Mapping):
        raise InvalidAnswer("no JSON object with 'subtask' and 'skill' found")
    skill = str(answer.get("skill", "")).strip().lower().replace(" ", "_").removesuffix("()")
    subtask = str(answer.get("subtask", "")).strip()
    names = [s.name for s in SKILLS]
    if skill not in names:
        raise InvalidAnswer(f"{unknown_name_error('skill', skill, names)}; skills: {', '.join(names)}")
    if not subtask and skill != "done":
        raise InvalidAnswer("the subtask is empty: say what the skill should achieve")
    return skill, subtask


def parse_choice(answer: str | Mapping[str, Any], key: str, count: int) -> int:
    """The 1-based number under ``key`` (an int, or a string holding one) if within 1..count; else InvalidAnswer."""
    value = answer.get(key) if isinstance(answer, Mapping) else None
    try:
        number = int(str(value).strip().removeprefix("#")) if not isinstance(value, bool) else None
    except ValueError:
        number = None
    if number is None or not 1 <= number <= count:
        raise InvalidAnswer(f"{key} {value!r} is not one of the offered {key}s 1..{count}")
    return number


def parse_verdict(answer: str | Mapping[str, Any]) -> tuple[bool, str]:
    """(achieved, reasoning) of a verification answer; InvalidAnswer without a boolean 'achieved'."""
    if not isinstance(answer, Mapping) or not isinstance(answer.get("achieved"), bool):
        raise InvalidAnswer("'achieved' must be true or false")
    return bool(answer["achieved"]), str(answer.get("reasoning", "")).strip()
