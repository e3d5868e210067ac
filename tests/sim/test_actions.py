"""Magic actions: preconditions with typed failure reasons, observability, navigation and step counting."""

from __future__ import annotations

import math

import numpy as np
import pytest

from more_agent.sim.actions import (
    MAX_TURN_RAD,
    REACH_M,
    FailureReason,
    close,
    count_low_level_steps,
    distance_to_footprint,
    go_to_and,
    grasp,
    navigate_to,
    open_,
    place_inside,
    place_ontop,
)
from more_agent.sim.env import SimRobot
from more_agent.sim.labels import InstanceLabels
from tests.sim.test_navgrid import labelled, two_room_world


def test_hidden_item_cannot_be_grasped_until_container_opened():
    world = two_room_world()
    labels = labelled(world)
    assert not world.is_observable("apple_0")
    result = go_to_and(world, "grasp", "apple_0", labels)
    assert not result.ok and result.reason is FailureReason.HIDDEN
    assert "must open fridge A first" in result.feedback
    assert go_to_and(world, "open", "fridge_0", labels).ok
    assert world.is_observable("apple_0")
    assert go_to_and(world, "grasp", "apple_0", labels).ok and world.robot.held == "apple_0"


def test_hand_rules_for_grasp_open_close_and_place():
    world = two_room_world()
    labels = labelled(world)
    assert place_ontop(world, "table_0", labels).reason is FailureReason.HAND_EMPTY
    assert go_to_and(world, "grasp", "box_0", labels).ok
    assert grasp(world, "bowl_0", labels).reason is FailureReason.HAND_FULL
    full = go_to_and(world, "open", "fridge_0", labels)
    assert not full.ok and full.reason is FailureReason.HAND_FULL and full.feedback.startswith("hand is full")
    assert full.path == []  # a doomed action costs no motion
    placed = go_to_and(world, "place_ontop", "table_0", labels)
    assert placed.ok and world.get("box_0").parent == "table_0" and world.robot.held is None


def test_open_close_preconditions():
    world = two_room_world()
    labels = labelled(world)
    assert go_to_and(world, "open", "table_0", labels).reason is FailureReason.NOT_OPENABLE
    assert go_to_and(world, "close", "fridge_0", labels).reason is FailureReason.ALREADY_CLOSED
    assert go_to_and(world, "open", "fridge_0", labels).ok
    assert open_(world, "fridge_0", labels).reason is FailureReason.ALREADY_OPEN
    assert close(world, "fridge_0", labels).ok and not world.get("fridge_0").is_open
    assert grasp(world, "table_0", labels).reason is FailureReason.NOT_GRASPABLE
    assert grasp(world, "nothing_9", labels).reason is FailureReason.UNKNOWN_OBJECT


def test_place_inside_needs_open_target_and_valid_target():
    world = two_room_world()
    labels = labelled(world)
    assert go_to_and(world, "grasp", "box_0", labels).ok
    closed = go_to_and(world, "place_inside", "fridge_0", labels)
    assert closed.reason is FailureReason.TARGET_CLOSED and closed.feedback == "must open fridge A first"
    assert place_inside(world, "door_0", labels).reason is FailureReason.INVALID_TARGET
    assert place_inside(world, "floor_kitchen_0", labels).reason is FailureReason.INVALID_TARGET


def test_manipulation_needs_reach():
    world = two_room_world()
    labels = labelled(world)
    world.set_robot_pose(1.0, 0.5, 0.0)
    assert distance_to_footprint(world, "bowl_0") > REACH_M
    far = grasp(world, "bowl_0", labels)
    assert far.reason is FailureReason.TOO_FAR and world.robot.held is None


def test_navigate_ends_free_within_reach_facing_object_and_counts_steps():
    world = two_room_world()
    labels = labelled(world)
    start = (world.robot.x, world.robot.y)
    result = navigate_to(world, "bowl_0", labels)
    assert result.ok and result.path[0] == start
    end = (world.robot.x, world.robot.y)
    assert result.path[-1] == end and distance_to_footprint(world, "bowl_0") <= REACH_M
    bowl = world.get("bowl_0").center
    assert abs(math.atan2(bowl[1] - end[1], bowl[0] - end[0]) - world.robot.yaw) < 1e-6
    length = sum(math.dist(a, b) for a, b in zip(result.path, result.path[1:]))
    assert result.low_level_steps >= math.ceil(length / 0.075)


