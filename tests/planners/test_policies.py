"""Subpolicies on a real (small) instantiated task: low-level motion, map growth, magic actions, feedback."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from more_agent.mapping import FREE, OCCUPIED, UNKNOWN
from more_agent.planners.policies import (
    Embodiment,
    agent_nav_grid,
    explore,
    go_to_and,
    navigate,
    path_to_nearest,
    pick_target,
)
from more_agent.planners.policies.embodiment import PolicyConfig
from more_agent.planners.policies.skills import (
    RETRACE_M,
    STEP_AWAY_M,
    back_out,
    explore_frontiers,
    place_on_floor,
    plan_path,
    step_away,
    way_back,
)
from more_agent.records import FailureReason
from more_agent.robot_spec import ROBOT
from more_agent.scene_graph import ObjectNode, OccupancyMap, SceneGraph
from more_agent.sim.env import SimRobot
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.motion import clearance, obstacle_boxes
from more_agent.sim.scene import load_scene
from tests.sim.test_navgrid import labelled, two_room_world

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


def fresh() -> tuple[TaskInstance, Embodiment, SceneGraph]:
    """A kitchen task instance after the initial full turn, and its scene graph (the robot starts in the kitchen)."""
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0, start="task-room")
    body = Embodiment(SimRobot(inst.world, labels=inst.labels))
    body.look_around()
    return inst, body, body.build()


def oil_in_view(body: Embodiment, graph: SceneGraph) -> tuple[SceneGraph, ObjectNode]:
    """The scene graph once the robot has seen the cooking oil, which lies low in a paper bag: the
    camera sees it from beside the bag, turning (never within 0.95 m, the floor it cannot see)."""
    bag = next(o for o in graph.objects.values() if o.category == "paper_bag")
    assert navigate(body, graph, bag).ok
    body.look_around()
    graph = body.build()
    return graph, next(o for o in graph.objects.values() if o.category == "bottle_of_cooking_oil")


@pytest.fixture(scope="module")
def looked_around() -> tuple[TaskInstance, Embodiment, SceneGraph]:
    """``fresh()`` shared by the tests that do not move the robot."""
    return fresh()


def test_look_around_is_a_full_turn_of_low_level_steps(
    looked_around: tuple[TaskInstance, Embodiment, SceneGraph],
) -> None:
    inst, body, graph = looked_around
    assert body.low_level_steps == 11  # 360 deg in turns of at most 35 deg
    assert graph.objects and "fridge A" in graph.objects and inst.world.get("fridge_0").instance_id in body.observed
    assert graph.robot.region_id in graph.regions


def test_agent_grid_keeps_clear_of_obstacles_and_unknown() -> None:
    grid = np.full((20, 10), FREE)
    grid[10, :] = OCCUPIED
    grid[:, 0] = 0  # unknown column
    nav = agent_nav_grid(OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1), inflation_m=0.25)
    free = nav.free
    assert not free[:, 0].any() and not free[8:13, :].any() and free[15, 5] and free[5, 5]
    path, index = path_to_nearest(nav, (0.35, 0.35), [(1.55, 0.55), (0.85, 0.65)], snap_m=0.5)
    assert index == 1 and path.found  # the nearer goal lies beyond the wall: unreachable
    assert math.dist(path.waypoints[0], (0.35, 0.35)) < 1e-9 and math.dist(path.waypoints[-1], (0.85, 0.65)) < 0.1


def test_navigate_drives_with_low_level_moves_and_faces_the_object() -> None:
    inst, body, graph = fresh()
    target = graph.objects["breakfast_table A"]
    before, start = body.low_level_steps, body.xy
    result = navigate(body, graph, target)
    assert result.ok, result.feedback
    assert result.low_level_steps == body.low_level_steps - before > 0
    assert len(body.trajectory) > 1 and body.xy != start
    heading = math.atan2(target.position[1] - body.xy[1], target.position[0] - body.xy[0])
    assert abs(math.remainder(heading - inst.world.robot.yaw, 2 * math.pi)) < 0.05


def test_go_to_and_feedback_for_failed_preconditions() -> None:
    inst, body, graph = fresh()
    cabinet = graph.objects["bottom_cabinet A"]
    graph, item = oil_in_view(body, graph)
    assert go_to_and(body, graph, "place_inside", cabinet).feedback == "hand is empty"
    grasped = go_to_and(body, graph, "grasp", item)
    assert grasped.ok, grasped.feedback
    assert inst.world.robot.held == "bottle__of__cooking_oil_1"
    full = go_to_and(body, graph, "open", cabinet)
    assert not full.ok and full.reason is FailureReason.HAND_FULL and "hand is full" in full.feedback
    closed = go_to_and(body, graph, "place_inside", cabinet)
    assert not closed.ok and closed.feedback == "must open bottom_cabinet A first"
    graph = body.build()
    assert graph.held_object is not None and graph.held_object.id == "bottle_of_cooking_oil A"


def test_explore_reaches_a_frontier_then_reports_none_left() -> None:
    inst, body, graph = fresh()
    region = graph.robot.region_id
    assert region is not None and graph.frontiers(region)
    first = explore(body, graph, region, "kitchen_0")
    assert first.low_level_steps > 11 and len(body.visited_frontiers) == 1
    for _ in range(12):
        result = explore(body, body.build(), region, "kitchen_0")
        if not result.ok and result.feedback == "no frontier left in kitchen_0":
            break
    else:
        pytest.fail("explore never ran out of frontiers")
    assert result.reason is FailureReason.INVALID_TARGET and result.low_level_steps == 0


def test_explore_looks_from_the_nearest_reachable_spot_when_no_path_leads_to_a_frontier() -> None:
    """A frontier no path leads to is looked at from the reachable spot nearest it within sensor range
    (hoe_weeds seed 1 saw the playroom only as a strip through a door, too thin for the base, and gave up)."""
    _, body, graph = fresh()
    graph, beyond = _with_strip(graph, 2.5)
    before = body.low_level_steps
    result = explore_frontiers(body, graph, [beyond], "kitchen_0")
    assert result.ok, result.feedback
    assert math.dist(body.xy, beyond) <= body.builder.config.max_range_m
    assert result.low_level_steps == body.low_level_steps - before >= 11  # drove there, then a full turn
    assert body.visited_frontiers == [beyond]


def _with_strip(graph: SceneGraph, length_m: float) -> tuple[SceneGraph, tuple[float, float]]:
    """``graph`` with a strip of floor one cell wide seen running ``length_m`` east from the map's
    easternmost free cell (floor glimpsed through a door, too thin for the base), and the strip's end."""
    occupancy = graph.occupancy
    assert occupancy is not None
    free = np.argwhere(occupancy.grid == FREE)
    ix, iy = free[np.argmax(free[:, 0])]
    end = ix + round(length_m / occupancy.resolution_m)
    grid = np.array(occupancy.grid)
    assert end < grid.shape[0]
    grid[ix : end + 1, iy] = FREE
    strip = occupancy.model_copy(update={"grid": grid})
    x, y = occupancy.frame.xy_of((end, iy))
    return graph.model_copy(update={"occupancy": strip}), (float(x), float(y))


