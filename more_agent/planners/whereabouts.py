"""Where an item is usually kept: which room types, inside which containers.

Commonsense a language model brings to a search ("tools are in the utility room or the garage, on a
workbench"; "a suitcase is in no kitchen cabinet"; "a car is outside"), made deterministic for the
planner that runs without one. It is read from bddl's 1016 activity definitions: their initial states
say where each item starts (``(ontop item furniture)``, ``(inside item container)``, items on items)
and in which room type each piece of furniture stands (``(inroom furniture room_type)``). Each item
placed so is one piece of evidence: (item synset, room type, the synset it rests on or in, whether
inside).

The evidence of the activity being played is left out (leave-one-out: a planner never reads its own
task's initial state). A synset with too little evidence of its own borrows its parent's in the
taxonomy (every synset the corpus places under it), up to ``MAX_LEVELS`` generations up; beyond that
there is no prior and the search ranks as it would without one. Parsed once per process on first use,
taxonomy included (about 0.5 s on the 2-core machine of docs/benchmarks.md, 2026-12-06).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from itertools import combinations
from typing import Any

from more_agent.sim import catalog
from more_agent.vocabulary import scope_synset

MIN_EVIDENCE = 1
"""Items placed in other activities below which a synset borrows its parents' evidence (its siblings')."""

MAX_LEVELS = 1
"""How many generations up the taxonomy a synset may borrow evidence from: a drill's siblings are hand
tools; two generations up, every tool, a kitchen's ladles among them."""

NEVER_INSIDE_ACTIVITIES = 3
"""Activities placing an item, none of them inside anything, that make it one never kept in a container."""

DELIVERY_ACTIVITIES = 3
"""Activities putting items into or onto a kind of furniture below which where they start says nothing."""

PLACEMENTS = ("ontop", "inside", "under", "nextto")
"""Init predicates that place an item relative to another object."""


@dataclass(frozen=True)
class Evidence:
    """One item's initial placement in one activity."""

    activity: str
    room_type: str | None
    """The room type of the furniture it ends up on or in (None when the chain reaches no ``inroom``)."""
    support: str
    """The synset of the object it rests on or in directly."""
    inside: bool


@cache
def _problems() -> tuple[tuple[str, list[Any], list[Any]], ...]:
    """(activity, init, goal) of every bddl activity, parsed once for the corpus and the deliveries alike."""
    return tuple((name, *catalog.activity_problem(name)[1:]) for name in catalog.activity_names())


@cache
def corpus() -> dict[str, tuple[Evidence, ...]]:
    """Item synset -> its evidence over every bddl activity (read with bddl's own parser: static knowledge
    of the library, not the episode's task, which planners may not import)."""
    found: dict[str, list[Evidence]] = {}
    for name, init, _ in _problems():
        for synset, ev in _activity_evidence(name, init):
            found.setdefault(synset, []).append(ev)
    return {s: tuple(evs) for s, evs in found.items()}


def _activity_evidence(name: str, parsed: list[Any]) -> list[tuple[str, Evidence]]:
    """(item synset, evidence) for each item the activity's initial state (``parsed``) places on or in something."""
    init = [lit for lit in parsed if lit and isinstance(lit[0], str)]
    room = {lit[1]: lit[2] for lit in init if lit[0] == "inroom" and len(lit) == 3}
    rests = {lit[1]: (lit[0], lit[2]) for lit in init if lit[0] in PLACEMENTS and len(lit) == 3}
    out = []
    for item, (predicate, support) in rests.items():
        if item in room:
            continue  # furniture beside furniture: not an item
        seen, at = {item}, support
        while at not in room and at in rests and at not in seen:  # a book on a box on a shelf
            seen.add(at)
            at = rests[at][1]
        ev = Evidence(name, room.get(at), scope_synset(support), predicate == "inside")
        out.append((scope_synset(item), ev))
    return out


@cache
def _pooled() -> dict[str, tuple[Evidence, ...]]:
    """Synset -> the evidence of itself and of every corpus synset below it in the taxonomy."""
    tax = catalog.taxonomy()
    pooled: dict[str, list[Evidence]] = {}
    for synset, evs in corpus().items():
        above = tax.get_ancestors(synset) if tax.is_valid_synset(synset) else set()
        for s in {synset, *above}:
            pooled.setdefault(s, []).extend(evs)
    return {s: tuple(evs) for s, evs in pooled.items()}


@cache
def evidence(synset: str, leave_out: str = "") -> tuple[Evidence, ...]:
    """The evidence for ``synset`` outside activity ``leave_out``: its own, else its nearest ancestors'
    (``MIN_EVIDENCE``, ``MAX_LEVELS``); () when there is too little. Cached: the search asks for every
    closed container and missing item at every step."""
    tax = catalog.taxonomy()
    level = [synset]
    for _ in range(MAX_LEVELS + 1):
        evs = tuple(e for s in level for e in _pooled().get(s, ()) if e.activity != leave_out)
        if len(evs) >= MIN_EVIDENCE:
            return evs
        level = sorted({p for s in level if tax.is_valid_synset(s) for p in tax.get_parents(s)})
    return ()


@dataclass(frozen=True)
class Delivery:
    """One item a goal puts into or onto a piece of furniture, and whether it starts in that furniture's room."""

    activity: str
    destination: str
    """The synset of the furniture (a scope with an ``inroom`` in the activity's initial state)."""
    same_room: bool


