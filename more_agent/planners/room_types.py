"""Room types from the furniture seen in a region, and which room types hold a category.

Both come from BEHAVIOR-1K's scene inventory (bddl's ``combined_room_object_list.json``: 51 scenes,
their rooms and the furniture categories in each): counts per room type, smoothed. This is the
prior knowledge a language model brings about houses, made deterministic for the planner that
runs without one.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable
from functools import cache

from more_agent.sim import catalog

SMOOTHING = 0.5
"""Additive smoothing of the category counts per room type."""

OUTDOOR_ROOM_TYPES = frozenset({"garden"})
"""BEHAVIOR-1K's room types under the open sky (its scenes' lawns, driveways and yards are all gardens)."""


@cache
def room_type_counts() -> dict[str, Counter[str]]:
    """Room type ('kitchen') -> furniture category counts over every BEHAVIOR-1K scene."""
    counts: dict[str, Counter[str]] = {}
    for scene in catalog.scene_names():
        for room, objects in catalog.scene_rooms(scene).items():
            kind = counts.setdefault(room.rsplit("_", 1)[0], Counter())
            for key, n in objects.items():  # keys are 'category-model'
                kind[key.rsplit("-", 1)[0]] += n
    return counts


def is_furniture(category: str) -> bool:
    """Whether some room type lists ``category`` (else its likelihood only reflects room sizes)."""
    return any(category in counts for counts in room_type_counts().values())


def is_standing_furniture(category: str) -> bool:
    """Whether a category is furniture that stands on its own (big enough for a scene to place it as
    furniture: ``catalog.furniture_role``), not a loose item such as a pillow or a beach toy: what rests
    on a loose item lying on a floor rests on that floor too (docs/tasks.md, predicate semantics)."""
    return catalog.furniture_role(category) != "skip"


@cache
def category_likelihood(category: str, room_type: str) -> float:
    """Smoothed share of ``room_type``'s furniture that is ``category`` (0 for unknown room types). Cached:
    the grounded planner names the room type of every unlabelled region on every step from all the categories it
    holds (a store's region holds hundreds), and the inventory's totals cost more than the division."""
    counts = room_type_counts().get(room_type)
    if counts is None:
        return 0.0
    vocabulary = len(set().union(*room_type_counts().values())) + 1
    return (counts.get(category, 0) + SMOOTHING) / (sum(counts.values()) + SMOOTHING * vocabulary)


def listed_share(category: str, room_type: str) -> float:
    """Share of ``room_type``'s listed objects that are ``category``; 0 when no scene lists it in such a room
    (or the room type is unknown). Where to look for a missing piece: unlike :func:`category_likelihood`,
    no smoothing, which would rank the room types with the shortest lists first for what none lists."""
    counts = room_type_counts().get(room_type)
    if not counts or not counts.get(category):
        return 0.0
    return counts[category] / sum(counts.values())


def furniture_rooms(categories: Iterable[str]) -> dict[str, float]:
    """Room type -> the share of the listed pieces of ``categories`` that stand in such rooms (fridges: 0.77 in
    kitchens, 0.09 in grocery stores): where a missing piece of furniture is likeliest; {} when no scene lists
    any of them."""
    cats = set(categories)
    counts = {kind: sum(n for c, n in listed.items() if c in cats) for kind, listed in room_type_counts().items()}
    total = sum(counts.values())
    return {kind: n / total for kind, n in counts.items() if n} if total else {}


def likely_room_type(categories: Iterable[str]) -> str | None:
    """The room type that best explains the furniture categories seen (naive Bayes, uniform prior);
    None when none of them is furniture any room type lists."""
    seen = [c for c in categories if is_furniture(c)]
    if not seen:
        return None
    return max(sorted(room_type_counts()), key=lambda t: sum(math.log(category_likelihood(c, t)) for c in seen))
