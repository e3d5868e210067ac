"""Which goal instances a task's description cannot single out.

A goal binds scopes, not categories: ``(ontop money.n.01_1 checkout.n.03_1)`` holds on the one
checkout counter the task bound, however many the store has, and ``(forall (?plate.n.04 - plate.n.04)
...)`` ranges over the task's plates, not the scene's own. The description names an instance with a
``$scope`` word (its label, ``fridge A``); otherwise "the checkout" fits every checkout counter of the
room type and "every plate" every plate in the house. :func:`ambiguous_scopes` lists the goal's
scopes in that position: another object of the world (furniture, a distractor or another task
object the goal treats differently) shares their category, and the description does not name them,
so no reader of the description can do better than chance. The default descriptions
(``sim.descriptions``) name every such scope, as the paper's ``$`` words do (docs/tasks.md).
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from more_agent.sim import catalog
from more_agent.sim.tasks import ParsedLiteral, TaskDefinition, atoms, literal_text
from more_agent.sim.world import World
from more_agent.vocabulary import scope_synset


class DescribedTask(Protocol):
    """What these functions read of a task instance (``instantiate.TaskInstance``)."""

    world: World
    definition: TaskDefinition
    scope: dict[str, str]
    description_template: str


SCOPE_NAME = r"[\w.]+?\.n\.\d+_(?:\d+|\*)"
"""A bddl scope name: 'apple.n.01_1', or 'cabinet.n.01_*' (a scope of any one instance)."""
SCOPE_WORD = re.compile(rf"\$({SCOPE_NAME})")
"""A ``$scope`` word of a description template."""
_QUANTIFIER_VARIABLES = {"forall": (1,), "exists": (1,), "forn": (2,), "forpairs": (1, 2), "fornpairs": (2, 3)}
"""Quantifier -> positions of its variable declarations (``['?x', '-', 'plate.n.04']``) in the node."""


@dataclass(frozen=True)
class ScopeGroup:
    """Goal scopes a reader must tell from the world's other objects as one: a scope the goal names
    directly (with its twins: scopes the goal treats alike), or the scopes a quantifier ranges over."""

    scopes: tuple[str, ...]
    quantifier: str | None
    """None for scopes written in the goal; else the quantifier ('forall', 'exists', ...)."""


def described_scopes(instance: DescribedTask) -> set[str]:
    """Scopes whose instance the description names (:func:`template_scopes` of its template)."""
    return template_scopes(instance.description_template, instance.definition, instance.world, instance.scope)


def template_scopes(template: str, definition: TaskDefinition, world: World, scope: Mapping[str, str]) -> set[str]:
    """Scopes a description template names: the paper's ``$scope`` words, and the other ``$scope``
    words that stand for an instance (a world object, a floor of a room; a virtual scope's category or
    'the robot' names none)."""
    written = set(SCOPE_WORD.findall(template)) & set(scope)
    paper = set(SCOPE_WORD.findall(definition.paper_description or ""))
    return {s for s in written if s in paper or _names_instance(world, scope[s])}


def _names_instance(world: World, name: str) -> bool:
    obj = world.objects.get(name)
    return obj is not None and (obj.kind != "floor" or obj.room is not None)


def _names_room(text: str, room_type: str) -> bool:
    """Whether ``text`` names rooms of ``room_type`` ('living_room': "living room" or "living_room")."""
    words = text.lower()
    return room_type.lower() in words or room_type.lower().replace("_", " ") in words


def scope_categories(scope: str) -> frozenset[str]:
    """Object categories that count as a scope's synset: the synset's own and its descendants' (and
    the synset's lemma, for synsets the taxonomy lacks)."""
    synset = scope_synset(scope)
    return frozenset(catalog.synset_categories(synset)) | {synset.split(".")[0]}


def ambiguous_scopes(instance: DescribedTask) -> list[str]:
    """The goal scopes the instance's description cannot single out (module docstring), sorted."""
    return ambiguous_in(
        instance.world, instance.definition, instance.scope, described_scopes(instance), instance.description_template
    )


