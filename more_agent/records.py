"""The per-episode record: what one episode did and how it ended.

Written as ``DIR/episode.json`` by ``more-agent run`` and as one line of ``DIR/episodes.jsonl`` by
``more-agent eval``. Metrics (``more_agent.eval.metrics``) are pure functions of these records.

Everything that says why something ended is typed: an action's :class:`FailureReason` (the world's and
the subpolicies' reason, carried as is from the env to the record), the episode's
:data:`Termination` and, for a system error only, its :data:`ErrorKind`. Nothing downstream parses
feedback or error text. Records of older schema versions are read by upgrading them
(:meth:`EpisodeRecord._upgrade`).
"""

from __future__ import annotations

from enum import Enum
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from more_agent.errors import UserError
from more_agent.perception_spec import parse_perception
from more_agent.sensing_spec import DEFAULT_SENSING, LEGACY_SENSING, parse_sensing

RECORD_SCHEMA_VERSION = 6
"""6: ``sensing`` (the sensing cadence); 5: ``perception`` (the perception mode), ``misperceived`` and
``perception_aliases``; 4: typed action reasons, ``termination``, ``gave_up`` and ``error_kind`` (``error`` holds system errors
only); 3: ``history`` (the action history option) and ``descriptions`` (the description mode). Older
records are read through :data:`UPGRADES`."""


class FailureReason(str, Enum):
    """Why an action failed: the world's magic actions, the subpolicies and the planners report one."""

    UNKNOWN_OBJECT = "unknown_object"
    HIDDEN = "hidden"
    NOT_REACHABLE = "not_reachable"
    PATH_BLOCKED_BY_DOOR = "path_blocked_by_door"
    TOO_FAR = "too_far"
    HAND_FULL = "hand_full"
    HAND_EMPTY = "hand_empty"
    NOT_OPENABLE = "not_openable"
    ALREADY_OPEN = "already_open"
    ALREADY_CLOSED = "already_closed"
    NOT_GRASPABLE = "not_graspable"
    TARGET_CLOSED = "target_closed"
    INVALID_TARGET = "invalid_target"
    INVALID_ANSWER = "invalid_answer"
    """The planner's model gave no usable answer (after its re-asks): no skill ran."""


REACH_FAILURES = frozenset({FailureReason.NOT_REACHABLE, FailureReason.PATH_BLOCKED_BY_DOOR})
"""Reasons of an action that failed on the way to its target (no path, blocked), not at it."""

Termination = Literal["done", "step_limit", "steps_after_goal"]
"""How the episode loop ended (paper Sec. III-D): the planner called done(), the high-level step limit
passed, or the planner kept acting for too many steps after every goal condition held."""

ErrorKind = Literal["llm", "input", "crash"]
"""What kind of system error ended an episode: the LLM failed (transport, server, replay miss), the
input was bad (unknown task or scene, a task that cannot be instantiated), or code raised / a worker died."""

FailureCause = Literal[
    "unsatisfiable",
    "never_observed",
    "unreachable",
    "subpolicy_failure",
    "wrong_instance",
    "done_not_called",
    "done_early",
    "misperceived",
    "step_limit",
    "invalid_llm_answers",
    "llm_error",
    "other",
]
"""Why an unsuccessful episode failed; the classes are documented in docs/evaluation.md."""

HistoryMode = Literal["paper", "lasting"]
"""The action history the LLM and VLM planners show: ``paper``, the last five actions and every earlier
failed one (paper Sec. III-C); ``lasting``, our extension, also every earlier successful grasp, place,
open and close (``more_agent.llm.prompts.history_text``)."""

HISTORY_MODES: tuple[HistoryMode, ...] = ("paper", "lasting")
DEFAULT_HISTORY: HistoryMode = "paper"

LEGACY_HISTORY: HistoryMode = "lasting"
"""What an LLM planner was shown by the versions before the history option (since the skill table)."""


GT_PERCEPTION = "gt"
"""The perception mode of the paper and of every version before the option: ground truth."""


LEGACY_DESCRIPTIONS = "paper"
"""The description mode of the versions before the option: the paper's text (the instances its ``$``
words name, nothing more)."""


def upgrade_from_2(data: dict[str, Any]) -> dict[str, Any]:
    """A record of schema 2 in schema 3's form: the history and descriptions its episode ran with."""
    data = legacy_history(data) if "history" not in data else data
    return {"descriptions": LEGACY_DESCRIPTIONS, **data, "schema_version": 3}


