"""The LLM planners: MORE and the MoMa-LLM baselines, as configurations of one class.

One high-level step (paper Sec. III-B/C, MPC style): build the scene graph from everything sensed,
label new regions with the cheaper room model, put the graph into words, let the LLM filter it to
the task-relevant subgraph (MORE only), ask the LLM for one subpolicy call given the task, the
subgraph, the robot's room and held object, the history (last five actions and every failed one,
the paper's; ``lasting`` also keeps every earlier successful grasp, place, open and close) and the last
feedback, then run that subpolicy. Planners differ only in their
:class:`LLMPlannerConfig`:

- ``more``: filtering, alphabetical instance ids, spatial relations;
- ``moma-llm``: no filtering, MoMa-LLM's own scene encoding and answer format
  (:mod:`~more_agent.planners.moma_encoding`), objects by class, no spatial relations;
- ``moma-llm-sr``: ``moma-llm`` with spatial relations.

The planning request of each (:mod:`~more_agent.planners.plan_prompts`) enumerates the valid names in
its answer schema when the client asks for name enums (llama.cpp by default).

The class implements the :class:`~more_agent.planners.base.Planner` protocol. LLM transport errors
(timeouts, a server gone, a replay miss) propagate as :class:`~more_agent.llm.errors.LLMError` for
the episode loop to record; an answer still invalid after the bounded re-asks becomes an ``invalid``
action whose failure is fed back to the next step, so LLM output never crashes an episode. Each
step's trace (:meth:`LLMPlanner.step_trace`: scene texts, action, every LLM exchange, the scene graph)
is what the episode folder's ``steps.jsonl`` and ``graphs/`` hold.
"""

from __future__ import annotations

import logging
from collections.abc import Collection
from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field

from more_agent.llm import (
    FilterAnswer,
    InvalidAnswer,
    LLMClient,
    LLMConfig,
    LLMConfigError,
    RoomLabelAnswer,
    ask_validated,
    configured_llm,
    filter_messages,
    load_llm_config,
    make_client,
    parse_filter_answer,
    parse_room_label,
    room_messages,
    room_spec,
)
from more_agent.llm.limits import MAX_NAME_CHARS, clip
from more_agent.llm.name_enums import (
    constrains_names,
    constrains_positions,
    filter_answer_with_names,
    with_name_enums,
)
from more_agent.mapping import MappingConfig
from more_agent.planners.base import EpisodeContext, Step, StepTrace, needed
from more_agent.planners.exchanges import CallLog, RecordingClient
from more_agent.planners.history import append_action
from more_agent.planners.language import LanguageOptions, SceneView, scene_view
from more_agent.planners.plan_prompts import PlanState, PromptKind, plan_request
from more_agent.planners.policies import Embodiment, PolicyConfig, pick_target, run_skill
from more_agent.planners.session import MappingSession
from more_agent.planners.targets import Area, Target, Unresolved
from more_agent.records import DEFAULT_HISTORY, ActionRecord, FailureReason, HistoryMode, LLMUsage
from more_agent.robot import ActionResult
from more_agent.scene_graph import SceneGraph
from more_agent.skills import INVALID, SKILLS_BY_NAME
from more_agent.vocabulary import FLOOR, ROOM_TYPES

log = logging.getLogger(__name__)


class LLMPlannerConfig(BaseModel):
    """What distinguishes MORE from the MoMa-LLM baselines, and the knobs they share."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field(description="Planner name as registered, e.g. 'more'.")
    filtering: bool = Field(description="Ask the LLM for the task-relevant subgraph before planning (MORE).")
    language: LanguageOptions = Field(description="Instance ids and spatial relations in the scene text.")
    prompt: PromptKind = Field(default="more", description="Planning prompt: MORE's or MoMa-LLM's own encoding.")
    max_reasks: int = Field(
        default=2, ge=0, description="Re-asks after an invalid answer before it counts as an invalid action."
    )
    room_types: tuple[str, ...] = Field(default=ROOM_TYPES, description="Room labels the room classifier chooses from.")
    policy: PolicyConfig = Field(default_factory=PolicyConfig, description="Subpolicy knobs.")
    mapping: MappingConfig = Field(default_factory=MappingConfig, description="Mapping and scene-graph knobs.")


PLANNER_CONFIGS: dict[str, LLMPlannerConfig] = {
    "more": LLMPlannerConfig(
        name="more", filtering=True, language=LanguageOptions(instance_ids=True, spatial_relations=True)
    ),
    "moma-llm": LLMPlannerConfig(
        name="moma-llm",
        filtering=False,
        language=LanguageOptions(instance_ids=False, spatial_relations=False),
        prompt="moma",
    ),
    "moma-llm-sr": LLMPlannerConfig(
        name="moma-llm-sr",
        filtering=False,
        language=LanguageOptions(instance_ids=False, spatial_relations=True),
        prompt="moma",
    ),
}
"""The paper's LLM planners by name."""


