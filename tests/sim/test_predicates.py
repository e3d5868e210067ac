"""The goal predicates on a hand-built world: what holds, what does not, and names the world lacks."""

from __future__ import annotations

import numpy as np

from more_agent.sim.predicates import ROBOT_NAME, holds
from more_agent.sim.world import WorldObject
from tests.sim.test_navgrid import two_room_world


def test_rearrangement_predicates_follow_the_world() -> None:
    world = two_room_world()
    assert holds(world, "inside", ("apple_0", "fridge_0")) and not holds(world, "open", ("fridge_0",))
    assert holds(world, "ontop", ("bowl_0", "table_0")) and holds(world, "ontop", ("box_0", "floor_kitchen_0"))
    assert holds(world, "ontop", ("table_0", "floor_living_room_0"))  # furniture stands on its room's floor
    assert holds(world, "ontop", (ROBOT_NAME, "floor_kitchen_0"))  # the robot stands in the kitchen
    assert not holds(world, "ontop", (ROBOT_NAME, "floor_living_room_0"))
    world.set_open("fridge_0", True)
    assert holds(world, "open", ("fridge_0",))


def test_geometric_predicates_and_grasp() -> None:
    world = two_room_world()
    assert holds(world, "touching", ("bowl_0", "table_0")) and not holds(world, "touching", ("box_0", "table_0"))
    assert holds(world, "nextto", ("table_0", "table_0")) and not holds(world, "nextto", ("box_0", "table_0"))
    assert not holds(world, "under", ("box_0", "table_0"))
    world.place_on_floor_at("box_0", "floor_living_room_0", (7.5, 2.0))  # below the table top
    assert holds(world, "under", ("box_0", "table_0"))
    world.pick("apple_0")
    assert holds(world, "grasped", (ROBOT_NAME, "apple_0")) and not holds(world, "grasped", ("box_0", "apple_0"))


def test_names_the_world_lacks_and_unmodelled_predicates_read_false() -> None:
    world = two_room_world()
    assert not holds(world, "inside", ("water.n.06_1", "fridge_0"))
    assert not holds(world, "ontop", ("bowl_0", "dust.n.01_1"))
    assert not holds(world, "cooked", ("apple_0",))


def test_attached_is_an_attachable_thing_put_directly_on_another() -> None:
    """OmniGibson attaches a camera put on a tripod's mount (the paper: "put the digital camera on top the
    tripod"); a bowl on a table is not attached, nor is a camera on a plate on the tripod."""
    world = two_room_world()
    for name, size in [("digital_camera_0", 0.1), ("camera_tripod_0", 0.3), ("plate_0", 0.2)]:
        world.add(WorldObject(name=name, category=name[:-2], kind="item", center=np.zeros(3), size=np.full(3, size)))
    world.place("camera_tripod_0", "floor_kitchen_0", "ontop")
    world.place("digital_camera_0", "floor_kitchen_0", "ontop")
    assert not holds(world, "attached", ("digital_camera_0", "camera_tripod_0"))
    world.place("digital_camera_0", "camera_tripod_0", "ontop")
    assert holds(world, "attached", ("digital_camera_0", "camera_tripod_0"))
    assert not holds(world, "attached", ("camera_tripod_0", "digital_camera_0"))
    assert not holds(world, "attached", ("bowl_0", "table_0"))  # on top, but neither is attachable
    world.place("plate_0", "camera_tripod_0", "ontop")
    world.place("digital_camera_0", "plate_0", "ontop")
    assert holds(world, "ontop", ("digital_camera_0", "camera_tripod_0"))
    assert not holds(world, "attached", ("digital_camera_0", "camera_tripod_0"))  # on the tripod, not on its mount
