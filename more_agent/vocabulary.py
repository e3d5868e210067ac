"""The words every layer shares about a house: floors, furniture, room types and spatial relations.

Defined once here, at the bottom of the package, so that the world, the scene graph, the planners
and the prompts cannot drift apart. Data only.

*Furniture* has two meanings in the code, on purpose, and both derive from BEHAVIOR-1K's scene
inventory (bddl's ``combined_room_object_list.json``): a world object of kind ``"furniture"`` is a
listed category big enough for the floor-plan generator to place as scene furniture
(``sim.catalog.furniture_role``); a *furniture category*, as planners reason about it, is any
category some room type lists (``planners.room_types.is_furniture``), which also covers the small
listed things the generator leaves to clutter (a store's cartons).
"""

from __future__ import annotations

from typing import Literal

Relation = Literal["inside", "ontop"]
"""How an object rests on another: the spatial relations of the world, the scene graph and the goals."""

RELATIONS: tuple[Relation, ...] = ("inside", "ontop")
"""The values of :data:`Relation`."""

ObjectKind = Literal["floor", "door", "furniture", "item"]
"""What a world object is: a room's ground, a door, scene furniture (fixed in place) or a movable item."""

FLOOR = "floor"
"""How planners, their scene text and their skills name a room's floor (floors are the rooms'
ground, not scene-graph objects)."""

FLOOR_SYNSETS = frozenset({"floor.n.01", "lawn.n.01", "driveway.n.01", "carpet.n.01"})
"""Synsets of room grounds: a goal's scope of one of these is a room's floor."""

OUTDOOR_ROOM_TYPES = frozenset({"garden"})
"""Room types that lie outdoors (their ground is lawn)."""

ROOM_TYPES: tuple[str, ...] = (
    "bar",
    "bathroom",
    "bedroom",
    "biology_lab",
    "break_room",
    "chemistry_lab",
    "childs_room",
    "classroom",
    "closet",
    "computer_lab",
    "conference_hall",
    "copy_room",
    "corridor",
    "dining_room",
    "empty_room",
    "entryway",
    "exercise_room",
    "garage",
    "garden",
    "grocery_store",
    "gym",
    "hammam",
    "infirmary",
    "kitchen",
    "living_room",
    "lobby",
    "locker_room",
    "meeting_room",
    "pantry_room",
    "phone_room",
    "playroom",
    "private_office",
    "sauna",
    "shared_office",
    "spa",
    "staircase",
    "storage_room",
    "television_room",
    "utility_room",
)
"""BEHAVIOR-1K room types: every type in bddl's combined_room_object_list.json (a test checks it against
the inventory), sorted. The LLM's room classifier chooses from them."""


def scope_synset(scope: str) -> str:
    """The synset of a bddl scope or goal term: 'apple.n.01_1' -> 'apple.n.01', 'cabinet.n.01_*' -> 'cabinet.n.01';
    a '?' dropped, and a quantified variable ('?bottle__of__catsup.n.01', no instance suffix) is its synset already."""
    term = scope.lstrip("?")
    head, _, suffix = term.rpartition("_")
    return head if head and "." not in suffix else term


def room_type(room_id: str) -> str:
    """The type of a room by its id: 'kitchen_0' -> 'kitchen' (bddl's room naming)."""
    return room_id.rsplit("_", 1)[0]
