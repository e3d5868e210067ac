"""World state: every object with its pose, containment and articulation, and the robot.

The world is symbolic where the paper's magic actions are (what rests inside / on top of what, what
is open, what is held) and geometric where sensing and navigation need it (axis-aligned boxes).
Positions of movable items are derived from their support: an item placed on or in a parent takes
the first free slot on the parent's top surface or interior floor. Nothing here knows about tasks,
actions or rendering; they read and change the world through this API.
"""

from __future__ import annotations

import re
import string
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from more_agent.sim.scene import STRUCTURAL_CLASSES, Scene

Relation = Literal["inside", "ontop"]
ObjectKind = Literal["floor", "door", "furniture", "item"]

SLAB_FRACTION = 0.08
"""Thickness of a container's bottom / top slab as a share of its height (inner items rest on it)."""

SLOT_GAP_M = 0.02
"""Gap left between neighbouring items on one support."""

CARRY_HEIGHT_M = 1.0
"""Height of a held item's centre, above the robot base."""

REACH_TOP_M = 1.6
"""Highest surface the arm places on (the Fetch arm with its torso lowered, like the 1.2 m camera, which
sees items there from about a metre away). A support with inner levels whose top is higher takes
items on top on its highest level at most this high (``support_surface``)."""

LEVELLED_CATEGORIES = frozenset(
    """shelf bookcase grocery_shelf commercial_kitchen_shelf candy_dispenser_shelf dry_food_dispenser_shelf
    shoe_rack magazine_rack snack_rack""".split()
)
"""Supports with inner shelf levels: BEHAVIOR-1K's ``ontop`` holds on any of their levels."""

LEVEL_STEP_M = 0.4
"""Spacing of the inner levels of a ``LEVELLED_CATEGORIES`` support, from its bottom slab up."""

MAX_FOLDS = 3
"""Times a cloth item is folded in half, at most, to fit where it is put (``World.fit``)."""

CLOTH_LAYER_M = 0.01
"""Thickness of one layer of cloth: a garment folded n times lies 2^n layers thick (``World.fit``)."""


def floor_name(room_id: str) -> str:
    """Name of the floor object of a room (every room has one)."""
    return f"floor_{room_id}"