@cache
def deliveries() -> tuple[Delivery, ...]:
    """Every item that a bddl activity's goal puts inside or on top of a piece of furniture, with whether its
    initial state sets it out in the furniture's room: the car of a car-packing activity stands on the lawn where
    its suitcases wait, a cabinet's dishes start in its kitchen, a breakfast table's plates often in the kitchen
    next door (:func:`destination_share`)."""
    found = []
    evidence_of = _by_activity()
    for name, init, goal in _problems():
        rooms = {lit[1]: lit[2] for lit in init if lit and lit[0] == "inroom" and len(lit) == 3}
        for item, furniture in _placements(goal):
            room = rooms.get(furniture)
            if room is None:
                continue
            for e in evidence_of.get(name, {}).get(scope_synset(item), []):
                if e.room_type:
                    found.append(Delivery(name, scope_synset(furniture), e.room_type == room))
    return tuple(found)


def _placements(goal: Any) -> list[tuple[str, str]]:
    """(item term, destination scope) of every ``inside`` / ``ontop`` literal in a parsed goal, quantified or not;
    not a negated one (what is taken out of a car says nothing of where a car's load waits)."""
    if not isinstance(goal, list) or not goal or goal[0] == "not":
        return []
    if goal[0] in ("inside", "ontop") and len(goal) == 3 and all(isinstance(a, str) for a in goal[1:]):
        return [(goal[1], goal[2].lstrip("?"))]
    return [pair for part in goal if isinstance(part, list) for pair in _placements(part)]


@cache
def destination_share(synset: str, leave_out: str = "") -> float | None:
    """The share of the items that other activities' goals put into or onto furniture of ``synset`` which start
    in its room, each activity weighing one (bddl 3.6: a car 0.80 over 15 activities, a cabinet 0.90, a fridge
    0.82, a breakfast table 0.61); None with fewer than ``DELIVERY_ACTIVITIES`` activities."""
    per_activity: dict[str, list[bool]] = {}
    for d in deliveries():
        if d.destination == synset and d.activity != leave_out:
            per_activity.setdefault(d.activity, []).append(d.same_room)
    if len(per_activity) < DELIVERY_ACTIVITIES:
        return None
    return sum(sum(v) / len(v) for v in per_activity.values()) / len(per_activity)


@cache
def _by_activity() -> dict[str, dict[str, list[Evidence]]]:
    """Activity -> item synset -> the evidence it gives (the corpus regrouped by activity)."""
    grouped: dict[str, dict[str, list[Evidence]]] = {}
    for synset, evs in corpus().items():
        for e in evs:
            grouped.setdefault(e.activity, {}).setdefault(synset, []).append(e)
    return grouped


@cache
def together_share() -> float:
    """How often two items one activity places share a room type, over the pairs of distinct item synsets
    of every activity (0.98 in bddl 3.6: 955 of its 1016 activities place every item in one room type): a
    task's objects are set out together, so one found tells where the others are."""
    rooms = [[{e.room_type for e in evs if e.room_type} for evs in items.values()] for items in _by_activity().values()]
    pairs = [bool(a & b) for items in rooms for a, b in combinations([r for r in items if r], 2)]
    return sum(pairs) / len(pairs)


def room_prior(synset: str, leave_out: str = "") -> dict[str, float]:
    """Room type -> share of the activities (each weighing one, however many items it places) placing
    the item in such a room ({} without evidence)."""
    evs = [e for e in evidence(synset, leave_out) if e.room_type]
    per_activity = Counter(e.activity for e in evs)
    counts: dict[str, float] = {}
    for e in evs:
        kind = e.room_type or ""
        counts[kind] = counts.get(kind, 0.0) + 1 / per_activity[e.activity]
    total = sum(counts.values())
    return {kind: n / total for kind, n in counts.items()}


def container_prior(synset: str, leave_out: str = "") -> dict[str, float]:
    """Container synset -> share of the item's evidence placing it inside one ({} without such evidence)."""
    evs = evidence(synset, leave_out)
    counts = Counter(e.support for e in evs if e.inside)
    return {support: n / len(evs) for support, n in counts.items()}


def never_inside(synset: str, leave_out: str = "") -> bool:
    """Whether at least ``NEVER_INSIDE_ACTIVITIES`` activities place the item and none inside anything: a
    car, a bow, a branch is kept in no container. Thinner evidence says nothing (containers in the corpus
    are named finely: a grocery store's fridge is no kitchen's)."""
    evs = evidence(synset, leave_out)
    return len({e.activity for e in evs}) >= NEVER_INSIDE_ACTIVITIES and not any(e.inside for e in evs)


def container_share(category: str, prior: dict[str, float], siblings: Sequence[str] = ()) -> float:
    """Share of an item's evidence inside containers that the object ``category`` is (or descends from).

    ``siblings``: the categories of the containers it stands among (itself included), over which the evidence
    for a kind of container is spread: one of a kitchen's 14 cabinets is less likely to hold the bottles than
    its one fridge, though bottles are kept in cabinets a little more often than in fridges."""
    total = 0.0
    for support, share in prior.items():
        kind = frozenset({support})
        if catalog.descends_from(category, kind):
            total += share / max(1, sum(catalog.descends_from(c, kind) for c in siblings))
    return total
