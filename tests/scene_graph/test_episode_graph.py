"""A whole episode's scene graph, built from rendered frames, matches the world's rooms.

The robot visits every room of a generated BEHAVIOR-1K plan (Rs_int, all doors open) and every
door between them, and turns once in place at each; the graph built from those frames must have one region per room, every
Voronoi node of a region inside that room, and every observed object in the region of its room.
"""

from __future__ import annotations

from collections import Counter

from more_agent.planners.policies import Embodiment
from more_agent.sim.env import SimRobot
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.navgrid import nav_grid
from more_agent.sim.scenes import get_scene
from more_agent.sim.world import World


def test_explored_rs_int_graph_has_one_region_per_room_with_its_objects() -> None:
    world = World.from_scene(get_scene("Rs_int", 0))
    for door in world.scene.doors:
        world.set_open(door.id, True)
    grid = nav_grid(world)
    labels = InstanceLabels()
    body = Embodiment(SimRobot(world, labels=labels))
    centres = [((r.bounds[0] + r.bounds[2]) / 2, (r.bounds[1] + r.bounds[3]) / 2) for r in world.scene.rooms]
    doors = [((d.bounds()[0] + d.bounds()[2]) / 2, (d.bounds()[1] + d.bounds()[3]) / 2) for d in world.scene.doors]
    for x, y in centres + doors:  # as a robot driving from room to room sees them: the doors it passes too
        world.set_robot_pose(*grid.centre(grid.snap(x, y)), 0.0)
        body.look_around()
    graph = body.build()

    region_room = {}
    for rid, region in graph.regions.items():
        rooms = Counter(world.room_at(*graph.nav.node_xy[i]) for i in region.nav_nodes)
        assert len(rooms) == 1, f"{rid} spans {dict(rooms)}"
        region_room[rid] = next(iter(rooms))
    assert sorted(region_room.values()) == sorted(r.id for r in world.scene.rooms)

    placed = [o for o in graph.objects.values() if o.category != "door" and o.region_id is not None]
    assert len(placed) >= 20
    for obj in placed:
        assert region_room[obj.region_id] == world.get(labels.find(obj.label) or obj.label).room, obj.label
