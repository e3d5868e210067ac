"""Instance labels: what the robot calls the objects it has seen ('fridge A'), kept on the perception side.

An object has no label until it is observed (or named by the task description, which reserves its
label before the episode): labels are handed out per category in that order, so a label never
reveals an instance not yet seen. The world knows nothing of them; the task instance owns one
``InstanceLabels`` and the simulator's robot and env label what their frames show through it.
Perception is ground truth in the paper (S.2), so an instance's attributes are read from the world.
"""

from __future__ import annotations

import re
import string
from collections.abc import Iterable
from typing import Any

import numpy as np

from more_agent.sim.objects import WorldObject
from more_agent.sim.world import World


class InstanceLabels:
    """World name -> label of every object observed or named so far, and how many of each category."""

    def __init__(self) -> None:
        self._labels: dict[str, str] = {}
        self._names: dict[str, str] = {}
        """Label -> world name."""
        self._used: dict[str, int] = {}
        """Category -> how many labels of it have been handed out."""
        self._by_instance: dict[int, WorldObject] = {}
        """Instance id -> object, rebuilt only when an id no longer names an object of the world."""

    def reserve(self, obj: WorldObject) -> str:
        """The object's label, giving it the next free one of its category first if it has none.

        Floors get none (they are named by their room).
        """
        if obj.name not in self._labels and obj.kind != "floor":
            label = self.fresh_label(obj.category)
            self._labels[obj.name], self._names[label] = label, obj.name
        return self._labels.get(obj.name, "")

    def fresh_label(self, category: str) -> str:
        """The next free label of ``category`` (counted as handed out)."""
        used = self._used.get(category, 0)
        self._used[category] = used + 1
        return f"{category} {_alpha(used)}"

    def observe(self, objects: Iterable[WorldObject]) -> None:
        """Label the objects seen for the first time, in the order given."""
        for obj in objects:
            self.reserve(obj)

    def assign_all(self, world: World) -> None:
        """Label every object not labelled yet, per category in name order (tools and tests; an
        episode labels objects as they are observed)."""
        self.observe(sorted(world.objects.values(), key=lambda o: _natural_key(o.name)))

    def label(self, name: str) -> str:
        """The label of the object named ``name`` ('' while it has none)."""
        return self._labels.get(name, "")

    def display(self, obj: WorldObject) -> str:
        """What the robot may call an object: its label once observed, else just its category."""
        return self._labels.get(obj.name) or obj.category

    def find(self, label: str, *, ignore_case: bool = False) -> str | None:
        """World name of the object with this label (exactly, else with ``ignore_case`` ignoring case), or None."""
        if label in self._names or not ignore_case:
            return self._names.get(label)
        key = label.lower()
        return next((name for known, name in self._names.items() if known.lower() == key), None)

    def table(self, world: World, instance: np.ndarray, pixels: np.ndarray | None = None) -> dict[int, dict[str, Any]]:
        """Metadata of every instance id seen in an instance image, plus the held item. ``pixels``: the image's
        pixels per id when the caller has counted them (``Frame.instance_pixels``).

        Objects seen for the first time get their label here, in the order of their first pixel, so
        labels follow the order of observation.

        Maps id -> {"name", "label", "category", "open" (bool, None when not openable), "held"}; the
        held item is listed (held=True) although no camera sees it, so that a map can drop it from its
        old place.
        """
        flat = instance.ravel()
        pixels = np.bincount(flat) if pixels is None else pixels  # per instance id
        seen = set(np.flatnonzero(pixels).tolist()) - {0}
        held = world.robot.held
        if held is not None:
            seen.add(world.objects[held].instance_id)
        by_id = self._objects(world, seen)
        new = [i for i in seen if by_id[i].name not in self._labels and by_id[i].kind != "floor"]
        if new:  # first observations get their labels in reading order of the image
            is_new = np.zeros(pixels.size, dtype=bool)
            is_new[[i for i in new if i < pixels.size]] = True
            at = np.flatnonzero(is_new[flat])  # only the new ones' pixels are sorted, not the whole image's
            ids, first = np.unique(flat[at], return_index=True)
            order = dict(zip(ids.tolist(), at[first].tolist()))
            self.observe(by_id[i] for i in sorted(new, key=lambda i: (order.get(i, -1), i)))
        return {
            i: {
                "name": by_id[i].name,
                "label": self.label(by_id[i].name),
                "category": by_id[i].category,
                "open": bool(by_id[i].is_open) if by_id[i].openable else None,
                "held": by_id[i].name == held,
            }
            for i in sorted(seen)
        }

    def _objects(self, world: World, ids: Iterable[int]) -> dict[int, WorldObject]:
        """The objects with the given instance ids (id -> object), without a pass over every object
        on each call: sensing asks this for every frame, and a store holds hundreds of objects."""
        found = {}
        for i in ids:
            obj = self._by_instance.get(i)
            if obj is None or world.objects.get(obj.name) is not obj:  # added or removed since
                self._by_instance = {o.instance_id: o for o in world.objects.values()}
                obj = self._by_instance[i]
            found[i] = obj
        return found


def _alpha(i: int) -> str:
    """0 -> A, 25 -> Z, 26 -> AA, ... (spreadsheet-style column letters)."""
    letters = ""
    i += 1
    while i:
        i, rem = divmod(i - 1, 26)
        letters = string.ascii_uppercase[rem] + letters
    return letters


def _natural_key(name: str) -> list[object]:
    """Sort 'apple_2' before 'apple_10'."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]
