"""What the bag writer says of the world beside the images: the items the robot put down, what it found
inside what it opened."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from more_agent.interop.bag_reader import BagStream
from more_agent.interop.bag_writer import BagRecorder
from more_agent.interop.ingest import FrameMapper
from more_agent.robot import Frame
from more_agent.sim.env import SimRobot
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.scene import load_scene
from tests.sim.test_navgrid import two_room_world

KITCHEN = Path(__file__).parent.parent / "fixtures" / "tasks_kitchen_scene.json"


def _blank_frame() -> Frame:
    """A frame that shows nothing (the label table then holds only what the robot did)."""
    empty = np.zeros((4, 4), dtype=np.int32)
    T = np.eye(4)
    T[2, 3] = 1.3
    return Frame(
        rgb=np.zeros((4, 4, 3), dtype=np.uint8),
        depth=np.full((4, 4), np.nan, dtype=np.float32),
        semantic=empty,
        instance=empty,
        K=np.array([[2.0, 0.0, 2.0], [0.0, 2.0, 2.0], [0.0, 0.0, 1.0]]),
        T_world_cam=T,
    )


def test_an_item_put_down_comes_with_what_rode_on_it(tmp_path: Path) -> None:
    """The simulator's robot reports a sack it put down with the groceries in it, each at its box; the bag
    must say the same, or an ingested graph keeps the groceries where the robot last saw them (in its hand)."""
    kitchen = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)
    world = kitchen.world
    sack = world.get("sack_2")
    riders = world.descendants(sack.name)
    assert len(riders) == 3  # the yogurt, the cereal, the can
    with BagRecorder(tmp_path / "bag", storage="mcap") as recorder:
        world.robot.held = sack.name
        recorder.record(world, kitchen.labels, _blank_frame())
        world.robot.held = None
        recorder.record(world, kitchen.labels, _blank_frame())
    held, put_down = BagStream(tmp_path / "bag").frames()
    assert not held.placed
    assert set(put_down.placed) == {sack.instance_id, *(o.instance_id for o in riders)}
    for obj in (sack, *riders):
        lo, hi = obj.box()
        np.testing.assert_allclose(put_down.placed[obj.instance_id][0], lo)
        np.testing.assert_allclose(put_down.placed[obj.instance_id][1], hi)


def test_what_opening_revealed_travels_with_the_frame_it_was_told_with(tmp_path: Path) -> None:
    """The robot that opened the fridge is told of the apple inside though its camera looks away
    (``Observation.revealed``); the bag says so on the same frame, and an ingested map holds the apple."""
    world = two_room_world()
    labels = InstanceLabels()
    labels.reserve(world.get("fridge_0"))
    apple = world.get("apple_0")
    with BagRecorder(tmp_path / "bag", storage="mcap") as recorder:
        robot = SimRobot(world, labels=labels, on_sensed=recorder.hook(world, labels))
        robot.sense()
        assert robot.act("open", "fridge A").ok
        x, y, yaw = robot.pose
        world.set_robot_pose(x, y, yaw + np.pi)
        told = robot.sense(["fridge A"])
    assert apple.instance_id in told.revealed and apple.instance_id not in told.frame.instance
    frames = list(BagStream(tmp_path / "bag").frames())
    assert [set(f.revealed) for f in frames] == [set(), {apple.instance_id}]
    assert frames[-1].instances[apple.instance_id].label == "apple A"
    np.testing.assert_allclose(frames[-1].revealed[apple.instance_id][0], apple.box()[0])
    mapper = FrameMapper(world.class_names)
    for frame in frames:
        mapper.add(frame)
    assert "apple A" in mapper.build().objects
