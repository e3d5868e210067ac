"""The episode loop of the LLM planners: sense, filter, plan, act, feed back, until the episode ends.

``run_llm_episode(spec)`` instantiates the task, lets an :class:`~more_agent.planners.llm_planner.LLMPlanner`
turn once in place and then run high-level steps (build graph -> room labels -> filter -> plan ->
one subpolicy -> feedback) until it calls ``done()``, 50 high-level steps pass, or it keeps acting
for five steps after all goal conditions hold (paper Sec. III-D; the limits are the runner's).

What sets it apart from the generic runner is what LLMs bring: an LLM error (timeout after the
retries, server gone, HTTP errors, a replay miss) ends the episode with ``record.error`` naming it
and everything so far kept (actions, steps, goal progress, LLM usage), without a traceback; an
answer still invalid after the bounded re-asks is an ``invalid`` action, fed back and recorded like
any failed action. LLM usage is summed into the record; ``timings['llm']`` is the time spent waiting
for answers, so ``timings['plan'] - timings['llm']`` is the planning overhead of our own code.
With ``out_dir`` it writes ``episode.json``, ``map.png`` and ``steps.jsonl`` (per step: scene text,
planning text, action, feedback), and with ``save_graph`` each step's scene graph as JSON.
"""

from __future__ import annotations

import json
import logging
import time
import traceback
from pathlib import Path
from typing import TYPE_CHECKING

from more_agent.errors import UserError
from more_agent.eval.episode import EPISODE_FILE, MAP_FILE, MAX_HIGH_LEVEL_STEPS, STEPS_AFTER_GOAL, observed_task_objects
from more_agent.eval.record import ActionRecord, EpisodeRecord, EpisodeSpec
from more_agent.llm import LLMError
from more_agent.planners.base import EpisodeContext
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner, LLMPlannerConfig, make_clients

if TYPE_CHECKING:
    from more_agent.sim.goals import GoalStatus

log = logging.getLogger(__name__)

STEPS_FILE = "steps.jsonl"
GRAPHS_DIR = "graphs"


def run_llm_episode(
    spec: EpisodeSpec,
    *,
    out_dir: Path | None = None,
    clients: LLMClients | None = None,
    config: LLMPlannerConfig | None = None,
    save_graph: bool = False,
    strict: bool = False,
) -> EpisodeRecord:
    """Run one episode of an LLM planner and return its record (also written under ``out_dir``).

    ``clients`` default to the LLM config (``--llm`` = ``spec.llm``, environment, config file);
    ``config`` defaults to the registered configuration of ``spec.planner``. ``strict`` re-raises
    a UserError (unknown task / scene / planner, no LLM configured) instead of recording it.
    """
    from more_agent.sim.goals import GoalChecker
    from more_agent.sim.instantiate import instantiate

    start = time.perf_counter()
    timings: dict[str, float] = {}
    record = EpisodeRecord(task=spec.task, scene=spec.scene or "", seed=spec.seed, planner=spec.planner, llm=spec.llm)
    planner: LLMPlanner | None = None
    out = Path(out_dir) if out_dir is not None else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / STEPS_FILE).write_text("", encoding="utf-8")
    try:
        t = time.perf_counter()
        if config is None and spec.planner not in PLANNER_CONFIGS:
            raise UserError(f"unknown LLM planner {spec.planner!r}; LLM planners: {', '.join(PLANNER_CONFIGS)}")
        config = config or PLANNER_CONFIGS[spec.planner]
        clients = clients or make_clients(spec.llm)
        record.llm = clients.spec
        instance = instantiate(spec.task, spec.scene, spec.seed)
        goals = GoalChecker(instance)
        record.scene, record.description = instance.scene, instance.description
        world = instance.world
        record.trajectory = [(round(world.robot.x, 4), round(world.robot.y, 4))]
        _tick(timings, "instantiate", t)
        planner = LLMPlanner(config, clients)
        t = time.perf_counter()
        planner.reset(EpisodeContext(instance=instance, goals=goals, llm=clients.spec, out_dir=out))
        _tick(timings, "sense", t)
        status = goals.check(world)
        after_goal = 0
        while record.high_level_steps < MAX_HIGH_LEVEL_STEPS:
            t = time.perf_counter()
            planner.observe()
            t = _tick(timings, "sense", t)
            action = planner.decide()
            t = _tick(timings, "plan", t)
            result = planner.execute(action)
            status = goals.check(world)
            _tick(timings, "act", t)
            record.actions.append(ActionRecord(
                step=record.high_level_steps, name=action.name, arguments=list(action.arguments), ok=result.ok,
                feedback=result.feedback, low_level_steps=result.low_level_steps,
            ))
            record.high_level_steps += 1
            record.low_level_steps += result.low_level_steps
            record.trajectory += [(round(x, 4), round(y, 4)) for x, y in result.path[1:]]
            if out is not None:
                _write_step(out, planner, record.actions[-1], save_graph)
            if action.is_done:
                record.done_called = True
                break
            after_goal = after_goal + 1 if status.all_met else 0
            if after_goal > STEPS_AFTER_GOAL:
                record.error = f"all goal conditions held for {STEPS_AFTER_GOAL} steps without done()"
                break
        else:
            record.error = f"step limit of {MAX_HIGH_LEVEL_STEPS} high-level steps reached"
        _finish(record, status, instance.scope, planner)
    except LLMError as e:
        record.error = f"LLM error ({type(e).__name__}): {e}"
        if planner is not None and planner.body is not None:
            _finish(record, goals.check(world), instance.scope, planner)
    except UserError as e:
        if strict:
            raise
        record.error = str(e)
    except Exception as e:  # noqa: BLE001 - an episode that raises is a recorded failure
        record.error = f"{type(e).__name__}: {e}"
        record.traceback = traceback.format_exc()
    if planner is not None:
        record.llm_usage = planner.llm_usage()
        timings["llm"] = planner.llm_seconds
    timings["total"] = time.perf_counter() - start
    record.timings = {k: round(v, 6) for k, v in timings.items()}
    if out is not None:
        _write_outputs(record, planner, out)
    return record


