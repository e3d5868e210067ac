"""``NoisyRobot``: a :class:`~more_agent.robot.Robot` that perceives through a real robot's errors.

It wraps the simulator's robot (``SimRobot``) and passes every call through, except what perception
touches: each :meth:`NoisyRobot.sense` goes through the episode's
:class:`~more_agent.perception.model.NoisyPerception` (frames, pose, names), labels it made up are
turned back into the real object's before a world action, a reach query or a sensing of what was just
acted on, and the real label in an action's feedback is given back as the made-up one. Motion and world
actions stay exact. A real robot needs none of it: its perception errs on its own.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import replace

from more_agent.perception.model import NoisyPerception
from more_agent.robot import XY, ActionResult, Observation, Robot


class NoisyRobot:
    """``robot`` with the perception errors of ``noise`` (module docstring)."""

    def __init__(self, robot: Robot, noise: NoisyPerception) -> None:
        self.inner, self.noise = robot, noise
        self._odometry_at = 1
        """How many points of the robot's trajectory the odometry drift has accounted for."""

    @property
    def class_names(self) -> Sequence[str]:
        return self.inner.class_names

    @property
    def pose(self) -> tuple[float, float, float]:
        return self.inner.pose

    @property
    def held(self) -> int | None:
        return self.inner.held

    @property
    def trajectory(self) -> Sequence[XY]:
        return self.inner.trajectory

    @property
    def low_level_steps(self) -> int:
        return self.inner.low_level_steps

    def sense(self, acted_on: Sequence[str] = (), head: tuple[float, float] | None = None) -> Observation:
        """The inner robot's observation as this perception reports it (drift brought up to date first)."""
        self._drive_odometry()
        real = [self.noise.real_label(label) for label in acted_on]
        seen = self.inner.sense(real, head=head)
        known = {i for i, info in seen.instances.items() if info.held or info.label in real}
        frame, instances = self.noise.observe(
            seen.frame, seen.instances, known | set(seen.placed) | set(seen.revealed), told=seen.revealed
        )
        return Observation(frame=frame, instances=instances, placed=seen.placed, revealed=seen.revealed)

    def _drive_odometry(self) -> None:
        """Drift for every stretch driven since the last sensing, in order."""
        path = self.inner.trajectory
        for k in range(self._odometry_at, len(path)):
            self.noise.moved(path[k - 1], math.dist(path[k - 1], path[k]))
        self._odometry_at = len(path)

    def move_forward(self, distance: float) -> bool:
        return self.inner.move_forward(distance)

    def turn(self, angle: float) -> None:
        self.inner.turn(angle)

    def act(self, action: str, target: str = "") -> ActionResult:
        """The world action on the real object behind ``target``; its feedback and the door in its way name
        objects as perceived."""
        real = self.noise.real_label(target)
        result = self.inner.act(action, real)
        acted_on = {real: target} if real and real != target else {}
        feedback = self.noise.perceived_text(result.feedback, acted_on)
        door = result.blocking and self.noise.perceived_text(result.blocking, acted_on)
        if (feedback, door) == (result.feedback, result.blocking):
            return result
        return replace(result, feedback=feedback, blocking=door)

    def reach_distance(self, target: str) -> float | None:
        return self.inner.reach_distance(self.noise.real_label(target))

    def floor_here(self) -> str | None:
        return self.inner.floor_here()

    def room_input(self, objects: Iterable[tuple[str, str]]) -> list[str]:
        """What the room classifier reads for (label, category) pairs (room-label noise)."""
        return self.noise.room_input(objects)
