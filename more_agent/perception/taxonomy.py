"""Which category a detector confuses an object with: its nearest relatives in bddl's object taxonomy."""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

import numpy as np

from more_agent.sim import catalog

MAX_LEVELS = 1
"""How far up the taxonomy a relative is sought: siblings only (a shared parent synset). Cousins
(a shared grandparent) reach too far: a mug's include the bathtub."""


@cache
def relatives(category: str, levels: int = MAX_LEVELS) -> tuple[tuple[str, ...], ...]:
    """Categories sharing an ancestor with ``category``, nearest first: one sorted tuple per level
    (shared parent synset, then grandparent, ...), ``category`` itself left out. apple -> pear, ...

    >>> "pear" in relatives("apple")[0]
    True
    """
    tax = catalog.taxonomy()
    frontier = set(catalog.category_synsets(category))
    out: list[tuple[str, ...]] = []
    for _ in range(levels):
        frontier = {p for s in frontier for p in tax.get_parents(s)}
        found = {c for p in frontier for c in tax.get_subtree_categories(p)} - {category}
        out.append(tuple(sorted(found)))
    return tuple(out)


def sibling_category(category: str, vocabulary: Sequence[str], rng: np.random.Generator) -> str | None:
    """A random nearest relative of ``category`` among ``vocabulary`` (the detector's classes), None if none."""
    known = set(vocabulary)
    for level in relatives(category):
        options = [c for c in level if c in known]
        if options:
            return options[int(rng.integers(len(options)))]
    return None
