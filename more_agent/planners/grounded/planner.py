"""The ``grounded`` planner: the episode's state (its :class:`~.belief.Belief`) and the planner protocol
around the pure choice of :func:`~.choose.choose`."""

from __future__ import annotations

from collections.abc import Callable, Iterable

from more_agent.planners.base import DONE, EpisodeContext, Step, StepTrace, needed
from more_agent.planners.grounded.agenda import Agenda, agenda_of
from more_agent.planners.grounded.belief import NEW_FLOOR_M2, Belief, StepOutcome, learn_from_graph, learn_from_outcome
from more_agent.planners.grounded.choose import choose
from more_agent.planners.grounded.situation import Situation
from more_agent.planners.language import room_names
from more_agent.planners.policies import Embodiment, PolicyConfig, run_skill
from more_agent.planners.room_types import likely_room_type
from more_agent.records import LLMUsage
from more_agent.robot import ActionResult
from more_agent.scene_graph import ObjectNode, SceneGraph


class GroundedPlanner:
    """Goal-aware planner on the scene graph (package docstring); no LLM, deterministic."""

    name = "grounded"
    llm: str | None = None
    reads_goal = True
    """The runner hands it the goal's literals (``GoalSpec.goal``)."""

    def __init__(self, llm: str | None = None, *, config: PolicyConfig | None = None) -> None:
        del llm  # plans without a language model
        self.config = config or PolicyConfig()
        self.body: Embodiment | None = None
        self.agenda: Agenda | None = None
        self.belief = Belief()
        self.graph: SceneGraph | None = None
        """The step's scene graph (set by ``observe()``)."""

    def reset(self, context: EpisodeContext) -> None:
        """Read the goal, forget the last episode, start the robot with a full turn in place (paper S.3)."""
        if context.goal.goal is None:
            raise ValueError("the grounded planner reads the goal: its GoalSpec must carry the literals")
        self.agenda = agenda_of(context.goal.goal)
        self.belief = Belief()
        self.graph = None
        self.body = Embodiment(context.robot, config=self.config, sensing=context.sensing)
        self.body.start()

    def observe(self) -> None:
        """Build the scene graph (its rooms typed by their furniture) and learn from it."""
        body = needed(self.body, "reset()")
        self.graph = body.step_graph(lambda g: room_types(g, body.room_input))
        learn_from_graph(self.belief, self.graph)

    def situation(self) -> Situation:
        """What the robot perceives now: the step's graph, its room names, the robot's position and way."""
        body = needed(self.body, "reset()")
        graph = needed(self.graph, "observe()")
        return Situation(graph, room_names(graph), body.xy, body.trajectory, body.builder.config.max_range_m)

    def decide(self) -> Step:
        """``done`` when every goal literal holds as far as the robot knows, else the next step."""
        choice = choose(self.belief, self.situation(), needed(self.agenda, "reset()"))
        self.belief.opened_in_a_row = self.belief.opened_in_a_row + 1 if choice.looking else 0
        return choice.action

    def execute(self, action: Step) -> ActionResult:
        """Run the skill on the step's target, and learn from its outcome."""
        body, graph = needed(self.body, "reset()"), needed(self.graph, "observe()")
        if action.name == DONE or action.target is None:
            return run_skill(body, graph, DONE, None)
        held = graph.held_object
        known, mapped = len(body.observed), body.mapped_m2
        result = run_skill(body, graph, action.name, action.target)
        outcome = StepOutcome(
            result,
            held=held.label if held is not None else None,
            region=graph.robot.region_id,
            news=len(body.observed) > known or body.mapped_m2 - mapped >= NEW_FLOOR_M2,
            path_length=len(body.trajectory),
        )
        learn_from_outcome(self.belief, needed(self.agenda, "reset()").goal, action, outcome)
        return result

    def step_trace(self) -> StepTrace:
        """The scene graph the step planned on."""
        return StepTrace(graph=self.graph)

    def llm_usage(self) -> LLMUsage:
        """No LLM."""
        return LLMUsage()


def room_types(graph: SceneGraph, read: Callable[[Iterable[ObjectNode]], list[str]]) -> dict[str, str]:
    """Region id -> the room type its furniture fits best, for the regions without a label; ``read`` gives
    the categories the classifier reads for a region's objects (``Embodiment.room_input``)."""
    labels = {}
    for rid, region in graph.regions.items():
        if region.room_label is None:
            kind = likely_room_type(read(graph.objects_in(rid)))
            if kind is not None:
                labels[rid] = kind
    return labels
