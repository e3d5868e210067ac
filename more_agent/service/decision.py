"""``decide``: one MORE decision (paper Sec. III-B/C) on a scene graph from outside the simulator.

Room labels for unlabelled regions (the room model), the scene text, MORE's filter, then the plan:
the subpolicy and its arguments. Only the LLM planners run here (``more``, ``moma-llm``,
``moma-llm-sr``): the oracle and ``grounded`` read the simulator's goal and have no place on real data.
"""

from __future__ import annotations

from collections.abc import Sequence

from pydantic import BaseModel, Field

from more_agent.llm import LLMConfigError, configured_llm, load_llm_config
from more_agent.planners.language import scene_view
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner, make_clients
from more_agent.records import ActionRecord, LLMUsage
from more_agent.scene_graph import SceneGraph

NO_LLM = (
    "MORE plans with an LLM and none is configured: pass --llm openai:MODEL (key in OPENAI_API_KEY, any "
    "OpenAI-compatible server in OPENAI_BASE_URL) or --llm llamacpp:PATH.gguf, or set MORE_AGENT_LLM / a config "
    "file (docs/llm.md). The privileged planners (oracle, grounded) never run on real data."
)

LLM_PLANNERS = tuple(PLANNER_CONFIGS)
"""Planners ``decide`` runs."""


class Decision(BaseModel):
    """One decision: what MORE saw, kept and chose."""

    skill: str = Field(description="Subpolicy to run next (skills.py), or 'invalid' when no usable answer came back.")
    arguments: list[str] = Field(description="Its arguments: room name, then object name where it takes one.")
    reasoning: str = Field(description="The LLM's reasoning, or why the answer was unusable.")
    scene: str = Field(description="The full scene text.")
    filtered_scene: str = Field(description="The scene text the plan was made on (after MORE's filter).")
    room_labels: dict[str, str] = Field(description="Room labels given this call, region id -> room type.")
    regions: dict[str, str] = Field(description="Room name in the scene text -> region id of the graph.")
    llm: str = Field(description="The planning LLM, e.g. 'openai:gpt-4o'.")
    llm_usage: LLMUsage = Field(description="LLM calls of this decision.")


def planner_clients(llm: str | None) -> LLMClients:
    """The LLM clients (same config, cache and redaction as ``run``); a UserError saying how to configure one."""
    config = load_llm_config()
    if configured_llm(config, llm) is None:
        raise LLMConfigError(NO_LLM)
    return make_clients(llm, config)


def feedback_line(history: Sequence[ActionRecord]) -> str:
    """The last action's outcome as the planner's next prompt shows it (``planners.history.append_action``)."""
    if not history:
        return ""
    last = history[-1]
    return f"{last.name}: {'success' if last.ok else 'failure'}; {last.feedback}"


def decide(
    graph: SceneGraph, task: str, history: Sequence[ActionRecord], clients: LLMClients, *, planner: str = "more"
) -> Decision:
    """One decision of the LLM planner ``planner`` on ``graph`` for ``task`` after ``history``."""
    agent = LLMPlanner(PLANNER_CONFIGS[planner], clients)
    agent.calls.new_episode()
    agent.calls.new_step()
    labels = agent._classify_rooms(graph)  # noqa: SLF001 - the planner's own step, without its simulator body
    graph = graph.with_room_labels(labels)
    agent.task, agent.history, agent.feedback = task, list(history), feedback_line(history)
    agent.graph, agent.view = graph, scene_view(graph, agent.config.language)
    action = agent.decide()
    planning = agent.planning_view or agent.view
    return Decision(
        skill=action.name,
        arguments=list(action.arguments),
        reasoning=action.note,
        scene=agent.view.text(),
        filtered_scene=planning.text(),
        room_labels=labels,
        regions={room.name: room.region_id for room in agent.view.rooms},
        llm=clients.spec,
        llm_usage=agent.llm_usage(),
    )