@dataclass(frozen=True)
class LLMClients:
    """The planning model and the (cheaper) room-classification model."""

    plan: LLMClient
    room: LLMClient
    spec: str
    """The planning LLM as a spec, e.g. 'openai:gpt-4o' (for the episode record)."""
    room_spec: str = ""
    """The room-classification LLM as a spec ('' = the planning LLM), for the episode record."""


def make_clients(llm: str | None, config: LLMConfig | None = None) -> LLMClients:
    """Clients for ``llm`` (else the configured LLM) per the LLM config; raises LLMConfigError without one."""
    config = config or load_llm_config()
    spec = configured_llm(config, llm)
    if spec is None:
        raise LLMConfigError(
            "this planner needs an LLM: pass --llm openai:MODEL (or llamacpp:PATH.gguf) or set MORE_AGENT_LLM"
        )
    rooms = room_spec(spec, config)
    plan = make_client(spec, config)
    room = plan if rooms == spec else make_client(rooms, config)
    return LLMClients(plan=plan, room=room, spec=str(spec), room_spec=str(rooms))


class LLMPlanner(MappingSession):
    """MORE / MoMa-LLM: the :class:`~more_agent.planners.base.Planner` protocol over an LLM (module docstring)."""

    def __init__(self, config: LLMPlannerConfig, clients: LLMClients) -> None:
        self.name = config.name
        self.llm: str | None = clients.spec
        self.room_llm: str | None = clients.room_spec or clients.spec
        """The LLM that labels rooms (the episode record's ``room_llm``)."""
        self.config = config
        self.calls = CallLog()
        """Every LLM call (room labels, filter, plan, re-asks): the episode's usage, the step's exchanges."""
        self.clients = LLMClients(
            plan=RecordingClient(clients.plan, self.calls),
            room=RecordingClient(clients.room, self.calls),
            spec=clients.spec,
            room_spec=clients.room_spec,
        )
        self.body: Embodiment | None = None
        self.task = ""
        self.history: list[ActionRecord] = []
        self.history_mode: HistoryMode = DEFAULT_HISTORY
        self.feedback = ""
        self.graph: SceneGraph | None = None
        self.view: SceneView | None = None
        """The step's full scene text."""
        self.planning_view: SceneView | None = None
        """The scene view the step planned on (the filtered one under filtering)."""
        self.planning_scene = ""
        """The scene text of the step's planning prompt (MoMa-LLM's encoding under ``prompt='moma'``)."""

    # -- Planner protocol ---------------------------------------------------------------------
    def reset(self, context: EpisodeContext) -> None:
        """Start an episode: a fresh map and history, then the full turn in place (paper S.3)."""
        self.body = Embodiment(
            context.robot, config=self.config.policy, mapping=self.config.mapping, sensing=context.sensing
        )
        described = context.goal.class_text if self.config.prompt == "moma" else ""
        self.task = described or context.goal.text
        self.history, self.history_mode, self.feedback = [], context.history, ""
        self.calls.new_episode()
        self.body.start()

    def observe(self) -> None:
        """Build the scene graph, label new regions, put it into words."""
        self.calls.new_step()
        graph = self.graph = self._body().step_graph(self._classify_rooms)
        self.view = scene_view(graph, self.config.language)

    def decide(self) -> Step:
        """Filter (MORE) and plan: the next subpolicy call, or ``invalid`` when no valid answer came."""
        view = self._view()
        planning_view = self.planning_view = self._filter(view) if self.config.filtering else view
        state = PlanState(self.task, self._graph(), view, planning_view, self.history, self.feedback, self.history_mode)
        plan = self.clients.plan
        request = plan_request(
            self.config.prompt, state, name_enums=constrains_names(plan), by_position=constrains_positions(plan)
        )
        self.planning_scene = request.scene
        try:
            answer = ask_validated(
                self.clients.plan,
                request.messages,
                request.schema,
                request.validate,
                max_reasks=self.config.max_reasks,
                purpose="plan",
            )
        except InvalidAnswer as e:
            return Step(name=INVALID, note=e.reason)
        planned = answer.value
        return Step(
            name=planned.skill,
            arguments=planned.arguments,
            target=self._target(planned.skill, planned.arguments),
            note=planned.reasoning,
        )

    def execute(self, action: Step) -> ActionResult:
        """Run the subpolicy; its outcome is the next prompt's feedback."""
        result = self._run(action)
        self.feedback = append_action(self.history, action, result)
        return result

    def step_trace(self) -> StepTrace:
        """The step's scene texts, action and LLM exchanges (its ``steps.jsonl`` line) and scene graph."""
        view = self._view()
        log_line = {
            "action": self.history[-1].model_dump(),
            "scene": view.text(),
            "planning_scene": self.planning_scene or (self.planning_view or view).text(),
            "robot_room": view.robot_room,
            "exchanges": [e.to_json() for e in self.calls.exchanges],
        }
        return StepTrace(log=log_line, graph=self.graph)

    def llm_usage(self) -> LLMUsage:
        """LLM traffic of this episode so far, with the time spent waiting for answers."""
        return self.calls.usage()

    # -- steps ----------------------------------------------------------------------------------
    def _classify_rooms(self, graph: SceneGraph) -> dict[str, str]:
        """Room labels for regions without one that have objects (one call each with the room model);
        a region whose answer stays invalid is left unlabelled and asked again next step."""
        labels: dict[str, str] = {}
        schema = RoomLabelAnswer
        if constrains_names(self.clients.room):
            schema = with_name_enums(RoomLabelAnswer, {"room": self.config.room_types})
        for rid, region in sorted(graph.regions.items()):
            objects = [o for o in graph.objects_in(rid) if o.category != "door"]
            read = self.body.room_input(objects) if self.body is not None else [o.category for o in objects]
            names = sorted(set(read))  # the robot's reading (room-label noise); a graph from outside as it is
            if region.room_label is not None or not names:
                continue
            try:
                answer = ask_validated(
                    self.clients.room,
                    room_messages(names, self.config.room_types),
                    schema,
                    lambda a: parse_room_label(a, self.config.room_types),
                    max_reasks=self.config.max_reasks,
                    purpose="room",
                )
            except InvalidAnswer as e:
                log.info("room label of %s stays unknown: %s", rid, e.reason)
                continue
            labels[rid] = answer.value
        return labels

    def _filter(self, view: SceneView) -> SceneView:
        """The task-relevant subgraph (paper Sec. III-B); the full view when nothing to filter or no usable answer."""
        return filter_view(
            self.clients.plan, self.task, view, max_reasks=self.config.max_reasks, always={view.robot_room}
        )

    def _target(self, skill: str, arguments: tuple[str, ...]) -> Target:
        """What the planned skill acts on: the room's area, or the object the names mean in the scene
        text (of several, the one the skill can act on nearest the robot, where the graph has it); None for done."""
        graph, view = self._graph(), self._view()
        params = SKILLS_BY_NAME[skill].params
        if not params:  # done
            return None
        room = arguments[0]
        if "object" not in params or (arguments[1] == FLOOR and not view.resolve(room, FLOOR)):
            return Area(room, view.room(room).region_id)
        target = pick_target(graph, view.resolve(room, arguments[1]), skill, graph.robot.position)
        return target or Unresolved(FailureReason.UNKNOWN_OBJECT, f"unknown object {arguments[1]}")

    def _run(self, action: Step) -> ActionResult:
        """Run the decided skill on its target."""
        if action.name == INVALID:
            return ActionResult(
                ok=False, reason=FailureReason.INVALID_ANSWER, feedback=f"invalid answer: {action.note}"
            )
        return run_skill(self._body(), self._graph(), action.name, action.target)

    # -- bookkeeping ----------------------------------------------------------------------------
    def _view(self) -> SceneView:
        return needed(self.view, "observe()")