def upgrade_from_3(data: dict[str, Any]) -> dict[str, Any]:
    """A record of schema 3 (or 2) in schema 4's form. Those kept the step limit, the steps-after-goal end
    and a planner's giving up in ``error`` as text, the one place text is read: the phrases the runner
    of those versions wrote. Their actions carry no reasons."""
    data = {**data, "schema_version": 4}
    error: str | None = data.get("error")
    if data.get("done_called"):
        data["termination"] = "done"
    if error is None:
        return data
    if error.startswith("step limit of "):
        data.update(termination="step_limit", error=None)
    elif error.startswith("acted for more than "):
        data.update(termination="steps_after_goal", error=None)
    elif data.get("done_called") and data.get("traceback") is None:
        data.update(gave_up=error, error=None)
    else:
        crashed = data.get("traceback") or data.get("retryable")
        data["error_kind"] = "llm" if error.startswith("LLM error") else "crash" if crashed else "input"
    return data


def upgrade_from_4(data: dict[str, Any]) -> dict[str, Any]:
    """A record of schema 4 in schema 5's form: its episode perceived the ground truth."""
    return {"perception": GT_PERCEPTION, **data, "schema_version": 5}


def upgrade_from_5(data: dict[str, Any]) -> dict[str, Any]:
    """A record of schema 5 in schema 6's form: its robot fused frames on the way at 0.5 m or 30 deg (the
    cadence of those versions; the ones before f7db0a0 of 2026-12-01 fused a frame every 0.3 m and after every
    turn)."""
    return {"sensing": LEGACY_SENSING, **data, "schema_version": 6}


UPGRADES = {2: upgrade_from_2, 3: upgrade_from_3, 4: upgrade_from_4, 5: upgrade_from_5}
"""Schema version -> the function that turns such a record into the next version's form. Schema 1
predates the first release: no step exists, and validation refuses it (``record_validation``)."""


def legacy_history(data: dict[str, Any]) -> dict[str, Any]:
    """Stored ``data`` (a record or run configuration) written before the history option, with the
    ``history`` its episodes ran with: the longer one for an LLM planner, else the default."""
    return {**data, "history": LEGACY_HISTORY if data.get("llm") else DEFAULT_HISTORY}


class FrozenModel(BaseModel):
    """A pydantic model that is a value: it cannot be changed once built."""

    model_config = ConfigDict(frozen=True)


class GoalCondition(FrozenModel):
    """One conjunct of the grounded goal option that was closest to being met."""

    text: str = Field(description="The literal in BDDL form, e.g. '(inside apple.n.01_1 fridge.n.01_1)'.")
    satisfied: bool = Field(description="Whether the literal held in the final world state.")
    objects: list[str] = Field(default_factory=list, description="Instance names the literal mentions.")


class ActionRecord(FrozenModel):
    """One high-level action (subpolicy call or magic action) and its feedback."""

    step: int = Field(description="High-level step index, from 0.")
    name: str = Field(description="Subpolicy or action name, e.g. 'go_to_and_grasp'.")
    arguments: list[str] = Field(default_factory=list, description="Arguments as given.")
    ok: bool = Field(description="Whether the action succeeded.")
    reason: FailureReason | None = Field(
        default=None, description="Why it failed (None on success, or when no reason applies)."
    )
    feedback: str = Field(default="", description="Feedback returned to the planner (failure reason if not ok).")
    low_level_steps: int = Field(default=0, description="Low-level steps (moves, turns) the action took.")


class LLMUsage(BaseModel):
    """LLM traffic of an episode, summed over all calls."""

    calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cost_usd: float = 0.0
    cache_hits: int = 0
    images: int = Field(default=0, description="Images sent (vision planners).")
    image_bytes: int = Field(default=0, description="Bytes of the images sent (decoded PNG).")
    image_tokens: int = Field(
        default=0,
        description="Prompt tokens OpenAI bills for those images (included in prompt_tokens by OpenAI's server).",
    )
    reasoning_tokens: int = Field(
        default=0,
        description="Of completion_tokens, those spent on free reasoning before the command (by the share of characters).",
    )
    seconds: float = Field(default=0.0, description="Wall time spent waiting for answers (cache lookups included).")


class WorldStats(FrozenModel):
    """How hard the episode's world was: its size, its clutter and how far the robot starts from the task."""

    objects: int = Field(description="Objects in the world (furniture and items, task objects included).")
    task_objects: int = Field(description="Objects bound to the task's object scope.")
    distractors: int = Field(description="Movable items that are not task objects.")
    start_room: str = Field(description="Room the robot starts in.")
    task_rooms: list[str] = Field(default_factory=list, description="Rooms holding task objects at the start.")
    start_to_task_m: float | None = Field(
        default=None, description="Path length on the true map from the start pose to the nearest task object."
    )
    ambiguous_scopes: list[str] = Field(
        default_factory=list,
        description="Goal scopes of furniture the description does not single out among others of its kind (sim.ambiguity).",
    )


