"""Placement audit: task items that no camera pose could see or no arm could reach where they were put.

Two defects are counted (figures: docs/benchmarks.md, "World"):
- ``enclosed``: the item's box lies within the box of an object that is not one of its supports
  (a candle inside a TV that stands on the same coffee table); the renderer never draws it.
- ``out_of_reach``: the item rests higher than ``REACH_TOP_M`` (on top of a 2 m grocery shelf); the
  arm cannot take it and the 1.2 m camera sees at most its upper edge from afar.
"""

from __future__ import annotations

import numpy as np

from more_agent.sim.packing import REACH_TOP_M
from more_agent.sim.world import World

TOLERANCE_M = 0.01
"""How far an item may stick out of a box and still count as enclosed by it."""


def enclosing_object(world: World, name: str) -> str | None:
    """Name of an object, not among ``name``'s supports, whose box encloses ``name``'s box; else None."""
    lo, hi = world.objects[name].box()
    supports = {parent.name for parent, _ in world.ancestors(name)}
    others = [o for o in world.objects.values() if o.name != name and o.name not in supports and o.kind != "floor"]
    if not others:
        return None
    centers, halves = np.array([o.center for o in others]), np.array([o.size for o in others]) / 2
    encloses = np.all(lo >= centers - halves - TOLERANCE_M, axis=1) & np.all(
        hi <= centers + halves + TOLERANCE_M, axis=1
    )
    return next((o.name for o, e in zip(others, encloses) if e), None)


def out_of_reach(world: World, name: str) -> bool:
    """Whether the item rests higher than the arm reaches (``REACH_TOP_M``)."""
    return world.objects[name].bottom > REACH_TOP_M + TOLERANCE_M


def audit(world: World, names: list[str]) -> dict[str, dict[str, str] | list[str]]:
    """The items among ``names`` enclosed by another box (item -> that object's kind and name), and
    those out of reach."""
    enclosing = {n: enclosing_object(world, n) for n in names}
    return {
        "enclosed": {n: f"{world.objects[e].kind} {e}" for n, e in enclosing.items() if e is not None},
        "out_of_reach": [n for n in names if out_of_reach(world, n)],
    }
