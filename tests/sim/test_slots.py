"""Task items find room where there is room: the slot search behind instantiation.

Fifteen bddl activities stopped instantiating when slots began to avoid every box (docs/tasks.md,
"Report"): a free strip the slot grid did not line up with, an item that fits only turned, a next
layer that counted only the support's own items. These pin each rule and the nine activities it
brings back (the other six have no room without boxes passing through each other; docs/tasks.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from more_agent.sim import catalog, packing
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.placement_audit import enclosing_object
from more_agent.sim.predicates import is_inside
from more_agent.sim.scene import load_scene
from more_agent.sim.scenes import get_scene
from more_agent.sim.tasks import load_task, suitable_scenes
from more_agent.sim.world import World, WorldObject

TINY = Path(__file__).parent.parent / "fixtures" / "tiny_scene.json"

REGAINED = (
    "clean_a_flat_panel_monitor", "clean_a_pizza_stone", "cook_onions", "cook_sweet_potatoes",
    "make_dessert_watermelons", "make_lemon_pepper_wings", "serving_food_at_a_homeless_shelter",
    "set_up_a_home_office_in_your_garage", "sorting_books_on_shelf",
)
"""Instantiated in their first suitable scene with seed 0 before the strict slots, not after, and again now."""


def _add(world: World, name: str, category: str, kind: str, center: tuple[float, float, float],
         size: tuple[float, float, float], **extra: object) -> WorldObject:
    return world.add(WorldObject(name=name, category=category, kind=kind, center=np.array(center, dtype=float),
                                 size=np.array(size, dtype=float), **extra))


def _overlaps(world: World, name: str) -> list[str]:
    """Objects whose box meets ``name``'s by more than touching, other than its supports and its load."""
    lo, hi = world.objects[name].box()
    related = {p.name for p, _ in world.ancestors(name)} | {d.name for d in world.descendants(name)} | {name}
    return [o.name for o in world.objects.values() if o.kind != "floor" and o.name not in related
            and np.all(o.box()[0] < hi - 1e-5) and np.all(o.box()[1] > lo + 1e-5)]


def test_a_task_item_stacks_on_whatever_lies_in_the_way_not_only_the_supports_own_items() -> None:
    world = World(scene=load_scene(TINY))
    cabinet = _add(world, "cabinet_0", "bottom_cabinet_no_top", "furniture", (0.0, 0.0, 0.3), (0.73, 0.45, 0.6),
                   openable=True)
    _add(world, "board_0", "chopping_board", "item", (5.0, 5.0, 0.0), (0.24, 0.33, 0.02))
    _add(world, "knife_0", "carving_knife", "item", (5.0, 5.0, 0.0), (0.32, 0.04, 0.02))
    _add(world, "pan_0", "frying_pan", "item", (5.0, 5.0, 0.0), (0.54, 0.31, 0.09))
    assert world.place_if_room("board_0", cabinet.name, "inside")
    assert world.place_if_room("knife_0", "board_0", "ontop", stack=True)
    assert not world.place_if_room("pan_0", cabinet.name, "inside")  # no room beside the board
    assert world.place_if_room("pan_0", cabinet.name, "inside", stack=True)
    pan, knife = world.objects["pan_0"], world.objects["knife_0"]
    assert pan.bottom >= knife.top - 1e-9 and pan.top <= cabinet.top
    assert is_inside(world, "pan_0", cabinet.name) and enclosing_object(world, "pan_0") is None