def test_goals_snap_to_a_spot_in_sight_of_them() -> None:
    """explore()'s frontiers snap to a spot that sees them: the straight line between them crosses floor seen
    free, not the wall the camera has not mapped yet (bringing_newspaper_in seed 3 stood half a metre from a
    frontier seen through a door, on this side of the wall, looked around, and counted it explored)."""
    grid = np.full((40, 30), FREE)  # [ix, iy], 0.1 m cells
    grid[20, :] = UNKNOWN  # a wall the camera has not seen, at x = 2.0-2.1 m ...
    grid[20, 6:9] = FREE  # ... but for a door, the floor beyond seen through it ...
    grid[20, [5, 9]] = OCCUPIED  # ... between jambs narrower than the base's clearance
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    nav = agent_nav_grid(occupancy, inflation_m=0.25)
    start, goal = (0.55, 0.55), (2.45, 1.25)
    near = path_to_nearest(nav, start, [goal], snap_m=1.5)[0].waypoints[-1]
    assert near[0] < 2.0 and abs(near[1] - goal[1]) < 0.1  # straight across the wall
    seeing = path_to_nearest(nav, start, [goal], snap_m=1.5, sight=grid == FREE)[0].waypoints[-1]
    line = occupancy.frame.cell_of(np.linspace(seeing, goal, 40))
    assert (grid[line[:, 0], line[:, 1]] == FREE).all() and math.dist(seeing, goal) <= 1.5
    assert path_to_nearest(nav, start, [goal], snap_m=0.8, sight=grid == FREE)[0].waypoints[-1] == near  # none so near


