"""The paper's subpolicies (Sec. III-C): explore(room), navigate(room, object), go_to_and_<verb>(room, object).

Each takes the scene graph of the current step and the names the planner used, drives the robot
with low-level moves on the agent's own map (fusing the frames it sees on the way) and returns an
:class:`~more_agent.robot.ActionResult` whose ``feedback`` is what the planner reads next:
a success flag plus a simple reason ("hand is full", "must open fridge A first", "no frontier left
in kitchen_0", "unknown object"). ``go_to_and_<verb>`` drives to the Voronoi node closest to the
object, then runs the magic action on the world object the label resolves to; that action makes
the final approach on a circle around the object when the node is out of reach (paper S.3).

Planners run a decided skill with :func:`run_skill`, which looks the skill up in the table
(:data:`more_agent.skills.SKILLS`) and calls the subpolicy bound to it in :data:`SUBPOLICIES`.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Iterator, Sequence

import numpy as np

from more_agent.mapping import FREE
from more_agent.planners.policies.embodiment import Embodiment
from more_agent.planners.policies.navigation import agent_nav_grid, object_goal, path_to_nearest
from more_agent.planners.targets import Area, Target, Unresolved
from more_agent.records import FailureReason
from more_agent.robot import XY, ActionResult
from more_agent.robot_spec import ROBOT
from more_agent.scene_graph import ObjectNode, OccupancyMap, SceneGraph
from more_agent.sim.paths import NavGrid, PathResult
from more_agent.skills import Skill, Subpolicy, skill_named


def _fail(reason: FailureReason, feedback: str, steps: int = 0) -> ActionResult:
    return ActionResult(ok=False, reason=reason, feedback=feedback, low_level_steps=steps)


def _drive(
    body: Embodiment, graph: SceneGraph, goals: Sequence[XY], snap_m: float | None = None, *, in_sight: bool = False
) -> tuple[bool, int | None, str]:
    """Drive to the nearest reachable goal on the agent's map (goals off it snapped within ``snap_m``,
    default ``goal_snap_m``; with ``in_sight``, to a spot from which the straight line to the goal crosses
    only floor seen free where one lies that near, :func:`~.navigation.snap_goals`), replanning on the
    updated map when a move is blocked. Returns (reached, goal index, failure feedback)."""
    cfg = body.config
    snap_m = cfg.goal_snap_m if snap_m is None else snap_m
    occupancy, retraced = graph.occupancy, False
    for _ in range(cfg.max_replans + 1):
        if occupancy is None:
            return False, None, "no map yet"
        path, index = plan_path(body, occupancy, goals, snap_m, in_sight=in_sight)
        if index is None:  # once per drive: a way back walked again would lead into the nook again
            way = None if retraced else way_back(body, occupancy, goals, snap_m, in_sight=in_sight)
            if way is None:
                return False, None, "no path on the map"
            retraced = True
            if not body.follow(way):
                return False, None, "the way back is blocked"
            occupancy = body.build().occupancy
            continue
        if body.follow(path.waypoints):
            return True, index, ""
        occupancy = body.build().occupancy
        if occupancy is not None and (back_out(body, occupancy) or step_away(body)):
            occupancy = body.build().occupancy
    return False, None, "the way is blocked"


RETRACE_M = 12.0
"""How far back along its own way the robot retraces, at most, in ``back_out`` and ``way_back`` alike: a
slot can run deep (along a bed in Wainscott_0_garden's bedroom, full clearance lay over 4 m back)."""


def back_out(body: Embodiment, occupancy: OccupancyMap) -> bool:
    """After a blocked move, drive back along the robot's own way in, through the exact positions it
    held (each segment was driven before), to the last one with the full clearance of the agent's map:
    a final approach can leave the base in a slot narrower than that clearance (between a car and a
    fence), where paths through grid-cell centres graze what the exact way in missed, every move
    blocked. False when the robot stands with full clearance, none lies within ``RETRACE_M``, or the
    way back is blocked too."""
    grid = _nav_grid(body, occupancy)
    if grid.is_free(*body.xy):
        return False
    way = next((w for w in _ways_back(body, RETRACE_M) if grid.is_free(*w[-1])), None)
    return way is not None and body.follow(way)


STEP_AWAY_M = 0.15
"""How far the robot backs straight away from what a blocked move met (:func:`step_away`)."""


def step_away(body: Embodiment) -> bool:
    """After a blocked move that :func:`back_out` did not undo (mostly: the agent's map shows full clearance
    where the robot stands), back ``STEP_AWAY_M`` straight away from what the last blocked move met (the last
    bump, ahead on its heading). The map judges clearance by cell, and a final approach (whose exact way the map
    does not hold) can leave the base nearer furniture than its radius where the map shows it clear; the world
    then allows only moves that gain clearance, and every path the planner drew from there led past the corner
    and was blocked at its first move (putting_shopping_away seed 6: all 24 remaining steps failed 0.197 m from
    a stove). The nearest cell of the map is no guide: items on the floor, which the base drives over, show
    there as obstacles. The blocked move brought the base nearer a box, and the distance to a box is convex
    along a line, so the move straight back gains clearance from it. False when nothing was met or the step
    back is blocked too."""
    if not body.bumps:
        return False
    (x, y), (bx, by) = body.xy, body.bumps[-1]  # the bump lies a step and the radius ahead: never on the robot
    gap = math.hypot(x - bx, y - by)
    return body.follow([body.xy, (x + STEP_AWAY_M * (x - bx) / gap, y + STEP_AWAY_M * (y - by) / gap)])


def way_back(
    body: Embodiment, occupancy: OccupancyMap, goals: Sequence[XY], snap_m: float, *, in_sight: bool = False
) -> list[XY] | None:
    """When no path on the agent's map leads to any goal: the robot's own way in, walked backwards through
    the exact positions it held, to the last one (within ``RETRACE_M``) from which a path does lead on.
    The base drove those positions, and the world's base meets only furniture and walls: a final approach
    may have driven it over items on the floor, which its map then shows as obstacles across the way it
    came by (putting_out_condiments seed 2: seven such cells sealed a kitchen). The map keeps them; only
    the exact way driven is trusted through them. None when no position within reach of it leads on.
    ``in_sight`` as in :func:`_drive`."""
    grid = _nav_grid(body, occupancy, retrace=True)
    sight = _sight(occupancy, in_sight)
    parts = grid.components
    here = grid.snap(*body.xy)
    tried = {parts[here] if here is not None else 0, 0}
    for way in _ways_back(body, RETRACE_M):
        part = parts[grid.cell_at(*way[-1])] if grid.is_free(*way[-1]) else 0
        if part in tried:
            continue
        tried.add(part)
        if path_to_nearest(grid, way[-1], goals, snap_m=snap_m, sight=sight)[1] is not None:
            return way
    return None


SAME_SPOT_M = 0.01
"""Positions of the robot's way this close are one spot (a way retraced holds the same positions again)."""


def _ways_back(body: Embodiment, max_m: float) -> Iterator[list[XY]]:
    """Ways back over the positions the robot held, to each earlier one in turn (latest first) that lies
    within ``max_m`` of where it stands: the shortest, along segments it drove, through spots it held.

    A way in that passes a spot twice is a loop the way back need not drive again. A final approach can
    leave the base in a nook the world's base may leave but not re-enter (a move that ends within its
    clearance must gain clearance); walked backwards step by step, a way in that went there and came back
    (to grasp at a counter, then retraced) would lead into the nook again (putting_out_condiments seed 0)."""
    spots, edges, order = _spot_graph([*body.trajectory, body.xy], max_m)
    here = order[0]
    dist, previous = {here: 0.0}, {here: here}
    queue = [(0.0, here)]
    while queue:
        d, node = heapq.heappop(queue)
        if d > dist[node]:
            continue
        for other, length in edges[node].items():
            if d + length < dist.get(other, math.inf) and d + length <= max_m:
                dist[other], previous[other] = d + length, node
                heapq.heappush(queue, (d + length, other))
    for node in order[1:]:
        if node in dist:
            way = [node]
            while way[-1] != here:
                way.append(previous[way[-1]])
            yield [spots[k] for k in reversed(way)]


def _spot_graph(positions: Sequence[XY], max_m: float) -> tuple[list[XY], list[dict[int, float]], list[int]]:
    """Positions within ``max_m`` of the last one merged into spots (``SAME_SPOT_M``): each spot's position
    (its latest), the length of every segment driven between two spots, and the spots latest first, each
    once. A position farther away lies on no way back ``max_m`` long: it is left out, and its segments."""
    spots: list[XY] = []
    by_cell: dict[tuple[int, int], list[int]] = {}
    edges: list[dict[int, float]] = []
    order: list[int] = []
    last: int | None = None
    xy_all = np.asarray(positions, dtype=float)
    near = np.hypot(*(xy_all - xy_all[-1]).T) <= max_m
    for xy, within in zip(reversed(positions), near[::-1].tolist()):
        if not within:
            last = None
            continue
        i, j = math.floor(xy[0] / SAME_SPOT_M), math.floor(xy[1] / SAME_SPOT_M)
        cell = (k for a in (i - 1, i, i + 1) for b in (j - 1, j, j + 1) for k in by_cell.get((a, b), ()))
        node = next((k for k in cell if math.dist(spots[k], xy) <= SAME_SPOT_M), None)
        if node is None:
            node = len(spots)
            spots.append(xy)
            edges.append({})
            by_cell.setdefault((i, j), []).append(node)
            order.append(node)
        if last is not None and last != node:
            edges[last][node] = edges[node][last] = math.dist(spots[last], spots[node])
        last = node
    return spots, edges, order


def plan_path(
    body: Embodiment, occupancy: OccupancyMap, goals: Sequence[XY], snap_m: float, *, in_sight: bool = False
) -> tuple[PathResult, int | None]:
    """Shortest path on the agent's map to the nearest reachable goal; when none is, the same with the
    robot retracing its own path (``agent_nav_grid``'s ``retrace``), then with the clearance of the base
    itself (``ROBOT.radius_m``, the world's rule) rather than the planning margin on top: paths keep the
    full clearance wherever they can, the robot is never sealed in where a final approach left it, and a
    gap the base fits through on the map is not closed by the margin (a gap 0.4-0.5 m wide on the map
    hid the hall of packing_fishing_gear_into_car seed 0). ``in_sight`` as in :func:`_drive`."""
    full = body.config.plan_inflation_m
    sight = _sight(occupancy, in_sight)
    tight = min(full, ROBOT.radius_m)
    for inflation, retrace in ((full, False), (full, True), (tight, True)):
        grid = _nav_grid(body, occupancy, inflation_m=inflation, retrace=retrace)
        path, index = path_to_nearest(grid, body.xy, goals, snap_m=snap_m, sight=sight)
        if index is not None:
            break
    return path, index


def _sight(occupancy: OccupancyMap, in_sight: bool) -> np.ndarray | None:
    """The cells a line of sight crosses on the agent's map (those seen free) when ``in_sight``, else None."""
    return np.asarray(occupancy.grid) == FREE if in_sight else None


def _nav_grid(
    body: Embodiment, occupancy: OccupancyMap, inflation_m: float | None = None, retrace: bool = False
) -> NavGrid:
    """The agent's navigation grid for ``body`` now: its map, the cells it stood on and bumped into, the
    planning margin unless ``inflation_m`` says otherwise."""
    cfg = body.config
    return agent_nav_grid(
        occupancy,
        inflation_m=cfg.plan_inflation_m if inflation_m is None else inflation_m,
        stood_xy=body.trajectory,
        blind_radius_m=cfg.blind_radius_m,
        bumped_xy=body.bumps,
        retrace=retrace,
    )


def explore(body: Embodiment, graph: SceneGraph, region_id: str, room: str) -> ActionResult:
    """Go to the closest frontier of a region not explored before, and look around there."""
    return explore_frontiers(body, graph, graph.frontiers(region_id), room)


def explore_frontiers(body: Embodiment, graph: SceneGraph, candidates: Sequence[XY], room: str) -> ActionResult:
    """Go to the closest of ``candidates`` (frontiers) not explored before, and look around there;
    ``room`` names the area in the feedback. When no path leads to any of them (unknown space seen only
    as a strip through a doorway narrower than the robot's clearance on its map), go to the reachable spot
    nearest one within sensor range and look from there. Either way the spot is one that sees the frontier
    where there is one (:func:`~.navigation.nearest_in_sight`), not the nearest spot behind a wall the camera
    has not mapped: what the look around shows is then what lies beyond."""
    start = body.low_level_steps
    near = body.config.visited_frontier_m
    frontiers = [f for f in candidates if all(math.dist(f, v) > near for v in body.visited_frontiers)]
    if not frontiers:
        return _fail(FailureReason.INVALID_TARGET, f"no frontier left in {room}")
    reached, index, why = _drive(body, graph, frontiers, in_sight=True)
    if index is None:
        reached, index, why = _drive(body, graph, frontiers, snap_m=body.builder.config.max_range_m, in_sight=True)
    if index is not None:
        body.visited_frontiers.append(frontiers[index])
    if not reached:
        if index is None:  # no frontier reachable: do not offer them again
            body.visited_frontiers.extend(frontiers)
        return _fail(
            FailureReason.NOT_REACHABLE,
            f"cannot reach an unexplored area of {room}: {why}",
            body.low_level_steps - start,
        )
    if body.config.look_around_at_frontier:
        body.look_around()
    return ActionResult(ok=True, reason=None, feedback=f"explored {room}", low_level_steps=body.low_level_steps - start)


def navigate(body: Embodiment, graph: SceneGraph, target: ObjectNode) -> ActionResult:
    """Drive to the Voronoi node closest to the object on the agent's map, then face it. When that node
    lies in a part of the map the robot cannot drive to (a gap narrower than its clearance, unknown
    cells between), drive instead to the reachable spot closest to the object within arm's reach
    (``ROBOT.reach_m``) of its centre."""
    start = body.low_level_steps
    if target.held:
        return _fail(FailureReason.INVALID_TARGET, f"already holding {target.label}")
    goal = object_goal(graph, target.id)
    if goal is None:
        return _fail(FailureReason.NOT_REACHABLE, f"cannot reach {target.label}: no map yet")
    reached, index, why = _drive(body, graph, [goal])
    if index is None:  # the node is off the robot's part of the map: any spot within arm's reach will do
        reached, _, why = _drive(body, graph, [target.position[:2]], snap_m=ROBOT.reach_m)
    if not reached:
        return _fail(FailureReason.NOT_REACHABLE, f"cannot reach {target.label}: {why}", body.low_level_steps - start)
    body.face(target.position[:2])
    body.look_down_at(target.position[:2])  # its top and inside, below the driving pitch from close by
    return ActionResult(
        ok=True, reason=None, feedback=f"reached {target.label}", low_level_steps=body.low_level_steps - start
    )


def go_to_and(body: Embodiment, graph: SceneGraph, verb: str, target: ObjectNode) -> ActionResult:
    """navigate() unless the object is within reach, then the magic action on the world object."""
    start = body.low_level_steps
    distance = body.robot.reach_distance(target.label)
    if distance is None:
        return _fail(FailureReason.UNKNOWN_OBJECT, f"unknown object {target.label}")
    if not target.held and distance > ROBOT.reach_m:
        moved = navigate(body, graph, target)
        if not moved.ok:
            return moved
    elif not target.held:
        body.look_down_at(target.position[:2])  # what lies in or on it, before it is acted on
    result = body.act(verb, target.label)  # the robot's go-to-and-act: the final approach when still out of reach
    body.sense_after(result)
    if result.ok:  # what opening / placing revealed; the new state even out of view
        body.look_down_at(target.position[:2], acted_on=(target.label,))
    return ActionResult(
        ok=result.ok,
        reason=result.reason,
        feedback=result.feedback,
        low_level_steps=body.low_level_steps - start,
        blocking=result.blocking,
    )


def pick_target(graph: SceneGraph, ids: Sequence[str], skill: str, robot_xy: XY) -> ObjectNode | None:
    """The object a (possibly class-level) name means: among the candidates, those the skill can act
    on by their observed state (open needs closed, close needs open), nearest to the robot first."""
    nodes = [graph.objects[i] for i in ids if i in graph.objects]
    want_open = {"go_to_and_open": False, "go_to_and_close": True}.get(skill)
    suitable = [n for n in nodes if want_open is None or n.open is want_open] or nodes
    if not suitable:
        return None
    return min(suitable, key=lambda n: (math.dist(n.position[:2], robot_xy), n.id))


def place_on_floor(body: Embodiment, graph: SceneGraph, region_id: str | None, room: str) -> ActionResult:
    """Put the held item on the floor: where the robot stands, or in ``region_id`` after driving to the
    region's navigation node closest to its centre (floors are the rooms themselves, not graph objects)."""
    start = body.low_level_steps
    held = body.robot.held
    if held is None:
        return _fail(FailureReason.HAND_EMPTY, "hand is empty")
    if region_id is not None and graph.robot.region_id != region_id:
        region = graph.regions[region_id]
        nodes = graph.nav.node_xy[region.nav_nodes]
        if len(nodes) == 0:
            return _fail(FailureReason.NOT_REACHABLE, f"cannot reach {room}: no map yet")
        centre = min(((float(x), float(y)) for x, y in nodes), key=lambda p: math.dist(p, region.centroid))
        reached, _, why = _drive(body, graph, [centre])
        if not reached:
            return _fail(FailureReason.NOT_REACHABLE, f"cannot reach {room}: {why}", body.low_level_steps - start)
    floor = body.robot.floor_here()
    if floor is None:
        return _fail(FailureReason.INVALID_TARGET, "no floor here", body.low_level_steps - start)
    result = body.act("place_ontop", floor)
    body.sense_after(result)
    if result.ok:
        body.sense()  # the hand is empty now: without a frame the graph would still show the item held
    feedback = f"placed {_held_label(graph, held)} on the floor of {room}" if result.ok else result.feedback
    return ActionResult(
        ok=result.ok, reason=result.reason, feedback=feedback, low_level_steps=body.low_level_steps - start
    )


def _held_label(graph: SceneGraph, instance_id: int) -> str:
    """What the step's graph calls the held instance ('the item' when it shows none)."""
    return next((o.label for o in graph.objects.values() if o.instance_id == instance_id), "the item")


# -- dispatch through the skill table -----------------------------------------------------------


SubpolicyFn = Callable[[Embodiment, SceneGraph, Skill, Target], ActionResult]
"""A subpolicy as the table dispatches to it: the robot, the step's scene graph, the skill, its target."""


def _explore(body: Embodiment, graph: SceneGraph, skill: Skill, target: Target) -> ActionResult:
    if not isinstance(target, Area):
        return _fail(FailureReason.INVALID_TARGET, f"{skill.name} takes a room")
    if target.frontiers is not None:
        return explore_frontiers(body, graph, target.frontiers, target.name)
    if target.region_id is None:
        return _fail(FailureReason.INVALID_TARGET, f"{skill.name} takes a room")
    return explore(body, graph, target.region_id, target.name)


def _navigate(body: Embodiment, graph: SceneGraph, skill: Skill, target: Target) -> ActionResult:
    if isinstance(target, ObjectNode):
        return navigate(body, graph, target)
    return _cannot(skill, target)


def _go_to_and(body: Embodiment, graph: SceneGraph, skill: Skill, target: Target) -> ActionResult:
    assert skill.world_action is not None
    if isinstance(target, ObjectNode):
        return go_to_and(body, graph, skill.world_action, target)
    if isinstance(target, Area) and skill.world_action == "place_ontop":
        return place_on_floor(body, graph, target.region_id, target.name)
    return _cannot(skill, target)


def _done(body: Embodiment, graph: SceneGraph, skill: Skill, target: Target) -> ActionResult:
    return ActionResult(ok=True, reason=None, feedback="done")


def _cannot(skill: Skill, target: Target) -> ActionResult:
    """The failure of an object skill given an area (only placing on a floor is possible) or nothing."""
    where = f"the floor of {target.name}" if isinstance(target, Area) else "nothing"
    return _fail(FailureReason.INVALID_TARGET, f"cannot {skill.name} {where}")


SUBPOLICIES: dict[Subpolicy, SubpolicyFn] = {
    "explore": _explore,
    "navigate": _navigate,
    "go_to_and": _go_to_and,
    "done": _done,
}
"""The planners' binding of the skill table's subpolicies (:attr:`more_agent.skills.Skill.subpolicy`)
to the functions that run them."""


def run_skill(body: Embodiment, graph: SceneGraph, name: str, target: Target) -> ActionResult:
    """Run the skill ``name`` of the table on ``target`` through its subpolicy (an ``Unresolved`` target
    fails with its reason, running nothing)."""
    if isinstance(target, Unresolved):
        return _fail(target.reason, target.feedback)
    skill = skill_named(name)
    return SUBPOLICIES[skill.subpolicy](body, graph, skill, target)