def test_the_robot_names_the_door_in_the_way_as_its_target_was_named():
    """A planner that acts on labels is told the door's label, which it can open (never the world's name for
    it); the privileged oracle, acting on world names, the world name."""
    world = two_room_world(door_open=False)
    by_label = SimRobot(world, labels=labelled(world)).act("grasp", "bowl A")
    assert by_label.reason is FailureReason.PATH_BLOCKED_BY_DOOR and by_label.blocking == "door A"
    assert SimRobot(world, labels=labelled(world)).act("grasp", "bowl_0").blocking == "door_0"
    unlabelled = InstanceLabels()
    unlabelled.reserve(world.get("bowl_0"))  # the bowl seen, the door not yet
    assert SimRobot(world, labels=unlabelled).act("grasp", "bowl A").blocking is None


def test_closed_door_blocks_navigation_with_the_door_named_then_opening_it_helps():
    world = two_room_world(door_open=False)
    labels = labelled(world)
    blocked = go_to_and(world, "grasp", "bowl_0", labels)
    assert blocked.reason is FailureReason.PATH_BLOCKED_BY_DOOR and blocked.blocking == "door_0"
    assert "door A" in blocked.feedback
    assert go_to_and(world, "open", "door_0", labels).ok
    assert world.robot.x < 5.0  # opened from the kitchen side
    assert go_to_and(world, "grasp", "bowl_0", labels).ok


def test_contents_travel_with_their_container():
    world = two_room_world()
    labels = labelled(world)
    assert go_to_and(world, "grasp", "box_0", labels).ok
    assert go_to_and(world, "place_ontop", "table_0", labels).ok
    assert go_to_and(world, "grasp", "bowl_0", labels).ok
    assert go_to_and(world, "place_inside", "box_0", labels).ok
    assert go_to_and(world, "grasp", "box_0", labels).ok
    assert go_to_and(world, "place_ontop", "floor_kitchen_0", labels).ok
    box, bowl = world.get("box_0"), world.get("bowl_0")
    assert bowl.parent == "box_0" and bowl.room == "kitchen_0"
    assert abs(bowl.center[0] - box.center[0]) < box.size[0] / 2


@pytest.mark.parametrize(("turn", "expected"), [(0.0, 0), (MAX_TURN_RAD, 1), (MAX_TURN_RAD * 1.01, 2), (math.pi, 6)])
def test_turn_steps(turn, expected):
    assert count_low_level_steps(0.0, [(0.0, 0.0)], turn) == expected


def test_forward_steps():
    assert count_low_level_steps(0.0, [(0.0, 0.0), (0.75, 0.0)], 0.0) == 10


def test_opening_a_container_reveals_what_lies_inside_even_out_of_the_frame():
    """Paper S.2: "all inner objects within an articulated object become visible to the robot once the
    outer object is opened". From beside an open carton its rim can hide a book at its bottom: the robot
    that opened it is told of its contents whether or not the frame shows them, and only while it is open."""
    world = two_room_world()
    labels = InstanceLabels()
    labels.reserve(world.get("fridge_0"))
    robot = SimRobot(world, labels=labels)
    apple = world.get("apple_0").instance_id
    assert robot.sense(["fridge A"]).revealed == {}  # closed: nothing inside shows
    assert robot.act("open", "fridge A").ok
    x, y, yaw = robot.pose
    world.set_robot_pose(x, y, yaw + math.pi)  # the camera turned away from the fridge
    seen = robot.sense(["fridge A"])
    assert apple not in seen.frame.instance
    lo, hi = seen.revealed[apple]
    assert np.allclose(lo, world.get("apple_0").box()[0]) and np.allclose(hi, world.get("apple_0").box()[1])
    info = seen.instances[apple]
    assert (info.label, info.category, info.rests) == ("apple A", "apple", ("inside", "fridge A"))
    assert robot.sense().revealed == {}  # told once, with the action; frames show the rest
    assert robot.act("close", "fridge A").ok
    assert robot.sense(["fridge A"]).revealed == {}
