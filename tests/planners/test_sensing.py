"""The sensing schedule: frames on the way come at a fixed distance or angle, frames where the robot stops always."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from more_agent.planners.policies import Embodiment
from more_agent.planners.policies.sensing import SensingSchedule
from more_agent.sensing_spec import SensingCadence
from more_agent.sim.env import SimRobot
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.motion import clearance, obstacle_boxes
from more_agent.sim.navgrid import DEFAULT_NAV
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


def test_a_frame_is_due_after_the_distance_or_the_angle_not_before() -> None:
    schedule = SensingSchedule(SensingCadence(distance_m=0.6, angle_deg=30))
    assert schedule.due(0.0, 0.0, 0.0)  # nothing fused yet
    schedule.fused(0.0, 0.0, 0.0)
    assert not schedule.due(0.59, 0.0, 0.0) and schedule.due(0.6, 0.0, 0.0) and schedule.due(0.3, 0.55, 0.0)
    assert not schedule.due(0.0, 0.0, math.radians(29)) and schedule.due(0.0, 0.0, math.radians(30))
    schedule.fused(0.0, 0.0, math.radians(179))
    assert not schedule.due(0.0, 0.0, math.radians(-179))  # 2 deg across the wrap


def test_the_angle_stays_below_the_cameras_field_of_view() -> None:
    with pytest.raises(ValueError):
        SensingCadence(angle_deg=63.3)


@pytest.mark.parametrize("distance_m", [0.3, 0.6])
def test_frames_on_a_straight_drive_come_every_distance_and_at_arrival(distance_m: float) -> None:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0, start="task-room")
    robot = inst.world.robot
    inst.world.set_robot_pose(robot.x, robot.y, _clear_heading(inst.world, 1.5))
    body = Embodiment(SimRobot(inst.world, labels=inst.labels), sensing=SensingCadence(distance_m=distance_m, angle_deg=30))
    body.sense()  # the frame where the robot stands
    frames: list[tuple[float, float]] = []
    body.on_frame = lambda frame: frames.append(body.xy)
    start = body.xy
    yaw = body.robot.pose[2]
    goal = (start[0] + 1.5 * math.cos(yaw), start[1] + 1.5 * math.sin(yaw))  # straight ahead: no turn on the way
    assert body.follow([start, goal])
    gaps = [math.dist(a, b) for a, b in zip([start, *frames], frames, strict=False)]
    assert frames[-1] == body.xy == pytest.approx(goal)  # the arrival is always sensed
    assert all(g <= distance_m + 1e-6 for g in gaps), gaps  # never further apart than the cadence
    assert len(frames) == math.floor(1.5 / distance_m + 1e-6) + 1  # one per distance on the way, one at arrival


def _clear_heading(world: World, length_m: float) -> float:
    """A heading from the robot's position along which ``length_m`` of floor lie clear: the task-room start
    may face furniture, and a turn on the way would add frames of its own."""
    boxes, robot = obstacle_boxes(world), world.robot
    for yaw in np.linspace(0.0, 2 * math.pi, 16, endpoint=False):
        ahead = [(robot.x + d * math.cos(yaw), robot.y + d * math.sin(yaw)) for d in np.arange(0.0, length_m + 0.2, 0.05)]
        if all(clearance(boxes, x, y) > DEFAULT_NAV.robot_radius_m for x, y in ahead):
            return float(yaw)
    raise AssertionError("no clear heading from the start")
