"""The episode runner: instantiate a task, drive a planner step by step, check the goal, write the record.

``run_episode(spec)`` never raises for a failing episode: a system error goes into ``record.error`` with
its ``error_kind`` (and ``record.traceback`` when code raised; an LLM error is recorded without one).
Every planner, the oracle and the LLM planners alike, runs through this one loop. Termination follows
the paper (Sec. III-D, :mod:`more_agent.eval.termination`) and is recorded typed in
``record.termination``: the planner calls ``done``, ``MAX_HIGH_LEVEL_STEPS`` high-level steps pass, or the
planner keeps acting for more than ``STEPS_AFTER_GOAL`` steps after every goal condition holds. The runner
builds the robot a planner drives (:class:`~more_agent.sim.env.SimRobot`) and what it is told of the task
(:class:`~more_agent.goal.GoalSpec`); only a privileged planner (the oracle) is granted the world and the
goal checker. The step's motion (low-level steps and path) is read from the robot, the same way for every planner. With ``out_dir``
an :class:`~more_agent.eval.episode_folder.EpisodeFolder` writes the episode's files: the record,
the map, each step's timeline line and the planner's step trace. Timings are seconds per phase:
instantiate, sense, plan, act (goal checks included), write, total, and ``llm`` (waiting for
answers, part of plan) for LLM planners. Everything else in the record
is a function of (task, scene, seed, planner, llm) and, for a later trial, the long-term memory it was given.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from more_agent.errors import UserError
from more_agent.eval.episode_folder import EpisodeFolder
from more_agent.eval.failure import classify_failure
from more_agent.eval.termination import MAX_HIGH_LEVEL_STEPS, STEPS_AFTER_GOAL
from more_agent.goal import GoalSpec
from more_agent.llm.limits import MAX_FEEDBACK_CHARS, clip
from more_agent.planners.base import EpisodeContext, Planner, make_planner
from more_agent.records import DEFAULT_HISTORY, ActionRecord, EpisodeRecord, EpisodeSpec, HistoryMode, WorldStats
from more_agent.redaction import redact
from more_agent.robot import XY, Observation
from more_agent.safe_files import DISK_FULL_ERRNOS
from more_agent.sensing_spec import SensingCadence, parse_sensing

if TYPE_CHECKING:
    from more_agent.interop.bag_writer import BagRecorder
    from more_agent.perception.model import NoisyPerception
    from more_agent.robot import Frame
    from more_agent.sim.env import SimRobot
    from more_agent.sim.goals import GoalChecker, GoalStatus, PrivilegedContext
    from more_agent.sim.instantiate import TaskInstance
    from more_agent.sim.labels import InstanceLabels
    from more_agent.sim.world import World

LLM_ERROR_PREFIX = "LLM error"
"""Start of ``record.error`` when the LLM failed (transport, server, replay miss), for people to read
(``record.error_kind`` says it for code)."""


def observed_task_objects(scope: dict[str, str], world_names: Iterable[str]) -> list[str]:
    """World names of the task objects among the observed world objects, sorted.

    World names, like ``GoalCondition.objects``, so that rTP can match conditions to observations.
    """
    seen = set(world_names)
    return sorted({name for name in scope.values() if name in seen})


class _Clock:
    """Sums wall time per phase."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self._start = time.perf_counter()

    def add(self, phase: str, since: float) -> float:
        now = time.perf_counter()
        self.seconds[phase] = self.seconds.get(phase, 0.0) + now - since
        return now

    def total(self) -> dict[str, float]:
        out = {k: round(v, 6) for k, v in self.seconds.items()}
        out["total"] = round(time.perf_counter() - self._start, 6)
        return out


def _extend_path(trajectory: list[XY], path: list[XY]) -> None:
    for p in path:
        if not trajectory or trajectory[-1] != p:
            trajectory.append((round(p[0], 4), round(p[1], 4)))