def test_pick_target_prefers_what_the_skill_can_act_on(
    looked_around: tuple[TaskInstance, Embodiment, SceneGraph],
) -> None:
    _, body, graph = looked_around
    opened = graph.objects["fridge A"].model_copy(update={"id": "fridge Z", "label": "fridge Z", "open": True})
    g = graph.model_copy(update={"objects": {**graph.objects, "fridge Z": opened}})
    assert pick_target(g, ["fridge A", "fridge Z"], "go_to_and_close", body.xy).id == "fridge Z"
    assert pick_target(g, ["fridge A", "fridge Z"], "go_to_and_open", body.xy).id == "fridge A"
    assert pick_target(g, ["unicorn A"], "navigate", body.xy) is None


def test_agent_grid_blind_ring_bumps_and_goals_in_the_robots_component() -> None:
    grid = np.full((40, 20), FREE)  # [ix, iy], 0.1 m cells
    grid[8:13, 8:13] = 0  # the unseen spot under the robot at (1.05, 1.05)
    grid[25, :] = OCCUPIED  # a wall at x = 2.5 m, free space beyond it
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    blind = agent_nav_grid(occupancy, inflation_m=0.25)
    assert not blind.is_free(1.05, 1.05)  # without the ring the robot stands in a hole
    ring = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=[(1.05, 1.05)], blind_radius_m=0.5)
    assert ring.is_free(1.05, 1.05)
    path, index = path_to_nearest(ring, (1.05, 1.05), [(2.9, 1.0)], snap_m=1.0)
    assert index == 0 and path.waypoints[-1][0] < 2.5  # snapped to this side of the wall, not beyond it
    bumped = agent_nav_grid(
        occupancy, inflation_m=0.25, stood_xy=[(1.05, 1.05)], blind_radius_m=0.5, bumped_xy=[(1.6, 1.05)]
    )
    assert ring.is_free(1.6, 1.05) and not bumped.is_free(1.6, 1.05) and not bumped.is_free(1.45, 1.05)


def test_the_robot_leaves_a_nook_of_its_map_the_way_it_came() -> None:
    grid = np.full((40, 20), FREE)  # [ix, iy], 0.1 m cells; open floor at x < 2 m
    grid[20:, :] = OCCUPIED
    grid[20:31, 9:13] = FREE  # a slot 0.4 m wide: all of it within the 0.25 m inflation
    grid[31:38, 7:15] = FREE  # a nook at its end, wide enough for free cells of its own
    path = [(1.05 + 0.075 * k, 1.05) for k in range(33)]  # driven in by a magic action's final approach
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    sealed = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=path)
    assert path_to_nearest(sealed, path[-1], [(0.5, 0.5)], snap_m=0.5)[1] is None  # the nook is an island of the map
    nav = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=path, retrace=True)
    assert nav.is_free(3.45, 1.05) and not nav.is_free(2.55, 0.95)  # the slot is free only along the path
    result, index = path_to_nearest(nav, path[-1], [(0.5, 0.5)], snap_m=0.5)
    assert index == 0 and result.found
    grid[25, 10] = OCCUPIED  # something put down in the slot since: the way back is closed
    blocked = agent_nav_grid(
        OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1), inflation_m=0.25, stood_xy=path, retrace=True
    )
    assert path_to_nearest(blocked, path[-1], [(0.5, 0.5)], snap_m=0.5)[1] is None


class DrivenBody:
    """What ``back_out`` reads of an Embodiment, and the ways it is told to drive."""

    def __init__(self, trajectory: list[tuple[float, float]]) -> None:
        self.config = PolicyConfig(plan_inflation_m=0.25, blind_radius_m=0.0)
        self.trajectory, self.bumps = trajectory, []
        self.driven: list[list[tuple[float, float]]] = []

    @property
    def xy(self) -> tuple[float, float]:
        return self.trajectory[-1]

    def follow(self, waypoints: list[tuple[float, float]]) -> bool:
        self.driven.append(waypoints)
        return True


