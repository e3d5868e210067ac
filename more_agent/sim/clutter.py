"""The scenes' own small objects: food, dishes, books, tools, ... as movable distractor items.

bddl's ``combined_room_object_list.json`` lists, per room of every BEHAVIOR-1K scene, the loose
objects OmniGibson loads with it (grocery_store_cafe: 6,586 in its store room, 1,411 of them
apples). The floor-plan generator keeps only furniture (``catalog.furniture_role``); this module puts
the rest back into a world as items, each with its category's real (median) size:

- what: every listed category that the generator drops as small (``furniture_role == 'skip'``),
  has a sized model and is not a structural fixture, up to ``MAX_PER_CATEGORY`` per room and
  ``MAX_PER_ROOM`` per room in all (counts scaled down in proportion when a room lists more);
- where: on the tops of the room's surfaces (tables, desks, counters, shelves, cabinets, beds,
  sofas, ...: ``SURFACE_SYNSETS``) and inside its storage furniture (cabinets, lockers, fridges,
  boxes: ``CONTAINER_SYNSETS``; closed ones hide what they hold, as for task items), a support
  drawn with probability proportional to its free area;
  ``FLOOR_SHARE`` of them, and those no support has room for, on a free floor spot. An item for
  which no room is left anywhere is not added (counted in ``Clutter.dropped``).

Everything is deterministic per (scene, seed). Goals only concern the task's scoped objects, so a
distractor apple is just another apple, as in BEHAVIOR-1K.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from functools import cache

import numpy as np

from more_agent.sim import catalog
from more_agent.sim.catalog import is_surface
from more_agent.sim.floorspots import free_floor_spot
from more_agent.sim.packing import support_surface
from more_agent.sim.world import World, WorldObject, floor_name
from more_agent.vocabulary import Relation

MAX_PER_CATEGORY = 32
"""Most items of one category per room (a store lists 1,411 apples: a few full shelf rows stay)."""

MAX_PER_ROOM = 480
"""Most items per room in all; with its furniture every grocery store then holds over 500 objects
while the render and scene-graph budgets hold (docs/tasks.md)."""

FLOOR_SHARE = 0.08
"""Share of the items put on the floor (boxes and bags by a shelf, a book dropped by a sofa)."""

FLOOR_MARGIN_M = 0.05
"""Gap kept between a floor item and walls, furniture and other floor items."""

MAX_SUPPORT_TOP_M = 2.0
"""Furniture whose top is higher than this is not used as a surface (nobody reaches it)."""

MIN_SUPPORT_TOP_M = 0.25
"""Furniture lower than this (mats, low platforms) is not used as a surface."""

CONTAINER_SYNSETS: frozenset[str] = frozenset({"cabinet.n.01", "cabinet.n.03", "refrigerator.n.01", "box.n.01"})
"""Openable furniture things are stored inside: cabinets, lockers, fridges, boxes (cartons); not
ovens, dishwashers, washers or laptops."""

FIXTURE_CATEGORIES: frozenset[str] = frozenset({"handle", "l_shaped_handle", "door_handle", "knob", "hinge"})
"""Small listed parts of other objects, not objects of their own."""


@dataclass
class Clutter:
    """What ``add_distractors`` put into a world."""

    items: list[str] = field(default_factory=list)
    """World names of the distractor items added, in order."""
    dropped: int = 0
    """Listed items (after the caps) for which no support and no floor spot had room."""


def clutter_rng(scene: str, seed: int) -> np.random.Generator:
    """The random stream of a scene's distractors, independent of the task's own."""
    return np.random.default_rng([seed, zlib.crc32(scene.encode()), 0xC1])


def room_item_counts(scene: str) -> dict[str, dict[str, int]]:
    """Room id -> {category: count} of the distractor items of a BEHAVIOR-1K scene, caps applied.

    An unknown scene (a hand-written scene file) lists none.
    """
    if scene not in catalog.scene_names():
        return {}
    sized = set(catalog.sized_categories())
    out: dict[str, dict[str, int]] = {}
    for room, objects in catalog.scene_rooms(scene).items():
        listed: dict[str, int] = {}
        for key, n in objects.items():
            category = key.rsplit("-", 1)[0]
            if category in sized and _is_loose(category):
                listed[category] = listed.get(category, 0) + n
        counts = _scale_to(MAX_PER_ROOM, {c: min(n, MAX_PER_CATEGORY) for c, n in sorted(listed.items())})
        if counts:
            out[room] = counts
    return out


def _scale_to(total: int, counts: dict[str, int]) -> dict[str, int]:
    """Counts scaled down in proportion to sum to ``total`` (largest remainders round up; each at
    least 1) when they sum to more; unchanged otherwise."""
    listed = sum(counts.values())
    if listed <= total:
        return counts
    exact = {c: n * total / listed for c, n in counts.items()}
    out = {c: max(1, int(x)) for c, x in exact.items()}
    by_remainder = sorted(counts, key=lambda c: (out[c] - exact[c], c))
    for c in by_remainder[: max(total - sum(out.values()), 0)]:
        out[c] += 1
    return out


@cache
def is_storage(category: str) -> bool:
    """Whether distractors are stored inside this (openable) furniture category (``CONTAINER_SYNSETS``)."""
    return catalog.descends_from(category, CONTAINER_SYNSETS)


def _is_loose(category: str) -> bool:
    return (
        category not in catalog.SKIPPED_CATEGORIES
        and category not in FIXTURE_CATEGORIES
        and catalog.furniture_role(category) == "skip"
    )


def add_distractors(world: World, rng: np.random.Generator, counts: dict[str, dict[str, int]] | None = None) -> Clutter:
    """Add the scene's own small objects to ``world`` as items (see module docstring).

    ``counts`` (room -> category -> n) defaults to ``room_item_counts(world.scene.name)``.
    """
    counts = room_item_counts(world.scene.name) if counts is None else counts
    rooms = {r.id for r in world.scene.rooms}
    clutter = Clutter()
    serial = 0
    slots = rng.spawn(1)[0]  # the slots' own stream: drawing them leaves every other draw as it was
    for room, per_category in counts.items():
        if room not in rooms:
            continue
        placer = _RoomPlacer(world, room, rng, slots)
        for category in sorted(per_category):
            synsets = catalog.category_synsets(category)
            synset, size = synsets[0] if synsets else None, catalog.category_size(category)
            openable, cloth = catalog.is_openable(category), catalog.is_cloth(category)
            for _ in range(per_category[category]):
                while f"{category}_o{serial}" in world.objects:
                    serial += 1
                name = f"{category}_o{serial}"
                world.add(
                    WorldObject(
                        name=name,
                        category=category,
                        kind="item",
                        room=room,
                        synset=synset,
                        center=np.zeros(3),
                        size=np.array(size, dtype=float),
                        openable=openable,
                        cloth=cloth,
                    )
                )
                if placer.place(name):
                    clutter.items.append(name)
                else:
                    del world.objects[name]
                    clutter.dropped += 1
    return clutter


class _RoomPlacer:
    """Scratch state for placing one room's distractors: its supports and which are full for what."""

    def __init__(self, world: World, room: str, rng: np.random.Generator, slots: np.random.Generator) -> None:
        self.world, self.room, self.rng, self.slots = world, room, rng, slots
        self.supports: list[tuple[WorldObject, Relation]] = []
        for obj in world.objects.values():
            if obj.kind != "furniture" or obj.room != room:
                continue
            if MIN_SUPPORT_TOP_M <= obj.top <= MAX_SUPPORT_TOP_M and is_surface(obj.category):
                self.supports.append((obj, "ontop"))
            if obj.openable and is_storage(obj.category):
                self.supports.append((obj, "inside"))
        self.area = np.array([_surface_area(world, s, rel) for s, rel in self.supports])
        self.full: set[tuple[int, str]] = set()
        """(support index, category) pairs known to have no room left for that category."""
        self._fitting: dict[str, list[int]] = {}

    def place(self, name: str) -> bool:
        """Put item ``name`` on / in a support with room, or on the floor; False when nothing has room."""
        obj = self.world.get(name)
        if self.rng.random() >= FLOOR_SHARE and self._on_support(obj):
            return True
        return self._on_floor(obj)

    def _on_support(self, obj: WorldObject) -> bool:
        if obj.category not in self._fitting:  # one category, one size
            self._fitting[obj.category] = [
                i for i, (s, rel) in enumerate(self.supports) if _fits(self.world, obj, s, rel)
            ]
        fits = [i for i in self._fitting[obj.category] if (i, obj.category) not in self.full]
        if not fits:
            return False
        p = self.area[fits] / self.area[fits].sum()
        for i in self.rng.choice(fits, size=len(fits), replace=False, p=p):
            support, rel = self.supports[int(i)]
            if self.world.place_if_room(obj.name, support.name, rel, rng=self.slots):
                return True
            self.full.add((int(i), obj.category))
        return False

    def _on_floor(self, obj: WorldObject) -> bool:
        half = obj.size[:2] / 2 + FLOOR_MARGIN_M
        xy = free_floor_spot(self.world, self.room, half, self.rng, exclude=obj.name)
        if xy is None:
            return False
        self.world.place_on_floor_at(obj.name, floor_name(self.room), xy)
        return True


def _surface_area(world: World, support: WorldObject, relation: Relation) -> float:
    lo, hi, _ = support_surface(support, relation)
    return float(max(hi[0] - lo[0], 0.0) * max(hi[1] - lo[1], 0.0))


def _fits(world: World, obj: WorldObject, support: WorldObject, relation: Relation) -> bool:
    """Whether the item's footprint fits the support's surface and, inside, its height fits the interior."""
    lo, hi, z = support_surface(support, relation)
    if np.any(obj.size[:2] > hi - lo):
        return False
    return relation == "ontop" or z + obj.size[2] <= support.top - 0.02
