"""Which goal instances a task's description cannot single out.

A goal binds scopes, not categories: ``(ontop money.n.01_1 checkout.n.03_1)`` holds on the one
checkout counter the task bound, however many the store has. The description names an instance
with a ``$scope`` word (its label, ``fridge A``); otherwise "the checkout" fits every checkout
counter of the room type. :func:`ambiguous_scopes` lists the goal's scopes in that position: the
scene has another object of their synset (in a room of their type, for furniture bound by an
``inroom`` literal) and the description does not name them, so no reader of the description can do
better than chance (docs/tasks.md, "Descriptions that cannot be satisfied as written"). Distractors
are not counted: whether one of a goal item's category should count for the goal is the world's
decision.
"""

from __future__ import annotations

import re

from more_agent.sim import catalog
from more_agent.sim.instantiate import TaskInstance
from more_agent.sim.tasks import atoms, scope_synset

_SCOPE_WORD = re.compile(r"\$([\w.]+?\.n\.\d+_\d+)")
_INSTANCE_LABEL = re.compile(r"\S+ [A-Z]+|the .+ floor")
"""An instance label ('apple A') or a floor's ('the garden floor'); a bare category ('every mail')
names no instance."""


def described_scopes(instance: TaskInstance) -> set[str]:
    """Scopes whose instance the description names: the paper's ``$scope`` words, or the scopes whose
    instance label a description generated from the goal contains ('the garden floor' included; a
    quantified scope is named by its category only: 'every mail' binds no instance)."""
    text = instance.definition.paper_description
    if text is not None:
        return set(_SCOPE_WORD.findall(text)) & set(instance.scope)
    return {s for s in instance.scope
            if _INSTANCE_LABEL.fullmatch(label := instance.label(s)) and re.search(rf"\b{re.escape(label)}\b", instance.description)}


def scope_categories(scope: str) -> frozenset[str]:
    """Object categories that count as a scope's synset: the synset's own and its descendants' (and
    the synset's lemma, for synsets the taxonomy lacks)."""
    synset = scope_synset(scope)
    return frozenset(catalog.synset_categories(synset)) | {synset.split(".")[0]}


def ambiguous_scopes(instance: TaskInstance) -> list[str]:
    """The scopes the goal names (not through a quantifier: 'every cabinet' addresses them all) that
    the description does not name and that share their synset with another object of the scene
    (not a task object, not a distractor): in a room of their type, for an ``inroom`` scope; an item,
    for a scope the goal moves (the reader knows furniture stays put); sorted."""
    world = instance.world
    goal = list(atoms(instance.definition.goal))
    written = {term.lstrip("?") for atom in goal for term in atom[1:]}
    moved = {atom[1].lstrip("?") for atom in goal if len(atom) == 3}
    room_of = {lit[1]: lit[-1] for lit in instance.definition.init if lit[0] == "inroom"}
    room_types = {r.id: r.type for r in world.scene.rooms}
    task_or_distractor = set(instance.scope.values()) | set(instance.distractors)
    others = [o for o in world.objects.values() if o.name not in task_or_distractor]
    out = []
    for scope in sorted(written & set(instance.scope) - described_scopes(instance)):
        own = world.objects.get(instance.scope[scope])
        if own is None or own.kind == "floor":
            continue
        categories, room_type = scope_categories(scope), room_of.get(scope)
        if any(o.category in categories and (room_type is None or room_types.get(o.room or "") == room_type)
               and (o.movable or scope not in moved) for o in others):
            out.append(scope)
    return out