def ambiguous_in(
    world: World, definition: TaskDefinition, scope: Mapping[str, str], described: set[str], text: str = ""
) -> list[str]:
    """The goal scopes of ``definition`` bound to world objects (``scope``: scope -> world name) that
    ``described`` leaves out and that the world's other objects make ambiguous, sorted.

    A group (:func:`scope_groups`) is ambiguous when an object outside it has one of its categories:
    for furniture, in a room of its ``inroom`` type when the description ``text`` names that type ("the
    shelf" alone fits a bookcase of any room; "the shelf in the living room" only the living room's), in any
    room otherwise; movable, for a group the goal moves (a reader
    knows furniture stays put). A ``forall`` over furniture the goal does not move ("close every
    cabinet") is addressed by acting on them all, so it never is; nor is an ``exists`` one of whose
    range the description names (the reader acts on that one).
    """
    goal = definition.goal
    moved = {atom[1].lstrip("?") for atom in atoms(goal) if len(atom) == 3}
    room_of = {lit[1]: lit[-1] for lit in definition.init if lit[0] == "inroom"}
    room_types = {r.id: r.type for r in world.scene.rooms}
    out: set[str] = set()
    for group in scope_groups(goal, definition.objects):
        members = [
            s
            for s in group.scopes
            if s in scope and scope[s] in world.objects and world.objects[scope[s]].kind != "floor"
        ]
        unnamed = [s for s in members if s not in described]
        is_moved = any(s in moved for s in members) or (group.quantifier is not None and _variable_moved(goal, members))
        addressed_all = group.quantifier == "forall" and not is_moved
        one_named = group.quantifier == "exists" and len(unnamed) < len(members)
        if not unnamed or addressed_all or one_named:
            continue
        own = {scope[s] for s in members}
        categories = scope_categories(members[0])
        rooms = {room_of[s] for s in members if s in room_of and _names_room(text, room_of[s])}
        if any(
            o.name not in own
            and o.category in categories
            and (not rooms or room_types.get(o.room or "") in rooms)
            and (o.movable or not is_moved)
            for o in world.objects.values()
        ):
            out.update(unnamed)
    return sorted(out)


def scope_groups(goal: list[ParsedLiteral], objects: Mapping[str, list[str]]) -> list[ScopeGroup]:
    """The goal's scopes as a reader must find them (:class:`ScopeGroup`): each quantifier's range
    (the task's scopes of its synset), then each scope written in the goal with its twins (scopes of
    its synset whose exchange leaves the goal unchanged: "put the two apples in the fridge")."""
    groups = [ScopeGroup(tuple(objects.get(synset, ())), quantifier) for quantifier, synset in _quantified(goal)]
    written = sorted(written_scopes(goal))
    seen: set[str] = set()
    for s in written:
        if s in seen:
            continue
        twins = tuple(
            t for t in written if t not in seen and scope_synset(t) == scope_synset(s) and _exchangeable(goal, s, t)
        )
        seen.update(twins)
        groups.append(ScopeGroup(twins, None))
    return groups


def _quantified(node: Any) -> Iterator[tuple[str, str]]:
    """(quantifier, synset) for every quantifier variable anywhere in a parse tree, in order."""
    if not isinstance(node, list) or not node:
        return
    if isinstance(node[0], str) and node[0] in _QUANTIFIER_VARIABLES:
        for i in _QUANTIFIER_VARIABLES[node[0]]:
            yield node[0], node[i][-1]
    for child in node:
        yield from _quantified(child)


def _variable_moved(goal: list[ParsedLiteral], members: list[str]) -> bool:
    """Whether a quantifier variable of the members' synset is the subject of a placement literal."""
    synset = scope_synset(members[0]) if members else ""
    return any(len(atom) == 3 and atom[1].lstrip("?") == synset for atom in atoms(goal))


def written_scopes(node: Any) -> set[str]:
    """The scope names a (part of a) goal writes in its atoms; quantifier variables are no scopes."""
    return {t.lstrip("?") for atom in atoms(node) for t in atom[1:] if re.fullmatch(SCOPE_NAME, t.lstrip("?"))}


def _exchangeable(goal: list[ParsedLiteral], a: str, b: str) -> bool:
    """Whether swapping scopes ``a`` and ``b`` leaves the goal's conjuncts the same."""
    swap = {a: b, b: a, f"?{a}": f"?{b}", f"?{b}": f"?{a}"}

    def swapped(node: Any) -> Any:
        return swap.get(node, node) if isinstance(node, str) else [swapped(x) for x in node]

    return sorted(literal_text(c) for c in goal) == sorted(literal_text(swapped(c)) for c in goal)
