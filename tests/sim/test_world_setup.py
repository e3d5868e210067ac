"""The benchmark world's setup: scene draw, random start, the scenes' own objects, labels in order of observation."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from more_agent.errors import UserError
from more_agent.sim.actions import approach_rounds
from more_agent.sim.clutter import (
    MAX_PER_CATEGORY,
    MAX_PER_ROOM,
    add_distractors,
    clutter_rng,
    is_storage,
    is_surface,
    room_item_counts,
)
from more_agent.sim.floorspots import PASSAGE_CLEARANCE_M
from more_agent.sim.instantiate import instantiate, instantiate_in_scene
from more_agent.sim.navgrid import nav_grid, shortest_path
from more_agent.sim.render import Renderer
from more_agent.sim.scene import load_scene, save_scene
from more_agent.sim.scenes import get_scene
from more_agent.sim.start import random_start
from more_agent.sim.tasks import EXCLUDED_SCENES, check_scene_suits, draw_scenes, episode_scenes, suitable_scenes
from more_agent.sim.world import World, WorldObject

KITCHEN = Path(__file__).parent.parent / "fixtures" / "tasks_kitchen_scene.json"


# -- scene per episode -------------------------------------------------------------------------------
def test_scene_draw_is_seeded_uniform_and_skips_the_papers_excluded_scenes() -> None:
    task = "putting_shopping_away"
    assert "restaurant_diner" in suitable_scenes(task)
    scenes = episode_scenes(task)
    assert not set(scenes) & set(EXCLUDED_SCENES)
    assert draw_scenes(task, 4) == draw_scenes(task, 4) and sorted(draw_scenes(task, 4)) == scenes
    firsts = [draw_scenes(task, seed)[0] for seed in range(60)]
    assert len(set(firsts)) >= 10  # not always the alphabetically first scene


def test_a_named_scene_must_suit_the_task() -> None:
    with pytest.raises(UserError, match="scene 'office_large' does not suit task 'putting_shopping_away'; choose --scene"):
        check_scene_suits("putting_shopping_away", "office_large")
    check_scene_suits("putting_shopping_away", "Rs_int")
    check_scene_suits("putting_shopping_away", "my_scene.json")  # files are taken as they are


# -- random start ------------------------------------------------------------------------------------
def test_random_start_is_reachable_seeded_and_measured() -> None:
    scene = load_scene(KITCHEN)
    rooms = set()
    for seed in range(6):
        inst = instantiate_in_scene("putting_shopping_away", scene, seed=seed)
        world, facts = inst.world, inst.start
        rooms.add(world.room_at(world.robot.x, world.robot.y))
        grid = nav_grid(world, all_doors_open=True)
        targets = [n for n in inst.scope.values() if n in world.objects and world.get(n).kind != "floor"]
        poses = [p for t in targets for r in approach_rounds(world, t) for p in r]
        assert shortest_path(grid, (world.robot.x, world.robot.y), poses).found  # some task object is reachable
        assert facts is not None and facts.start_room == world.room_at(world.robot.x, world.robot.y)
        assert facts.task_rooms == ["kitchen_0"]
        assert facts.start_to_task_m is not None and facts.start_to_task_m >= 0
    assert rooms == {"kitchen_0", "corridor_0"}  # both rooms get drawn


def test_the_robot_never_starts_among_floor_items_or_behind_a_row_of_them() -> None:
    """The world's base drives over floor items, the robot's map does not: a start is drawn clear of them
    (``PASSAGE_CLEARANCE_M``) and connected to the task on a grid where they block, so a row of boxes across
    the kitchen leaves the strip behind it (no task object there) out of the draw, where starts landed before."""
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)
    world, rng = inst.world, np.random.default_rng(0)
    targets = [n for n in inst.scope.values() if n in world.objects and world.get(n).kind != "floor"]
    assert any(random_start(world, targets, rng)[0] > 4.7 for _ in range(300))  # type: ignore[index]
    for k in range(9):  # boxes 0.5 m long across the kitchen (x 4.5-4.7), from its wall to a counter
        world.add(
            WorldObject(
                name=f"box_{k}", category="carton", kind="item", center=np.zeros(3), size=np.array([0.2, 0.5, 0.4])
            )
        )
        world.place_on_floor_at(f"box_{k}", "floor_kitchen_0", (4.6, 0.25 + 0.5 * k))
    starts = [random_start(world, targets, rng) for _ in range(300)]
    assert all(s is not None and s[0] < 4.5 - PASSAGE_CLEARANCE_M + 0.075 for s in starts)  # uniform within a cell


@pytest.mark.slow
def test_random_start_draws_rooms_uniformly_random_area_draws_by_area() -> None:
    inst = instantiate("putting_shopping_away", "Rs_int", seed=0, start="task-room", distractors=False)
    world, rng = inst.world, np.random.default_rng(0)
    targets = [n for n in inst.scope.values() if n in world.objects and world.get(n).kind != "floor"]

    def shares(by_room: bool) -> Counter[str]:
        rooms = Counter(world.room_at(*random_start(world, targets, rng, by_room=by_room)[:2]) for _ in range(600))
        return Counter({r: n / 600 for r, n in rooms.items()})

    per_room, per_area = shares(True), shares(False)
    n = len(per_room)
    assert n >= 3 and all(0.5 / n < s < 1.6 / n for s in per_room.values())
    largest = max(world.scene.rooms, key=lambda r: (r.bounds[2] - r.bounds[0]) * (r.bounds[3] - r.bounds[1])).id
    assert per_area[largest] > 1.3 / n > per_room[largest]


def test_task_room_start_keeps_the_tasks_own_room() -> None:
    for seed in range(4):
        inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=seed, start="task-room")
        assert inst.world.room_at(inst.world.robot.x, inst.world.robot.y) == "kitchen_0"


def test_unknown_start_names_the_choices() -> None:
    with pytest.raises(UserError, match="unknown start 'kitchen'; use --start with one of: random, random-area, task-room"):
        instantiate("putting_shopping_away", start="kitchen")


# -- the scenes' own objects -------------------------------------------------------------------------
def test_store_counts_follow_bddl_up_to_the_caps() -> None:
    counts = room_item_counts("grocery_store_cafe")
    store = counts["grocery_store_0"]
    assert sum(store.values()) == MAX_PER_ROOM  # 6,586 listed
    assert store["apple"] == max(store.values()) <= MAX_PER_CATEGORY and min(store.values()) >= 1
    assert counts["dining_room_0"] == {"bowl": 12, "magazine": 12, "beaker": 8, "teacup": 4}  # under the caps: as listed
    assert "bathroom_0" not in room_item_counts("grocery_store_asian")  # it lists only door handles
    assert room_item_counts("my_hand_written_scene") == {}


def test_distractors_rest_on_supports_inside_containers_and_on_the_floor() -> None:
    world = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0, distractors=False).world
    before = set(world.objects)
    clutter = add_distractors(world, np.random.default_rng(0), {"kitchen_0": {"apple": 30, "bowl": 10, "plate": 10}})
    assert len(clutter.items) + clutter.dropped == 50 and len(clutter.items) >= 40
    added = [world.get(n) for n in clutter.items]
    assert not set(clutter.items) & before and all(o.movable and o.room == "kitchen_0" for o in added)
    relations = {(world.get(o.parent).kind, o.relation) for o in added}
    assert ("furniture", "ontop") in relations and ("furniture", "inside") in relations
    hidden = [o for o in added if not world.is_observable(o.name)]
    assert hidden and all(world.enclosing_closed_container(o.name) is not None for o in hidden)
    for support in {o.parent for o in added}:  # no two items on one support overlap
        items = [o for o in world.children(support) if o.name in clutter.items]
        for i, a in enumerate(items):
            for b in items[i + 1:]:
                if a.relation == b.relation:
                    gap = np.abs(a.center[:2] - b.center[:2]) - (a.size[:2] + b.size[:2]) / 2
                    assert np.any(gap >= -1e-9), (a.name, b.name)


def test_surfaces_and_storage_follow_the_taxonomy() -> None:
    assert all(map(is_surface, ("desk", "cubicle", "countertop", "shelf", "bottom_cabinet", "sofa", "shopping_cart")))
    assert not any(map(is_surface, ("monitor", "table_lamp", "range_hood", "pot_plant", "bicycle", "swivel_chair")))
    assert all(is_storage(c) for c in ("bottom_cabinet", "locker", "fridge", "carton"))
    assert not any(is_storage(c) for c in ("oven", "laptop", "dishwasher", "blender"))


def test_office_distractors_rest_on_desks_and_tables_not_on_monitors() -> None:
    world = World.from_scene(get_scene("office_large", 0))
    clutter = add_distractors(world, clutter_rng("office_large", 0))
    supports = Counter(world.get(world.get(n).parent).category for n in clutter.items)
    assert supports["desk"] + supports["conference_table"] > len(clutter.items) / 3
    furniture = {o.category for o in world.objects.values() if o.kind == "furniture"}
    assert {"monitor", "photocopier", "bottom_cabinet"} <= furniture
    for category in supports:
        assert category.startswith("floor") or is_surface(category) or is_storage(category), category


def test_grocery_store_is_cluttered_and_deterministic() -> None:
    a = instantiate("buy_a_air_conditioner", "grocery_store_convenience", seed=1)
    b = instantiate("buy_a_air_conditioner", "grocery_store_convenience", seed=1)
    assert len(a.world.objects) >= 500 and len(a.distractors) >= 400
    assert [tuple(a.world.get(n).center) for n in a.distractors] == [tuple(b.world.get(n).center) for n in b.distractors]
    assert not set(a.distractors) & set(a.scope.values())


# -- labels in order of observation -----------------------------------------------------------------
def test_labels_follow_observation_and_reveal_no_unseen_instance() -> None:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=2)
    world, labels = inst.world, inst.labels
    named = {o.name for o in world.objects.values() if labels.label(o.name)}
    assert named == {"fridge_0", inst.scope["cabinet.n.01_1"]}  # only what the description names
    assert "fridge A" in inst.description
    renderer = Renderer()
    seen: list[str] = []
    for k in range(12):
        world.set_robot_pose(world.robot.x, world.robot.y, k * np.pi / 6)
        version = world.version
        table = labels.table(world, renderer.render(world).instance)
        assert world.version == version  # seeing and labelling change nothing in the world
        seen += [d["name"] for d in table.values() if d["name"] not in seen]
        assert all(d["label"] for d in table.values() if world.get(d["name"]).kind != "floor")
    by_category: dict[str, list[str]] = {}
    for o in world.objects.values():
        if labels.label(o.name):
            by_category.setdefault(o.category, []).append(labels.label(o.name).rsplit(" ", 1)[1])
    for letters in by_category.values():  # per category the letters handed out are A, B, C, ... without gaps
        assert sorted(letters, key=lambda s: (len(s), s)) == [chr(ord("A") + i) for i in range(len(letters))]
    unseen = [o for o in world.objects.values() if o.name not in seen and o.kind != "floor" and o.name not in named]
    assert all(labels.label(o.name) == "" and labels.display(o) == o.category for o in unseen)


def test_what_one_frame_shows_first_is_labelled_in_reading_order_of_its_first_pixels() -> None:
    """Two countertops first seen in the same frame: the one whose first pixel comes first (row by row) is A,
    however the instance ids run."""
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=2)
    world, labels = inst.world, inst.labels
    low, high = sorted((world.get("countertop_0"), world.get("countertop_1")), key=lambda o: o.instance_id)
    image = np.zeros((3, 4), dtype=np.int32)
    image[1, 3], image[2, 0], image[2, 2] = high.instance_id, low.instance_id, high.instance_id
    table = labels.table(world, image)
    assert (labels.label(high.name), labels.label(low.name)) == ("countertop A", "countertop B")
    assert set(table) == {low.instance_id, high.instance_id}


def test_assign_all_labels_the_rest_after_the_reserved() -> None:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=2)
    inst.labels.assign_all(inst.world)
    assert inst.labels.label("fridge_0") == "fridge A"
    cabinets = sorted(inst.labels.label(o.name) for o in inst.world.objects.values() if o.category == "bottom_cabinet")
    assert cabinets == ["bottom_cabinet A", "bottom_cabinet B"]


def test_a_forced_scene_that_cannot_hold_the_task_says_what_to_change(tmp_path: Path) -> None:
    scene = load_scene(KITCHEN)
    scene = scene.model_copy(update={"furniture": [f for f in scene.furniture if f.category != "fridge"]})
    path = tmp_path / "no_fridge.json"
    save_scene(scene, path)
    with pytest.raises(UserError, match=r"inroom electric_refrigerator.*seed 3\); choose another --seed or --scene$"):
        instantiate("putting_shopping_away", str(path), seed=3)
