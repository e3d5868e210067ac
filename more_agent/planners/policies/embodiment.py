"""The robot as the subpolicies drive it: world, camera, scene-graph builder and step accounting.

The robot steps the world only through the Gymnasium env (:class:`more_agent.sim.env.MoreAgentEnv`,
built without sensors, goal or privileged info): every low-level action (7.5 cm forward moves, turns
of at most 35 degrees) and every magic action is one ``env.step``, and is counted. Frames are
rendered by the robot's own camera and fused into the
:class:`~more_agent.scene_graph.SceneGraphBuilder` after every turn sequence and every few forward
moves on the way (``PolicyConfig.sense_every_steps``), so the map grows while the robot drives.
Perception is ground truth as in the paper (S.2): instance attributes, open state and how an object
rests (inside / on top of what) are read from the world for the instances in view. With a
:class:`~more_agent.perception.NoisyPerception` (``--perception noisy``) the frames and the pose fused
into the map carry its errors, and what it names is resolved back to the real object
(:meth:`Embodiment.resolve`); the world and its magic actions stay exact.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from more_agent.mapping import MappingConfig
from more_agent.perception.model import NoisyPerception, correctly_seen
from more_agent.perception.noise import FRAGMENT_BASE
from more_agent.robot_spec import ROBOT
from more_agent.scene_graph import InstanceInfo, ObjectNode, SceneGraph, SceneGraphBuilder
from more_agent.sim.actions import FORWARD_STEP_M, MAX_TURN_RAD, ActionResult, FailureReason
from more_agent.sim.camera import Camera
from more_agent.sim.env import ACTION_TYPES, MoreAgentEnv
from more_agent.sim.motion import full_turn_angles
from more_agent.sim.navgrid import XY
from more_agent.sim.render import Frame, Renderer, instance_table
from more_agent.sim.world import World
from more_agent.vocabulary import Relation

PLAN_MARGIN_M = 0.05
"""Margin beyond the robot's radius that paths on the agent's map keep from mapped obstacles."""


class PolicyConfig(BaseModel):
    """Knobs of the subpolicies, in physical units."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    plan_inflation_m: float = Field(
        default=ROBOT.radius_m + PLAN_MARGIN_M,
        gt=0,
        description="Clearance from mapped obstacles kept by paths on the agent's map (robot radius + margin).",
    )
    sense_every_steps: int = Field(default=4, ge=1, description="Fuse a frame after this many forward moves on a path.")
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
        default_factory=lambda: Camera().blind_floor_m,
        ge=0,
        description="Unknown cells this close to where the robot has been count as free on its map: the camera "
        "never sees the floor this close to the robot (``Camera.blind_floor_m``: 0.56 m at 90 deg, 0.95 m at the Fetch's 63.3 deg).",
    )
    look_around_at_frontier: bool = Field(default=True, description="Turn in place once at a reached frontier.")


