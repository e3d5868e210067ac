"""Wall fixtures a task binds (sim/fixtures.py) and the activities that need them."""

from __future__ import annotations

import numpy as np

from more_agent.sim.fixtures import (
    WALL_FIXTURE_HEIGHTS_M,
    hang_listed_fixtures,
    listed_fixtures,
)
from more_agent.sim.instantiate import InstantiationError, instantiate
from more_agent.sim.scenes import get_scene
from more_agent.sim.tasks import task_set
from more_agent.sim.world import World

SCENE, GARAGE = "house_double_floor_lower", "garage_0"


def _against_a_wall(world: World, name: str) -> bool:
    """The box's back face touches a full-height wall piece's face, within the piece's length."""
    lo, hi = world.get(name).box()
    for w in world.scene.walls:
        if w.z_min > 0 or w.z_max < hi[2]:
            continue
        bx0, by0, bx1, by1 = w.bounds
        if bx0 <= lo[0] and hi[0] <= bx1 and (abs(lo[1] - by1) < 1e-6 or abs(hi[1] - by0) < 1e-6):
            return True
        if by0 <= lo[1] and hi[1] <= by1 and (abs(lo[0] - bx1) < 1e-6 or abs(hi[0] - bx0) < 1e-6):
            return True
    return False


def test_listed_wall_nails_hang_on_the_garage_walls_clear_of_everything() -> None:
    world = World.from_scene(get_scene(SCENE, 0))
    assert "wall_nail" not in {o.category for o in world.objects.values()}  # the plan leaves them out
    others = [o.box() for o in world.objects.values() if o.kind in ("furniture", "door")]
    names = hang_listed_fixtures(world, GARAGE, {"wall_nail", "car"})
    assert names == ["wall_nail_0", "wall_nail_1"]  # bddl lists two in the garage; the car is no fixture
    for name in names:
        nail = world.get(name)
        assert (nail.kind, nail.room, nail.synset) == ("furniture", GARAGE, "wall_nail.n.01")
        assert abs(nail.bottom - WALL_FIXTURE_HEIGHTS_M["wall_nail"]) < 1e-9
        assert world.room_at(float(nail.center[0]), float(nail.center[1])) == GARAGE
        assert _against_a_wall(world, name), name
        lo, hi = nail.box()
        assert not any(np.all(lo < b_hi) and np.all(b_lo < hi) for b_lo, b_hi in others)


def test_fixtures_are_the_same_per_world_and_only_those_listed() -> None:
    a, b = (World.from_scene(get_scene(SCENE, 0)) for _ in range(2))
    hang_listed_fixtures(a, GARAGE, {"wall_nail"})
    hang_listed_fixtures(b, GARAGE, {"wall_nail"})
    assert [tuple(o.center) for o in a.objects.values()] == [tuple(o.center) for o in b.objects.values()]
    assert hang_listed_fixtures(b, GARAGE, {"mirror"}) == []  # not listed in this garage
    assert listed_fixtures("my_scene.json", GARAGE, {"wall_nail"}) == []  # a scene file lists nothing
    assert listed_fixtures(SCENE, GARAGE, {"wall_nail"}) == [("wall_nail", "wlnail")] * 2


def test_store_christmas_lights_instantiates_with_the_default_worlds() -> None:
    """It failed for every seed ('no garage ... holds a wall_nail.n.01') before wall fixtures were hung."""
    done = []
    for seed in range(5):
        try:
            inst = instantiate("store_christmas_lights", seed=seed)
        except InstantiationError:
            continue
        done.append(seed)
        nails = [inst.world.get(inst.scope[f"wall_nail.n.01_{k}"]) for k in (1, 2)]
        assert {n.category for n in nails} == {"wall_nail"} and {n.room for n in nails} == {GARAGE}
        assert inst.distractors and inst.start_mode == "random"  # the default, harder worlds
        assert "(attached icicle_lights.n.01_1 wall_nail.n.01_1)" in inst.unsupported_literals
    assert done == list(range(5))


def test_task_data_counts_store_christmas_lights() -> None:
    assert "store_christmas_lights" in task_set("behavior-rearrange")