@dataclass
class WorldObject:
    """One object of the world. ``center`` / ``size`` describe its axis-aligned box in metres."""

    name: str
    category: str
    kind: ObjectKind
    center: np.ndarray
    size: np.ndarray
    room: str | None = None
    synset: str | None = None
    label: str = ""
    openable: bool = False
    is_open: bool = False
    cloth: bool = False
    """Folds to fit where it rests (``World.fit``), as BEHAVIOR-1K's deformable garments crumple."""
    parent: str | None = None
    relation: Relation | None = None
    instance_id: int = 0

    @property
    def movable(self) -> bool:
        """Items can be grasped and placed; floors, doors and furniture stay put."""
        return self.kind == "item"

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """(min corner, max corner) of the box."""
        half = self.size / 2
        return self.center - half, self.center + half

    def footprint(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the box seen from above."""
        (x0, y0, _), (x1, y1, _) = self.box()
        return float(x0), float(y0), float(x1), float(y1)

    @property
    def top(self) -> float:
        return float(self.center[2] + self.size[2] / 2)

    @property
    def bottom(self) -> float:
        return float(self.center[2] - self.size[2] / 2)


@dataclass
class RobotState:
    """The robot base pose (x, y in metres, yaw in radians from +x, counter-clockwise) and its gripper."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    held: str | None = None


@dataclass
class World:
    """The mutable state of one episode's world, built from a static ``Scene``.

    ``version`` increases on every change so that renderers and planners can cache derived data.
    """

    scene: Scene
    objects: dict[str, WorldObject] = field(default_factory=dict)
    robot: RobotState = field(default_factory=RobotState)
    class_names: list[str] = field(default_factory=lambda: list(STRUCTURAL_CLASSES))
    version: int = 0
    layout_version: int = 0
    """Increases on every change of an object (pose, support, open state); unlike ``version``, not
    when the robot merely moves, so renderers rebuild their geometry only when it changed. Carrying an
    item moves it but counts only when something rests in or on it: a held item is never drawn."""
    _labels_used: dict[str, int] = field(default_factory=dict, repr=False, init=False)
    """Category -> how many instance labels of it have been handed out."""

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def from_scene(cls, scene: Scene) -> World:
        """A world holding the scene's floors (one per room), doors and furniture, no items yet."""
        world = cls(scene=scene)
        for room in scene.rooms:
            x0, y0, x1, y1 = room.bounds
            world.add(WorldObject(
                name=floor_name(room.id), category=room.ground, kind="floor", room=room.id,
                center=np.array([(x0 + x1) / 2, (y0 + y1) / 2, -0.005]), size=np.array([x1 - x0, y1 - y0, 0.01]),
            ))
        for door in scene.doors:
            x0, y0, x1, y1 = door.bounds()
            world.add(WorldObject(
                name=door.id, category="door", kind="door", room=door.rooms[0], synset="door.n.01",
                center=np.array([(x0 + x1) / 2, (y0 + y1) / 2, door.height / 2]),
                size=np.array([x1 - x0, y1 - y0, door.height]), openable=True, is_open=door.open,
            ))
        for f in scene.furniture:
            world.add(WorldObject(
                name=f.id, category=f.category, kind="furniture", room=f.room, synset=f.synset,
                center=np.array(f.center, dtype=float), size=np.array(f.size, dtype=float),
                openable=f.openable, is_open=f.open,
            ))
        return world

    def add(self, obj: WorldObject) -> WorldObject:
        """Add an object, give it the next instance id and register its category as a semantic class."""
        if obj.name in self.objects:
            raise ValueError(f"duplicate object name {obj.name!r}")
        obj.instance_id = len(self.objects) + 1
        self.semantic_id(obj.category)
        self.objects[obj.name] = obj
        self.version += 1
        self.layout_version += 1
        return obj

    def semantic_id(self, category: str) -> int:
        """The semantic class id of a category (structural classes first), registering it if new."""
        try:
            return self.class_names.index(category)
        except ValueError:
            self.class_names.append(category)
            return len(self.class_names) - 1

    # -- instance labels ----------------------------------------------------------------------
    # An object has no label until it is observed (or named by the task description): labels are
    # handed out per category in that order, so a label never reveals an instance not yet seen.
    def reserve_label(self, name: str) -> str:
        """The object's label, giving it the next free one of its category first if it has none.

        Floors get none (they are named by their room).
        """
        obj = self.objects[name]
        if not obj.label and obj.kind != "floor":
            used = self._labels_used.get(obj.category, 0)
            obj.label = f"{obj.category} {_alpha(used)}"
            self._labels_used[obj.category] = used + 1
        return obj.label

    def observe(self, names: Iterable[str]) -> None:
        """Label the objects among ``names`` seen for the first time, in the order given."""
        for name in names:
            self.reserve_label(name)

    def display_label(self, name: str) -> str:
        """What the robot may call an object: its label once observed, else just its category."""
        obj = self.objects[name]
        return obj.label or obj.category

    def assign_labels(self) -> None:
        """Label every object not labelled yet, per category in name order (tools and tests; an
        episode labels objects as they are observed)."""
        for obj in sorted(self.objects.values(), key=lambda o: _natural_key(o.name)):
            self.reserve_label(obj.name)

    # -- queries ------------------------------------------------------------------------------
    def get(self, name: str) -> WorldObject:
        """The object with this name (KeyError if none)."""
        return self.objects[name]

    def by_label(self, label: str) -> WorldObject | None:
        """The object with this alphabetical label, if any."""
        return next((o for o in self.objects.values() if o.label == label), None)

    def children(self, name: str, relation: Relation | None = None) -> list[WorldObject]:
        """Objects resting directly inside / on top of ``name``."""
        return [o for o in self.objects.values() if o.parent == name and (relation is None or o.relation == relation)]

    def ancestors(self, name: str) -> list[tuple[WorldObject, Relation]]:
        """The chain of supports of ``name``, nearest first, with the relation to each."""
        chain: list[tuple[WorldObject, Relation]] = []
        obj = self.objects[name]
        while obj.parent is not None and obj.relation is not None:
            parent = self.objects[obj.parent]
            chain.append((parent, obj.relation))
            obj = parent
        return chain

    def descendants(self, name: str) -> list[WorldObject]:
        """Everything resting in / on ``name``, directly or through other objects (depth first)."""
        found: list[WorldObject] = []
        for child in self.children(name):
            found.append(child)
            found.extend(self.descendants(child.name))
        return found

    def is_inside(self, name: str, container: str) -> bool:
        """True when ``name`` is within ``container``: directly, or on / in something that is inside it.

        An apple on a plate in the fridge is inside the fridge; an apple in a bowl on a table is not
        inside the table: what counts is the relation of the link that reaches ``container``.
        """
        return any(parent.name == container and rel == "inside" for parent, rel in self.ancestors(name))

    def enclosing_closed_container(self, name: str) -> WorldObject | None:
        """The outermost closed container that ``name`` is inside of, or None if nothing hides it."""
        hidden_by = None
        for parent, rel in self.ancestors(name):
            if rel == "inside" and parent.openable and not parent.is_open:
                hidden_by = parent
        return hidden_by

    def is_observable(self, name: str) -> bool:
        """Whether sensors may see ``name``: not held and not shut away inside a closed container."""
        if self.robot.held == name:
            return False
        return self.enclosing_closed_container(name) is None

    def room_at(self, x: float, y: float) -> str | None:
        """The room whose footprint contains (x, y), if any."""
        for room in self.scene.rooms:
            x0, y0, x1, y1 = room.bounds
            if x0 <= x <= x1 and y0 <= y <= y1:
                return room.id
        return None

    def items(self) -> list[WorldObject]:
        """All movable objects."""
        return [o for o in self.objects.values() if o.movable]

    # -- changes ------------------------------------------------------------------------------
    def set_open(self, name: str, is_open: bool) -> None:
        """Open or close an openable object (no precondition checks: actions do those)."""
        obj = self.objects[name]
        if not obj.openable:
            raise ValueError(f"{name} is not openable")
        obj.is_open = is_open
        self.version += 1
        self.layout_version += 1

    def place(self, name: str, parent: str, relation: Relation) -> None:
        """Rest item ``name`` inside / on top of ``parent`` at the first free slot (no precondition checks)."""
        obj, support = self.objects[name], self.objects[parent]
        self._rest(obj, support, relation, *self._magic_fit(obj, support, relation))

    def place_if_room(self, name: str, parent: str, relation: Relation, *, stack: bool = False) -> bool:
        """Like ``place``, but only where it fits (``fit``); False (nothing changed) when it does not."""
        obj, support = self.objects[name], self.objects[parent]
        fitted = self.fit(obj, support, relation, stack=stack)
        if fitted is None:
            return False
        self._rest(obj, support, relation, *fitted)
        return True

    def place_on_floor_at(self, name: str, floor: str, xy: tuple[float, float]) -> None:
        """Rest item ``name`` on a room floor at a given position (no precondition checks)."""
        obj, support = self.objects[name], self.objects[floor]
        self._rest(obj, support, "ontop", np.array([xy[0], xy[1], support.top + obj.size[2] / 2]), obj.size)

    def _rest(self, obj: WorldObject, support: WorldObject, relation: Relation, center: np.ndarray, size: np.ndarray) -> None:
        """Make ``obj`` rest in / on ``support`` centred at ``center`` with box ``size`` (folded cloth; what
        rests on it moves along), out of the gripper if it was held."""
        obj.parent, obj.relation, obj.room, obj.size = support.name, relation, support.room, size
        self._move_subtree(obj, center)
        if self.robot.held == obj.name:
            self.robot.held = None
        self.version += 1
        self.layout_version += 1

    def pick(self, name: str) -> None:
        """Put item ``name`` in the robot's gripper, detached from its support (no precondition checks)."""
        obj = self.objects[name]
        obj.parent, obj.relation = None, None
        self.robot.held = name
        self._carry()
        self.version += 1
        self.layout_version += 1

    def set_robot_pose(self, x: float, y: float, yaw: float) -> None:
        """Move the robot base; a held item moves along with it."""
        self.robot.x, self.robot.y, self.robot.yaw = float(x), float(y), float(np.arctan2(np.sin(yaw), np.cos(yaw)))
        self._carry()
        self.version += 1
        if self.robot.held is not None and self.children(self.robot.held):  # what rests in / on it moved along
            self.layout_version += 1

    def _carry(self) -> None:
        """Move the held item (and what rests in / on it) to the gripper, ``CARRY_HEIGHT_M`` above the base."""
        if self.robot.held is not None:
            held = self.objects[self.robot.held]
            held.room = self.room_at(self.robot.x, self.robot.y)
            self._move_subtree(held, np.array([self.robot.x, self.robot.y, CARRY_HEIGHT_M]))

    def _move_subtree(self, obj: WorldObject, center: np.ndarray) -> None:
        """Move ``obj`` to ``center``; what rests in / on it moves by the same offset (and changes room)."""
        delta = center - obj.center
        obj.center = center
        for d in self.descendants(obj.name):
            d.center = d.center + delta
            d.room = obj.room

    # -- geometry helpers -----------------------------------------------------------------------
    def support_surface(self, support: WorldObject, relation: Relation) -> tuple[np.ndarray, np.ndarray, float]:
        """(footprint min xy, footprint max xy, surface z) where items rest in / on ``support``."""
        lo, hi = support.box()
        if relation == "ontop":
            return lo[:2], hi[:2], _top_level(support)
        slab = SLAB_FRACTION * support.size[2]
        margin = np.minimum(0.05, support.size[:2] * 0.1)
        return lo[:2] + margin, hi[:2] - margin, support.bottom + slab

    def _magic_fit(self, obj: WorldObject, support: WorldObject, relation: Relation) -> tuple[np.ndarray, np.ndarray]:
        """Centre and size where ``obj`` fits, stacking when the surface is full (``fit``), else the
        support's centre: magic placement, like the paper's, never fails for lack of room."""
        fitted = self.fit(obj, support, relation, stack=True)
        if fitted is not None:
            return fitted
        lo, hi, z = self.support_surface(support, relation)
        cx, cy = (lo + hi) / 2
        return np.array([cx, cy, z + obj.size[2] / 2]), obj.size

    def fit(self, obj: WorldObject, support: WorldObject, relation: Relation, *, stack: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
        """(centre, size) of ``obj`` at its first free slot (``free_slot``) in its own shape or, for
        cloth, folded in half up to ``MAX_FOLDS`` times, as a garment goes into a washer or a carton;
        None when no shape fits. A fold halves the longer side and lays the garment flat, 2^folds
        layers of cloth thick at most (a garment model's box is a draped heap, mostly air)."""
        lo, hi, _ = self.support_surface(support, relation)
        size, folds = obj.size, MAX_FOLDS if obj.cloth else 0
        for fold in range(folds + 1):
            if fold:
                size = size * np.where(np.arange(3) == np.argmax(size[:2]), 0.5, 1.0)
                size[2] = min(size[2], CLOTH_LAYER_M * 2**fold)
            if fold < folds and np.any(size[:2] + SLOT_GAP_M > hi - lo):
                continue  # cloth folds rather than overhang
            slot = self.free_slot(obj, support, relation, stack=stack, size=size)
            if slot is not None:
                return slot, size
        return None

    def free_slot(
        self, obj: WorldObject, support: WorldObject, relation: Relation, *, stack: bool = False, size: np.ndarray | None = None,
    ) -> np.ndarray | None:
        """Centre of the first slot on the support, in reading order, where the item's box (of ``size``,
        default its own) meets no other box (``_obstacles``); with ``stack``, when the surface is full,
        on the next layer up (on the items already there; in a closed-lid container only while it fits
        under the lid). An item wider than the surface overhangs it, centred. None when there is no such slot."""
        size = obj.size if size is None else size
        lo, hi, z = self.support_surface(support, relation)
        half = size[:2] / 2 + SLOT_GAP_M / 2
        xs, ys = (_slot_centres(lo[k], hi[k], half[k]) for k in (0, 1))
        gx, gy = np.meshgrid(xs, ys)  # rows follow y: reading order is row by row
        slots = np.stack([gx.ravel(), gy.ravel()], axis=1)
        while True:
            others = self._obstacles(obj, support, lo, hi, z, size[2])
            free = slots
            if others:
                centers = np.array([o.center[:2] for o in others])
                reach = half + np.array([o.size[:2] / 2 for o in others])
                overlap = np.all(np.abs(slots[:, None, :] - centers[None]) < reach[None], axis=2).any(axis=1)
                free = slots[~overlap]
            if len(free):
                return np.array([free[0, 0], free[0, 1], z + size[2] / 2])
            layer = [o.top for o in others if o.parent == support.name and o.relation == relation]
            lidded = relation == "inside" and support.openable
            if not stack or not layer or (lidded and max(layer) + size[2] > support.top):
                return None
            z = max(layer)

    def _obstacles(
        self, obj: WorldObject, support: WorldObject, lo: np.ndarray, hi: np.ndarray, z: float, height: float,
    ) -> list[WorldObject]:
        """Objects in the space an item of ``height`` would take on the surface (``lo``, ``hi``, ``z``):
        items already there and anything else standing in it (a TV on the coffee table, a shelf
        hung above a desk), but not the supports of ``support`` nor ``obj``, its load or the held item."""
        lo3, hi3 = np.array([lo[0], lo[1], z]), np.array([hi[0], hi[1], z + height])
        skip = {obj.name, support.name, self.robot.held} | {o.name for o in self.descendants(obj.name)}
        skip |= {parent.name for parent, _ in self.ancestors(support.name)}
        objs = [o for o in self.objects.values() if o.kind != "floor" and o.name not in skip]
        if not objs:
            return []
        centers, halves = np.array([o.center for o in objs]), np.array([o.size for o in objs]) / 2
        eps = 1e-5  # boxes that merely touch (a card under a barrel's band) do not overlap
        meets = np.all(centers - halves < hi3 - eps, axis=1) & np.all(centers + halves > lo3 + eps, axis=1)
        return [o for o, m in zip(objs, meets) if m]


def _slot_centres(lo: float, hi: float, half: float) -> np.ndarray:
    """Slot centres along one axis of a surface from ``lo`` to ``hi`` for an item of half-width ``half``;
    the surface's centre alone when the item is wider."""
    centres = np.arange(lo + half, hi - half + 1e-9, 2 * half)
    return centres if len(centres) else np.array([(lo + hi) / 2])


def _top_level(support: WorldObject) -> float:
    """Height items rest at on top of ``support``: its top, or for a levelled support taller than the
    arm reaches (``LEVELLED_CATEGORIES``) its highest inner level at most ``REACH_TOP_M`` high. Inner
    levels lie ``LEVEL_STEP_M`` apart from the bottom slab up, a step or more below the top; a
    support with none within reach (a single board hung high) keeps its top."""
    if support.category not in LEVELLED_CATEGORIES or support.top <= REACH_TOP_M:
        return support.top
    first = support.bottom + SLAB_FRACTION * support.size[2]
    highest = min(REACH_TOP_M, support.top - LEVEL_STEP_M)
    if highest < first:
        return support.top
    return first + LEVEL_STEP_M * np.floor((highest - first) / LEVEL_STEP_M)


def _alpha(i: int) -> str:
    """0 -> A, 25 -> Z, 26 -> AA, ... (spreadsheet-style column letters)."""
    letters = ""
    i += 1
    while i:
        i, rem = divmod(i - 1, 26)
        letters = string.ascii_uppercase[rem] + letters
    return letters


def _natural_key(name: str) -> list[object]:
    """Sort 'apple_2' before 'apple_10'."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]
