"""Where items are put: never inside another object's box, never above the arm's reach on a tall shelf.

The two task worlds are the defects the pipeline-ceiling pass found (figures:
docs/benchmarks.md, "World"); the hand-built ones pin the rule behind them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from more_agent.sim.instantiate import instantiate
from more_agent.sim.packing import LEVELLED_CATEGORIES, REACH_TOP_M, support_surface
from more_agent.sim.placement_audit import audit, enclosing_object
from more_agent.sim.predicates import is_inside, is_ontop
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World, WorldObject

TINY = Path(__file__).parent.parent / "fixtures" / "tiny_scene.json"


def _world() -> World:
    return World(scene=load_scene(TINY))


def _add(world: World, name: str, category: str, kind: str, center: tuple[float, float, float],
         size: tuple[float, float, float], **extra: object) -> WorldObject:
    return world.add(WorldObject(name=name, category=category, kind=kind, center=np.array(center, dtype=float),
                                 size=np.array(size, dtype=float), **extra))


def _task_items(task: str, seed: int) -> tuple[World, list[str]]:
    inst = instantiate(task, seed=seed, start="task-room", distractors=False)
    virtual = set(inst.virtual_scopes)
    names = [n for s, n in inst.scope.items() if s not in virtual and inst.world.objects.get(n) is not None
             and inst.world.objects[n].kind == "item"]
    return inst.world, names


def test_items_on_a_coffee_table_stay_clear_of_the_tv_standing_on_it() -> None:
    world, items = _task_items("assembling_gift_baskets", 1)
    assert "standing_tv_0" in world.objects
    assert audit(world, items) == {"enclosed": {}, "out_of_reach": []}
    on_table = [n for n in items if world.objects[n].parent == "coffee_table_0"]
    assert len(on_table) >= 3


def test_items_on_a_tall_grocery_shelf_rest_on_a_level_within_reach() -> None:
    world, items = _task_items("buy_candle_making_supplies", 0)
    paraffin = world.objects["paraffin_1"]
    shelf = world.objects[paraffin.parent]
    assert shelf.category in LEVELLED_CATEGORIES and shelf.top > REACH_TOP_M
    assert shelf.bottom < paraffin.bottom <= REACH_TOP_M
    assert is_ontop(world, "paraffin_1", shelf.name)  # BEHAVIOR-1K's ontop holds on any level
    assert audit(world, items)["out_of_reach"] == []


def test_a_free_slot_avoids_furniture_standing_on_the_support() -> None:
    world = _world()
    table = _add(world, "table_0", "coffee_table", "furniture", (0.0, 0.0, 0.25), (1.0, 0.6, 0.5))
    _add(world, "tv_0", "standing_tv", "furniture", (-0.25, 0.0, 0.8), (0.5, 0.6, 0.6))
    for k in range(3):
        _add(world, f"cup_{k}", "cup", "item", (5.0, 5.0, 0.0), (0.1, 0.1, 0.1))
        world.place(f"cup_{k}", table.name, "ontop")
        assert enclosing_object(world, f"cup_{k}") is None
        assert world.objects[f"cup_{k}"].center[0] - 0.05 >= 0.0  # on the free half
    _add(world, "box_0", "carton", "item", (5.0, 5.0, 0.0), (0.6, 0.6, 0.1))
    assert not world.place_if_room("box_0", table.name, "ontop")  # only the free half is left


def test_a_full_open_container_takes_more_items_on_a_second_layer() -> None:
    world = _world()
    basket = _add(world, "basket_0", "wicker_basket", "furniture", (0.0, 0.0, 0.15), (0.3, 0.3, 0.3))
    for k in range(2):
        _add(world, f"corn_{k}", "sweet_corn", "item", (5.0, 5.0, 0.0), (0.28, 0.28, 0.08))
    assert world.place_if_room("corn_0", basket.name, "inside")
    assert not world.place_if_room("corn_1", basket.name, "inside")  # the floor is full
    assert world.place_if_room("corn_1", basket.name, "inside", stack=True)
    lower, upper = world.objects["corn_0"], world.objects["corn_1"]
    assert upper.bottom >= lower.top - 1e-9 and is_inside(world, "corn_1", basket.name)


def test_a_tall_shelf_takes_items_on_top_at_its_highest_level_within_reach() -> None:
    world = _world()
    shelf = _add(world, "shelf_0", "grocery_shelf", "furniture", (0.0, 0.0, 1.15), (1.6, 0.6, 2.3))
    low = _add(world, "table_0", "coffee_table", "furniture", (3.0, 0.0, 0.25), (1.0, 0.6, 0.5))
    for name in ("jar_0", "jar_1"):
        _add(world, name, "jar", "item", (5.0, 5.0, 0.0), (0.1, 0.1, 0.1))
    world.place("jar_0", shelf.name, "ontop")
    world.place("jar_1", low.name, "ontop")
    assert world.objects["jar_0"].bottom <= REACH_TOP_M < shelf.top
    assert world.objects["jar_0"].bottom > REACH_TOP_M - 0.4  # the highest level, not the lowest
    assert world.objects["jar_1"].bottom == low.top  # a low support keeps its top


def test_a_single_board_hung_high_keeps_items_on_its_top() -> None:
    world = _world()
    board = _add(world, "shelf_0", "shelf", "furniture", (0.0, 0.0, 2.15), (1.0, 0.3, 0.1))
    _add(world, "jar_0", "jar", "item", (5.0, 5.0, 0.0), (0.1, 0.1, 0.1))
    world.place("jar_0", board.name, "ontop")
    assert world.objects["jar_0"].bottom == board.top and enclosing_object(world, "jar_0") is None


def test_a_garment_folds_into_a_washer_where_a_rigid_box_of_its_size_does_not() -> None:
    world = _world()
    washer = _add(world, "washer_0", "washer", "furniture", (0.0, 0.0, 0.42), (0.58, 0.6, 0.85), openable=True)
    size = (0.77, 0.46, 0.31)  # the median jersey model: a draped heap wider than the drum
    for k in range(4):
        _add(world, f"jersey_{k}", "jersey", "item", (5.0, 5.0, 0.0), size, cloth=True)
        assert world.place_if_room(f"jersey_{k}", washer.name, "inside", stack=True)
        jersey = world.objects[f"jersey_{k}"]
        lo, hi, _ = support_surface(washer, "inside")
        assert np.all(jersey.box()[0][:2] >= lo - 1e-9) and np.all(jersey.box()[1][:2] <= hi + 1e-9)  # no overhang
        assert jersey.top <= washer.top and enclosing_object(world, f"jersey_{k}") is None
        assert jersey.size[0] * jersey.size[1] < size[0] * size[1]  # folded
    _add(world, "crate_0", "crate", "item", (5.0, 5.0, 0.0), size)
    world.place_if_room("crate_0", washer.name, "inside", stack=True)
    assert np.array_equal(world.objects["crate_0"].size, size)  # a rigid item keeps its shape
