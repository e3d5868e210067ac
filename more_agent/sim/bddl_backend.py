"""Our bddl backend: predicate classes that read the embedded world, and the scope objects bddl holds.

bddl compiles a goal into a tree whose leaves are instances of the classes ``get_predicate_class``
returns; each leaf calls ``_evaluate`` with the scope entries of its arguments. Scope entries are
``ScopeObject``s (a scope name and the world object it stands for, never a str or None) and the
predicates read the backend's current ``world``, so one compiled goal follows a world as it changes
and can be pointed at another world. We never call ``bddl.set_backend`` (it imports iGibson).

Every leaf evaluates ``more_agent.sim.predicates.holds`` on the world names of its arguments (the
semantics are documented there); a predicate the world does not model (cooked, covered, filled, ...)
evaluates False.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Literal as TypingLiteral

from bddl.backend_abc import BDDLBackend
from bddl.logic_base import BinaryAtomicFormula, UnaryAtomicFormula

from more_agent.sim.predicates import holds
from more_agent.sim.world import World

ScopeKind = TypingLiteral["object", "agent", "virtual"]


@dataclass(frozen=True)
class ScopeObject:
    """What a bddl scope entry holds: the scope name and the world object (or robot) it stands for.

    ``kind`` is 'agent' for the robot (``world_name`` is ``predicates.ROBOT_NAME``) and 'virtual' for
    what the world does not model: substances (water, dust, ...) and objects that only exist in the
    future (``future`` literals); those have ``world_name`` equal to the scope name, which names no
    world object, so every predicate over them is False.
    """

    scope: str
    world_name: str
    kind: ScopeKind = "object"


class WorldBackend(BDDLBackend):
    """Resolves predicate names to classes that evaluate against ``self.world``."""

    def __init__(self, world: World) -> None:
        self.world = world

    def get_predicate_class(self, predicate_name: str) -> type:
        return _predicate_class(predicate_name)


class _Unary(UnaryAtomicFormula):
    def _sample(self, obj: ScopeObject, binary_state: bool) -> None:
        raise NotImplementedError("sampling is done by more_agent.sim.instantiate")


class _Binary(BinaryAtomicFormula):
    def _sample(self, obj1: ScopeObject, obj2: ScopeObject, binary_state: bool) -> None:
        raise NotImplementedError("sampling is done by more_agent.sim.instantiate")


@cache
def _predicate_class(name: str) -> type:
    """The bddl leaf class of predicate ``name``: ``predicates.holds`` on the backend's world."""
    base = _Unary if _predicate_arity(name) == 1 else _Binary

    def _evaluate(self: object, *args: ScopeObject) -> bool:
        return holds(self.backend.world, name, [a.world_name for a in args])  # type: ignore[attr-defined]

    return type(f"Predicate_{name}", (base,), {"STATE_NAME": name, "_evaluate": _evaluate})


@cache
def _predicate_arity(name: str) -> int:
    """Number of arguments of a predicate of bddl's omnigibson domain (2 for unknown names)."""
    from bddl.parsing import parse_domain

    *_, predicates = parse_domain("omnigibson")
    return len(predicates.get(name, ("a", "b")))
