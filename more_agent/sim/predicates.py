"""The goal predicates over world names: the one definition that bddl (through ``bddl_backend``) and
the oracle both evaluate.

Arguments are world object names; ``ROBOT_NAME`` stands for the robot, and any other name the world
does not hold (a substance, an object that only exists in the future) makes every predicate False.

Semantics, in the symbolic world:
- ``inside(a, b)``: ``World.is_inside`` (a in b, or on / in something that is in b).
- ``ontop(a, b)``: a rests on top of b, directly or on a stack of things resting on top of one
  another (apple on plate on table: ontop table). A link 'inside' breaks the chain (apple in a bowl
  on the table is not on top of the table). The robot is on top of a floor when it stands in that
  floor's room.
- ``open(a)``: a is openable and open.
- ``nextto(a, b)``: boxes overlap vertically and are at most ``NEXTTO_GAP_M`` apart horizontally.
- ``under(a, b)``: a's centre lies within b's footprint and a's top is at most b's top.
- ``touching(a, b)``: one rests directly on / in the other, or their boxes are within
  ``TOUCH_GAP_M`` of each other.
- ``grasped(robot, a)``: the robot holds a.
- ``attached(a, b)``: a rests directly on top of b and both are attachable (BEHAVIOR-1K's ``attachable``
  ability): OmniGibson attaches such objects when one is put on the other's mount, and the paper words
  attach_a_camera_to_a_tripod as "put the digital camera on top the tripod". The world's set-up never
  attaches anything (``NOT_SET_UP``).
Every other predicate (cooked, covered, filled, ...) is not modelled: ``holds`` reads it as False.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from more_agent.goal import ROBOT_NAME
from more_agent.sim.catalog import is_attachable
from more_agent.sim.world import World, WorldObject, floor_name

NEXTTO_GAP_M = 0.3
"""Largest horizontal gap between two boxes that still counts as next to each other."""

TOUCH_GAP_M = 0.02
"""Largest gap between two boxes that still counts as touching."""


def is_open(world: World, name: str) -> bool:
    """``open(a)``: an openable object that is open."""
    obj = world.objects.get(name)
    return bool(obj is not None and obj.openable and obj.is_open)


def is_inside(world: World, name: str, container: str) -> bool:
    """``inside(a, b)``: ``World.is_inside`` over two objects of the world."""
    return name in world.objects and container in world.objects and world.is_inside(name, container)


def is_ontop(world: World, name: str, support: str) -> bool:
    """``ontop(a, b)``: ``name`` rests on ``support`` directly or through a stack of 'ontop' links;
    the robot is on a floor when it stands in that floor's room.

    Furniture has no support link: it stands on the floor of its room.
    """
    if support not in world.objects:
        return False
    if name == ROBOT_NAME:
        floor = world.objects[support]
        return floor.kind == "floor" and world.room_at(world.robot.x, world.robot.y) == floor.room
    obj = world.objects.get(name)
    if obj is None:
        return False
    if obj.kind == "furniture":
        return obj.room is not None and support == floor_name(obj.room)
    for parent, rel in world.ancestors(name):
        if rel != "ontop":
            return False
        if parent.name == support:
            return True
    return False


def is_nextto(world: World, a: str, b: str) -> bool:
    """``nextto(a, b)``: the boxes overlap vertically and are at most ``NEXTTO_GAP_M`` apart horizontally."""
    pair = _objects(world, a, b)
    return pair is not None and _z_gap(*pair) <= TOUCH_GAP_M and _xy_gap(*pair) <= NEXTTO_GAP_M


def is_under(world: World, a: str, b: str) -> bool:
    """``under(a, b)``: a's centre within b's footprint, a's top at most b's top, a not inside b."""
    pair = _objects(world, a, b)
    if pair is None or a == b:
        return False
    lo, hi = pair[1].box()
    centre = pair[0].center[:2]
    inside_footprint = bool(np.all(centre >= lo[:2]) and np.all(centre <= hi[:2]))
    return inside_footprint and pair[0].top <= pair[1].top + 1e-6 and not world.is_inside(a, b)


def is_touching(world: World, a: str, b: str) -> bool:
    """``touching(a, b)``: one rests directly on / in the other, or the boxes are within ``TOUCH_GAP_M``."""
    pair = _objects(world, a, b)
    if pair is None or a == b:
        return False
    if pair[0].parent == b or pair[1].parent == a:
        return True
    return max(_xy_gap(*pair), _z_gap(*pair)) <= TOUCH_GAP_M


def is_attached(world: World, name: str, mount: str) -> bool:
    """``attached(a, b)``: ``name`` rests directly on top of ``mount`` and both are attachable."""
    pair = _objects(world, name, mount)
    if pair is None or pair[0].parent != mount or pair[0].relation != "ontop":
        return False
    return is_attachable(pair[0].category) and is_attachable(pair[1].category)


def is_grasped(world: World, agent: str, name: str) -> bool:
    """``grasped(robot, a)``: the robot holds a."""
    return agent == ROBOT_NAME and world.robot.held == name


PREDICATES: dict[str, Callable[..., bool]] = {
    "inside": is_inside,
    "ontop": is_ontop,
    "open": is_open,
    "nextto": is_nextto,
    "under": is_under,
    "touching": is_touching,
    "grasped": is_grasped,
    "attached": is_attached,
}
"""The predicates the world models, by bddl name."""

NOT_SET_UP = frozenset({"attached"})
"""Modelled predicates that the world's set-up does not make true from a task's init literals: what hangs on a
fixture lies at a free spot instead, and the literal is kept in ``TaskInstance.unsupported_literals``."""


def holds(world: World, predicate: str, args: Sequence[str]) -> bool:
    """Whether ``predicate(*args)`` holds in ``world`` (False for a predicate the world does not model)."""
    check = PREDICATES.get(predicate)
    return check is not None and check(world, *args)


def _objects(world: World, a: str, b: str) -> tuple[WorldObject, WorldObject] | None:
    """Both named objects, or None when either is not an object of the world."""
    obj_a, obj_b = world.objects.get(a), world.objects.get(b)
    return None if obj_a is None or obj_b is None else (obj_a, obj_b)


def _xy_gap(a: WorldObject, b: WorldObject) -> float:
    """Horizontal distance between two boxes (0 when their footprints overlap)."""
    d = np.abs(a.center[:2] - b.center[:2]) - (a.size[:2] + b.size[:2]) / 2
    return float(np.linalg.norm(np.maximum(d, 0.0)))


def _z_gap(a: WorldObject, b: WorldObject) -> float:
    """Vertical distance between two boxes (0 when they overlap in height)."""
    return max(0.0, a.bottom - b.top, b.bottom - a.top)