def run_episode(
    spec: EpisodeSpec,
    *,
    out_dir: Path | None = None,
    save_frames: bool = False,
    save_graph: bool = False,
    strict: bool = False,
    planner: Planner | None = None,
    viewer: bool = False,
    bag: BagRecorder | None = None,
) -> EpisodeRecord:
    """Run one episode of ``spec`` and return its record (also written under ``out_dir`` when given).

    ``planner`` replaces the registry's planner of ``spec.planner`` (tests inject LLM clients this
    way). ``strict`` re-raises a ``UserError`` from bad input (unknown task / scene / planner, a
    task that cannot be instantiated in the scene, no LLM configured) instead of recording it: the
    CLI turns those into exit status 2. An LLM error (timeout after the retries, server gone, a
    replay miss) ends the episode with ``record.error`` naming it, everything so far kept.
    ``viewer`` (with ``out_dir``) saves what the episode viewer reads: frames and scene graphs, without
    the slow per-step graph pictures unless ``save_graph`` asks for them
    (``more_agent.eval.viewer.run_episode_with_viewer`` then writes the page).
    ``bag`` (an open recorder) gets every frame the robot renders: ``run --bag`` (docs/ros.md).
    """
    from more_agent.llm.errors import LLMError
    from more_agent.perception.model import perception_for
    from more_agent.sim.goals import GoalChecker
    from more_agent.sim.world_cache import instantiate_cached

    clock = _Clock()
    record = EpisodeRecord.for_spec(spec)
    folder = (
        None
        if out_dir is None
        else EpisodeFolder(
            Path(out_dir),
            frames=save_frames or viewer,
            graphs=save_graph or viewer,
            graph_pictures=save_graph,
        )
    )
    world: World | None = None
    labels: InstanceLabels | None = None
    goals: GoalChecker | None = None
    robot: SimRobot | None = None
    perception: NoisyPerception | None = None
    privileged: PrivilegedContext | None = None
    scope: dict[str, str] = {}
    if folder is not None:
        folder.clear()  # an earlier episode's steps and frames must never show in this one's viewer
    try:
        t = time.perf_counter()
        instance = instantiate_cached(
            spec.task,
            spec.scene,
            spec.seed,
            start=spec.start,
            distractors=spec.distractors,
            descriptions=spec.descriptions,
        )
        goals, scope = GoalChecker(instance), instance.scope
        planner = planner or make_planner(spec.planner, spec.llm)
        record.llm = planner.llm
        record.room_llm = getattr(planner, "room_llm", None)  # only the planners that label rooms have one
        world, labels = instance.world, instance.labels
        record.scene, record.description = instance.scene, instance.description
        record.world_stats = world_stats(instance)
        record.trajectory = [(round(world.robot.x, 4), round(world.robot.y, 4))]
        t = clock.add("instantiate", t)
        perception = perception_for(spec.perception, world, labels, spec.seed, spec.task)
        on_frame = folder.frame_writer(world.class_names) if folder is not None else None
        robot, privileged = reset_planner(
            planner,
            instance,
            goals,
            descriptions=spec.descriptions,
            history=spec.history,
            on_frame=on_frame,
            on_sensed=bag.hook(world, instance.labels) if bag is not None else None,
            trace_graphs=folder is not None and folder.graphs,
            perception=perception,
            past_failures=spec.past_failures,
            sensing=parse_sensing(spec.sensing),
        )
        clock.add("sense", t)
        if folder is not None:
            folder.start(steps_log=planner.llm is not None)
        _run_steps(record, planner, robot, goals, world, labels, clock, folder)
    except LLMError as e:
        record.error, record.error_kind = f"{LLM_ERROR_PREFIX} ({type(e).__name__}): {e}", "llm"
        record.retryable = e.retryable
    except UserError as e:
        if strict:
            raise
        record.error, record.error_kind = redact(str(e)), "input"
    except Exception as e:  # noqa: BLE001 - an episode that raises is a recorded failure
        record.error, record.error_kind = redact(f"{type(e).__name__}: {e}"), "crash"
        record.traceback = redact(traceback.format_exc())
        record.retryable = isinstance(e, OSError) and e.errno in DISK_FULL_ERRNOS  # free space, run again
    if world is not None and goals is not None and planner is not None:
        seen = perception.observed() if perception is not None else robot.observed if robot is not None else set()
        observed = seen | (privileged.observed if privileged else set())
        _finish(record, goals.check(world), scope, planner, observed)
        if perception is not None:
            record.misperceived = perception.misperceived(sorted(set(scope.values())))
            record.perception_aliases = dict(perception.aliases)
    record.failure = classify_failure(
        record,
        world,
        labels,
        goals.objects if goals is not None else (),
        satisfiable=record.success or goals is None or goals.satisfiable,  # solved only when an episode is lost
    )
    if folder is not None:
        t = time.perf_counter()
        folder.write_map(record, world, labels, set(scope.values()))
        clock.add("write", t)
    record.timings = clock.total()
    if record.llm_usage.calls:
        record.timings["llm"] = round(record.llm_usage.seconds, 6)
    if folder is not None:
        folder.write_record(record)
    return record