def test_a_robot_blocked_in_a_slot_backs_out_through_the_exact_positions_it_came_by() -> None:
    """A final approach left the base in a slot narrower than the map's clearance (Beechwood's car
    beside the fence; a bed and a wall, 7 m deep): it drives back through the positions it held, not cell
    centres, to the first with full clearance; standing with full clearance, or with none within
    ``RETRACE_M``, it does not."""
    grid = np.full((110, 20), FREE)  # [ix, iy], 0.1 m cells; open floor at x < 2 m
    grid[20:, :] = OCCUPIED
    grid[20:, 9:13] = FREE  # a slot 0.4 m wide: all of it within the 0.25 m inflation
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    way_in = [(1.0 + 0.07 * k, 1.03 + 0.001 * k) for k in range(30)]
    body = DrivenBody(list(way_in))
    assert back_out(body, occupancy)  # type: ignore[arg-type]
    (driven,) = body.driven
    free = agent_nav_grid(occupancy, inflation_m=0.25)
    assert driven == [way_in[-1], *way_in[::-1][1 : len(driven)]]  # exactly the positions held, backwards
    assert free.is_free(*driven[-1]) and not any(free.is_free(*xy) for xy in driven[:-1])
    outside = DrivenBody(way_in[:3])
    assert not back_out(outside, occupancy) and not outside.driven  # type: ignore[arg-type]
    slot = [(1.0 + 0.07 * k, 1.03) for k in range(115)]  # to x = 9 m: 7 m of it in the slot
    body = DrivenBody(list(slot))
    assert back_out(body, occupancy)  # type: ignore[arg-type]
    assert free.is_free(*body.driven[0][-1]) and body.driven[0][-1][0] < 2.0
    deep = [(2.1 + 0.07 * k, 1.03) for k in range(int(RETRACE_M / 0.07) + 5)]
    assert not back_out(DrivenBody(deep), occupancy)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("gap", "towards"),
    [
        ((0.197 / math.sqrt(2), 0.197 / math.sqrt(2)), (7.0, 1.0)),  # off a corner, driving at it
        ((-0.3, 0.206), (6.0, 2.3)),  # above an edge, driving along it and a little towards it
    ],
)
def test_a_blocked_robot_its_map_shows_clear_steps_straight_back_from_what_it_met(
    gap: tuple[float, float], towards: tuple[float, float]
) -> None:
    """A final approach can leave the base nearer furniture than its radius, or just outside it, where the
    agent's map shows full clearance (putting_shopping_away seed 6: 0.197 m from a stove's corner), and every
    path drawn from there is refused at its first move. After such a refusal the robot backs straight away
    from what it met, which the world allows and which gains clearance; with nothing met it does not move."""
    world = two_room_world()
    corner = np.array([8.25, 2.45])  # the table's corner; its top edge runs west from here
    world.set_robot_pose(*(corner + gap), 0.0)
    body = Embodiment(SimRobot(world, labels=labelled(world)))
    boxes = obstacle_boxes(world)
    start = body.xy
    before = clearance(boxes, *start)
    assert before == pytest.approx(math.hypot(*gap) if gap[0] > 0 else gap[1]) and before < ROBOT.radius_m + 0.01
    assert not step_away(body) and body.xy == start  # nothing met
    assert not body.follow([start, towards]) and body.xy == start  # refused at its first move
    assert step_away(body)
    assert math.dist(body.xy, start) == pytest.approx(STEP_AWAY_M) and clearance(boxes, *body.xy) > before


