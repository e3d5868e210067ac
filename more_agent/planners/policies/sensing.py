"""When the robot fuses a frame while it moves: the cadence of its mapper.

A real robot's mapper does not fuse every camera frame; like the keyframe selection of visual SLAM
and volumetric mappers, it takes a new frame once the camera has moved far enough or turned far
enough since the last fused one. :class:`SensingSchedule` holds that rule in one place: the
embodiment asks :meth:`SensingSchedule.due` after each low-level move or turn and tells it the pose
of every frame it fuses (:meth:`SensingSchedule.fused`). Frames where the robot stops (arrival,
blocked move, manipulation) are fused regardless; the schedule only thins the frames on the way.
The default, 0.5 m or 30 deg (the rule BUMBLE's visual memory keeps frames by; the angle well below
the 63.3 deg field of view of the Fetch's camera), keeps the maps and graphs of the previous cadence
(a frame every 0.3 m and after every turn) within the agreement measured in docs/benchmarks.md
(``benchmarks/sensing_cadence.py``).
"""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field


class SensingCadence(BaseModel):
    """How far the robot moves or turns between two frames fused on the way."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    distance_m: float = Field(
        default=0.5, gt=0, description="Fuse a frame once the base moved this far since the last one."
    )
    angle_deg: float = Field(
        default=30.0, gt=0, lt=63.3, description="... or turned this far (below the camera's field of view)."
    )


class SensingSchedule:
    """Tracks the pose of the last fused frame and says when the next one is due."""

    def __init__(self, cadence: SensingCadence | None = None) -> None:
        self.cadence = cadence or SensingCadence()
        self._last: tuple[float, float, float] | None = None

    def due(self, x: float, y: float, yaw: float) -> bool:
        """Whether the pose (x, y, yaw) is far enough from the last fused frame's for a new frame."""
        if self._last is None:
            return True
        lx, ly, lyaw = self._last
        turned = abs(math.atan2(math.sin(yaw - lyaw), math.cos(yaw - lyaw)))
        return (
            math.hypot(x - lx, y - ly) >= self.cadence.distance_m - 1e-9
            or math.degrees(turned) >= self.cadence.angle_deg - 1e-9
        )

    def fused(self, x: float, y: float, yaw: float) -> None:
        """Record that a frame was fused at pose (x, y, yaw)."""
        self._last = (x, y, yaw)