def reset_planner(
    planner: Planner,
    instance: TaskInstance,
    goals: GoalChecker,
    *,
    descriptions: str = "named",
    history: HistoryMode = DEFAULT_HISTORY,
    on_frame: Callable[[Frame], None] | None = None,
    on_sensed: Callable[[Observation], None] | None = None,
    trace_graphs: bool = False,
    perception: NoisyPerception | None = None,
    past_failures: tuple[str, ...] = (),
    sensing: SensingCadence | None = None,
) -> tuple[SimRobot, PrivilegedContext | None]:
    """Start ``planner`` on ``instance``: build the robot it drives on the instance's world (``on_frame``
    gets every frame it renders, ``on_sensed`` every observation of one; with ``perception``, the planner
    drives it through a :class:`~more_agent.perception.robot.NoisyRobot`), tell it the task
    (:func:`goal_spec`), the ``past_failures`` of earlier trials and the ``sensing`` cadence (default: the
    default cadence), grant the world and the goal checker
    to a privileged planner (one with ``grant``: the oracle), then ``reset`` it. Returns the simulator's
    robot and the privileged context (None for any other planner)."""
    from more_agent.perception.robot import NoisyRobot
    from more_agent.sim.env import SimRobot
    from more_agent.sim.goals import PrivilegedContext

    robot = SimRobot(instance.world, labels=instance.labels, on_frame=on_frame, on_sensed=on_sensed)
    grant = getattr(planner, "grant", None)
    privileged = PrivilegedContext(world=instance.world, goals=goals) if grant is not None else None
    if grant is not None:
        grant(privileged)
    goal = goal_spec(instance, goals, descriptions, with_goal=getattr(planner, "reads_goal", False))
    driven = robot if perception is None else NoisyRobot(robot, perception)
    planner.reset(
        EpisodeContext(
            robot=driven,
            goal=goal,
            llm=planner.llm,
            history=history,
            past_failures=past_failures,
            sensing=sensing or SensingCadence(),
            trace_graphs=trace_graphs,
        )
    )
    return robot, privileged


def goal_spec(instance: TaskInstance, goals: GoalChecker, descriptions: str, *, with_goal: bool) -> GoalSpec:
    """What a planner is told of its task: the description (also by class), and the goal's literals when it
    reads them."""
    from more_agent.sim.task_goal import task_goal

    goal = task_goal(instance, goals) if with_goal else None
    return GoalSpec(
        text=instance.description, class_text=instance.class_description, descriptions=descriptions, goal=goal
    )