def test_a_robot_its_map_walls_in_retraces_the_exact_way_it_drove_in() -> None:
    """A final approach drove the base over items on the floor (the world's base meets only furniture
    and walls): its map shows them across its way in, and no path on the map leads out. The way back
    runs backwards through the exact positions it held to the first from which the map leads on; none
    when the goal is out of reach from everywhere it drove, or the way in is longer than ``RETRACE_M``."""
    grid = np.full((60, 20), FREE)  # [ix, iy], 0.1 m cells: one corridor, open floor
    grid[30:33, :] = OCCUPIED  # items across the corridor, mapped once the base had driven over them
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    way_in = [(1.0 + 0.075 * k, 1.03) for k in range(60)]  # from x = 1 m across the items to x = 5.4 m
    body = DrivenBody(list(way_in))
    goal = [(0.5, 1.0)]
    sealed = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=way_in, retrace=True)
    assert path_to_nearest(sealed, body.xy, goal, snap_m=0.5)[1] is None  # its own map seals it in
    way = way_back(body, occupancy, goal, 0.5)  # type: ignore[arg-type]
    assert way is not None and way == [way_in[-1], *way_in[::-1][1 : len(way)]]  # the positions held, backwards
    assert sealed.is_free(*way[-1]) and way[-1][0] < 3.0 <= way[-2][0]  # the first position past the items
    assert way_back(body, occupancy, [(5.5, 1.0)], 0.5) is None  # type: ignore[arg-type]  # reachable: no way back
    assert way_back(body, occupancy, [(1.0, 5.0)], 0.5) is None  # type: ignore[arg-type]  # out of reach anyway
    long_way = [(1.0 + 0.075 * k, 1.03) for k in range(-int(RETRACE_M / 0.075) - 40, 60)]
    far = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=long_way, retrace=True)
    assert path_to_nearest(far, long_way[-1], goal, snap_m=0.5)[1] is None
    assert way_back(DrivenBody(long_way), occupancy, [(-RETRACE_M, 1.0)], 0.5) is None  # type: ignore[arg-type]


def test_the_way_back_does_not_drive_again_a_loop_the_way_in_made() -> None:
    """A way in that went into a nook and came back (a final approach to a counter, then retraced) passes
    the same spots twice; the world's base may leave such a nook but not re-enter it. The way back cuts
    the loop: from the spot where the excursion began it goes on backwards, never into the nook."""
    grid = np.full((60, 30), FREE)  # [ix, iy], 0.1 m cells
    grid[30:33, :] = OCCUPIED  # items across the way in, mapped once the base had driven over them
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    way_in = [(1.0 + 0.075 * k, 1.03) for k in range(60)]
    nook = [(way_in[-1][0], 1.03 + 0.075 * k) for k in range(1, 11)]
    body = DrivenBody([*way_in, *nook, *nook[-2::-1], way_in[-1], (way_in[-1][0] + 0.075, 1.03)])
    way = way_back(body, occupancy, [(0.5, 1.0)], 0.5)  # type: ignore[arg-type]
    assert way is not None and way[-1][0] < 3.0
    assert all(y < 1.04 for _, y in way)  # never into the nook
    assert way[1:] == way_in[::-1][: len(way) - 1]  # then the positions held on the way in, backwards


def test_a_gap_the_base_fits_through_is_not_closed_by_the_planning_margin() -> None:
    """A doorway 0.45 m wide on the map: the base (0.2 m radius) fits, the full clearance (0.25 m) does
    not. Paths keep the full clearance where they can and fall back to the base's own radius only when
    no goal is reachable otherwise; a gap narrower than the base stays closed."""
    grid = np.full((80, 40), FREE)  # [ix, iy], 0.05 m cells
    grid[38:42, :] = OCCUPIED  # a wall at x = 1.9..2.1 m
    grid[38:42, 10:19] = FREE  # a doorway 0.45 m wide (y = 0.5..0.95 m)
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.05)
    body = DrivenBody([(1.0, 0.725)])
    assert path_to_nearest(agent_nav_grid(occupancy, inflation_m=0.25), body.xy, [(3.0, 0.725)], snap_m=0.3)[1] is None
    path, index = plan_path(body, occupancy, [(3.0, 0.725)], 0.3)  # type: ignore[arg-type]
    assert index == 0 and path.found and path.waypoints[-1][0] > 2.5
    grid[38:42, 25:40] = FREE  # a wide opening too (y = 1.25..2 m): the path keeps the full clearance through it
    wide = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.05)
    path, index = plan_path(body, wide, [(3.0, 0.725)], 0.3)  # type: ignore[arg-type]
    crossing = next((a, b) for a, b in zip(path.waypoints, path.waypoints[1:], strict=False) if a[0] < 2.0 <= b[0])
    (xa, ya), (xb, yb) = crossing
    assert index == 0 and ya + (yb - ya) * (2.0 - xa) / (xb - xa) > 1.25 + 0.25
    grid[38:42, 10:40] = OCCUPIED
    grid[38:42, 11:18] = FREE  # 0.35 m: narrower than the base
    narrow = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.05)
    assert plan_path(body, narrow, [(3.0, 0.725)], 0.3)[1] is None  # type: ignore[arg-type]


