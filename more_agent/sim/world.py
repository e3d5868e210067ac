"""World state: every object with its pose, containment and articulation, and the robot.

The world is symbolic where the paper's magic actions are (what rests inside / on top of what, what
is open, what is held) and geometric where sensing and navigation need it (axis-aligned boxes).
Positions of movable items are derived from their support: an item placed on or in a parent takes
the first free slot on the parent's top surface or interior floor (:mod:`more_agent.sim.packing`
says where; the world only rests it there). Nothing here knows about tasks,
actions, rendering or what the robot calls an object (:mod:`more_agent.sim.labels`); they read and change the world through this API.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from more_agent.sim import packing
from more_agent.sim.objects import WorldObject
from more_agent.sim.scene import STRUCTURAL_CLASSES, Scene
from more_agent.vocabulary import Relation

CARRY_HEIGHT_M = 1.0
"""Height of a held item's centre, above the robot base."""


def floor_name(room_id: str) -> str:
    """Name of the floor object of a room (every room has one)."""
    return f"floor_{room_id}"


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

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def from_scene(cls, scene: Scene) -> World:
        """A world holding the scene's floors (one per room), doors and furniture, no items yet."""
        world = cls(scene=scene)
        for room in scene.rooms:
            x0, y0, x1, y1 = room.bounds
            world.add(
                WorldObject(
                    name=floor_name(room.id),
                    category=room.ground,
                    kind="floor",
                    room=room.id,
                    center=np.array([(x0 + x1) / 2, (y0 + y1) / 2, -0.005]),
                    size=np.array([x1 - x0, y1 - y0, 0.01]),
                )
            )
        for door in scene.doors:
            x0, y0, x1, y1 = door.bounds()
            world.add(
                WorldObject(
                    name=door.id,
                    category="door",
                    kind="door",
                    room=door.rooms[0],
                    synset="door.n.01",
                    center=np.array([(x0 + x1) / 2, (y0 + y1) / 2, door.height / 2]),
                    size=np.array([x1 - x0, y1 - y0, door.height]),
                    openable=True,
                    is_open=door.open,
                )
            )
        for f in scene.furniture:
            world.add(
                WorldObject(
                    name=f.id,
                    category=f.category,
                    kind="furniture",
                    room=f.room,
                    synset=f.synset,
                    center=np.array(f.center, dtype=float),
                    size=np.array(f.size, dtype=float),
                    openable=f.openable,
                    is_open=f.open,
                )
            )
        return world

    def add(self, obj: WorldObject) -> WorldObject:
        """Add an object, give it the next instance id and register its category as a semantic class."""
        if obj.name in self.objects:
            raise ValueError(f"duplicate object name {obj.name!r}")
        obj.instance_id = len(self.objects) + 1
        self.semantic_id(obj.category)
        self.objects[obj.name] = obj
        self._changed(layout=True)
        return obj

    def semantic_id(self, category: str) -> int:
        """The semantic class id of a category (structural classes first), registering it if new."""
        try:
            return self.class_names.index(category)
        except ValueError:
            self.class_names.append(category)
            return len(self.class_names) - 1

    # -- queries ------------------------------------------------------------------------------
    def get(self, name: str) -> WorldObject:
        """The object with this name (KeyError if none)."""
        return self.objects[name]

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

    def shown_by_opening(self, name: str) -> list[WorldObject]:
        """What an open ``name`` shows the robot that opened it: the observable objects inside it, depth
        first (paper S.2: "all inner objects within an articulated object become visible to the robot once
        the outer object is opened"); nothing while it is closed or cannot open."""
        obj = self.get(name)
        if not (obj.openable and obj.is_open):
            return []
        return [o for o in self.descendants(name) if self.is_inside(o.name, name) and self.is_observable(o.name)]

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

    def on_floor(self, obj: WorldObject) -> bool:
        """Whether ``obj`` is an item resting directly on a floor (what the base drives over)."""
        return obj.kind == "item" and obj.parent is not None and self.objects[obj.parent].kind == "floor"

    # -- changes ------------------------------------------------------------------------------
    def set_open(self, name: str, is_open: bool) -> None:
        """Open or close an openable object (no precondition checks: actions do those)."""
        obj = self.objects[name]
        if not obj.openable:
            raise ValueError(f"{name} is not openable")
        obj.is_open = is_open
        self._changed(layout=True)

    def place(self, name: str, parent: str, relation: Relation) -> None:
        """Rest item ``name`` inside / on top of ``parent`` at the first free slot (no precondition checks)."""
        obj, support = self.objects[name], self.objects[parent]
        self._rest(obj, support, relation, *packing.magic_fit(obj, support, relation, self._in_the_way(obj, support)))

    def place_if_room(
        self, name: str, parent: str, relation: Relation, *, stack: bool = False, rng: np.random.Generator | None = None
    ) -> bool:
        """Like ``place``, but only where it fits (``packing.fit``; at a free slot ``rng`` draws, when given);
        False (nothing changed) when it does not."""
        obj, support = self.objects[name], self.objects[parent]
        fitted = packing.fit(obj, support, relation, self._in_the_way(obj, support), stack=stack, rng=rng)
        if fitted is None:
            return False
        self._rest(obj, support, relation, *fitted)
        return True

    def place_on_floor_at(self, name: str, floor: str, xy: tuple[float, float]) -> None:
        """Rest item ``name`` on a room floor at a given position (no precondition checks)."""
        obj, support = self.objects[name], self.objects[floor]
        self._rest(obj, support, "ontop", np.array([xy[0], xy[1], support.top + obj.size[2] / 2]), obj.size)

    def _rest(
        self, obj: WorldObject, support: WorldObject, relation: Relation, center: np.ndarray, size: np.ndarray
    ) -> None:
        """Make ``obj`` rest in / on ``support`` centred at ``center`` with box ``size`` (folded cloth; what
        rests on it moves along), out of the gripper if it was held."""
        obj.parent, obj.relation, obj.room, obj.size = support.name, relation, support.room, size
        self._move_subtree(obj, center)
        if self.robot.held == obj.name:
            self.robot.held = None
        self._changed(layout=True)

    def pick(self, name: str) -> None:
        """Put item ``name`` in the robot's gripper, detached from its support (no precondition checks)."""
        obj = self.objects[name]
        obj.parent, obj.relation = None, None
        self.robot.held = name
        self._carry()
        self._changed(layout=True)

    def set_robot_pose(self, x: float, y: float, yaw: float) -> None:
        """Move the robot base; a held item moves along with it."""
        self.robot.x, self.robot.y, self.robot.yaw = float(x), float(y), float(np.arctan2(np.sin(yaw), np.cos(yaw)))
        self._carry()
        # a held item is never drawn: the layout changed only when something rests in / on it
        self._changed(layout=self.robot.held is not None and bool(self.children(self.robot.held)))

    def _in_the_way(self, obj: WorldObject, support: WorldObject) -> list[WorldObject]:
        """What may stand where ``obj`` goes on ``support`` (``packing``): items already there and anything
        else (a TV on the coffee table, a shelf hung above a desk), but no floor, not the supports of
        ``support`` nor ``obj``, its load or the held item."""
        skip = {obj.name, support.name, self.robot.held} | {o.name for o in self.descendants(obj.name)}
        skip |= {parent.name for parent, _ in self.ancestors(support.name)}
        return [o for o in self.objects.values() if o.kind != "floor" and o.name not in skip]

    def _changed(self, *, layout: bool) -> None:
        """The one place the versions move: ``version`` on every change, ``layout_version`` when an
        object changed (pose, support, open state), not when the robot merely moved."""
        self.version += 1
        if layout:
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