class Failure(FrozenModel):
    """The cause of an unsuccessful episode, from its own trace and the world's ground truth afterwards."""

    cause: FailureCause = Field(description="The failure class (docs/evaluation.md).")
    detail: str = Field(default="", description="One line naming the objects, literal or reason involved.")


class EpisodeRecord(BaseModel):
    """Everything one episode produced; the same task, scene and seed give the same record, timings aside."""

    schema_version: int = RECORD_SCHEMA_VERSION
    task: str = Field(description="BEHAVIOR-1K activity name.")
    scene: str = Field(description="Scene name, e.g. 'Rs_int'.")
    seed: int = Field(description="Seed of scene generation and task instantiation.")
    trial: int = Field(
        default=0, ge=0, description="Trial of this (task, scene, seed) world, from 0 (``eval --trials``)."
    )
    planner: str = Field(
        description="Planner name: 'oracle', 'more', 'moma-llm', 'moma-llm-sr', 'bumble', 'bumble-filter'."
    )
    llm: str | None = Field(default=None, description="LLM spec, e.g. 'openai:gpt-4o'; None for the oracle.")
    room_llm: str | None = Field(
        default=None, description="LLM that labelled rooms (MORE, MoMa-LLM; the paper: gpt-3.5-turbo); None: no rooms."
    )
    start: str = Field(default="random", description="Start mode of the robot ('random', 'random-area', 'task-room').")
    distractors: bool | None = Field(
        default=None,
        description="Whether the world held the scene's own small objects; None in records written before it was kept.",
    )
    description: str = Field(default="", description="Language description the planner received.")
    descriptions: str = Field(
        default="named", description="How the description was written: 'named' or 'paper' (sim.descriptions)."
    )
    history: HistoryMode = Field(
        default=DEFAULT_HISTORY, description="Action history shown to LLM and VLM planners (others ignore it)."
    )
    perception: str = Field(
        default=GT_PERCEPTION, description="Perception mode: 'gt' or 'noisy[:KEY=VALUE,...]' (more_agent.perception)."
    )
    sensing: str = Field(
        default=DEFAULT_SENSING,
        description="Sensing cadence on the way, 'DISTANCEm/ANGLEdeg' (more_agent.sensing_spec).",
    )
    long_term_memory: bool = Field(
        default=False,
        description="Whether the planner was given the failure summaries of earlier trials (BUMBLE's --add_past).",
    )
    failure_summaries: list[str] = Field(
        default_factory=list,
        description="Long-term memory this episode leaves for the later trials of its task: one summary per failed "
        "step (BUMBLE; empty for planners without one).",
    )
    misperceived: dict[str, str] = Field(
        default_factory=dict,
        description="Task objects in view at some point but never perceived as themselves, and how (noisy perception).",
    )
    perception_aliases: dict[str, str] = Field(
        default_factory=dict,
        description="Labels noisy perception made up (an instance seen as another category, a fragment) -> world name.",
    )
    success: bool = Field(default=False, description="All goal conditions met and done() called (SR).")
    all_goals_met: bool = Field(default=False, description="All goal conditions met at the end (TTC).")
    done_called: bool = Field(default=False, description="Whether the planner ended the episode with done().")
    task_progress: float = Field(default=0.0, description="Share of goal conditions met (TP).")
    goal_conditions: list[GoalCondition] = Field(default_factory=list)
    observed_objects: list[str] = Field(
        default_factory=list, description="Task instance names the robot observed during the episode (for rTP)."
    )
    high_level_steps: int = 0
    low_level_steps: int = 0
    actions: list[ActionRecord] = Field(default_factory=list)
    trajectory: list[tuple[float, float]] = Field(
        default_factory=list, description="Robot base positions (x, y) in metres, world frame, one per pose change."
    )
    llm_usage: LLMUsage = Field(default_factory=LLMUsage)
    timings: dict[str, float] = Field(default_factory=dict, description="Seconds per phase, e.g. 'instantiate'.")
    world_stats: WorldStats | None = Field(
        default=None, description="Size and difficulty of the world; None if not built."
    )
    failure: Failure | None = Field(default=None, description="Why the episode failed; None for a success.")
    termination: Termination | None = Field(
        default=None, description="How the step loop ended; None when it did not end on its own (a system error)."
    )
    gave_up: str | None = Field(
        default=None, description="The planner's reason when it called done() on purpose with goals unmet."
    )
    error: str | None = Field(default=None, description="None, or the system error that ended the episode abnormally.")
    error_kind: ErrorKind | None = Field(default=None, description="The kind of ``error``; None without one.")
    retryable: bool = Field(
        default=False, description="The error is transient (LLM transport, worker death, timeout): worth re-running."
    )
    traceback: str | None = Field(default=None, description="Python traceback when the episode raised.")

    @model_validator(mode="before")
    @classmethod
    def _upgrade(cls, data: Any) -> Any:
        """A stored record of an older schema version in today's form (:data:`UPGRADES`, step by step);
        versions it has no step for are left to the validation that refuses them."""
        if not isinstance(data, dict):
            return data
        version = data.get("schema_version", RECORD_SCHEMA_VERSION)
        while isinstance(version, int) and version in UPGRADES:
            data, version = UPGRADES[version](data), version + 1
        return data

    def key(self) -> tuple[str, str, int, str, int]:
        """Identity of the episode within a run: (task, scene, seed, planner, trial)."""
        return (self.task, self.scene, self.seed, self.planner, self.trial)

    @classmethod
    def for_spec(cls, spec: EpisodeSpec, **fields: object) -> EpisodeRecord:
        """A record of ``spec`` (an unset scene as ''), with ``fields`` set; the outcome fields at their defaults."""
        return cls(
            task=spec.task,
            scene=spec.scene or "",
            seed=spec.seed,
            trial=spec.trial,
            planner=spec.planner,
            **episode_settings(spec),
            **fields,
        )


