"""Floor-plan generator: determinism, bddl rooms and furniture, geometry rules, reachability."""

import json

import networkx as nx
import numpy as np
import pytest
from scipy import ndimage

from more_agent.sim import catalog
from more_agent.sim.floorplan import generate_floorplan, scene_rng
from more_agent.sim.furnish import box_distance, reach_grid
from more_agent.sim.scene import Scene, SceneError, load_scene
from more_agent.sim.scenes import get_scene, scene_names
from more_agent.vocabulary import OUTDOOR_ROOM_TYPES, room_type

SAMPLE = ["Rs_int", "Rs_garden", "Beechwood_0_garden", "house_single_floor", "restaurant_diner", "office_bike",
          "grocery_store_convenience", "gates_bedroom"]


def _fp(f):
    return (f.center[0] - f.size[0] / 2, f.center[1] - f.size[1] / 2, f.center[0] + f.size[0] / 2, f.center[1] + f.size[1] / 2)


def _overlap(a, b, eps=1e-6):
    return a[0] < b[2] - eps and b[0] < a[2] - eps and a[1] < b[3] - eps and b[1] < a[3] - eps


def test_deterministic_per_scene_and_seed():
    rooms = catalog.scene_rooms("Rs_int")
    a = generate_floorplan("Rs_int", rooms, rng=scene_rng("Rs_int", 3), seed=3).model_dump_json()
    b = generate_floorplan("Rs_int", rooms, rng=scene_rng("Rs_int", 3), seed=3).model_dump_json()
    c = generate_floorplan("Rs_int", rooms, rng=scene_rng("Rs_int", 4), seed=4).model_dump_json()
    assert a == b and a != c
    assert get_scene("Rs_int", 3).model_dump_json() == a


@pytest.mark.parametrize("name", scene_names())
def test_every_scene_has_bddl_rooms_and_furniture(name):
    s = get_scene(name)
    rooms = catalog.scene_rooms(name)
    assert [r.id for r in s.rooms] == list(rooms)
    for rid, objs in rooms.items():
        listed = {k.rsplit("-", 1)[0] for k in objs}
        want = {c for c in listed if catalog.furniture_role(c) not in ("skip", "carpet")}
        got = {f.category for f in s.furniture if f.room == rid}
        assert got == want, rid
    # rooms are connected through doors, open or closed
    g = nx.Graph()
    g.add_nodes_from(rooms)
    g.add_edges_from(d.rooms for d in s.doors)
    assert nx.is_connected(g)
    Scene.model_validate_json(s.model_dump_json())  # round trip


@pytest.mark.parametrize("name", SAMPLE)
def test_geometry_rules(name):
    s = get_scene(name)
    for i, r in enumerate(s.rooms):
        for q in s.rooms[i + 1:]:
            assert not _overlap(r.bounds, q.bounds)
    ground_walls = [w.bounds for w in s.walls if w.z_min < 0.3]
    for f in s.furniture:
        room = s.room(f.room)
        fp = _fp(f)
        assert room.bounds[0] < fp[0] and fp[2] < room.bounds[2] and room.bounds[1] < fp[1] and fp[3] < room.bounds[3]
        assert not any(_overlap(fp, w) for w in ground_walls), f.id
    for i, f in enumerate(s.furniture):  # no two pieces share space (3D)
        for g in s.furniture[i + 1:]:
            zf, zg = (f.center[2] - f.size[2] / 2, f.center[2] + f.size[2] / 2), (g.center[2] - g.size[2] / 2, g.center[2] + g.size[2] / 2)
            assert not (_overlap(_fp(f), _fp(g)) and zf[0] < zg[1] - 2e-3 and zg[0] < zf[1] - 2e-3), (f.id, g.id)
    for d in s.doors:  # nothing stands in a door's swing zone
        x, y = d.center
        zone = (x - 0.45, y - 0.8, x + 0.45, y + 0.8) if d.axis == "x" else (x - 0.8, y - 0.45, x + 0.8, y + 0.45)
        assert not any(_overlap(zone, _fp(f)) for f in s.furniture if f.center[2] - f.size[2] / 2 < 2.0), d.id


@pytest.mark.parametrize("name", SAMPLE)
def test_every_piece_reachable_on_raster(name):
    """Rasterise the whole plan at 0.075 m: a 0.3 m robot disc gets within 1 m of every piece from one component."""
    s = get_scene(name)
    blocks = [w.bounds for w in s.walls if w.z_min < 0.3]
    blocks += [_fp(f) for f in s.furniture if f.center[2] - f.size[2] / 2 < 0.3]
    xs, ys, free = reach_grid(s.bounds, blocks, robot_radius_m=0.3, resolution_m=0.075)
    inside = np.zeros_like(free)
    for r in s.rooms:
        inside |= box_distance(xs, ys, r.bounds) == 0
    labels, _ = ndimage.label(free & inside)
    main = np.bincount(labels.ravel())[1:].argmax() + 1
    reach = labels == main
    for r in s.rooms:
        assert (reach & (box_distance(xs, ys, r.bounds) == 0)).any(), r.id
    for f in s.furniture:
        assert _reaches(xs, ys, reach, _fp(f), 1.0), f.id


def _reaches(xs, ys, reach, b, d):
    """Whether a reachable cell lies within ``d`` of rectangle ``b``: ``box_distance`` over the window of
    cells within ``d`` of it on both axes (every cell outside is farther), not over the whole plan."""
    cols, rows = (xs >= b[0] - d) & (xs <= b[2] + d), (ys >= b[1] - d) & (ys <= b[3] + d)
    return bool((reach[np.ix_(rows, cols)] & (box_distance(xs[cols], ys[rows], b) <= d)).any())


