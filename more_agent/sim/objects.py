"""One object of the world: its box, what it is and where it rests (the world's and the packing's unit)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from more_agent.vocabulary import ObjectKind, Relation


@dataclass
class WorldObject:
    """One object of the world. ``center`` / ``size`` describe its axis-aligned box in metres."""

    name: str
    category: str
    kind: ObjectKind
    center: np.ndarray
    size: np.ndarray
    room: str | None = None
    synset: str | None = None
    openable: bool = False
    is_open: bool = False
    cloth: bool = False
    """Folds to fit where it rests (``packing.fit``), as BEHAVIOR-1K's deformable garments crumple."""
    parent: str | None = None
    relation: Relation | None = None
    instance_id: int = 0

    @property
    def movable(self) -> bool:
        """Items can be grasped and placed; floors, doors and furniture stay put."""
        return self.kind == "item"

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """(min corner, max corner) of the box."""
        half = self.size / 2
        return self.center - half, self.center + half

    def footprint(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the box seen from above (``box`` in plain floats: the same
        arithmetic, without numpy's per-call cost, as world building asks it hundreds of thousands of times)."""
        cx, cy, hx, hy = float(self.center[0]), float(self.center[1]), float(self.size[0]) / 2, float(self.size[1]) / 2
        return cx - hx, cy - hy, cx + hx, cy + hy

    @property
    def top(self) -> float:
        return float(self.center[2] + self.size[2] / 2)

    @property
    def bottom(self) -> float:
        return float(self.center[2] - self.size[2] / 2)
