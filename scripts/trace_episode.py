"""Print an episode step by step: where the robot stands, what the planner chose and why, what came of it.

    python scripts/trace_episode.py TASK SEED [--planner grounded] [--descriptions named|paper] [--truth] [--map OUT.png]

One line per high-level step: the robot's region (and the room type the planner gives it), the step and
its arguments, the planner's note (the grounded planner's reason, an LLM's reasoning, the oracle's
literal) and the outcome. For the ``grounded`` planner a second line lists the regions with frontiers
left (type, frontier count, distance from the robot): that is where the search may go next. It is the
tool that traces a lost episode to the mechanism that lost it (docs/benchmarks.md). ``--truth`` first
prints where the world put each task object (room, what it lies in or on, metres from the start) and
names the room the robot truly stands in at each step: what no planner is told. ``--map OUT.png`` (the
``grounded`` planner) then draws the robot's own occupancy map as the episode left it, its path, where it
stood at each step (numbered), the frontiers left, and where the world put each task object: green once
the robot saw it, red if it never did. A search's blind spots show at a glance (an item behind a tree, a
lawn left for the far end, a checkout's back row).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from more_agent.eval.episode import run_episode
from more_agent.planners.base import Planner, Step, make_planner
from more_agent.planners.grounded import GroundedPlanner
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.robot import ActionResult
from more_agent.sim.instantiate import TaskInstance, instantiate
from more_agent.sim.world import World
from more_agent.viz.graph_plot import draw_occupancy
from more_agent.viz.trajectory import draw_trajectory

NOTE_CHARS = 160
"""An LLM's reasoning is clipped to this many characters a line."""


def traced(
    planner: Planner,
    out: Callable[[str], None] = print,
    world: World | None = None,
    stops: list[tuple[float, float]] | None = None,
) -> Planner:
    """``planner`` with its ``decide`` and ``execute`` wrapped to print each step through ``out``; with the
    episode's ``world`` (its rooms never move) each step also names the room the robot truly stands in.
    ``stops`` collects where the robot stands at each step (the ``grounded`` planner)."""
    decide, execute = planner.decide, planner.execute
    steps = [0]

    def traced_decide() -> Step:
        step = decide()
        out(f"{steps[0]:3d} {where(planner, world):28s} {step.name}({', '.join(step.arguments)})  # {clip(step.note)}")
        if isinstance(planner, GroundedPlanner):
            out(f"    open: {frontier_rooms(planner)}")
            if stops is not None and planner.graph is not None:
                x, y = planner.graph.robot.position[:2]
                stops.append((x, y))
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


def trace(
    spec: EpisodeSpec,
    out: Callable[[str], None] = print,
    world: World | None = None,
    *,
    planner: Planner | None = None,
    stops: list[tuple[float, float]] | None = None,
) -> EpisodeRecord:
    """Run ``spec`` with its planner (or ``planner``) traced through ``out`` (``world``, ``stops``: see
    :func:`traced`); print and return the record's outcome."""
    planner = planner or make_planner(spec.planner, spec.llm)
    record = run_episode(spec, planner=traced(planner, out, world, stops))
    failure = record.failure.cause if record.failure is not None else "-"
    out(f"success={record.success} steps={record.high_level_steps} failure={failure} error={record.error or '-'}")
    return record


def truth(spec: EpisodeSpec, out: Callable[[str], None] = print) -> TaskInstance:
    """Print where the world of ``spec`` puts each task object: room, parent, relation, distance from the
    start; return that task instance (its world, the same every time for the spec)."""
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
    return instance


def draw_map(planner: GroundedPlanner, instance: TaskInstance, stops: list[tuple[float, float]], path: Path) -> None:
    """Write ``path`` (PNG): the robot's occupancy map as the episode left it (``draw_occupancy``), its path,
    where it stood at each step, the frontiers left and the task objects of ``instance`` (instantiated again
    from the episode's spec, so its instance ids are the episode's), green once observed, red if never."""
    graph, body = planner.graph, planner.body
    if graph is None or graph.occupancy is None or body is None:
        raise SystemExit("--map needs an episode of the grounded planner that has sensed")
    fig, ax = plt.subplots(figsize=(10, 10))
    draw_occupancy(ax, graph.occupancy)
    draw_trajectory(ax, body.trajectory, color="tab:blue")
    for k, (x, y) in enumerate(stops):
        ax.plot(x, y, "o", color="tab:purple", ms=4)
        ax.annotate(str(k), (x, y), fontsize=6, color="tab:purple", xytext=(2, 2), textcoords="offset points")
    frontiers = np.array([f for r in graph.regions.values() for f in r.frontiers] or np.empty((0, 2)))
    ax.plot(frontiers[:, 0], frontiers[:, 1], ".", color="tab:cyan", ms=3, label="frontiers left")
    for name in sorted(set(instance.scope.values())):
        obj = instance.world.objects.get(name)
        if obj is None or obj.kind == "floor":
            continue
        colour = "tab:green" if obj.instance_id in body.observed else "tab:red"
        ax.plot(obj.center[0], obj.center[1], "*", color=colour, ms=9)
        ax.annotate(
            name, (obj.center[0], obj.center[1]), fontsize=6, color=colour, xytext=(3, -6), textcoords="offset points"
        )
    ax.set_title(f"{instance.task} in {instance.scene}: the robot's map, stops, and the task objects", fontsize=9)
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=7)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("task")
    parser.add_argument("seed", type=int)
    parser.add_argument("--planner", default="grounded")
    parser.add_argument("--llm", default=None, help="LLM spec for an LLM planner (docs/llm.md)")
    parser.add_argument("--descriptions", default="named", choices=["named", "paper"])
    parser.add_argument("--truth", action="store_true", help="first print where the task's objects are")
    parser.add_argument("--map", type=Path, default=None, help="draw the robot's map and the task objects (PNG)")
    args = parser.parse_args()
    spec = EpisodeSpec(
        task=args.task, seed=args.seed, planner=args.planner, llm=args.llm, descriptions=args.descriptions
    )
    planner = make_planner(spec.planner, spec.llm)
    if args.map and not isinstance(planner, GroundedPlanner):
        parser.error("--map draws the grounded planner's own map")
    instance = truth(spec, print if args.truth else lambda _: None) if args.truth or args.map else None
    stops: list[tuple[float, float]] = []
    trace(spec, world=instance.world if instance and args.truth else None, planner=planner, stops=stops)
    if args.map and instance is not None and isinstance(planner, GroundedPlanner):
        draw_map(planner, instance, stops, args.map)
        print(f"map: {args.map}")


if __name__ == "__main__":
    main()