def test_outdoor_ground_doors_windows():
    s = get_scene("Rs_garden")
    garden = s.room("garden_0")
    assert garden.outdoor and garden.ground == "lawn"
    assert all(not r.outdoor and r.ground == "floor" for r in s.rooms if r.id != "garden_0")
    drive = [p for p in s.ground_patches if p.ground == "driveway"]
    assert drive and drive[0].room == "garden_0"
    car = next(f for f in s.furniture if f.category == "car")
    assert car.openable and _overlap(_fp(car), drive[0].bounds)
    assert any("garden_0" in d.rooms for d in s.doors)
    assert any("garden_0" in w.rooms and len(w.rooms) == 2 for w in s.windows)  # see inside from the garden
    assert all(len(set(d.rooms)) == 2 for d in s.doors)  # no exterior doors
    assert any(not d.open for d in get_scene("house_single_floor").doors)
    assert any(p.ground == "carpet" for p in get_scene("Rs_int").ground_patches)


def _shared_wall_m(a, b):
    """Length of the edge two room footprints share (0 if they only touch at a corner or not at all)."""
    if abs(a[2] - b[0]) < 1e-6 or abs(b[2] - a[0]) < 1e-6:
        return min(a[3], b[3]) - max(a[1], b[1])
    if abs(a[3] - b[1]) < 1e-6 or abs(b[3] - a[1]) < 1e-6:
        return min(a[2], b[2]) - max(a[0], b[0])
    return 0.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_garden_has_the_doors_to_the_house_that_its_inventory_lists(seed):
    """bddl's house_single_floor lists ten doors in its garden (front door, garage, patio, ...): the plan gives
    the garden that many, or one on every wall it shares with a room where a door fits (the spanning tree alone
    gave it one or two)."""
    listed = sum(n for key, n in catalog.scene_rooms("house_single_floor")["garden_0"].items() if key.split("-")[0] in ("door", "sliding_door"))
    s = get_scene("house_single_floor", seed)
    garden = s.room("garden_0").bounds
    fits = {r.id for r in s.rooms if r.id != "garden_0" and _shared_wall_m(garden, r.bounds) >= 0.9 + 2 * 0.35}
    doors = [d for d in s.doors if "garden_0" in d.rooms]
    assert listed == 10 and {r for d in doors for r in d.rooms} - {"garden_0"} <= fits
    assert len(doors) == min(listed, len(fits)) >= 4


def _area(b):
    return (b[2] - b[0]) * (b[3] - b[1])


def test_a_garden_is_sized_by_its_own_furniture_not_by_the_house_rooms_retries():
    """house_single_floor's layout retries 8 to 11 times over seeds 0-4 because indoor rooms' furniture does not
    fit, and its house ends up 760-910 m². Each retry grew the garden 5 % too, to 2,010-2,326 m² (1.5-1.7 times
    what its pool, cars, trees and chairs need); a garden's band now grows only when its own furniture does not fit."""
    scenes = [get_scene("house_single_floor", seed) for seed in range(5)]
    gardens = [_area(s.room("garden_0").bounds) for s in scenes]
    houses = [sum(_area(r.bounds) for r in s.rooms if not r.outdoor) for s in scenes]
    assert max(houses) / min(houses) > 1.15
    assert max(gardens) / min(gardens) < 1.01 and max(gardens) < 1500


GARDENS = [name for name in scene_names() if any(room_type(r) in OUTDOOR_ROOM_TYPES for r in catalog.scene_rooms(name))]


@pytest.mark.parametrize("name", GARDENS)
def test_the_rooms_of_a_house_connect_without_going_outdoors(name):
    """A kitchen or a closet whose only door opens to the garden is no house's plan; the spanning tree
    joined rooms through the garden in 13 of these scenes' first five seeds each."""
    for seed in range(3):
        s = get_scene(name, seed)
        indoor = [r.id for r in s.rooms if not r.outdoor]
        g = nx.Graph()
        g.add_nodes_from(indoor)
        g.add_edges_from(d.rooms for d in s.doors if set(d.rooms) <= set(indoor))
        assert nx.is_connected(g), (name, seed)
        assert all(any(r.id in d.rooms for d in s.doors) for r in s.rooms if r.outdoor)


def test_tiny_fixture_loads(tmp_path):
    s = load_scene("tests/fixtures/tiny_scene.json")
    assert [r.id for r in s.rooms] == ["kitchen_0", "living_room_0"]
    assert s.doors[0].rooms == ("kitchen_0", "living_room_0") and s.windows and {f.category for f in s.furniture} == {"fridge", "breakfast_table"}
    assert get_scene("tests/fixtures/tiny_scene.json") == s


def test_malformed_scene_names_field(tmp_path):
    data = json.loads(open("tests/fixtures/tiny_scene.json").read())
    data["rooms"][0]["bounds"] = [4.0, 0.0, 1.0, 4.0]
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(data))
    with pytest.raises(SceneError, match=r"rooms\[0\]\.bounds|rooms\[0\]"):
        load_scene(p)
    data = json.loads(open("tests/fixtures/tiny_scene.json").read())
    data["furniture"][0]["size"] = [0.7, "big", 1.0]
    p.write_text(json.dumps(data))
    with pytest.raises(SceneError, match=r"furniture\[0\]\.size"):
        load_scene(p)
