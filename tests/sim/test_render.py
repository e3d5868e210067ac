"""Rendered frames: depth, semantic and instance ids, occlusion by walls, doors and containers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from more_agent.robot_spec import OMNIGIBSON_FETCH_HFOV_DEG
from more_agent.sim.camera import Camera, camera_pose, project
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.render import Renderer, render, scene_geometry
from more_agent.sim.scene import Door, Furniture, Room, Scene, Wall, Window
from more_agent.sim.world import World, WorldObject

T = 0.1  # wall thickness


def two_rooms() -> World:
    """Room a (x 0..4, floor) and room b (x 4..8, carpet), a door at (4, 2), a window in a's south wall,
    a closed fridge in a and a table in b; walls are centred on the room edges."""
    h = T / 2
    walls = [
        Wall(bounds=(-h, -h, h, 4 + h)), Wall(bounds=(8 - h, -h, 8 + h, 4 + h)), Wall(bounds=(-h, 4 - h, 8 + h, 4 + h)),
        Wall(bounds=(-h, -h, 1.5, h)), Wall(bounds=(2.5, -h, 8 + h, h)),  # south wall, window gap at x 1.5..2.5
        Wall(bounds=(1.5, -h, 2.5, h), z_max=0.9), Wall(bounds=(1.5, -h, 2.5, h), z_min=2.0),
        Wall(bounds=(4 - h, -h, 4 + h, 1.5)), Wall(bounds=(4 - h, 2.5, 4 + h, 4 + h)),  # door gap at y 1.5..2.5
        Wall(bounds=(4 - h, 1.5, 4 + h, 2.5), z_min=2.1),
    ]
    scene = Scene(
        name="two_rooms", bounds=(-h, -h, 8 + h, 4 + h),
        rooms=[Room(id="kitchen_0", type="kitchen", bounds=(0, 0, 4, 4)),
               Room(id="living_room_0", type="living_room", bounds=(4, 0, 8, 4), ground="carpet")],
        walls=walls,
        doors=[Door(id="door_0", rooms=("kitchen_0", "living_room_0"), center=(4, 2), width=1.0, axis="y", thickness=T)],
        windows=[Window(id="window_0", bounds=(1.5, -h, 2.5, h), rooms=("kitchen_0",))],
        furniture=[
            Furniture(id="fridge_0", category="fridge", room="kitchen_0", center=(1, 3.5, 0.9), size=(0.8, 0.7, 1.8), openable=True),
            Furniture(id="table_0", category="table", room="living_room_0", center=(6, 2, 0.375), size=(1, 1, 0.75)),
        ],
    )
    world = World.from_scene(scene)
    world.add(WorldObject(name="apple_0", category="apple", kind="item", center=np.zeros(3), size=np.array([0.08, 0.08, 0.08])))
    world.place("apple_0", "fridge_0", "inside")
    world.add(WorldObject(name="mug_0", category="mug", kind="item", center=np.zeros(3), size=np.array([0.1, 0.1, 0.12])))
    world.place("mug_0", "table_0", "ontop")
    return world


def back_project(frame, v: int, u: int) -> np.ndarray:
    """World point seen at pixel (row v, column u)."""
    p = np.linalg.inv(frame.K) @ np.array([u, v, 1.0]) * frame.depth[v, u]
    return frame.T_world_cam[:3, :3] @ p + frame.T_world_cam[:3, 3]


def pixel_of(frame, point) -> tuple[int, int]:
    uv, _ = project(np.array([point], dtype=float), frame.K, frame.T_world_cam)
    u, v = uv[0]
    return int(round(v)), int(round(u))


def test_camera_pose_is_a_pitched_opencv_frame():
    T = camera_pose(1.0, 2.0, math.pi / 2, height_m=1.2, pitch_rad=math.radians(20))
    R = T[:3, :3]
    assert np.allclose(R.T @ R, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)
    assert np.allclose(T[:3, 3], [1, 2, 1.2])
    assert np.allclose(R[:, 2], [0, math.cos(math.radians(20)), -math.sin(math.radians(20))])  # forward: north, down
    assert np.allclose(R[:, 0], [1, 0, 0])  # right of north is east
    K = Camera().intrinsics()
    # OmniGibson's Fetch: a 17 mm focal length over a 20.955 mm aperture, the default
    assert OMNIGIBSON_FETCH_HFOV_DEG == pytest.approx(63.3, abs=0.05) and Camera().hfov_deg == OMNIGIBSON_FETCH_HFOV_DEG
    assert K[0, 0] == pytest.approx(128.0 * 17.0 / (20.955 / 2)) and K[0, 2] == pytest.approx(127.5)
    assert Camera(hfov_deg=90.0).focal_px == pytest.approx(128.0)
    assert Camera(hfov_deg=OMNIGIBSON_FETCH_HFOV_DEG).blind_floor_m == pytest.approx(0.95, abs=0.005)


def test_depth_to_a_wall_at_a_known_distance():
    world = two_rooms()
    world.set_robot_pose(2.0, 2.0, math.pi)  # facing the west wall, whose face is at x = 0.05
    frame = Renderer(Camera(pitch_deg=0.0)).render(world)
    assert frame.depth.dtype == np.float32 and frame.depth.shape == (256, 256)
    wall = world.class_names.index("wall")
    assert frame.depth[128, 128] == pytest.approx(1.95, abs=1e-4)
    assert frame.depth[64, 40] == pytest.approx(1.95, abs=1e-4)  # z-depth: same on the whole plane
    assert frame.semantic[128, 128] == wall and frame.instance[128, 128] == 0


def test_back_projected_pixels_land_on_the_surfaces_hit():
    world = two_rooms()
    world.set_robot_pose(2.0, 2.0, math.pi)
    frame = render(world)
    floor = world.class_names.index("floor")
    assert frame.semantic[250, 128] == floor
    assert back_project(frame, 250, 128)[2] == pytest.approx(0.0, abs=1e-4)
    assert back_project(frame, 60, 128)[0] == pytest.approx(T / 2, abs=1e-4)


def test_semantic_and_instance_of_a_known_object():
    world = two_rooms()
    world.set_robot_pose(1.0, 1.0, math.pi / 2)  # facing the fridge 2.15 m north
    frame = render(world)
    fridge = world.get("fridge_0")
    v, u = pixel_of(frame, (1.0, 3.15, 0.9))
    assert frame.semantic[v, u] == world.class_names.index("fridge")
    assert frame.instance[v, u] == fridge.instance_id
    assert back_project(frame, v, u)[1] == pytest.approx(3.15, abs=1e-3)
    table = InstanceLabels().table(world, frame.instance)
    assert table[fridge.instance_id] == {"name": "fridge_0", "label": "fridge A", "category": "fridge", "open": False, "held": False}


def test_instance_ids_name_the_objects_after_objects_come_and_go():
    """``InstanceLabels.table`` (read every frame) looks objects up by id through a cache that keeps no
    stale entry when an object is removed and another added under its id."""
    world, labels = two_rooms(), InstanceLabels()
    fridge = world.get("fridge_0")
    assert labels.table(world, np.array([[0, fridge.instance_id]]))[fridge.instance_id]["name"] == "fridge_0"
    last = max(world.objects.values(), key=lambda o: o.instance_id)
    del world.objects[last.name]
    new = world.add(WorldObject(name="mug_9", category="mug", kind="item", room=last.room, center=np.zeros(3),
                                size=np.full(3, 0.1)))
    assert new.instance_id == last.instance_id
    table = labels.table(world, np.array([[new.instance_id, fridge.instance_id]]))
    assert {i: row["name"] for i, row in table.items()} == {new.instance_id: "mug_9", fridge.instance_id: "fridge_0"}
    assert table[new.instance_id]["label"] == "mug A"


def test_fridge_content_hidden_until_opened():
    world = two_rooms()
    world.set_robot_pose(1.0, 1.0, math.pi / 2)
    renderer = Renderer()
    apple = world.get("apple_0").instance_id
    assert apple not in renderer.render(world).instance
    world.set_open("fridge_0", True)
    frame = renderer.render(world)
    assert apple in frame.instance
    assert InstanceLabels().table(world, frame.instance)[world.get("fridge_0").instance_id]["open"] is True


def test_open_container_keeps_its_full_box():
    world = two_rooms()
    world.set_open("fridge_0", True)
    g = scene_geometry(world)
    mine = g.instance == world.get("fridge_0").instance_id
    lo, hi = world.get("fridge_0").box()
    assert mine.sum() == 6  # two slabs, four posts
    assert np.allclose(g.lo[mine].min(axis=0), lo) and np.allclose(g.hi[mine].max(axis=0), hi)


def test_an_open_top_container_shows_what_it_holds_from_above_and_keeps_its_full_box():
    """A basket (not openable, not a shelf) has no top slab, as nothing covers it in BEHAVIOR-1K's meshes: the
    apple at its bottom shows to a camera looking straight down. An opened fridge keeps its top (the test above)."""
    world = two_rooms()
    world.add(WorldObject(name="basket_0", category="wicker_basket", kind="item", center=np.zeros(3),
                          size=np.array([0.5, 0.5, 0.4])))
    world.place_on_floor_at("basket_0", "floor_kitchen_0", (2.5, 1.5))
    world.add(WorldObject(name="apple_1", category="apple", kind="item", center=np.zeros(3), size=np.array([0.08, 0.08, 0.08])))
    world.place("apple_1", "basket_0", "inside")
    g = scene_geometry(world)
    mine = g.instance == world.get("basket_0").instance_id
    lo, hi = world.get("basket_0").box()
    assert mine.sum() == 5  # the bottom slab, four posts
    assert np.allclose(g.lo[mine].min(axis=0), lo) and np.allclose(g.hi[mine].max(axis=0), hi)
    apple = world.get("apple_1")
    above = camera_pose(2.5, 1.5, 0.0, height_m=1.5, pitch_rad=math.pi / 2 - 1e-6)
    frame = Renderer().render_at(world, above)
    v, u = pixel_of(frame, apple.center)
    assert frame.instance[v, u] == apple.instance_id


def test_closed_door_hides_the_next_room():
    world = two_rooms()
    world.set_robot_pose(2.0, 2.0, 0.0)  # facing the door at x = 4 and the table behind it
    renderer = Renderer()
    door, table = world.get("door_0").instance_id, world.get("table_0").instance_id
    carpet = world.class_names.index("carpet")
    seen = renderer.render(world)
    assert table in seen.instance and carpet in seen.semantic
    assert door in seen.instance  # the lintel above the opening
    world.set_open("door_0", False)
    shut = renderer.render(world)
    assert table not in shut.instance and carpet not in shut.semantic
    v, u = pixel_of(shut, (4.0, 2.0, 1.0))
    assert shut.instance[v, u] == door and shut.semantic[v, u] == world.class_names.index("door")


def test_items_rest_at_their_heights_and_held_items_vanish():
    world = two_rooms()
    world.set_robot_pose(4.8, 2.0, 0.0)
    mug = world.get("mug_0")
    frame = render(world)
    v, u = pixel_of(frame, mug.center)
    assert frame.instance[v, u] == mug.instance_id
    assert mug.bottom - 1e-3 <= back_project(frame, v, u)[2] <= mug.top + 1e-3
    assert mug.bottom == pytest.approx(0.75)
    world.pick("mug_0")
    after = render(world)
    assert mug.instance_id not in after.instance
    assert InstanceLabels().table(world, after.instance)[mug.instance_id]["held"] is True


def test_window_is_see_through_and_range_is_five_metres():
    world = two_rooms()
    world.set_robot_pose(2.0, 1.6, -math.pi / 2)  # facing the window in the south wall
    frame = Renderer(Camera(pitch_deg=0.0)).render(world)
    v, u = pixel_of(frame, (2.0, 0.0, 1.5))
    assert np.isnan(frame.depth[v, u]) and frame.semantic[v, u] == 0 and not frame.rgb[v, u].any()
    v, u = pixel_of(frame, (2.0, 0.0, 0.5))
    assert frame.semantic[v, u] == world.class_names.index("wall")
    world.set_robot_pose(0.5, 2.0, 0.0)  # east wall is 7.45 m away: beyond range
    far = Renderer(Camera(pitch_deg=0.0)).render(world)
    assert np.isnan(far.depth[128, 128]) and np.nanmax(far.depth) <= 5.0


def test_the_range_is_a_distance_from_the_camera_not_a_z_depth():
    """A wall 4.5 m ahead spans the whole image; towards the image's edges it lies farther than 5 m from the
    camera though its z-depth is 4.5 m: invalid there, depth and semantics alike, as the mapper reads the
    range (the robot's `observed` set counted objects there that its map never held)."""
    h = T / 2
    scene = Scene(
        name="hall", bounds=(-h, -6 - h, 12 + h, 6 + h),
        rooms=[Room(id="hall_0", type="corridor", bounds=(0, -6, 12, 6))],
        walls=[Wall(bounds=(-h, -6 - h, h, 6 + h))],
    )
    world = World.from_scene(scene)
    world.set_robot_pose(4.55, 0.0, math.pi)  # the wall's face 4.5 m ahead
    frame = Renderer(Camera(pitch_deg=0.0)).render(world)
    wall = world.class_names.index("wall")
    row = 128  # level: every pixel of the row meets the wall's plane
    assert frame.depth[row, 128] == pytest.approx(4.5, abs=1e-4) and frame.semantic[row, 128] == wall
    rays = Camera(pitch_deg=0.0).pixel_rays().reshape(256, 256, 3)
    far = np.linalg.norm(rays[row], axis=1) * 4.5 > 5.0
    assert far.any() and not far.all()
    assert np.isnan(frame.depth[row, far]).all() and not frame.semantic[row, far].any()
    assert (frame.semantic[row, ~far] == wall).all()
    hits = np.isfinite(frame.depth)
    assert np.all(np.linalg.norm(rays[hits], axis=1) * frame.depth[hits] <= 5.0 + 1e-4)


def nearest_entries_by_brute_force(world: World, T_world_cam: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Depth and instance per pixel from slab-testing every box of the world with every pixel's ray (the first
    box listed wins a tie), cut at the sensor range: what the renderer's culling must not change."""
    g = scene_geometry(world)
    rays = camera.pixel_rays()
    rot, o = T_world_cam[:3, :3], T_world_cam[:3, 3]
    d = np.stack([rot[i, 0] * rays[:, 0] + rot[i, 1] * rays[:, 1] + rot[i, 2] for i in range(3)], axis=1)
    d[d == 0.0] = 1e-12
    inv = 1.0 / d
    best, box = np.full(len(rays), np.inf), np.full(len(rays), -1)
    for b in range(g.n_boxes):
        ta, tb = (g.lo[b] - o) * inv, (g.hi[b] - o) * inv
        t0, t1 = np.minimum(ta, tb).max(axis=1), np.maximum(ta, tb).min(axis=1)
        hit = (t0 <= t1) & (t0 >= 0.0) & (t0 < best)
        best[hit], box[hit] = t0[hit], b
    seen = (box >= 0) & (best * np.linalg.norm(rays, axis=1) <= camera.max_range_m)
    depth = np.where(seen, best, np.nan).reshape(camera.height, camera.width)
    return depth, np.where(seen, g.instance[box], 0).reshape(camera.height, camera.width)


@pytest.mark.parametrize(
    ("x", "y", "z", "yaw_deg", "pitch_deg"),
    [
        (3.8, 2.0, 1.2, 180.0, 20.0),  # back to the doorway: the door frame and the walls reach behind the camera
        (0.25, 0.3, 1.2, 45.0, 20.0),  # in a corner, both walls beside and behind
        (1.0, 2.6, 1.2, 90.0, 55.0),  # head tilted down at the fridge's front, close by
        (5.0, 2.0, 1.2, 0.0, 89.0),  # looking straight down past the table's edge
        (2.0, 0.2, 1.2, -90.0, 0.0),  # level, at the window
        (6.0, 2.0, 0.5, 180.0, 10.0),  # inside the table's box: it is not seen, the rest is
        (7.9485, 2.0, 1.2, 0.0, 0.0),  # 1.5 mm from the east wall's face
        (2.5, 1.5, 1.2, 0.0, 90.0 - 1e-4),  # straight down at a sheet 0.3 mm below the lens: no corner beyond
    ],  # the near plane, yet every ray hits it
)
def test_every_pixel_shows_the_nearest_box_its_ray_enters(x, y, z, yaw_deg, pitch_deg):
    """The renderer tests a box only with the pixels of the rectangle its projection covers; boxes that reach
    behind the camera, lie beside it, hold it or touch it must still show in every pixel whose ray enters them
    first."""
    world = two_rooms()
    world.set_open("fridge_0", True)
    sheet = np.array([0.4, 0.4, 0.0005])
    world.add(WorldObject(name="sheet_0", category="table", kind="furniture", center=np.array([2.5, 1.5, 1.2 - 0.0003 - sheet[2] / 2]), size=sheet))
    camera = Camera()
    T = camera_pose(x, y, math.radians(yaw_deg), height_m=z, pitch_rad=math.radians(pitch_deg))
    frame = Renderer(camera).render_at(world, T)
    depth, instance = nearest_entries_by_brute_force(world, T, camera)
    assert np.array_equal(frame.instance, instance)
    assert np.array_equal(frame.depth, depth.astype(np.float32), equal_nan=True)


def test_rendering_is_deterministic_and_cached():
    world = two_rooms()
    world.set_robot_pose(1.0, 1.0, 0.7)
    renderer = Renderer()
    a, b = renderer.render(world), render(world)
    for name in ("rgb", "depth", "semantic", "instance", "K", "T_world_cam"):
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=name == "depth")
    assert renderer.geometry(world) is renderer.geometry(world)
    world.set_open("fridge_0", True)
    assert renderer.geometry(world).n_boxes == scene_geometry(world).n_boxes


def test_carrying_rebuilds_the_geometry_only_when_something_rides_along():
    """A held item is never drawn: carrying it keeps the cached geometry; carrying a tray with a mug on it
    moves the mug, and the cached renderer draws it where a fresh one does."""
    world = two_rooms()
    world.set_robot_pose(4.8, 1.2, 0.0)
    renderer = Renderer()
    world.pick("mug_0")
    held_alone = renderer.geometry(world)
    world.set_robot_pose(5.0, 1.2, math.pi / 2)
    assert renderer.geometry(world) is held_alone
    world.add(WorldObject(name="tray_0", category="tray", kind="item", center=np.zeros(3), size=np.array([0.4, 0.3, 0.03])))
    world.place("tray_0", "table_0", "ontop")
    world.place("mug_0", "tray_0", "ontop")
    world.pick("tray_0")
    before = renderer.geometry(world)
    world.set_robot_pose(5.0, 1.0, math.pi / 2)
    assert renderer.geometry(world) is not before
    cached, fresh = renderer.render(world), Renderer().render(world)
    for name in ("depth", "semantic", "instance", "rgb"):
        assert np.array_equal(getattr(cached, name), getattr(fresh, name), equal_nan=name == "depth")