def test_a_task_item_takes_the_far_end_when_the_near_corner_is_taken() -> None:
    world = World(scene=load_scene(TINY))
    stand = _add(world, "nightstand_0", "nightstand", "furniture", (0.0, 0.0, 0.25), (0.5, 0.8, 0.5))
    _add(world, "lamp_0", "table_lamp", "furniture", (0.0, -0.24, 0.8), (0.32, 0.32, 0.6))  # at the near end
    _add(world, "bag_0", "backpack", "item", (5.0, 5.0, 0.0), (0.45, 0.4, 0.45))
    assert not world.place_if_room("bag_0", stand.name, "ontop")  # a distractor's grid only: no room
    assert world.place_if_room("bag_0", stand.name, "ontop", stack=True)
    bag = world.objects["bag_0"]
    assert bag.box()[0][1] >= -0.08 and abs(bag.box()[1][1] - (0.4 - 0.01)) < 1e-9  # flush with the far edge
    assert bag.parent == stand.name and _overlaps(world, "bag_0") == []


def test_a_baking_sheet_lies_across_the_strip_a_microwave_leaves_on_a_sink() -> None:
    inst = instantiate_in_scene(load_task("clean_a_pizza_stone"), get_scene("Pomaria_1_int", 6), 6)
    world = inst.world
    sheet = world.objects[inst.scope["cookie_sheet.n.01_1"]]
    assert sheet.parent == "furniture_sink_0" and "microwave_0" in world.objects
    assert sheet.size[0] > sheet.size[1] and catalog.category_size(sheet.category)[0] < catalog.category_size(sheet.category)[1]
    assert _overlaps(world, sheet.name) == []


@pytest.mark.parametrize("task", REGAINED)
def test_activities_lost_to_the_strict_slots_instantiate_again(task: str) -> None:
    scene = get_scene(suitable_scenes(task)[0], 0)
    inst = instantiate_in_scene(load_task(task), scene, 0)
    GoalChecker(inst)  # counted only when the goal can be scored
    items = [n for n in inst.scope.values() if n in inst.world.objects and inst.world.objects[n].kind == "item"]
    assert {n: _overlaps(inst.world, n) for n in items if _overlaps(inst.world, n)} == {}


def _table_with_apple() -> World:
    """A breakfast table on the tiny scene and an apple not yet placed."""
    world = World(scene=load_scene(TINY))
    _add(world, "table_0", "breakfast_table", "furniture", (0.0, 0.0, 0.35), (1.6, 0.9, 0.7))
    _add(world, "apple_0", "apple", "item", (5.0, 5.0, 0.0), (0.08, 0.08, 0.08))
    return world


def test_an_item_rests_at_a_free_slot_the_seed_draws_not_the_first_in_reading_order() -> None:
    """OmniGibson samples an ontop pose over the support at random: with a generator, every free slot can come,
    the same one for the same seed; without, or inside a container, the first in reading order."""
    spots = []
    for seed in range(8):
        world = _table_with_apple()
        _add(world, "cup_0", "mug", "item", (5.0, 5.0, 0.0), (0.1, 0.1, 0.1))
        assert world.place_if_room("cup_0", "table_0", "ontop", rng=np.random.default_rng(seed))
        assert world.place_if_room("apple_0", "table_0", "ontop", rng=np.random.default_rng(seed + 100))
        assert _overlaps(world, "apple_0") == [] and world.objects["apple_0"].parent == "table_0"
        spots.append(tuple(np.round(world.objects["apple_0"].center, 6)))
    assert len(set(spots)) >= 6  # not one corner for every seed
    again = _table_with_apple()
    assert again.place_if_room("apple_0", "table_0", "ontop")
    apple, table = again.objects["apple_0"], again.objects["table_0"]
    assert np.all(apple.box()[0][:2] <= table.box()[0][:2] + 0.1)  # the near corner, in reading order
    cabinet = _add(again, "cabinet_0", "bottom_cabinet_no_top", "furniture", (3.0, 0.0, 0.3), (0.73, 0.45, 0.6),
                   openable=True)
    _add(again, "pear_0", "pear", "item", (5.0, 5.0, 0.0), (0.08, 0.08, 0.1))
    assert again.place_if_room("pear_0", cabinet.name, "inside", rng=np.random.default_rng(7))
    assert np.all(again.objects["pear_0"].box()[0][:2] <= cabinet.box()[0][:2] + 0.1)  # inside: packed from the corner
    kitchen = load_scene(TINY.parent / "tasks_kitchen_scene.json")
    first, second = (instantiate_in_scene("putting_shopping_away", kitchen, seed=3) for _ in range(2))
    assert {n: tuple(o.center) for n, o in first.world.objects.items()} == {
        n: tuple(o.center) for n, o in second.world.objects.items()
    }  # the same seed, the same world


