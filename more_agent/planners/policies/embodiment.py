"""The robot as the subpolicies drive it: a :class:`~more_agent.robot.Robot`, the scene-graph builder
its frames feed, and what the subpolicies remember of where it went.

Every low-level action (7.5 cm forward moves, turns of at most 35 degrees) and every magic action is
one call of the robot (the simulator's steps its Gymnasium env), which counts it. Frames are sensed
by the robot and fused into the :class:`~more_agent.scene_graph.SceneGraphBuilder` wherever the robot
stops (arrival, a blocked move, after acting, every turn of a look around) and, on the way, at the
cadence of its mapper (the episode's ``sensing``, :class:`~more_agent.sensing_spec.SensingCadence`: once
it moved or turned far enough since the last frame), so the map grows while the robot drives. Nothing
here reads the world: what perception reports comes with each :class:`~more_agent.robot.Observation`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import Protocol, runtime_checkable

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from more_agent.mapping import MappingConfig
from more_agent.planners.policies.sensing import SensingSchedule
from more_agent.robot import XY, ActionResult, Frame, Robot
from more_agent.robot_spec import FORWARD_STEP_M, MAX_TURN_RAD, ROBOT, full_turn_angles
from more_agent.scene_graph import ObjectNode, SceneGraph, SceneGraphBuilder
from more_agent.sensing_spec import SensingCadence

PLAN_MARGIN_M = 0.05
"""Margin beyond the robot's radius that paths on the agent's map keep from mapped obstacles."""


RETYPE_GROWTH = 2
"""A typed region is typed again once it shows this many times the object categories it was typed on: the
first look into a garden may show only its patio's sofa and pillows (a living room), the rest of it trees and
bushes. Doubling bounds the retyping (and a language model's room calls) to a logarithm of what a room holds."""

LOOK_AROUND_TILT_DEG = 55.0
"""Head tilt of the downward looks in a full turn: with the Fetch's 63.3 deg view the image then spans 23 to
87 deg below the horizon, the floor from right beside the base to 2.8 m out (``Embodiment.look_around``)."""


class PolicyConfig(BaseModel):
    """Knobs of the subpolicies, in physical units."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    plan_inflation_m: float = Field(
        default=ROBOT.radius_m + PLAN_MARGIN_M,
        gt=0,
        description="Clearance from mapped obstacles kept by paths on the agent's map (robot radius + margin).",
    )
    max_replans: int = Field(
        default=3, ge=0, description="Replans on the updated map after a blocked move before giving up."
    )
    goal_snap_m: float = Field(
        default=1.0,
        gt=0,
        description="A goal off the traversable map moves to the nearest traversable cell within this distance.",
    )
    visited_frontier_m: float = Field(
        default=0.75, gt=0, description="Frontiers within this distance of one explored before are not chosen again."
    )
    blind_radius_m: float = Field(
        default=ROBOT.radius_m + PLAN_MARGIN_M,
        ge=0,
        description="Unknown cells this close to where the robot has been count as free on its map: the floor under "
        "and beside the base, which the head's downward looks (``look_around``, after a magic action's approach) "
        "do not show on a real robot. The driving pitch alone never shows the floor within ``Camera.blind_floor_m`` "
        "(0.95 m at the Fetch's 63.3 deg).",
    )
    look_around_at_frontier: bool = Field(default=True, description="Turn in place once at a reached frontier.")


@runtime_checkable
class MisreadsRooms(Protocol):
    """A robot whose room classifier input errs (``more_agent.perception.robot.NoisyRobot``, room-label noise)."""

    def room_input(self, objects: Iterable[tuple[str, str]]) -> list[str]:
        """The categories the room classifier reads for (label, category) pairs."""


class Embodiment:
    """A :class:`~more_agent.robot.Robot` + scene-graph builder, with what the subpolicies remember of
    the robot's way (frontiers explored, bumps)."""

    def __init__(
        self,
        robot: Robot,
        *,
        config: PolicyConfig | None = None,
        mapping: MappingConfig | None = None,
        sensing: SensingCadence | None = None,
        on_frame: Callable[[Frame], None] | None = None,
    ) -> None:
        self.robot = robot
        self.config = config or PolicyConfig()
        self.builder = SceneGraphBuilder(robot.class_names, mapping)
        self.visited_frontiers: list[XY] = []
        self.bumps: list[XY] = []
        """Where blocked moves met something (just ahead of the base): obstacles on the robot's map."""
        self.on_frame = on_frame
        """Called with every sensed frame (BUMBLE keeps them in its visual memory)."""
        self.observed: set[int] = set()
        """Instance ids seen so far, in view or in the hand (a planner tells from it whether a skill revealed anything)."""
        self.schedule = SensingSchedule(sensing)
        self.typed_on: dict[str, int] = {}
        """Region id -> how many object categories it showed when it was last typed (``RETYPE_GROWTH``)."""

    @property
    def xy(self) -> XY:
        """Robot base position."""
        x, y, _ = self.robot.pose
        return x, y

    @property
    def trajectory(self) -> Sequence[XY]:
        """Every base position since the episode began (the robot's odometry)."""
        return self.robot.trajectory

    @property
    def mapped_m2(self) -> float:
        """Floor area the robot's map knows (free or occupied), square metres: how much an explore showed."""
        cell = self.builder.config.resolution_m
        return float(np.count_nonzero(self.builder.voxels.top_class >= 0)) * cell * cell

    @property
    def low_level_steps(self) -> int:
        """Low-level steps since the episode began (the robot's count)."""
        return self.robot.low_level_steps

    def sense(self, acted_on: Sequence[str] = (), head: tuple[float, float] | None = None) -> None:
        """Sense a frame from the current pose and fuse it into the scene-graph builder: what the robot
        released since the last frame stays at its boxes until a frame shows it; ``acted_on`` (labels:
        what it just opened or closed) are reported with their new state even when out of view.
        ``head`` (pan left, tilt down; radians) points the head away from its driving pose
        (:meth:`look_down_at`)."""
        seen = self.robot.sense(acted_on, head=head)
        if self.on_frame is not None:
            self.on_frame(seen.frame)
        for instance_id, box in [*seen.placed.items(), *seen.revealed.items()]:
            self.builder.remember(instance_id, *box)
        frame = seen.frame
        self.builder.integrate(
            frame.depth, frame.semantic, frame.instance, frame.K, frame.T_world_cam, seen.instances, self.xy
        )
        self.observed.update([*np.flatnonzero(frame.instance_pixels).tolist(), *seen.revealed])
        if self.robot.held is not None:
            self.observed.add(self.robot.held)
        self.observed.discard(0)
        self.schedule.fused(*self.robot.pose)

    def look_down_at(self, xy: Sequence[float], acted_on: Sequence[str] = ()) -> None:
        """Pan and tilt the head to the floor at ``xy`` and sense (the base turns only when ``xy`` lies beyond
        the head's pan limit; head motions are no base steps and are not counted): the driving pitch leaves
        the floor within ``Camera.blind_floor_m``, and what lies low in a bag or on a table beside the robot,
        below the image. Aiming at the floor under an object puts its top and inside in view; through a
        doorway, the floor of the next room."""
        x, y, yaw = self.robot.pose
        cam = ROBOT.camera
        dx, dy = xy[0] - x, xy[1] - y
        pan = math.atan2(dy, dx) - yaw if math.hypot(dx, dy) > 1e-6 else 0.0
        pan = math.atan2(math.sin(pan), math.cos(pan))
        if abs(pan) > math.radians(cam.head_pan_limit_deg):  # behind the head's reach: turn the base
            self.face(xy)
            pan = 0.0
        tilt = min(
            max(math.atan2(cam.height_m, math.hypot(dx, dy)), math.radians(cam.pitch_deg)),
            math.radians(cam.head_tilt_limit_deg),
        )
        self.sense(acted_on, head=(pan, tilt))

    def sense_if_due(self) -> None:
        """Sense on the way: only when the schedule says the robot moved or turned far enough."""
        if self.schedule.due(*self.robot.pose):
            self.sense()

    def room_input(self, objects: Iterable[ObjectNode]) -> list[str]:
        """The categories the room classifier reads for these objects: theirs, or with a robot of noisy
        perception, some read as another category (room-label noise, docs/sensors.md#noisy-perception)."""
        pairs = [(o.label, o.category) for o in objects]
        if isinstance(self.robot, MisreadsRooms):
            return self.robot.room_input(pairs)
        return [category for _, category in pairs]

    def build(self) -> SceneGraph:
        """The scene graph of everything sensed so far, from the robot's position (joined with the
        components its path can drive back to)."""
        return self.builder.build(self.xy, self.trajectory)

    def start(self, *, sense_first: bool = True) -> None:
        """Begin an episode as every planner does: a frame where the robot stands (unless not
        ``sense_first``), then the full turn in place (paper S.3)."""
        if sense_first:
            self.sense()
        self.look_around()

    def step_graph(self, label_rooms: Callable[[SceneGraph], dict[str, str]] | None = None) -> SceneGraph:
        """The scene graph a step plans on: :meth:`build` without the frontiers explored before (so the
        scene text and explore() agree), its unlabelled regions labelled by ``label_rooms`` (region id
        -> room type; the builder keeps the labels for later steps), and so again each labelled region
        that has come to show ``RETYPE_GROWTH`` times the object categories it was typed on (handed to
        ``label_rooms`` without its label; it keeps its label when ``label_rooms`` gives none)."""
        graph = without_visited_frontiers(self.build(), self.visited_frontiers, self.config.visited_frontier_m)
        if label_rooms is None:
            return graph
        shown = {rid: len(_categories(graph, rid)) for rid in graph.regions}
        grown = [
            rid
            for rid, region in graph.regions.items()
            if region.room_label is not None and shown[rid] >= RETYPE_GROWTH * max(1, self.typed_on.get(rid, 0))
        ]
        labels = label_rooms(graph.without_room_labels(grown) if grown else graph)
        self.typed_on.update({rid: shown[rid] for rid in labels})
        if labels:
            self.builder.set_room_labels(labels)
            graph = graph.with_room_labels(labels)
        return graph

    def act(self, kind: str, target: str = "") -> ActionResult:
        """One magic action of the robot (a world action of the skill table: ``navigate_to``, ``grasp``,
        ..., ``done``) on ``target``, a label; the robot counts its motion."""
        return self.robot.act(kind, target)

    def turn_by(self, angle: float, *, on_the_way: bool = False) -> None:
        """Turn in place by ``angle`` radians in steps of at most 35 degrees, then sense (on the way:
        when the schedule says so)."""
        angle = math.atan2(math.sin(angle), math.cos(angle))
        n = math.ceil(abs(angle) / MAX_TURN_RAD - 1e-9)
        for _ in range(n):
            self.robot.turn(angle / n)
        if n:
            self.sense_if_due() if on_the_way else self.sense()

    def face(self, xy: Sequence[float], *, on_the_way: bool = False) -> None:
        """Turn towards a point (no-op when standing on it)."""
        x, y, yaw = self.robot.pose
        dx, dy = xy[0] - x, xy[1] - y
        if math.hypot(dx, dy) > 1e-6:
            self.turn_by(math.atan2(dy, dx) - yaw, on_the_way=on_the_way)

    def look_around(self) -> None:
        """A full turn in place, sensing after every turn (episode start, reached frontiers), with the head
        also tilted down after every other turn (``LOOK_AROUND_TILT_DEG``): the driving pitch never shows the
        floor within ``Camera.blind_floor_m``, which would leave the robot standing in a hole of unknown
        space that cuts it off from the map around it."""
        for i, angle in enumerate(full_turn_angles()):
            self.robot.turn(angle)
            self.sense()
            if i % 2 == 0:
                self.sense(head=(0.0, math.radians(LOOK_AROUND_TILT_DEG)))

    def follow(self, waypoints: Sequence[XY]) -> bool:
        """Drive along a polyline with low-level moves; False as soon as a move is blocked."""
        for target in waypoints[1:]:
            self.face(target, on_the_way=True)
            remaining = math.dist(self.xy, target)
            while remaining > 1e-6:
                distance = min(FORWARD_STEP_M, remaining)
                if not self.robot.move_forward(distance):
                    reach = FORWARD_STEP_M + ROBOT.radius_m
                    x, y, yaw = self.robot.pose
                    self.bumps.append((x + reach * math.cos(yaw), y + reach * math.sin(yaw)))
                    self.sense(head=(0.0, math.radians(LOOK_AROUND_TILT_DEG)))  # down at what the move met
                    return False
                remaining -= distance  # a move below the full step is made whole or not at all
                self.sense_if_due()
        self.sense()
        return True

    def sense_after(self, result: ActionResult) -> None:
        """Sense once a magic action has moved the robot (its path is not empty), also with the head down:
        the approach ends where the robot may never have seen the floor."""
        if result.path:
            self.sense()
            self.sense(head=(0.0, math.radians(LOOK_AROUND_TILT_DEG)))


def _categories(graph: SceneGraph, region_id: str) -> set[str]:
    """The object categories a region shows, doors left out (every room has them)."""
    return {o.category for o in graph.objects_in(region_id) if o.category != "door"}


def without_visited_frontiers(graph: SceneGraph, visited: Sequence[XY], radius_m: float) -> SceneGraph:
    """The graph without frontiers near ones already explored, so the scene text and explore() agree."""
    if not visited:
        return graph
    regions = {
        rid: r.model_copy(
            update={"frontiers": [f for f in r.frontiers if all(math.dist(f, v) > radius_m for v in visited)]}
        )
        for rid, r in graph.regions.items()
    }
    return graph.model_copy(update={"regions": regions})
