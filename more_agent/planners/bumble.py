"""The BUMBLE baselines (paper Table I rows 1-2): a VLM planner with visual memory, with and without MORE's filter.

Follows the paper's adaptation of BUMBLE (supplementary "BUMBLE Implementation"; original:
UT-Austin-RobIn/BUMBLE): the same episode loop, subpolicies, feedback and termination as MORE, but
the planner reasons over images instead of a scene text.

- **Perception**: the renderer's ground-truth instance segmentation replaces Grounded SAM; instance
  0 (floor, carpet, lawn, driveway, walls, windows) is background and never marked. Objects are the
  scene graph's (its labels, states and relations describe them); the graph also gives the map the
  subpolicies drive on and the unexplored areas (frontiers).
- **Frame buffer**: every rendered frame is offered to a :class:`VisualMemory` buffer (one frame per
  0.5 m or 30 degrees, the initial turn included), for the landmark and exploration questions.
- **BUMBLE's memories** (:mod:`~more_agent.planners.bumble_memory`): short-term, the episode's steps
  each with the annotated view seen then (downscaled, the last eight with images); long-term, the failure
  summaries of earlier trials of the task it is given (``EpisodeContext.past_failures``); each failed
  step adds one to ``failure_summaries``, which the episode record keeps for the next trial.
- **Deciding**: the VLM gets the task, the current view annotated set-of-mark style with its marked
  objects listed (with their distance from the robot, as BUMBLE's selector gets them), the memories
  and the skills, analyses step by step (whether the object is within reach included) and answers a
  subtask and a skill.
- **Reaching an object** (``navigate``, ``go_to_and_*``): the landmark step (BUMBLE's
  ``goto_landmark``) shows buffer frames with their object lists and asks for a frame; the object step
  (``navigate_to_point_on_ground``) shows that frame with numbered marks and asks for a mark.
- **Exploring**: the VLM picks one of the buffer frames that show unexplored areas; the robot explores
  the closest area seen in it. The VLM then sees the frames acquired during the exploration and says
  whether the subtask was achieved: that verdict is the action's success flag and feedback (so an
  exploration that found nothing enters the long-term memory of failed actions).
- **``bumble-filter``**: MORE's filter (its prompt and parser) on the objects annotated in the
  current view (the paper's "applied to the objects that get annotated in the current view"); only
  the kept ones are marked and listed in it. Memory frames are annotated unfiltered.

Requests hold at most ``MemoryConfig.max_images`` buffer frames (8), chosen to show as many
candidate objects as possible (greedy cover) or, for exploration verdicts, evenly spread; the step
and object questions send one image. Invalid answers are re-asked (``max_reasks``), then become an
``invalid`` action fed back to the next step, as for MORE.
"""

from __future__ import annotations

import logging
import math
from collections import Counter
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from more_agent.llm import InvalidAnswer, LLMClient, ask_validated
from more_agent.llm.completion import ChatMessage
from more_agent.llm.images import png_bytes
from more_agent.llm.name_enums import constrains_names, with_name_enums
from more_agent.mapping import MappingConfig
from more_agent.planners.base import DONE, EpisodeContext, Step, StepTrace, needed
from more_agent.planners.bumble_memory import (
    PastStep,
    downscaled_png,
    failure_summary,
    long_term_message,
    short_term_messages,
)
from more_agent.planners.exchanges import CallLog, RecordingClient
from more_agent.planners.history import append_action
from more_agent.planners.language import LanguageOptions, RoomText, SceneView, room_names, scene_view
from more_agent.planners.llm_planner import filter_view, make_clients
from more_agent.planners.policies import Embodiment, PolicyConfig, run_skill
from more_agent.planners.session import MappingSession
from more_agent.planners.set_of_marks import annotate_marks
from more_agent.planners.targets import Area, Unresolved
from more_agent.planners.visual_memory import (
    MemoryConfig,
    MemoryFrame,
    VisualMemory,
    covering_frames,
    shows_points,
    spread,
)
from more_agent.planners.vlm_prompts import (
    FrameAnswer,
    MarkAnswer,
    Picture,
    StepAnswer,
    VerifyAnswer,
    frame_captions,
    frames_messages,
    object_messages,
    parse_choice,
    parse_step,
    parse_verdict,
    step_messages,
)
from more_agent.records import DEFAULT_HISTORY, ActionRecord, FailureReason, HistoryMode, LLMUsage
from more_agent.robot import ActionResult, Frame
from more_agent.scene_graph import ObjectNode, SceneGraph
from more_agent.skills import INVALID, SKILLS