def _meets(box: WorldObject, bottom: np.ndarray, top: np.ndarray) -> bool:
    """Whether ``box`` overlaps the space from ``bottom`` to ``top`` by more than 1e-5 m along every axis."""
    return all(
        box.center[k] - box.size[k] / 2 < top[k] - 1e-5 and box.center[k] + box.size[k] / 2 > bottom[k] + 1e-5
        for k in range(3)
    )


def _flush_box(name: str, slot: np.ndarray, half: np.ndarray, z: float) -> WorldObject:
    """A 10 cm box beside an item at ``slot`` (half extents ``half``) whose x-distance from the slot equals half the
    item plus half the box exactly in floating point: flush against it, taking no slot."""
    x = slot[0] + half[0] + 0.05
    gap = abs(slot[0] - x)
    h = gap - half[0]
    while half[0] + h != gap:  # the box's half width that adds up to the gap exactly
        h = float(np.nextafter(h, np.inf if half[0] + h < gap else -np.inf))
    return WorldObject(name=name, category="box", kind="item", center=np.array([x, slot[1], z + 0.05]),
                       size=np.array([2 * h, 0.1, 0.1]))


def test_the_first_free_slot_is_the_first_no_box_in_the_items_space_covers() -> None:
    """``in_space`` and ``free_slot`` against their definitions written out box by box: a box is in the space of
    an item on a surface when it overlaps it by more than 1e-5 m along all three axes (touching boxes, and boxes
    above the item's height, are not); a slot is taken when such a box lies closer than half the item (with the
    slot gap) plus half the box along both x and y. Boxes on a 5 cm lattice make touching faces common."""
    rng = np.random.default_rng(0)
    table = WorldObject(name="table_0", category="table", kind="furniture",
                        center=np.array([1.0, 1.0, 0.375]), size=np.array([1.2, 0.8, 0.75]))
    lo, hi, z = packing.support_surface(table, "ontop")
    lattice = 0.05
    for _ in range(40):
        others = [
            WorldObject(name=f"box_{i}", category="box", kind="item",
                        center=np.round(rng.uniform([0.3, 0.5, 0.7], [1.7, 1.5, 1.1]) / lattice) * lattice,
                        size=np.round(rng.uniform(0.05, 0.3, 3) / lattice) * lattice)
            for i in range(int(rng.integers(0, 12)))
        ]
        item = WorldObject(name="item_0", category="apple", kind="item", center=np.zeros(3),
                           size=np.round(rng.uniform(0.05, 0.25, 3) / lattice) * lattice)
        height = float(item.size[2])
        half = item.size[:2] / 2 + packing.SLOT_GAP_M / 2
        slots = packing._slots(lo, hi, half, flush=False)
        others += [_flush_box(f"flush_{k}", s, half, z) for k, s in enumerate(slots[rng.integers(0, len(slots), 2)])]
        there = [o for o in others if _meets(o, np.array([lo[0], lo[1], z]), np.array([hi[0], hi[1], z + height]))]
        assert [o.name for o in packing.in_space(others, lo, hi, z, height)] == [o.name for o in there]
        free = [
            s for s in slots
            if not any(all(abs(s[k] - o.center[k]) < half[k] + o.size[k] / 2 for k in (0, 1)) for o in there)
        ]
        slot = packing.free_slot(item, table, "ontop", others)
        if free:
            assert slot is not None and np.array_equal(slot[:2], free[0]) and slot[2] == z + height / 2
        else:
            assert slot is None