EPISODE_SETTINGS = (
    "llm",
    "start",
    "distractors",
    "descriptions",
    "history",
    "perception",
    "sensing",
    "long_term_memory",
)
"""The settings an episode shares with its run beside (task, scene, seed, planner): the one list that
specs, records and folder names copy from each other, so a new setting is added here once."""


def episode_settings(source: object) -> dict[str, Any]:
    """:data:`EPISODE_SETTINGS` read from ``source`` (a spec, record or run config)."""
    return {name: getattr(source, name) for name in EPISODE_SETTINGS}


class EpisodeSpec(FrozenModel):
    """What to run: one (task, scene, seed, planner, llm) combination; the unit of evaluation work."""

    task: str = Field(description="BEHAVIOR-1K activity name.")
    scene: str | None = Field(
        default=None, description="Scene name; None draws one with the seed among the task's suitable scenes."
    )
    seed: int = Field(default=0, description="Seed of scene generation and task instantiation.")
    trial: int = Field(default=0, ge=0, description="Trial of this (task, scene, seed) world, from 0.")
    planner: str = Field(default="oracle", description="Planner name.")
    llm: str | None = Field(default=None, description="LLM spec such as 'openai:gpt-4o'; None for the oracle.")
    start: str = Field(
        default="random",
        description="Robot start: 'random' (a reachable room, then a pose in it), 'random-area' or 'task-room'.",
    )
    distractors: bool = Field(
        default=True,
        description="Add the scene's own small objects as distractor items (False: only the task's objects).",
    )
    descriptions: str = Field(
        default="named",
        description="'named': the paper's text naming every goal instance the world makes ambiguous; 'paper': verbatim.",
    )
    history: HistoryMode = Field(default=DEFAULT_HISTORY, description="Action history shown to LLM and VLM planners.")
    perception: str = Field(
        default=GT_PERCEPTION, description="Perception mode: 'gt' or 'noisy[:KEY=VALUE,...]' (more_agent.perception)."
    )
    sensing: str = Field(
        default=DEFAULT_SENSING,
        description="Sensing cadence: the robot fuses a frame on the way once it moved DISTANCE or turned ANGLE "
        "('DISTANCEm/ANGLEdeg', more_agent.sensing_spec).",
    )
    long_term_memory: bool = Field(
        default=False, description="Give the planner the failure summaries of earlier trials (BUMBLE's --add_past)."
    )
    past_failures: tuple[str, ...] = Field(
        default=(),
        description="With long_term_memory: the failure summaries the earlier trials of this task left, oldest first "
        "(filled by the harness from their records, or by `run --bumble-memory` from its file).",
    )

    @field_validator("perception", "sensing")
    @classmethod
    def _canonical(cls, value: str, info: ValidationInfo) -> str:
        """The canonical text of a perception mode or a sensing cadence (their parsers' ``text()``)."""
        try:
            return (parse_perception(value) if info.field_name == "perception" else parse_sensing(value)).text()
        except UserError as e:
            raise ValueError(str(e)) from None
