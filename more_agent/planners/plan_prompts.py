"""The planning request of the LLM planners: MORE's prompt (paper Fig. 4) or MoMa-LLM's, with its answer schema.

A :class:`PlanRequest` is what one planning call sends and how its answer is checked: the chat
messages, the answer model (with the valid names enumerated when the client wants name enums,
:mod:`more_agent.llm.name_enums`) and the validator. :func:`plan_request` builds it for the
planner's ``prompt`` (``more`` or ``moma``); the LLM planner's loop is the same for both.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from pydantic import BaseModel

from more_agent.llm import PlanAnswer, PlannedAction, parse_plan_answer, plan_messages, render_prompt
from more_agent.llm.answers import MomaPlanAnswer
from more_agent.llm.completion import ChatMessage
from more_agent.llm.name_enums import per_skill_answer, with_name_enums
from more_agent.planners.language import SceneView
from more_agent.planners.moma_encoding import moma_history, moma_scene, without_state
from more_agent.records import ActionRecord, HistoryMode
from more_agent.scene_graph import SceneGraph
from more_agent.skills import SKILLS, Skill

PromptKind = Literal["more", "moma"]
"""Which planning prompt: MORE's (scene text per room, JSON answer) or MoMa-LLM's (its encoding, Analysis / Reasoning / Command)."""


@dataclass(frozen=True)
class PlanRequest:
    """One planning call: messages, answer schema, and the validator of its answers."""

    messages: list[ChatMessage]
    schema: type[BaseModel]
    validate: Callable[[str | Mapping[str, Any]], PlannedAction]
    scene: str
    """The scene text the prompt carries (for the step's trace)."""


@dataclass(frozen=True)
class PlanState:
    """What the planner knows when it asks: task, scene, robot, history."""

    task: str
    graph: SceneGraph
    view: SceneView
    """The full scene view (names, robot room, held object)."""
    planning_view: SceneView
    """The scene the plan is made on (MORE: the filtered one)."""
    history: Sequence[ActionRecord]
    feedback: str
    history_mode: HistoryMode


def plan_request(
    kind: PromptKind,
    state: PlanState,
    *,
    name_enums: bool,
    by_position: bool = False,
    skills: Sequence[Skill] = SKILLS,
) -> PlanRequest:
    """The planning call of prompt ``kind``; with ``name_enums`` its schema enumerates the valid names, with
    ``by_position`` too per skill and argument position (a room where the skill table has a room...)."""
    rooms, objects = [r.name for r in state.view.rooms], state.view.object_names()
    if kind == "moma":
        scene = moma_scene(state.graph, state.planning_view).text()
        messages = moma_messages(state, scene, skills)
        schema: type[BaseModel] = MomaPlanAnswer
    else:
        scene = state.planning_view.text()
        messages = plan_messages(
            task=state.task,
            scene=scene,
            robot_room=state.view.robot_room,
            held_object=state.view.held,
            history=state.history,
            feedback=state.feedback,
            history_mode=state.history_mode,
            skills=skills,
        )
        schema = PlanAnswer
    if name_enums and by_position:
        schema = per_skill_answer(schema, skills, {"room": rooms, "object": objects})
    elif name_enums:
        schema = with_name_enums(schema, {"skill": [s.name for s in skills], "arguments": rooms + objects})

    def validate(answer: str | Mapping[str, Any]) -> PlannedAction:
        if kind == "moma":
            answer = stateless_arguments(answer)
        return parse_plan_answer(answer, skills, rooms, objects)

    return PlanRequest(messages=messages, schema=schema, validate=validate, scene=scene)


def moma_messages(state: PlanState, scene: str, skills: Sequence[Skill]) -> list[ChatMessage]:
    """MoMa-LLM's planning prompt: numbered functions, its scene encoding and its history line."""
    return render_prompt(
        "moma_plan",
        task=state.task,
        skills="\n".join(f"{i}. {s.signature}: {s.description}" for i, s in enumerate(skills, start=1)),
        scene=scene,
        held_object=state.view.held or "nothing",
        history=moma_history(state.history),
        feedback=state.feedback or "none",
    )


def stateless_arguments(answer: str | Mapping[str, Any]) -> str | Mapping[str, Any]:
    """A JSON answer with 'closed fridge' read as 'fridge' (MoMa-LLM's text shows states as prefixes)."""
    if not isinstance(answer, Mapping) or not isinstance(args := answer.get("arguments"), list):
        return answer
    return {**answer, "arguments": [without_state(a) if isinstance(a, str) else a for a in args]}