def _tick(timings: dict[str, float], phase: str, since: float) -> float:
    """Add the time since ``since`` to ``phase``; return now."""
    now = time.perf_counter()
    timings[phase] = timings.get(phase, 0.0) + now - since
    return now


def _finish(record: EpisodeRecord, status: GoalStatus, scope: dict[str, str], planner: LLMPlanner) -> None:
    """Goal outcome and what was observed, from the final state."""
    record.all_goals_met = status.all_met
    record.success = status.all_met and record.done_called
    record.task_progress = status.progress
    record.goal_conditions = list(status.conditions)
    record.observed_objects = observed_task_objects(scope, planner.observed_objects())


def _write_step(out: Path, planner: LLMPlanner, action: ActionRecord, save_graph: bool) -> None:
    """Append one line to steps.jsonl (and the step's graph JSON when asked)."""
    trace = planner.trace
    line = {
        "step": action.step, "action": action.model_dump(),
        "scene": trace.scene_text if trace else None, "planning_scene": trace.planning_text if trace else None,
        "robot_room": planner.view.robot_room if planner.view else None,
    }
    with (out / STEPS_FILE).open("a", encoding="utf-8") as f:
        f.write(json.dumps(line) + "\n")
    if save_graph and planner.graph is not None:
        graphs = out / GRAPHS_DIR
        graphs.mkdir(exist_ok=True)
        (graphs / f"step_{action.step:03d}.json").write_text(planner.graph.model_dump_json(), encoding="utf-8")


def _write_outputs(record: EpisodeRecord, planner: LLMPlanner | None, out: Path) -> None:
    """map.png (when the world was built) and episode.json (last, with final timings)."""
    if planner is not None and planner.body is not None:
        from more_agent.viz.trajectory import save_trajectory_map

        try:
            save_trajectory_map(planner.body.world, record.trajectory, out / MAP_FILE,
                                title=f"{record.task} ({record.scene}, {record.planner})")
        except Exception as e:  # noqa: BLE001 - a failed picture must not lose the record or change its outcome
            log.warning("could not draw %s: %s: %s", out / MAP_FILE, type(e).__name__, e)
    (out / EPISODE_FILE).write_text(record.model_dump_json(indent=2) + "\n", encoding="utf-8")