log = logging.getLogger(__name__)

T = TypeVar("T")

OBSERVED_ROOM = "observed_objects"
"""The single 'room' of the scene text the filter gets under ``bumble-filter`` (BUMBLE has no rooms)."""


class BumbleConfig(BaseModel):
    """What distinguishes BUMBLE from BUMBLE + filtering, and the knobs they share."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field(description="Planner name as registered.")
    filtering: bool = Field(description="Mark and list only the objects MORE's filter keeps.")
    max_reasks: int = Field(
        default=2, ge=0, description="Re-asks after an invalid answer before it counts as an invalid action."
    )
    memory: MemoryConfig = Field(default_factory=MemoryConfig, description="Frame buffer and images per request.")
    policy: PolicyConfig = Field(default_factory=PolicyConfig, description="Subpolicy knobs.")
    mapping: MappingConfig = Field(default_factory=MappingConfig, description="Mapping and scene-graph knobs.")


BUMBLE_CONFIGS: dict[str, BumbleConfig] = {
    "bumble": BumbleConfig(name="bumble", filtering=False),
    "bumble-filter": BumbleConfig(name="bumble-filter", filtering=True),
}
"""The paper's two BUMBLE planners by name."""


@dataclass
class StepLog:
    """What one step showed and got picked, for its trace (``steps.jsonl``, the VLM's images)."""

    subtask: str = ""
    """The subtask of the decided action (why it is invalid, for an ``invalid`` one)."""
    offered_frames: list[int] = field(default_factory=list)
    """Buffer indices of the frames offered in the landmark / exploration question."""
    frame: int | None = None
    """Buffer index of the frame the VLM picked."""
    marks: dict[int, str] = field(default_factory=dict)
    """Mark number -> object id of the object step's image."""
    pictures: dict[str, bytes] = field(default_factory=dict)
    """The annotated images the VLM was shown, PNG bytes by kind ('view', 'object')."""


