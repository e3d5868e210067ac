"""Low-level moves: 7.5 cm forward, turns of at most 35 degrees, collisions with walls, doors, furniture."""

from __future__ import annotations

import math

import numpy as np
import pytest

from more_agent.robot_spec import full_turn_angles
from more_agent.sim.motion import MotionFailure, clearance, move_forward, obstacle_boxes, turn
from more_agent.sim.scene import Door, Furniture, Room, Scene, Wall
from more_agent.sim.world import World, WorldObject


def corridor() -> World:
    """A 6 m x 2 m room: a wall across at x = 3 with a closed door at y = 1, a cabinet at the west end,
    a wall cabinet (starting at 1.5 m) at the east end, and an apple on the floor."""
    scene = Scene(
        name="corridor", bounds=(0, 0, 6, 2),
        rooms=[Room(id="corridor_0", type="corridor", bounds=(0, 0, 3, 2)), Room(id="corridor_1", type="corridor", bounds=(3, 0, 6, 2))],
        walls=[Wall(bounds=(2.95, 0, 3.05, 0.5)), Wall(bounds=(2.95, 1.5, 3.05, 2)), Wall(bounds=(2.95, 0.5, 3.05, 1.5), z_min=2.1)],
        doors=[Door(id="door_0", rooms=("corridor_0", "corridor_1"), center=(3, 1), width=1.0, axis="y", open=False)],
        furniture=[
            Furniture(id="bottom_cabinet_0", category="bottom_cabinet", room="corridor_0", center=(0.3, 1, 0.4), size=(0.6, 0.8, 0.8)),
            Furniture(id="wall_cabinet_0", category="wall_cabinet", room="corridor_1", center=(5.8, 1, 1.8), size=(0.4, 0.8, 0.6)),
        ],
    )
    world = World.from_scene(scene)
    world.add(WorldObject(name="apple_0", category="apple", kind="item", center=np.zeros(3), size=np.full(3, 0.08)))
    world.place_on_floor_at("apple_0", "floor_corridor_0", (2.0, 1.0))
    return world


def test_forward_step_is_7_5_cm_and_clipped():
    world = corridor()
    world.set_robot_pose(1.5, 1.0, 0.0)
    res = move_forward(world)
    assert res.ok and world.robot.x == pytest.approx(1.575) and world.robot.y == pytest.approx(1.0)
    res = move_forward(world, 0.5)
    assert res.ok and res.applied == pytest.approx(0.075) and "clipped" in res.feedback
    bad = move_forward(world, -0.1)
    assert not bad.ok and bad.reason is MotionFailure.INVALID_AMOUNT and world.robot.x == pytest.approx(1.65)


def test_turn_is_clipped_to_35_degrees():
    world = corridor()
    world.set_robot_pose(1.5, 1.0, 0.0)
    res = turn(world, math.radians(90))
    assert res.ok and "clipped" in res.feedback and world.robot.yaw == pytest.approx(math.radians(35))
    turn(world, -math.radians(20))
    assert world.robot.yaw == pytest.approx(math.radians(15))
    angles = full_turn_angles()
    assert len(angles) == 11 and sum(angles) == pytest.approx(2 * math.pi) and max(angles) <= math.radians(35)


def drive(world: World, n: int) -> int:
    """Forward moves until blocked (at most n); how many succeeded."""
    for i in range(n):
        if not move_forward(world).ok:
            return i
    return n


def test_closed_door_blocks_and_open_door_lets_through():
    world = corridor()
    world.set_robot_pose(2.0, 1.0, 0.0)
    moved = drive(world, 40)
    assert moved < 40 and world.robot.x < 2.95 - 0.2 + 1e-9  # stopped by the leaf, disc of radius 0.2
    blocked = move_forward(world)
    assert not blocked.ok and blocked.reason is MotionFailure.BLOCKED
    world.set_open("door_0", True)
    assert drive(world, 40) == 40 and world.robot.x > 4.0


def test_furniture_and_walls_block_but_items_and_wall_cabinets_do_not():
    world = corridor()
    world.set_robot_pose(2.5, 1.0, math.pi)  # west, over the apple, into the cabinet
    drive(world, 60)
    assert world.robot.x == pytest.approx(0.6 + 0.2, abs=0.08)
    world.set_robot_pose(2.0, 0.5, -math.pi / 2)  # south wall of the room: scene bounds
    drive(world, 20)
    assert world.robot.y >= 0.0
    world.set_open("door_0", True)
    world.set_robot_pose(5.0, 1.0, 0.0)  # east, under the wall cabinet, to the scene's edge
    drive(world, 20)
    assert world.robot.x > 5.8
    boxes = obstacle_boxes(world)
    assert not any(np.allclose(b, (5.6, 0.6, 6.0, 1.4)) for b in boxes)


def test_clearance_is_signed_and_infinite_without_boxes():
    boxes = np.array([[0.0, 0.0, 1.0, 1.0], [3.0, 0.0, 4.0, 1.0]])
    assert clearance(boxes, 0.5, 0.25) == pytest.approx(-0.25)  # inside: minus the distance to the nearest side
    assert clearance(boxes, 2.0, 2.0) == pytest.approx(math.sqrt(2.0))  # to the nearer box's corner
    assert clearance(np.zeros((0, 4)), 0.0, 0.0) == math.inf


def test_overlapping_robot_may_back_out_but_not_push_in():
    world = corridor()
    world.set_robot_pose(0.75, 1.0, math.pi)  # disc overlaps the cabinet (face at x = 0.6)
    boxes = obstacle_boxes(world)
    assert clearance(boxes, 0.75, 1.0) == pytest.approx(0.15)
    assert not move_forward(world).ok
    turn(world, math.radians(35))
    for _ in range(5):
        turn(world, math.radians(29))
    assert move_forward(world).ok  # now facing east, away from the cabinet