def make_more(llm: str | None) -> LLMPlanner:
    """Registry factory of ``more``."""
    return LLMPlanner(PLANNER_CONFIGS["more"], make_clients(llm))


def make_moma_llm(llm: str | None) -> LLMPlanner:
    """Registry factory of ``moma-llm``."""
    return LLMPlanner(PLANNER_CONFIGS["moma-llm"], make_clients(llm))


def make_moma_llm_sr(llm: str | None) -> LLMPlanner:
    """Registry factory of ``moma-llm-sr``."""
    return LLMPlanner(PLANNER_CONFIGS["moma-llm-sr"], make_clients(llm))


def filter_view(
    client: LLMClient, task: str, view: SceneView, *, max_reasks: int, always: Collection[str] = ()
) -> SceneView:
    """Ask MORE's filter (paper Sec. III-B) on ``view``; the rooms and objects it keeps (and the rooms
    in ``always``), or the whole view when it has no objects or no usable answer came back."""
    if not any(r.objects for r in view.rooms):
        return view
    try:
        answer = ask_validated(
            client,
            filter_messages(task, view.text()),
            filter_answer_with_names(view.names(), view.object_names()) if constrains_names(client) else FilterAnswer,
            lambda a: parse_filter_answer(a, view.names()),
            max_reasks=max_reasks,
            purpose="filter",
        )
    except InvalidAnswer as e:
        log.info("filter answer unusable, keeping the full scene: %s", e.reason)
        return view
    if answer.value.unknown_rooms or answer.value.unknown_objects:
        log.warning(
            "filter answer named unknown rooms %s / objects %s: ignored",
            clip(str(answer.value.unknown_rooms), MAX_NAME_CHARS),
            clip(str(answer.value.unknown_objects), MAX_NAME_CHARS),
        )
    return view.filtered(answer.value, always=always)