class BumblePlanner(MappingSession):
    """BUMBLE / BUMBLE + filtering: the :class:`~more_agent.planners.base.Planner` protocol over a VLM (module docstring)."""

    def __init__(self, config: BumbleConfig, client: LLMClient, spec: str) -> None:
        self.name = config.name
        self.llm: str | None = spec
        self.config = config
        self.calls = CallLog()
        """Every VLM call: the episode's usage."""
        self.client = RecordingClient(client, self.calls)
        self.body: Embodiment | None = None
        self.memory = VisualMemory(config.memory)
        self.task = ""
        self.history: list[ActionRecord] = []
        self.history_mode: HistoryMode = DEFAULT_HISTORY
        self.past: list[PastStep] = []
        """Short-term memory: the episode's steps with their views."""
        self.long_term: list[str] = []
        """Failure summaries of earlier trials of the task."""
        self.failure_summaries: list[str] = []
        """What this episode leaves for the later trials: a summary of each failed step."""
        self.feedback = ""
        self.graph: SceneGraph | None = None
        self.descriptions: dict[str, str] = {}
        """Object id -> how the VLM reads it ('apple A [inside fridge A]')."""
        self.relevant: set[str] | None = None
        """Object ids the filter kept (``bumble-filter``), None without filtering."""
        self.current: Frame | None = None
        """The latest rendered frame: the current view."""
        self.step_log = StepLog()

    # -- Planner protocol ---------------------------------------------------------------------
    def reset(self, context: EpisodeContext) -> None:
        """Start an episode: fresh map, memory and history, then the full turn in place (its frames fill the buffer).
        The robot senses on the way at least as often as the memory keeps frames: BUMBLE samples its camera
        continuously, so a thinner ``--sensing`` cadence never starves its buffer."""
        sensing = context.sensing.at_least_as_often_as(self.config.memory.keep)
        self.body = Embodiment(context.robot, config=self.config.policy, mapping=self.config.mapping, sensing=sensing)
        self.memory = VisualMemory(self.config.memory)

        def on_frame(frame: Frame) -> None:
            self.current = frame
            self.memory.offer(frame)

        self.body.on_frame = on_frame
        self.task = context.goal.text
        self.history, self.feedback, self.history_mode = [], "", context.history
        self.past, self.failure_summaries = [], []
        self.long_term = list(context.past_failures)
        self.calls.new_episode()
        self.body.start()

    def observe(self) -> None:
        """Build the scene graph (map, objects, frontiers), describe its objects, filter them (``bumble-filter``)."""
        self.memory.step = len(self.history)
        self.step_log = StepLog()
        self.calls.new_step()
        self.graph = self._body().step_graph()
        view = scene_view(self.graph, LanguageOptions(instance_ids=True, spatial_relations=True))
        self.descriptions = {i: o.text() for r in view.rooms for o in r.objects for i in o.ids}
        self.relevant = self._filter(view) if self.config.filtering else None

    def decide(self) -> Step:
        """Step decision, then the skill's parameter steps; ``invalid`` when an answer stays unusable."""
        try:
            schema = StepAnswer
            if constrains_names(self.client):
                schema = with_name_enums(StepAnswer, {"skill": [s.name for s in SKILLS]})
            skill, subtask = self._ask(self._step_messages(), schema, parse_step, "plan")
            if skill == DONE:
                return Step(name=DONE, note=subtask)
            target = self._explore_target(subtask) if skill == "explore" else self._object_target(subtask)
        except InvalidAnswer as e:
            return Step(name=INVALID, note=e.reason)
        arguments = (
            (target.label,) if isinstance(target, ObjectNode) else (target.name,) if isinstance(target, Area) else ()
        )
        return Step(name=skill, arguments=arguments, target=target, note=subtask)

    def execute(self, action: Step) -> ActionResult:
        """Run the subpolicy (explorations get the VLM's verdict as feedback)."""
        result = self._run(action)
        self.feedback = append_action(self.history, action, result)
        self.step_log.subtask = action.note
        self._remember(action, self.history[-1])
        return result

    def _remember(self, action: Step, done: ActionRecord) -> None:
        """The step into the short-term memory; a failure also into what the long-term memory keeps."""
        view = self.step_log.pictures.get("view")
        subtask = action.note if action.name != INVALID else ""
        step = PastStep(subtask, action.name, done.ok, done.feedback, downscaled_png(view) if view else None)
        self.past.append(step)
        if not step.ok:
            self.failure_summaries.append(failure_summary(step))

    def step_trace(self) -> StepTrace:
        """The step's action, subtask, the frames offered and picked (its ``steps.jsonl`` line) and the VLM's images."""
        step = self.step_log
        log_line = {
            "action": self.history[-1].model_dump(),
            "subtask": step.subtask,
            "offered_frames": step.offered_frames,
            "frame": step.frame,
            "marks": step.marks,
            "buffer_frames": len(self.memory.frames),
        }
        return StepTrace(log=log_line, pictures=step.pictures)

    def llm_usage(self) -> LLMUsage:
        """VLM traffic of this episode so far (images included), with the time spent waiting for answers."""
        return self.calls.usage()

    # -- what the VLM sees ------------------------------------------------------------------------
    def markable(self, instance_ids: Collection[int], *, filtered: bool = False) -> list[str]:
        """Object ids the VLM may be shown among ``instance_ids``, sorted by label: in the graph, not
        held, and with ``filtered`` (the current view) kept by the filter under ``bumble-filter``."""
        graph = self._graph()
        by_instance = {o.instance_id: o for o in graph.objects.values() if not o.held and o.id in self.descriptions}
        objs = [by_instance[i] for i in instance_ids if i in by_instance]
        if filtered and self.relevant is not None:
            objs = [o for o in objs if o.id in self.relevant]
        return [o.id for o in sorted(objs, key=lambda o: o.label)]

    def marked_picture(
        self, rgb: np.ndarray, instance: np.ndarray, object_ids: Sequence[str], caption: str
    ) -> tuple[Picture, list[str]]:
        """The frame annotated with marks on ``object_ids``; returns the picture and the object id of each mark."""
        graph = self._graph()
        marked = annotate_marks(rgb, instance, [graph.objects[o].instance_id for o in object_ids])
        by_instance = {graph.objects[o].instance_id: o for o in object_ids}
        return Picture(caption, png_bytes(marked.rgb)), [by_instance[m.instance_id] for m in marked.marks]

    def _frame_objects(self, frame: MemoryFrame) -> list[str]:
        return [self.descriptions[o] for o in self.markable(frame.instance_ids)]

    def _pictures(self, frames: Sequence[MemoryFrame]) -> list[Picture]:
        captions = frame_captions([self._frame_objects(f) for f in frames])
        return [Picture(c, f.png) for c, f in zip(captions, frames, strict=True)]

    # -- the questions ----------------------------------------------------------------------------
    def _step_messages(self) -> list[ChatMessage]:
        frame = self._current()
        ids = self.markable(self._in_view(), filtered=True)
        view, marked = self.marked_picture(frame.rgb, frame.instance, ids, "Current view:")
        self.step_log.pictures["view"] = view.png
        graph = self._graph()
        xy = graph.robot.position
        objects = [f"{self.descriptions[o]}, {math.dist(xy, graph.objects[o].position[:2]):.1f} m away" for o in marked]
        held = graph.held_object
        return step_messages(
            task=self.task,
            view=view,
            objects=objects,
            held=held.label if held is not None else None,
            feedback=self.feedback,
            memory=[*long_term_message(self.long_term), *short_term_messages(self.past)],
        )

    def _in_view(self) -> set[int]:
        """Instance ids in the current view, background (0) left out."""
        return set(np.unique(self._current().instance).tolist()) - {0}

    def _object_target(self, subtask: str) -> ObjectNode | Unresolved:
        """Landmark step (which frame), then object step (which mark in it)."""
        frames = self.memory.frames
        wanted = {
            self._graph().objects[o].instance_id for o in self.markable({i for f in frames for i in f.instance_ids})
        }
        offered = covering_frames(frames, wanted, self.config.memory.max_images)
        if not offered:
            return Unresolved(FailureReason.INVALID_TARGET, "no object to go to has been seen yet")
        self.step_log.offered_frames = [f.index for f in offered]
        pictures = self._pictures(offered)
        k = self._ask(
            frames_messages("bumble_landmark", task=self.task, subtask=subtask, pictures=pictures),
            FrameAnswer,
            lambda a: parse_choice(a, "frame", len(offered)),
            "landmark",
        )
        frame = offered[k - 1]
        self.step_log.frame = frame.index
        picture, marked = self.marked_picture(
            frame.rgb(), frame.instance(), self.markable(frame.instance_ids), "Frame:"
        )
        self.step_log.marks = dict(enumerate(marked, start=1))
        self.step_log.pictures["object"] = picture.png
        m = self._ask(
            object_messages(
                task=self.task, subtask=subtask, view=picture, objects=[self.descriptions[o] for o in marked]
            ),
            MarkAnswer,
            lambda a: parse_choice(a, "mark", len(marked)),
            "object",
        )
        return self._graph().objects[marked[m - 1]]

    def _explore_target(self, subtask: str) -> Area | Unresolved:
        """The unexplored areas of the frame the VLM picks (among buffer frames showing some), as the room
        most of them lie in: the skill table's ``explore(room)``."""
        graph = self._graph()
        points = np.array([f for r in graph.regions.values() for f in r.frontiers], dtype=float).reshape(-1, 2)
        owners = [rid for rid, r in graph.regions.items() for _ in r.frontiers]
        margin = self.config.memory.occlusion_margin_m
        seen = {
            f.index: set(np.flatnonzero(shows_points(f, points, margin_m=margin)).tolist()) for f in self.memory.frames
        }
        showing = [f for f in self.memory.frames if seen[f.index]]
        offered = covering_frames(
            showing, set(range(len(points))), self.config.memory.max_images, shown=lambda f: seen[f.index]
        )
        if not offered:
            return Unresolved(FailureReason.INVALID_TARGET, "no unexplored area in view of the robot's memory")
        self.step_log.offered_frames = [f.index for f in offered]
        k = self._ask(
            frames_messages("bumble_explore", task=self.task, subtask=subtask, pictures=self._pictures(offered)),
            FrameAnswer,
            lambda a: parse_choice(a, "frame", len(offered)),
            "explore",
        )
        chosen = offered[k - 1]
        self.step_log.frame = chosen.index
        picked = sorted(seen[chosen.index])
        frontiers = tuple((float(points[i][0]), float(points[i][1])) for i in picked)
        counts = Counter(owners[i] for i in picked)
        region = min(counts, key=lambda rid: (-counts[rid], rid))
        return Area(room_names(graph)[region], region, frontiers)

    def _verdict(self, subtask: str, frames: Sequence[MemoryFrame]) -> tuple[bool, str]:
        """(achieved, feedback) of an exploration, from the VLM shown the frames acquired during it.
        Without frames or a usable answer the exploration counts as done (its motion succeeded)."""
        shown = spread(frames, self.config.memory.max_images)
        if not shown:
            return True, "explored; no new view"
        try:
            achieved, why = self._ask(
                frames_messages("bumble_verify", task=self.task, subtask=subtask, pictures=self._pictures(shown)),
                VerifyAnswer,
                parse_verdict,
                "verify",
            )
        except InvalidAnswer as e:
            return True, f"explored; no verdict on the subtask ({e.reason})"
        verdict = "subtask achieved" if achieved else "subtask not achieved"
        return achieved, f"{verdict}: {why}" if why else verdict

    def _filter(self, view: SceneView) -> set[str]:
        """MORE's filter on the objects of the current view, as one room; all kept when the answer is unusable."""
        graph, in_view = self._graph(), self._in_view()
        objects = tuple(
            o for r in view.rooms for o in r.objects if any(graph.objects[i].instance_id in in_view for i in o.ids)
        )
        flat = SceneView(
            rooms=(RoomText(OBSERVED_ROOM, "", objects, False),),
            robot_room=OBSERVED_ROOM,
            held=view.held,
            held_id=view.held_id,
        )
        kept = filter_view(self.client, self.task, flat, max_reasks=self.config.max_reasks)
        return {i for r in kept.rooms for o in r.objects for i in o.ids}

    def _ask(
        self,
        messages: list[ChatMessage],
        schema: type[BaseModel],
        validate: Callable[[str | Mapping[str, Any]], T],
        purpose: str,
    ) -> T:
        """ask_validated with this planner's re-asks."""
        return ask_validated(
            self.client, messages, schema, validate, max_reasks=self.config.max_reasks, purpose=purpose
        ).value

    # -- acting ---------------------------------------------------------------------------------
    def _run(self, action: Step) -> ActionResult:
        """Dispatch one decided action to its subpolicy."""
        if action.name == INVALID:
            return ActionResult(
                ok=False, reason=FailureReason.INVALID_ANSWER, feedback=f"invalid answer: {action.note}"
            )
        body, graph = self._body(), self._graph()
        if action.name != "explore":
            return run_skill(body, graph, action.name, action.target)
        first = len(self.memory.frames)
        result = run_skill(body, graph, action.name, action.target)
        if not result.ok:
            return result
        achieved, feedback = self._verdict(action.note, self.memory.since(first))
        return ActionResult(ok=achieved, reason=None, feedback=feedback, low_level_steps=result.low_level_steps)

    # -- bookkeeping ----------------------------------------------------------------------------
    def _current(self) -> Frame:
        return needed(self.current, "reset()")


def make_bumble(llm: str | None) -> BumblePlanner:
    """Registry factory of ``bumble``."""
    clients = make_clients(llm)
    return BumblePlanner(BUMBLE_CONFIGS["bumble"], clients.plan, clients.spec)


def make_bumble_filter(llm: str | None) -> BumblePlanner:
    """Registry factory of ``bumble-filter``."""
    clients = make_clients(llm)
    return BumblePlanner(BUMBLE_CONFIGS["bumble-filter"], clients.plan, clients.spec)