class Embodiment:
    """World (stepped through the env) + renderer + scene-graph builder, with low-level step, trajectory
    and observation accounting."""

    def __init__(
        self,
        world: World,
        *,
        config: PolicyConfig | None = None,
        mapping: MappingConfig | None = None,
        renderer: Renderer | None = None,
        on_frame: Callable[[Frame], None] | None = None,
        perception: NoisyPerception | None = None,
    ) -> None:
        self.world = world
        self.env = MoreAgentEnv(sensors=False, max_steps=None)
        self.env.reset(options={"world": world})
        self.config = config or PolicyConfig()
        self.renderer = renderer or Renderer()
        self.builder = SceneGraphBuilder(world.class_names, mapping)
        self.low_level_steps = 0
        self.trajectory: list[XY] = [self.xy]
        self.observed: set[str] = set()
        """World object names seen so far (for the rTP metric)."""
        self.visited_frontiers: list[XY] = []
        self._reported_steps, self._reported_path = 0, 1
        self.bumps: list[XY] = []
        """Where blocked moves met something (just ahead of the base): obstacles on the robot's map."""
        self.on_frame = on_frame
        """Called with every rendered frame (``--save-frames`` writes them)."""
        self._held: str | None = None
        self.perception = perception
        """The episode's perception errors; None: ground truth."""

    @property
    def xy(self) -> XY:
        """Robot base position."""
        return (float(self.world.robot.x), float(self.world.robot.y))

    def sense(self, acted_on: Sequence[str] = ()) -> None:
        """Render a frame from the current pose and fuse it into the scene-graph builder.

        The robot knows what it did: an item released since the last frame is reported as no longer
        held, resting where it was put, even when no camera sees it (the builder keeps it, and what
        rode on or in it, at their boxes until a frame shows them), and the objects in ``acted_on``
        (world names: what it just opened or closed) are reported with their new state even when out
        of view.
        """
        frame = self.renderer.render(self.world)
        if self.perception is not None:
            frame = self.perception.frame(frame)
        if self.on_frame is not None:
            self.on_frame(frame)
        table = instance_table(self.world, self.perception.whole if self.perception else frame.instance)
        infos = {
            i: InstanceInfo(
                label=d["label"], category=d["category"], open=d["open"], held=d["held"], rests=self._rests(d["name"])
            )
            for i, d in table.items()
        }
        released = self._held if self._held is not None and self._held != self.world.robot.held else None
        for name in [*acted_on, *([released] if released is not None else [])]:
            obj = self.world.get(name)
            infos.setdefault(
                obj.instance_id,
                InstanceInfo(
                    label=obj.label,
                    category=obj.category,
                    open=obj.is_open if obj.openable else None,
                    held=self.world.robot.held == name,
                    rests=self._rests(name),
                ),
            )
        if self.perception is not None:
            infos = self._misnamed(infos)
        if released is not None:
            for obj in [self.world.get(released), *self.world.descendants(released)]:  # with what rode on it
                self.builder.remember(obj.instance_id, *obj.box())
        self._held = self.world.robot.held
        self.builder.integrate(frame.depth, frame.semantic, frame.instance, frame.K, frame.T_world_cam, infos, self.xy)
        self.observed.update(correctly_seen(self.perception, {i: d["name"] for i, d in table.items()}))

    def _misnamed(self, infos: dict[int, InstanceInfo]) -> dict[int, InstanceInfo]:
        """``infos`` as noisy perception names them: confused instances (in view, held or acted on) under
        their seen category and a fresh label, one more entry per fragment in view (id ``FRAGMENT_BASE + i``,
        like its whole), and supports named as perceived."""
        noise = self.perception
        assert noise is not None
        out = dict(infos)
        for i in noise.to_rename(infos).tolist():
            info = infos.get(i - FRAGMENT_BASE if i >= FRAGMENT_BASE else i)
            named = noise.name(i, info.category) if info is not None else None
            if info is not None and named is not None:
                out[i] = info.model_copy(update={"label": named[0], "category": named[1]})
        seen_as = noise.seen_labels()
        for i, info in out.items():
            if info.rests is not None and info.rests[1] in seen_as:
                out[i] = info.model_copy(update={"rests": (info.rests[0], seen_as[info.rests[1]])})
        return out

    def resolve(self, label: str) -> str | None:
        """World name of the object a label means: one the robot's perception made up resolves to the real
        object behind it, others as the env resolves them."""
        made_up = self.perception.resolve(label) if self.perception is not None else None
        return made_up or self.env.resolve(label)

    def room_input(self, objects: Iterable[ObjectNode]) -> list[str]:
        """The categories the room classifier reads for these objects (room-label noise, if any)."""
        pairs = [(o.label, o.category) for o in objects]
        return self.perception.room_input(pairs) if self.perception is not None else [c for _, c in pairs]

    def since_last_report(self, result: ActionResult) -> ActionResult:
        """``result`` with the low-level steps and path the robot made since the previous call (the first
        call's include the initial full turn): what one high-level step reports to the episode loop."""
        steps, self._reported_steps = self.low_level_steps - self._reported_steps, self.low_level_steps
        path = self.trajectory[self._reported_path - 1 :] if len(self.trajectory) > self._reported_path else []
        self._reported_path = len(self.trajectory)
        return ActionResult(
            ok=result.ok,
            reason=result.reason,
            feedback=result.feedback,
            low_level_steps=steps,
            path=path,
            blocking=result.blocking,
        )

    def _rests(self, name: str) -> tuple[Relation, str | None] | None:
        """How a seen object rests, as perception reports it: the world's support link (what the last
        placement did), the support named by its label (None for a floor); None while held."""
        obj = self.world.get(name)
        if obj.parent is None or obj.relation is None:
            return None if self.world.robot.held == name else ("ontop", None)
        parent = self.world.get(obj.parent)
        return obj.relation, parent.label if parent.kind != "floor" else None

    def build(self) -> SceneGraph:
        """The scene graph of everything sensed so far, from the robot's position (joined with the
        components its path can drive back to)."""
        return self.builder.build(self.xy, self.trajectory)

    def act(self, kind: str, target: str = "") -> ActionResult:
        """One magic action of the env (a world action of the skill table: ``navigate_to``, ``grasp``,
        ..., ``done``) on ``target``, a world name or label. Its steps and path are not accounted here
        (the oracle passes them to :meth:`add_motion`, the subpolicies to :meth:`record_jump`)."""
        info = self._step(kind, target=target)
        reason = FailureReason(info["reason"]) if info["reason"] else None
        return ActionResult(
            ok=info["action_ok"],
            reason=reason,
            feedback=info["feedback"],
            low_level_steps=info["low_level_steps"],
            path=info["path"],
            blocking=info["blocking"],
        )

    def _step(self, kind: str, *, target: str = "", amount: float | None = None) -> dict[str, Any]:
        """``env.step`` of action type ``kind`` (:data:`~more_agent.sim.env.ACTION_TYPES`); its info."""
        action: dict[str, object] = {"type": ACTION_TYPES.index(kind), "target": target}
        if amount is not None:
            action["amount"] = amount  # a Python float: the env keeps its full precision
        return self.env.step(action)[-1]

    def _turn(self, angle: float) -> None:
        """One low-level turn by ``angle`` radians (positive: left)."""
        self._step("turn_left" if angle >= 0 else "turn_right", amount=abs(angle))
        self.low_level_steps += 1

    def turn_by(self, angle: float) -> None:
        """Turn in place by ``angle`` radians in steps of at most 35 degrees, then sense."""
        angle = math.atan2(math.sin(angle), math.cos(angle))
        n = math.ceil(abs(angle) / MAX_TURN_RAD - 1e-9)
        for _ in range(n):
            self._turn(angle / n)
        if n:
            self.sense()

    def face(self, xy: Sequence[float]) -> None:
        """Turn towards a point (no-op when standing on it)."""
        dx, dy = xy[0] - self.world.robot.x, xy[1] - self.world.robot.y
        if math.hypot(dx, dy) > 1e-6:
            self.turn_by(math.atan2(dy, dx) - self.world.robot.yaw)

    def look_around(self) -> None:
        """A full turn in place, sensing after every turn (episode start, reached frontiers)."""
        for angle in full_turn_angles():
            self._turn(angle)
            self.sense()

    def follow(self, waypoints: Sequence[XY]) -> bool:
        """Drive along a polyline with low-level moves; False as soon as a move is blocked."""
        moved = 0
        for target in waypoints[1:]:
            self.face(target)
            remaining = math.dist(self.xy, target)
            while remaining > 1e-6:
                distance = min(FORWARD_STEP_M, remaining)
                ok = self._step("move_forward", amount=distance)["action_ok"]
                self.low_level_steps += 1
                if not ok:
                    reach = FORWARD_STEP_M + ROBOT.radius_m
                    yaw = self.world.robot.yaw
                    self.bumps.append((self.xy[0] + reach * math.cos(yaw), self.xy[1] + reach * math.sin(yaw)))
                    self.sense()
                    return False
                remaining -= distance  # a move below the full step is made whole or not at all
                moved += 1
                self._odometry(self.trajectory[-1], self.xy)
                self.trajectory.append(self.xy)
                if moved % self.config.sense_every_steps == 0:
                    self.sense()
        self.sense()
        return True

    def record_jump(self, path: Sequence[XY], steps: int) -> None:
        """Account for a motion a magic action made (its path and low-level steps), then sense."""
        self.add_motion(path, steps)
        if path:
            self.sense()

    def add_motion(self, path: Sequence[XY], steps: int) -> None:
        """Count a motion made by a magic action (its path, start included, and low-level steps) without sensing."""
        self.low_level_steps += steps
        for x, y in path[1:]:
            self._odometry(self.trajectory[-1], (float(x), float(y)))
            self.trajectory.append((float(x), float(y)))

    def _odometry(self, before: XY, after: XY) -> None:
        """Drift of the noisy perception's odometry for a move from ``before`` to ``after``."""
        if self.perception is not None:
            self.perception.moved(before, math.dist(before, after))
