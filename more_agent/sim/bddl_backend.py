"""Our bddl backend: predicate classes that read the embedded world, and the scope objects bddl holds.

bddl compiles a goal into a tree whose leaves are instances of the classes ``get_predicate_class``
returns; each leaf calls ``_evaluate`` with the scope entries of its arguments. Scope entries are
``ScopeObject``s (a scope name and the world object it stands for, never a str or None) and the
predicates read the backend's current ``world``, so one compiled goal follows a world as it changes
and can be pointed at another world. We never call ``bddl.set_backend`` (it imports iGibson).

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
- ``grasped(agent, a)``: the robot holds a.
Every other predicate (cooked, covered, filled, ...) evaluates False and is recorded in
``WorldBackend.unsupported``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Literal as TypingLiteral

import numpy as np
from bddl.backend_abc import BDDLBackend
from bddl.logic_base import BinaryAtomicFormula, UnaryAtomicFormula

from more_agent.sim.world import World, WorldObject, floor_name

NEXTTO_GAP_M = 0.3
"""Largest horizontal gap between two boxes that still counts as next to each other."""

TOUCH_GAP_M = 0.02
"""Largest gap between two boxes that still counts as touching."""

ROBOT_NAME = "robot"
"""World name the agent scope (``agent.n.01_1``) stands for."""

ScopeKind = TypingLiteral["object", "agent", "virtual"]

SUPPORTED_PREDICATES = frozenset({"inside", "ontop", "open", "nextto", "under", "touching", "grasped"})


@dataclass(frozen=True)
class ScopeObject:
    """What a bddl scope entry holds: the scope name and the world object (or robot) it stands for.

    ``kind`` is 'agent' for the robot and 'virtual' for what the world does not model: substances
    (water, dust, ...) and objects that only exist in the future (``future`` literals); those have
    ``world_name`` equal to the scope name.
    """

    scope: str
    world_name: str
    kind: ScopeKind = "object"


class WorldBackend(BDDLBackend):
    """Resolves predicate names to classes that evaluate against ``self.world``."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.unsupported: set[str] = set()

    def get_predicate_class(self, predicate_name: str) -> type:
        cls = _PREDICATES.get(predicate_name)
        if cls is not None:
            return cls
        return _unsupported_class(predicate_name)

    def obj(self, entry: ScopeObject) -> WorldObject | None:
        """The world object a scope entry stands for (None for the robot and virtual entries)."""
        if entry.kind != "object":
            return None
        return self.world.objects.get(entry.world_name)


class _Unary(UnaryAtomicFormula):
    def _sample(self, obj: ScopeObject, binary_state: bool) -> None:
        raise NotImplementedError("sampling is done by more_agent.sim.instantiate")


class _Binary(BinaryAtomicFormula):
    def _sample(self, obj1: ScopeObject, obj2: ScopeObject, binary_state: bool) -> None:
        raise NotImplementedError("sampling is done by more_agent.sim.instantiate")


class OpenPredicate(_Unary):
    STATE_NAME = "open"

    def _evaluate(self, obj: ScopeObject) -> bool:
        o = self.backend.obj(obj)
        return bool(o is not None and o.openable and o.is_open)


class InsidePredicate(_Binary):
    STATE_NAME = "inside"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        world: World = self.backend.world
        if obj1.kind != "object" or obj2.kind != "object" or obj1.world_name not in world.objects:
            return False
        return world.is_inside(obj1.world_name, obj2.world_name)


class OnTopPredicate(_Binary):
    STATE_NAME = "ontop"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        world: World = self.backend.world
        if obj2.kind != "object" or obj2.world_name not in world.objects:
            return False
        if obj1.kind == "agent":
            floor = world.objects[obj2.world_name]
            return floor.kind == "floor" and world.room_at(world.robot.x, world.robot.y) == floor.room
        if obj1.kind != "object" or obj1.world_name not in world.objects:
            return False
        return is_ontop(world, obj1.world_name, obj2.world_name)


class NextToPredicate(_Binary):
    STATE_NAME = "nextto"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        a, b = self.backend.obj(obj1), self.backend.obj(obj2)
        return a is not None and b is not None and _vertical_overlap(a, b) and _xy_gap(a, b) <= NEXTTO_GAP_M


class UnderPredicate(_Binary):
    STATE_NAME = "under"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        a, b = self.backend.obj(obj1), self.backend.obj(obj2)
        if a is None or b is None or a.name == b.name:
            return False
        lo, hi = b.box()
        inside_footprint = bool(np.all(a.center[:2] >= lo[:2]) and np.all(a.center[:2] <= hi[:2]))
        return inside_footprint and a.top <= b.top + 1e-6 and not self.backend.world.is_inside(a.name, b.name)


class TouchingPredicate(_Binary):
    STATE_NAME = "touching"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        a, b = self.backend.obj(obj1), self.backend.obj(obj2)
        if a is None or b is None or a.name == b.name:
            return False
        if a.parent == b.name or b.parent == a.name:
            return True
        gap = max(_xy_gap(a, b), _z_gap(a, b))
        return gap <= TOUCH_GAP_M


class GraspedPredicate(_Binary):
    STATE_NAME = "grasped"

    def _evaluate(self, obj1: ScopeObject, obj2: ScopeObject) -> bool:
        return obj1.kind == "agent" and self.backend.world.robot.held == obj2.world_name


_PREDICATES: dict[str, type] = {
    cls.STATE_NAME: cls
    for cls in (OpenPredicate, InsidePredicate, OnTopPredicate, NextToPredicate, UnderPredicate,
                TouchingPredicate, GraspedPredicate)
}


@cache
def _unsupported_class(name: str) -> type:
    """A predicate class for ``name`` that evaluates False and records the name as unsupported."""
    base = _Unary if _predicate_arity(name) == 1 else _Binary

    def _evaluate(self: object, *args: ScopeObject) -> bool:
        self.backend.unsupported.add(name)  # type: ignore[attr-defined]
        return False

    return type(f"Unsupported_{name}", (base,), {"STATE_NAME": name, "_evaluate": _evaluate})


@cache
def _predicate_arity(name: str) -> int:
    """Number of arguments of a predicate of bddl's omnigibson domain (2 for unknown names)."""
    from bddl.parsing import parse_domain

    *_, predicates = parse_domain("omnigibson")
    return len(predicates.get(name, ("a", "b")))


# -- geometry / support relations shared with instantiation ----------------------------------------
def is_ontop(world: World, name: str, support: str) -> bool:
    """True when ``name`` rests on ``support`` directly or through a stack of 'ontop' links.

    Furniture has no support link: it stands on the floor of its room.
    """
    obj = world.get(name)
    if obj.kind == "furniture":
        return support == floor_name(obj.room)
    for parent, rel in world.ancestors(name):
        if rel != "ontop":
            return False
        if parent.name == support:
            return True
    return False


def _xy_gap(a: WorldObject, b: WorldObject) -> float:
    """Horizontal distance between two boxes (0 when their footprints overlap)."""
    d = np.abs(a.center[:2] - b.center[:2]) - (a.size[:2] + b.size[:2]) / 2
    return float(np.linalg.norm(np.maximum(d, 0.0)))


def _z_gap(a: WorldObject, b: WorldObject) -> float:
    return max(0.0, a.bottom - b.top, b.bottom - a.top)


def _vertical_overlap(a: WorldObject, b: WorldObject) -> bool:
    return _z_gap(a, b) <= TOUCH_GAP_M
