"""When the robot fuses a frame while it moves: the cadence of its mapper.

:class:`SensingSchedule` holds the rule of an episode's :class:`~more_agent.sensing_spec.SensingCadence`
(``--sensing``, docs/sensors.md) in one place: the embodiment asks :meth:`SensingSchedule.due` after each
low-level move or turn and tells it the pose of every frame it fuses (:meth:`SensingSchedule.fused`).
Frames where the robot stops (arrival, blocked move, manipulation) are fused regardless; the schedule
only thins the frames on the way.
"""

from __future__ import annotations

import math

from more_agent.sensing_spec import SensingCadence


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
