"""What the robot perceives at the step the ``grounded`` planner chooses in: read, never changed."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from more_agent.robot import XY
from more_agent.scene_graph import SceneGraph


@dataclass(frozen=True)
class Situation:
    """The step's scene graph, the names the step's words give its regions, and the robot's way."""

    graph: SceneGraph
    names: dict[str, str]
    """Region id -> the room name steps and feedback use ('kitchen_0')."""
    xy: XY
    """The robot's base position."""
    path: Sequence[XY]
    """Every base position since the episode began."""
    sensor_range_m: float
    """How far the depth camera maps (the unseen floor a frontier shows lies within it)."""

    @property
    def here(self) -> str | None:
        """The robot's region."""
        return self.graph.robot.region_id

    def room(self, region_id: str | None) -> str:
        """The room name of a region ('unknown' for none)."""
        return self.names.get(region_id or "", "unknown")
