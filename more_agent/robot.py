"""The robot as a planner sees it: frames in, skills out.

:class:`Robot` is everything a planner may touch of the world: posed RGB-D frames with semantic and
instance images and what perception says of each instance in view (:class:`Observation`),
proprioception (pose, held object, odometry) and the typed outcome of each low-level move and of
each world action of the skill table (:data:`more_agent.skills.SKILLS`). The simulator offers one
(``more_agent.sim.env.SimRobot``, through the Gymnasium env); a real robot would offer another. A
planner that holds a ``Robot`` cannot reach the world behind it: ``tests/test_privilege.py`` checks it.

This module is data and a protocol only, at the bottom of the package, so that the simulator, the
planners and the runner all read the same types.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from functools import cached_property
from typing import Generic, Protocol, TypeVar

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from more_agent.records import FailureReason
from more_agent.vocabulary import Relation

XY = tuple[float, float]
"""A point on the floor (x, y) in metres, world frame."""

Reason = TypeVar("Reason", bound=Enum)


@dataclass(frozen=True)
class Outcome(Generic[Reason]):
    """Success, the reason of a failure (None on success) and feedback in words for the planner."""

    ok: bool
    reason: Reason | None
    feedback: str


@dataclass(frozen=True)
class ActionResult(Outcome[FailureReason]):
    """The outcome of one action: success, typed reason and feedback, and the motion it took."""

    low_level_steps: int = 0
    path: list[XY] = field(default_factory=list)
    """Robot base positions visited, start and end included, when the robot moved."""
    blocking: str | None = None
    """The closed door in the way, when ``reason`` is PATH_BLOCKED_BY_DOOR, named as the action named its target:
    its label for a planner (what it can open; None while the robot has no label for it)."""


@dataclass(frozen=True, eq=False)
class Frame:
    """One camera frame. depth: (H, W) float32 z-depth in metres, NaN where invalid (nothing hit or
    beyond range); semantic / instance: (H, W) int32 (0 = unlabelled / none); rgb: (H, W, 3) uint8;
    K: (3, 3) intrinsics; T_world_cam: (4, 4) camera-to-world pose (OpenCV camera axes)."""

    rgb: np.ndarray
    depth: np.ndarray
    semantic: np.ndarray
    instance: np.ndarray
    K: np.ndarray
    T_world_cam: np.ndarray

    @cached_property
    def instance_pixels(self) -> np.ndarray:
        """Pixels per instance id (``np.bincount`` of ``instance``; read-only), counted once: the simulator's
        perception, the robot's bookkeeping and BUMBLE's memory each ask of every frame."""
        pixels = np.bincount(self.instance.ravel())
        pixels.setflags(write=False)
        return pixels


class InstanceInfo(BaseModel):
    """What perception says of one instance id (the paper assumes perfect instance segmentation and
    open/closed detection, so the simulator fills these from the world)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    label: str = Field(description="Alphabetical instance label from the world, e.g. 'fridge A'.")
    category: str = Field(description="Object category, e.g. 'fridge', 'door', 'apple'.")
    open: bool | None = Field(default=None, description="Open state; None when not openable.")
    held: bool = Field(default=False, description="True while the robot holds it.")
    rests: tuple[Relation, str | None] | None = Field(
        default=None,
        description="How it rests as perceived: ('inside' | 'ontop', label of the container / support, None for "
        "the floor). None when not reported: the builder then derives relations from box geometry.",
    )


@dataclass(frozen=True, eq=False)
class Observation:
    """One sensing: a frame and what perception says of the instances in it."""

    frame: Frame
    instances: Mapping[int, InstanceInfo]
    """Instance id -> its attributes: those in view, the held item, and those the robot just acted on
    or released (it knows what it did even when no camera sees it)."""
    placed: Mapping[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    """Instance id -> box (min, max corner) of an item released since the last sensing and of what
    rode on or in it: where the robot put them, kept on the map until a frame shows them."""
    revealed: Mapping[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    """Instance id -> box of each object inside what the robot just opened: paper S.2, "all inner objects
    within an articulated object become visible to the robot once the outer object is opened", whether or
    not the frame shows them (the simulator's open container keeps a top slab, which hides a book at the
    bottom of a carton from the steep look of a robot standing beside it)."""


class Robot(Protocol):
    """What any robot gives a planner and takes from it (module docstring).

    Moves and world actions never raise for a failure: it is a typed result. Targets of world actions
    name objects as perception labels them ('fridge A'), or a floor as :meth:`floor_here` names it.
    """

    @property
    def class_names(self) -> Sequence[str]:
        """Semantic class of each id of a frame's ``semantic`` image."""

    @property
    def pose(self) -> tuple[float, float, float]:
        """The base's (x, y, yaw) in the world frame, metres and radians."""

    @property
    def held(self) -> int | None:
        """The instance id of the object in the hand; None for an empty hand."""

    @property
    def trajectory(self) -> Sequence[XY]:
        """Odometry: every base position since the episode began, start included, one per position change."""

    @property
    def low_level_steps(self) -> int:
        """Low-level steps (moves, turns, the steps of magic actions) since the episode began."""

    def sense(self, acted_on: Sequence[str] = (), head: tuple[float, float] | None = None) -> Observation:
        """A frame from the current pose with what perception says of it; ``acted_on`` (labels: what the
        robot just opened or closed) are reported with their new state even when out of view; ``head``
        (pan left, tilt down, radians; within the head's joint limits) points the camera away from its
        driving pose for this frame (None: the driving pose)."""

    def move_forward(self, distance: float) -> bool:
        """One low-level move of at most ``FORWARD_STEP_M``; False when blocked (the robot does not move)."""

    def turn(self, angle: float) -> None:
        """One low-level turn in place by ``angle`` radians (positive: left), at most ``MAX_TURN_RAD``."""

    def act(self, action: str, target: str = "") -> ActionResult:
        """One world action of the skill table (``navigate_to``, ``grasp``, ..., ``done``) on ``target``;
        it drives next to a target out of reach first (the paper's magic actions)."""

    def reach_distance(self, target: str) -> float | None:
        """How far the base is from ``target``'s footprint (its arm reaches ``ROBOT.reach_m``); None when
        no object goes by that label."""

    def floor_here(self) -> str | None:
        """How :meth:`act` names the floor under the robot; None where there is none."""
