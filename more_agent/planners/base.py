"""The planner protocol the episode runner drives, and the registry of planners by name.

One high-level step is ``observe()`` (sense), ``decide()`` (plan: the next ``Step``, or
``done``) and ``execute(action)`` (act: run it through the robot, get an ``ActionResult``). A planner
is given a :class:`~more_agent.robot.Robot` and a :class:`~more_agent.goal.GoalSpec` and nothing else
of the episode (:class:`EpisodeContext`); only a privileged planner (the oracle) is also granted the
world and the goal checker (``grant``, with a ``more_agent.sim.goals.PrivilegedContext``). The runner
times the three phases, counts steps, reads the step's motion from the robot, checks the goal and
hands the planner's ``step_trace()`` to the episode folder; a planner never writes files, and never
ends the episode itself except by deciding ``done``.
Planners are built by name from the registry: ``make_planner('oracle')``. Built-in planners are
listed by dotted path so that importing this module stays light; other code may add its own with
``register_planner``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from more_agent.errors import UserError, unknown_name_error
from more_agent.goal import GoalSpec
from more_agent.records import DEFAULT_HISTORY, HistoryMode, LLMUsage
from more_agent.robot import Robot
from more_agent.sensing_spec import SensingCadence

if TYPE_CHECKING:
    from more_agent.planners.targets import Target
    from more_agent.robot import ActionResult
    from more_agent.scene_graph import SceneGraph

T = TypeVar("T")

DONE = "done"
"""Name of the action that ends an episode."""

DEFAULT_PLANNER = "grounded"
"""The planner ``more-agent run`` uses when none is given and no LLM is configured: goal-aware,
through the scene graph and subpolicies like MORE, no LLM (``oracle`` is the privileged upper bound)."""


LLM_DEFAULT_PLANNER = "more"
"""The planner ``more-agent run`` uses when none is given and an LLM is configured."""


def default_planner(llm: str | None) -> str:
    """The planner to use when the user names none; the one place this default is decided.

    ``more`` when an LLM is configured (``--llm``, the environment or the config file), else ``grounded``.
    """
    from more_agent.llm import llm_configured, load_llm_config

    return LLM_DEFAULT_PLANNER if llm_configured(load_llm_config(), llm) else DEFAULT_PLANNER


@dataclass(frozen=True)
class Step:
    """One planner decision, typed: a skill of the table (or a magic action of the oracle) plus its typed
    arguments: the arguments as words (room, object label: what the record and the LLM's history show)
    and what the skill acts on as a typed target (``planners.targets``: an object node, an area, an
    unresolved name), which ``execute`` runs as it is."""

    name: str
    arguments: tuple[str, ...] = ()
    target: Target = None
    """What the skill acts on (None for done, and for the oracle, which acts on world names)."""
    note: str = ""
    """Why the planner chose it (an LLM's reasoning, the oracle's goal literal)."""
    gave_up: str = ""
    """On a ``done`` with goals unmet on purpose: why the planner gives up (recorded as ``record.gave_up``)."""

    @property
    def is_done(self) -> bool:
        return self.name == DONE


@dataclass(frozen=True)
class EpisodeContext:
    """What a planner is given at the start of an episode: a robot and what it is told of its task."""

    robot: Robot
    """The robot it drives: frames in, skills out."""
    goal: GoalSpec
    """The task's text; for a planner that reads the goal (``reads_goal``), its literals."""
    llm: str | None = None
    """LLM spec such as 'openai:gpt-4o', for planners that need one."""
    history: HistoryMode = DEFAULT_HISTORY
    """Which action history the LLM and VLM planners show (``more_agent.llm.prompts.history_text``)."""
    past_failures: tuple[str, ...] = ()
    """Long-term memory: failure summaries that earlier trials of the task left (BUMBLE's --add_past)."""
    sensing: SensingCadence = field(default_factory=SensingCadence)
    """How far the robot moves or turns between frames its mapper fuses on the way (``--sensing``)."""
    trace_graphs: bool = False
    """Whether each step's trace must carry the scene graph (``--save-graph``, ``--viewer``): a planner
    that does not plan on one builds it only then."""


@dataclass(frozen=True)
class StepTrace:
    """What a planner saw and decided in one step, for the episode folder (the runner writes it)."""

    log: Mapping[str, Any] | None = None
    """The step's line of ``steps.jsonl`` after its step number (LLM and VLM planners: the action as
    their history holds it, scene texts, LLM exchanges, frames offered); None: the planner keeps no log."""
    graph: SceneGraph | None = None
    """The scene graph the step planned on (saved with ``--save-graph`` / ``--viewer``)."""
    pictures: Mapping[str, bytes] = field(default_factory=dict)
    """The annotated images a VLM was shown in the step, as PNG bytes by kind ('view', 'object')."""


class Planner(Protocol):
    """A high-level planner the episode runner drives step by step.

    A planner whose class sets ``reads_goal = True`` (``grounded``) gets the goal's literals in
    ``EpisodeContext.goal.goal``; the others get the task's text only.
    """

    name: str
    llm: str | None
    """The LLM it plans with as a spec (e.g. 'openai:gpt-4o'); None for the oracle."""

    def reset(self, context: EpisodeContext) -> None:
        """Start an episode."""

    def observe(self) -> None:
        """Take in what the robot senses now (the sense phase; may do nothing)."""

    def decide(self) -> Step:
        """The next step (the plan phase)."""

    def execute(self, action: Step) -> ActionResult:
        """Carry out ``action`` in the world (the act phase); failures are results, not exceptions."""

    def step_trace(self) -> StepTrace:
        """What the step just executed saw and decided."""

    def llm_usage(self) -> LLMUsage:
        """LLM traffic of this episode so far."""


def needed(value: T | None, call: str) -> T:
    """``value``, set by a planner's ``call`` (``reset()``, ``observe()``), or a RuntimeError saying that
    ``call`` has to come first: the one guard of every planner's per-episode and per-step state."""
    if value is None:
        raise RuntimeError(f"{call} must be called before this step of the planner")
    return value


PlannerFactory = Callable[[str | None], Planner]
"""Builds a planner from an LLM spec (None when no LLM is configured)."""

_BUILTIN: dict[str, str] = {
    "oracle": "more_agent.planners.oracle:OraclePlanner",
    "grounded": "more_agent.planners.grounded:GroundedPlanner",
    "more": "more_agent.planners.llm_planner:make_more",
    "moma-llm": "more_agent.planners.llm_planner:make_moma_llm",
    "moma-llm-sr": "more_agent.planners.llm_planner:make_moma_llm_sr",
    "bumble": "more_agent.planners.bumble:make_bumble",
    "bumble-filter": "more_agent.planners.bumble:make_bumble_filter",
}
"""Built-in planners: name -> 'module:attribute' of a factory, imported on first use."""

_registered: dict[str, PlannerFactory] = {}


def register_planner(name: str, factory: PlannerFactory) -> None:
    """Make ``factory`` available as planner ``name`` (replacing any planner of that name)."""
    _registered[name] = factory


def planner_names() -> list[str]:
    """Names of all available planners, sorted."""
    return sorted(set(_BUILTIN) | set(_registered))


def make_planner(name: str, llm: str | None = None) -> Planner:
    """A fresh planner by name; an unknown name raises a UserError listing the available ones."""
    if name in _registered:
        return _registered[name](llm)
    if name not in _BUILTIN:
        names = planner_names()
        raise UserError(f"{unknown_name_error('planner', name, names)}; available: {', '.join(names)}")
    module, attr = _BUILTIN[name].split(":")
    factory: PlannerFactory = getattr(importlib.import_module(module), attr)
    return factory(llm)
