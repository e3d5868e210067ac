"""Prompt templates (files in ``prompts/``) and the renderer that turns them into chat messages.

A template file holds ``[[system]]`` / ``[[user]]`` sections with ``string.Template`` fields
(``$task``); literal dollars are ``$$``. Templates know nothing of the scene graph: the scene text
comes in as a string from the scene-graph language encoder. The ``*_messages`` helpers fill the
fields the paper's prompts need (Fig. 3 filtering, Fig. 4 planning, room classification).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Sequence
from importlib import resources
from string import Template
from typing import Protocol

from more_agent.errors import UserError, unknown_name_error
from more_agent.llm.completion import ChatMessage
from more_agent.records import DEFAULT_HISTORY, HISTORY_MODES, HistoryMode
from more_agent.skills import SKILLS, Skill

PROMPT_NAMES = ("room", "filter", "plan", "moma_plan")
VLM_PROMPT_NAMES = ("bumble_plan", "bumble_landmark", "bumble_object", "bumble_explore", "bumble_verify")
"""The BUMBLE baselines' prompts (:mod:`more_agent.planners.vlm_prompts` builds their messages with images)."""
HISTORY_LAST_N = 5
"""The planner sees the last five actions plus all failed ones (paper Sec. III-C)."""

_SECTION = re.compile(r"^\[\[(system|user|assistant)\]\]\s*$", re.M)


@functools.cache
def load_template(name: str) -> tuple[tuple[str, Template], ...]:
    """The (role, template) sections of ``prompts/NAME.txt``."""
    if name not in PROMPT_NAMES + VLM_PROMPT_NAMES:
        raise ValueError(f"unknown prompt {name!r}; prompts: {', '.join(PROMPT_NAMES)}")
    text = resources.files("more_agent.llm").joinpath("prompts", f"{name}.txt").read_text(encoding="utf-8")
    parts = _SECTION.split(text)
    if parts[0].strip():
        raise ValueError(f"prompt {name!r} has text before its first [[role]] line")
    return tuple((role, Template(body.strip("\n"))) for role, body in zip(parts[1::2], parts[2::2], strict=True))


def prompt_fields(name: str) -> frozenset[str]:
    """The fields prompt ``name`` needs."""
    return frozenset(f for _, t in load_template(name) for f in t.get_identifiers())


def render_prompt(name: str, **fields: str) -> list[ChatMessage]:
    """The chat messages of prompt ``name`` with ``fields`` filled in; missing or unknown fields are errors."""
    needed = prompt_fields(name)
    if missing := needed - fields.keys():
        raise ValueError(f"prompt {name!r} needs fields {sorted(missing)}")
    if extra := fields.keys() - needed:
        raise ValueError(f"prompt {name!r} has no fields {sorted(extra)}")
    sections = load_template(name)
    return [
        ChatMessage(role=role, content=t.substitute(fields))  # type: ignore[typeddict-item]
        for role, t in sections
    ]


class HistoryItem(Protocol):
    """An executed action as the history shows it (:class:`more_agent.records.ActionRecord` fits)."""

    @property
    def name(self) -> str: ...
    @property
    def arguments(self) -> list[str]: ...
    @property
    def ok(self) -> bool: ...
    @property
    def feedback(self) -> str: ...


def skill_api_text(skills: Iterable[Skill], *, vlm: bool = False) -> str:
    """One line per skill: signature and description; for the VLM, which names a skill without
    arguments (later questions pick its target), ``name()`` and the VLM description."""
    if vlm:
        return "\n".join(f"- {s.name}(): {s.vlm_description}" for s in skills)
    return "\n".join(f"- {s.signature}: {s.description}" for s in skills)


LASTING_SKILLS = frozenset(s.name for s in SKILLS if s.changes_world)
"""Skills whose success changes the world until undone: the ``lasting`` history keeps them beyond the last five."""


def check_history(mode: str) -> HistoryMode:
    """``mode`` as a history mode; a UserError naming the valid ones otherwise."""
    for m in HISTORY_MODES:
        if mode == m:
            return m
    raise UserError(
        f"{unknown_name_error('history', mode, HISTORY_MODES)}; use --history with one of: {', '.join(HISTORY_MODES)}"
    )


def history_text(
    actions: Sequence[HistoryItem], mode: HistoryMode = DEFAULT_HISTORY, last_n: int = HISTORY_LAST_N
) -> str:
    """The action history, numbered, in order, each action with its feedback (which names the objects:
    'placed hammer A inside toolbox A'); 'none' if empty.

    ``paper``: the last ``last_n`` actions plus all earlier failed ones (paper Sec. III-C); what the
    robot did shows in the scene text (held item, placed items, open or closed). ``lasting`` (our
    extension): also all earlier successful grasps, placements, openings and closings."""
    first_recent = max(0, len(actions) - last_n)
    lines = []
    for i, a in enumerate(actions):
        if i >= first_recent or not a.ok or (mode == "lasting" and a.name in LASTING_SKILLS):
            detail = f": {a.feedback}" if a.feedback else ""
            outcome = f"succeeded{detail}" if a.ok else f"failed{detail}"
            lines.append(f"{i + 1}. {a.name}({', '.join(a.arguments)}) -> {outcome}")
    return "\n".join(lines) or "none"


def room_messages(objects: Iterable[str], labels: Iterable[str]) -> list[ChatMessage]:
    """Room classification prompt: objects seen in a region, the room types to choose from."""
    return render_prompt("room", objects=", ".join(objects) or "none", labels=", ".join(labels))


def filter_messages(task: str, scene: str) -> list[ChatMessage]:
    """Scene filtering prompt (paper Fig. 3) for the full scene text."""
    return render_prompt("filter", task=task, scene=scene)


def plan_messages(
    *,
    task: str,
    scene: str,
    robot_room: str,
    held_object: str | None,
    history: Sequence[HistoryItem],
    feedback: str,
    skills: Sequence[Skill] = SKILLS,
    history_mode: HistoryMode = DEFAULT_HISTORY,
) -> list[ChatMessage]:
    """Planning prompt (paper Fig. 4) for the filtered scene text and the robot's state."""
    return render_prompt(
        "plan",
        task=task,
        scene=scene,
        skills=skill_api_text(skills),
        robot_room=robot_room,
        held_object=held_object or "nothing",
        history=history_text(history, history_mode),
        feedback=feedback or "none",
    )
