"""Wall fixtures a task binds: the nails, hooks, mirrors, ... that BEHAVIOR-1K hangs on a room's walls.

The floor-plan generator leaves structural things out of every plan (``catalog.SKIPPED_CATEGORIES``:
walls, windows, switches, nails, ...), and the distractors never add them (``sim.clutter``). Yet
activities bind some of them with ``inroom``: store_christmas_lights takes its lights off the
garage's two wall nails. When a task's ``inroom`` scope needs a category of ``WALL_FIXTURE_HEIGHTS_M``
that bddl's object list gives for a room of the scene, ``hang_listed_fixtures`` hangs that room's
listed instances on its walls: against a full-height piece of wall (none in a door or window gap),
at the category's height, clear of every other box. Other worlds are unchanged: no plan gets them.

Deterministic per (scene, seed, room), from a random stream of its own, so every task sees the
same fixtures in the same world.
"""

from __future__ import annotations

import zlib

import numpy as np

from more_agent.sim import catalog
from more_agent.sim.scene import Wall
from more_agent.sim.world import World, WorldObject

WALL_FIXTURE_HEIGHTS_M: dict[str, float] = {
    "wall_nail": 1.5,
    "hook": 1.5,
    "towel_rack": 1.0,
    "mirror": 1.0,
    "wall_mounted_tv": 1.2,
    "whiteboard": 0.9,
    "blackboard": 0.9,
    "showerhead": 1.0,
    "electric_switch": 1.1,
    "wall_socket": 0.3,
    "picture": 1.3,
    "painting": 1.3,
    "portrait": 1.3,
    "wall_clock": 1.8,
    "paper_towel_dispenser": 1.2,
    "soap_dispenser": 1.0,
    "toilet_paper_holder": 0.6,
    "hand_dryer": 1.1,
}
"""Categories hung on a wall that the generator leaves out, with the height (m) of their bottom face
(lowered where the wall is not that high)."""

END_MARGIN_M = 0.15
"""Gap kept between a fixture and the ends of its piece of wall (corners, door and window gaps)."""

TRIES = 60
"""Random positions tried per fixture before the room is said to have no wall for it."""


def fixture_rng(scene: str, seed: int, room: str) -> np.random.Generator:
    """The random stream of one room's fixtures, independent of the task's and the distractors'."""
    return np.random.default_rng([seed, zlib.crc32(scene.encode()), zlib.crc32(room.encode()), 0xF1])


def listed_fixtures(scene: str, room: str, categories: set[str]) -> list[tuple[str, str]]:
    """(category, model) per listed instance in bddl's object list of ``room`` whose category is in
    ``categories`` and hangs on a wall; none for a scene that is not BEHAVIOR-1K's."""
    if scene not in catalog.scene_names():
        return []
    out: list[tuple[str, str]] = []
    for key, n in sorted(catalog.scene_rooms(scene).get(room, {}).items()):
        category, model = key.rsplit("-", 1)
        if category in categories and category in WALL_FIXTURE_HEIGHTS_M:
            out += [(category, model)] * n
    return out


def hang_listed_fixtures(world: World, room: str, categories: set[str]) -> list[str]:
    """Hang the room's listed wall fixtures of ``categories`` on its walls; their world names.

    A fixture for which no wall has room is left out (the task's matching then reports it missing).
    """
    scene = world.scene
    rng = fixture_rng(scene.name, scene.seed, room)
    added: list[str] = []
    for category, model in listed_fixtures(scene.name, room, categories):
        size = np.array(catalog.model_size(model) or catalog.category_size(category), dtype=float)
        box = _wall_spot(world, room, size, WALL_FIXTURE_HEIGHTS_M[category], rng)
        if box is None:
            continue
        k = sum(o.category == category for o in world.objects.values())
        while f"{category}_{k}" in world.objects:
            k += 1
        center, extent = box
        world.add(
            WorldObject(
                name=f"{category}_{k}",
                category=category,
                kind="furniture",
                room=room,
                synset=next(iter(catalog.category_synsets(category)), None),
                center=center,
                size=extent,
            )
        )
        added.append(f"{category}_{k}")
    return added


def _room_walls(world: World, room: str) -> list[tuple[Wall, str]]:
    """Full-height wall pieces along the room's edges, with the side of the room they are on."""
    x0, y0, x1, y1 = world.scene.room(room).bounds
    out = []
    for w in world.scene.walls:
        if w.z_min > 0:
            continue  # a lintel or a window's sill / top
        bx0, by0, bx1, by1 = w.bounds
        horizontal = bx1 - bx0 > by1 - by0
        if horizontal and bx1 > x0 and bx0 < x1:
            out += [(w, s) for s, y in (("S", y0), ("N", y1)) if by0 <= y <= by1]
        elif not horizontal and by1 > y0 and by0 < y1:
            out += [(w, s) for s, x in (("W", x0), ("E", x1)) if bx0 <= x <= bx1]
    return out


def _wall_spot(
    world: World, room: str, size: np.ndarray, height: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, size) of a box against one of the room's walls, its long side along the wall, its
    bottom at ``height`` (lower when the wall is low), meeting no other object's box; None if none."""
    rx0, ry0, rx1, ry1 = world.scene.room(room).bounds
    along, depth, tall = float(max(size[:2])), float(min(size[:2])), float(size[2])
    spans = []
    for wall, side in _room_walls(world, room):
        bx0, by0, bx1, by1 = wall.bounds
        lo, hi = (max(bx0, rx0), min(bx1, rx1)) if side in "SN" else (max(by0, ry0), min(by1, ry1))
        lo, hi = lo + END_MARGIN_M + along / 2, hi - END_MARGIN_M - along / 2
        if hi > lo:
            spans.append((wall, side, lo, hi))
    if not spans:
        return None
    others = [o.box() for o in world.objects.values() if o.kind in ("furniture", "door")]
    weights = np.array([hi - lo for _, _, lo, hi in spans])
    for _ in range(TRIES):
        wall, side, lo, hi = spans[int(rng.choice(len(spans), p=weights / weights.sum()))]
        a = float(rng.uniform(lo, hi))
        z = max(min(height, wall.z_max - tall), 0.0) + tall / 2
        bx0, by0, bx1, by1 = wall.bounds
        face = {"S": by1, "N": by0, "W": bx1, "E": bx0}[side]
        inward = depth / 2 if side in "SW" else -depth / 2
        if side in "SN":
            center, extent = np.array([a, face + inward, z]), np.array([along, depth, tall])
        else:
            center, extent = np.array([face + inward, a, z]), np.array([depth, along, tall])
        lo3, hi3 = center - extent / 2, center + extent / 2
        if not any(np.all(lo3 < b_hi) and np.all(b_lo < hi3) for b_lo, b_hi in others):
            return center, extent
    return None
