"""Print an episode step by step: where the robot stands, what the planner chose and why, what came of it.

    python scripts/trace_episode.py TASK SEED [--planner grounded] [--descriptions named|paper] [--truth]

One line per high-level step: the robot's region (and the room type the planner gives it), the step and
its arguments, the planner's note (the grounded planner's reason, an LLM's reasoning, the oracle's
literal) and the outcome. For the ``grounded`` planner a second line lists the regions with frontiers
left (type, frontier count, distance from the robot): that is where the search may go next. It is the
tool that traces a lost episode to the mechanism that lost it (docs/benchmarks.md). ``--truth`` first
prints where the world put each task object (room, what it lies in or on, metres from the start) and
names the room the robot truly stands in at each step: what no planner is told.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from more_agent.eval.episode import run_episode
from more_agent.planners.base import Planner, Step, make_planner
from more_agent.planners.grounded import GroundedPlanner
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.robot import ActionResult
from more_agent.sim.instantiate import instantiate
from more_agent.sim.world import World

NOTE_CHARS = 160
"""An LLM's reasoning is clipped to this many characters a line."""


def traced(planner: Planner, out: Callable[[str], None] = print, world: World | None = None) -> Planner:
    """``planner`` with its ``decide`` and ``execute`` wrapped to print each step through ``out``; with the
    episode's ``world`` (its rooms never move) each step also names the room the robot truly stands in."""
    decide, execute = planner.decide, planner.execute
    steps = [0]

    def traced_decide() -> Step:
        step = decide()
        out(f"{steps[0]:3d} {where(planner, world):28s} {step.name}({', '.join(step.arguments)})  # {clip(step.note)}")
        if isinstance(planner, GroundedPlanner):
            out(f"    open: {frontier_rooms(planner)}")
        return step

    def traced_execute(action: Step) -> ActionResult:
        result = execute(action)
        out(f"    -> {'ok' if result.ok else 'FAILED'} {clip(result.feedback)}")
        steps[0] += 1
        return result

    planner.decide = traced_decide  # type: ignore[method-assign]
    planner.execute = traced_execute  # type: ignore[method-assign]
    return planner


def where(planner: Planner, world: World | None) -> str:
    """The robot's region and the type the grounded planner gives it ('?' for other planners), and with
    ``world`` the room it truly stands in."""
    if not isinstance(planner, GroundedPlanner) or planner.graph is None:
        return "?"
    region = planner.graph.robot.region_id or "-"
    truly = "" if world is None else f" [{world.room_at(*planner.graph.robot.position)}]"
    return f"{region} ({planner.belief.room_types.get(region, '?')}){truly}"


def frontier_rooms(planner: GroundedPlanner) -> str:
    """The step graph's regions with frontiers: type, count, metres from the robot to the nearest."""
    graph = planner.graph
    if graph is None:
        return ""
    xy = graph.robot.position
    parts = []
    for rid, region in sorted(graph.regions.items()):
        if region.frontiers:
            near = min(math.dist(xy, f) for f in region.frontiers)
            parts.append(f"{rid}:{planner.belief.room_types.get(rid, '?')}x{len(region.frontiers)}@{near:.0f}m")
    return " ".join(parts)


def clip(text: str) -> str:
    """One line of at most ``NOTE_CHARS`` characters."""
    line = " ".join(text.split())
    return line if len(line) <= NOTE_CHARS else line[: NOTE_CHARS - 1] + "…"


def trace(spec: EpisodeSpec, out: Callable[[str], None] = print, world: World | None = None) -> EpisodeRecord:
    """Run ``spec`` with its planner traced through ``out`` (``world``: see :func:`traced`); print and
    return the record's outcome."""
    record = run_episode(spec, planner=traced(make_planner(spec.planner, spec.llm), out, world))
    failure = record.failure.cause if record.failure is not None else "-"
    out(f"success={record.success} steps={record.high_level_steps} failure={failure} error={record.error or '-'}")
    return record


def truth(spec: EpisodeSpec, out: Callable[[str], None] = print) -> World:
    """Print where the world of ``spec`` puts each task object: room, parent, relation, distance from the
    start; return that world."""
    instance = instantiate(
        spec.task, spec.scene, spec.seed, start=spec.start, distractors=spec.distractors, descriptions=spec.descriptions
    )
    world = instance.world
    start = (world.robot.x, world.robot.y)
    out(f"{instance.scene}: {instance.description}")
    for scope, name in sorted(instance.scope.items()):
        obj = world.objects.get(name)
        if obj is not None:
            gap = math.dist(start, obj.center[:2])
            out(f"  {scope:32s} {name:40s} {obj.room} {obj.relation or ''} {obj.parent or ''} {gap:.0f}m")
    return world


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("task")
    parser.add_argument("seed", type=int)
    parser.add_argument("--planner", default="grounded")
    parser.add_argument("--llm", default=None, help="LLM spec for an LLM planner (docs/llm.md)")
    parser.add_argument("--descriptions", default="named", choices=["named", "paper"])
    parser.add_argument("--truth", action="store_true", help="first print where the task's objects are")
    args = parser.parse_args()
    spec = EpisodeSpec(
        task=args.task, seed=args.seed, planner=args.planner, llm=args.llm, descriptions=args.descriptions
    )
    trace(spec, world=truth(spec) if args.truth else None)


if __name__ == "__main__":
    main()