def test_the_graph_shows_the_hand_empty_right_after_a_floor_placement() -> None:
    _, body, graph = fresh()
    graph, item = oil_in_view(body, graph)
    assert go_to_and(body, graph, "grasp", item).ok
    graph = body.build()
    assert graph.held_object is not None and graph.held_object.id == item.id
    result = place_on_floor(body, graph, None, "kitchen_0")
    assert result.ok, result.feedback
    after = body.build()  # no move since: only the frame the placement took can tell
    assert after.held_object is None and item.id in after.objects


def test_the_robot_can_drive_back_along_a_magic_actions_approach() -> None:
    # A go-to-and-act approach adds only its waypoints to the trajectory, metres apart, through space
    # the map never saw: the robot stood on every cell between them, so it can drive back that way.
    grid = np.full((30, 30), 0)  # all unknown
    occupancy = OccupancyMap(grid=grid, origin_xy=(0.0, 0.0), resolution_m=0.1)
    jump = [(0.35, 0.35), (2.55, 0.35), (2.55, 2.55)]
    nav = agent_nav_grid(occupancy, inflation_m=0.25, stood_xy=jump, retrace=True)
    path, index = path_to_nearest(nav, jump[-1], [jump[0]], snap_m=0.2)
    assert index == 0 and path.found and path.length_m == pytest.approx(4.4, abs=0.2)


def test_a_region_is_typed_again_once_it_shows_twice_the_categories_it_was_typed_on() -> None:
    """A garden first seen from its patio (a sofa, pillows) is typed a living room; the trees and bushes
    seen later must reach the room classifier, else a car is never looked for there."""
    _, body, _ = fresh()
    asked: list[set[str]] = []

    def label(graph: SceneGraph) -> dict[str, str]:
        unlabelled = {rid for rid, r in graph.regions.items() if r.room_label is None}
        asked.append(unlabelled)
        return {rid: f"room{len(asked)}" for rid in unlabelled}

    first = body.step_graph(label)
    rid = first.robot.region_id
    assert rid is not None and rid in asked[0] and first.regions[rid].room_label == "room1"
    shows = len({o.category for o in first.objects_in(rid) if o.category != "door"})
    assert shows >= 2
    body.step_graph(label)
    assert rid not in asked[1]  # nothing new seen: the label stays
    body.typed_on[rid] = shows // 2  # as if typed when it showed half of what it shows now
    again = body.step_graph(label)
    assert rid in asked[2] and again.regions[rid].room_label == "room3"
    assert body.step_graph(label).regions[rid].room_label == "room3"  # kept by the builder, not asked again
    assert rid not in asked[3]


def test_within_answers_like_the_whole_grids_distance_transform() -> None:
    """The cropped distance test behind agent_nav_grid's inflation and blind radius gives the whole
    grid's transform's answer on every cell that asks (random grids, radii, a map with unknown rim)."""
    from scipy import ndimage

    from more_agent.planners.policies.navigation import _within

    rng = np.random.default_rng(0)
    for trial in range(200):
        grid = rng.choice([0, FREE, OCCUPIED], size=tuple(rng.integers(5, 60, 2)), p=[0.5, 0.4, 0.1])
        grid[: grid.shape[0] // 3] = 0  # an unknown rim, as a growing map has
        radius = float(rng.uniform(0.05, 0.6))
        known, occupied = grid == FREE, grid == OCCUPIED
        whole = ndimage.distance_transform_edt(~occupied) * 0.075 > radius
        cropped = ~_within(occupied, radius, 0.075, around=known if occupied.any() else None)
        assert np.array_equal(known & whole, known & cropped), trial


def test_what_opening_reveals_joins_the_map_unseen() -> None:
    """The contents of what the robot opened (``Observation.revealed``) are in its scene graph and count as
    observed though no frame showed them: the camera looks away from the fridge."""
    world = two_room_world()
    labels = InstanceLabels()
    labels.reserve(world.get("fridge_0"))
    body = Embodiment(SimRobot(world, labels=labels))
    body.start()
    assert body.act("open", "fridge A").ok
    x, y, yaw = body.robot.pose
    world.set_robot_pose(x, y, yaw + math.pi)
    body.sense(acted_on=("fridge A",))
    apple = body.build().objects["apple A"]
    assert apple.category == "apple" and world.get("apple_0").instance_id in body.observed
    assert np.allclose(apple.position, world.get("apple_0").center, atol=0.05)