def world_stats(instance: TaskInstance) -> WorldStats:
    """The world's size, clutter, start-to-task distance and the goal instances its description cannot
    single out, at the start of the episode."""
    from more_agent.sim.ambiguity import ambiguous_scopes

    world, facts = instance.world, instance.start
    task_objects = {n for s, n in instance.scope.items() if n in world.objects and s not in instance.virtual_scopes}
    return WorldStats(
        objects=sum(o.kind != "floor" for o in world.objects.values()),
        task_objects=sum(world.objects[n].kind != "floor" for n in task_objects),
        distractors=len(instance.distractors),
        start_room=facts.start_room if facts else "",
        task_rooms=list(facts.task_rooms) if facts else [],
        start_to_task_m=facts.start_to_task_m if facts else None,
        ambiguous_scopes=ambiguous_scopes(instance),
    )


def ended_abnormally(record: EpisodeRecord) -> bool:
    """Whether the episode ended in an error of the system (code raised, the LLM failed), not of the agent."""
    return record.traceback is not None or record.retryable or record.error_kind == "llm"


def redraw_map(spec: EpisodeSpec, record: EpisodeRecord, out_dir: Path) -> None:
    """Draw ``out_dir/map.png`` again from a finished episode's record: the path on the episode's world
    rebuilt from (task, scene, seed, start, distractors, descriptions) in its initial state (objects where they started)."""
    from more_agent.sim.instantiate import instantiate

    instance = instantiate(
        spec.task, spec.scene, spec.seed, start=spec.start, distractors=spec.distractors, descriptions=spec.descriptions
    )
    EpisodeFolder(out_dir).write_map(record, instance.world, instance.labels, set(instance.scope.values()))


def _run_steps(
    record: EpisodeRecord,
    planner: Planner,
    robot: SimRobot,
    goals: GoalChecker,
    world: World,
    labels: InstanceLabels,
    clock: _Clock,
    folder: EpisodeFolder | None = None,
) -> None:
    """High-level steps until done(), the step limit, or too many steps after the goal (paper Sec. III-D);
    each step goes to ``folder`` when given."""
    goal_held = goals.check(world).all_met
    steps_since_goal = 0
    while record.high_level_steps < MAX_HIGH_LEVEL_STEPS:
        t = time.perf_counter()
        planner.observe()
        t = clock.add("sense", t)
        action = planner.decide()
        t = clock.add("plan", t)
        # The outcome with the robot's low-level steps and path since the last step (the first step's
        # include the initial full turn).
        result = robot.since_last_report(planner.execute(action))
        status = goals.check(world)
        clock.add("act", t)
        record.actions.append(
            ActionRecord(
                step=record.high_level_steps,
                name=action.name,
                arguments=list(action.arguments),
                ok=result.ok,
                reason=result.reason,
                feedback=clip(result.feedback, MAX_FEEDBACK_CHARS),
                low_level_steps=result.low_level_steps,
            )
        )
        record.high_level_steps += 1
        record.low_level_steps += result.low_level_steps
        _extend_path(record.trajectory, result.path)
        if folder is not None:
            targets = [labels.display(world.objects[a]) if a in world.objects else a for a in action.arguments]
            folder.write_step(record, status, targets, planner.step_trace())
        if action.is_done:
            record.done_called, record.termination = True, "done"
            if not status.all_met and action.gave_up:
                record.gave_up = action.gave_up
            return
        # Steps taken while every goal condition already held (the completing step is not one of them).
        steps_since_goal = steps_since_goal + 1 if goal_held and status.all_met else 0
        goal_held = status.all_met
        if steps_since_goal > STEPS_AFTER_GOAL:
            record.termination = "steps_after_goal"
            return
    record.termination = "step_limit"


def _finish(
    record: EpisodeRecord, status: GoalStatus, scope: dict[str, str], planner: Planner, observed: set[str]
) -> None:
    """Goal outcome, what was observed (world names) and the LLM traffic, from the final state."""
    record.all_goals_met = status.all_met
    record.success = status.all_met and record.done_called
    record.task_progress = status.progress
    record.goal_conditions = list(status.conditions)
    record.observed_objects = observed_task_objects(scope, observed)
    record.llm_usage = planner.llm_usage()
    record.failure_summaries = list(getattr(planner, "failure_summaries", ()))  # only BUMBLE keeps them
