"""The Gymnasium environment ``MoreAgent/Behavior-v0``: one BEHAVIOR-1K activity in the embedded world.

Observation (a ``spaces.Dict``): ``rgb`` (256, 256, 3) uint8; ``depth`` (256, 256) float32 z-depth in
metres with **0 where invalid** (nothing hit or beyond 5 m; Gymnasium spaces cannot hold NaN, and
``frame_from_observation`` restores the renderer's NaN convention); ``semantic`` / ``instance``
(256, 256) int32 (ids index ``info["class_names"]`` / ``WorldObject.instance_id``); ``pose`` the 4x4
T_world_cam; ``intrinsics`` K; ``robot_pose`` (x, y, yaw); ``held`` the held item's instance id (0:
empty hand).

With ``sensors=False`` nothing is rendered: the observation holds only ``robot_pose`` and ``held``,
and reset makes no initial turn. That is how the agent's embodiment
(:class:`more_agent.planners.policies.Embodiment`) steps the world: it senses with its own camera
when it chooses to, not after every 7.5 cm move.

Action (a ``spaces.Dict``): ``type`` indexes ``ACTION_TYPES`` (the low-level moves, then the world
actions of the skill table :data:`more_agent.skills.SKILLS`); ``amount`` is metres for
``move_forward`` (at most 0.075) and radians for the turns (at most 35 degrees; more is clipped and
reported); ``target`` names an object by world name ('fridge_0') or label ('fridge A') for the magic
actions. Manipulations first drive next to a target out of reach (the paper's go-to-and-act
subpolicies). ``make_action`` builds actions with the paper's default amounts. An invalid action or
unknown object is reported in ``info`` (``action_ok`` False, ``reason``, ``feedback``) and the
episode goes on.

``reset(seed=..., options={"task": ..., "scene": ..., "instance": TaskInstance, "task_seed": int,
"world": World, "labels": InstanceLabels})``: an injected instance is used as is, with its labels; so
is an injected world (no task, the robot where it stands; its objects labelled through ``labels`` when
given, else afresh); a task is instantiated (seed ``task_seed``, else drawn from
``np_random``); a scene alone (default ``DEFAULT_SCENE``) gets no task and a start pose drawn from
``np_random`` among the free cells of the navigation grid. With sensors every episode starts with
a full turn in place (S.3): ``info["turn_frames"]`` holds the frames of the turn, and the observation is the
view after it. ``info["path_frames"]`` likewise holds views along a magic navigation's path every
``path_frame_spacing_m``. ``terminated`` when ``done`` is taken; ``truncated`` after ``max_steps``
steps (never when ``max_steps`` is None). The reward is the change in goal progress (0 without a task).

``info`` carries what the agent could know: the action's outcome and feedback, step counts, the
path of a magic navigation, the closed door that blocked it (``blocking``) and the instance table
of the view. Goal state is privileged: only an
env built with ``privileged_info=True`` adds ``info["goal_status"]`` (a ``GoalStatus``: per-conjunct
status, ``all_met``, ``progress``), for evaluation code and tests, never for a planner under test.

:class:`SimRobot` is the :class:`~more_agent.robot.Robot` the simulator offers a planner: it steps
this env without sensors (every low-level move and magic action one ``env.step``), renders with the
robot's own camera when the planner senses, and keeps the robot's odometry, which the episode runner
reads for each step's motion.
"""

from __future__ import annotations

import math
import string
from collections.abc import Callable, Mapping, Sequence
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from more_agent.records import FailureReason
from more_agent.robot import XY, ActionResult, InstanceInfo, Observation
from more_agent.robot_spec import full_turn_angles
from more_agent.sim import actions, motion
from more_agent.sim.camera import Camera, camera_pose
from more_agent.sim.goals import GoalChecker, GoalStatus
from more_agent.sim.instantiate import TaskInstance, instantiate
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.navgrid import free_cells, nav_grid
from more_agent.sim.render import Frame, Renderer
from more_agent.sim.scenes import get_scene
from more_agent.sim.world import World, floor_name
from more_agent.skills import SKILLS
from more_agent.vocabulary import Relation

ENV_ID = "MoreAgent/Behavior-v0"

MOTIONS: tuple[str, ...] = ("move_forward", "turn_left", "turn_right")
"""The low-level moves (paper S.3)."""

ACTION_TYPES: tuple[str, ...] = MOTIONS + tuple(s.world_action for s in SKILLS if s.world_action is not None)
"""Names of the action types, indexed by the action's ``type``: the low-level moves, then the world
actions of the skill table (navigate_to, open, close, grasp, place_inside, place_ontop, done)."""

DEFAULT_SCENE = "Rs_int"
"""Scene used when neither the constructor nor reset options name one (no task)."""

TARGET_CHARSET = string.ascii_letters + string.digits + " _-."
"""Characters of the ``target`` text space (object names and labels)."""

_INT32_MAX = np.iinfo(np.int32).max
_COORD_LIMIT_M = 1e4


def make_action(kind: str, target: str = "", amount: float | None = None) -> dict[str, Any]:
    """An action dict for ``kind`` (a name in ACTION_TYPES); the amount defaults to a full step or turn."""
    if amount is None:
        amount = (
            actions.FORWARD_STEP_M
            if kind == "move_forward"
            else actions.MAX_TURN_RAD
            if kind.startswith("turn")
            else 0.0
        )
    return {"type": ACTION_TYPES.index(kind), "amount": np.array(amount, dtype=np.float32), "target": target}


def frame_from_observation(obs: Mapping[str, np.ndarray]) -> Frame:
    """The renderer's ``Frame`` (NaN for invalid depth) from an observation."""
    depth = obs["depth"].astype(np.float32, copy=True)
    depth[depth <= 0] = np.nan
    return Frame(
        rgb=obs["rgb"].copy(),
        depth=depth,
        semantic=obs["semantic"].copy(),
        instance=obs["instance"].copy(),
        K=obs["intrinsics"].copy(),
        T_world_cam=obs["pose"].copy(),
    )


def _observation_space(cam: Camera, sensors: bool) -> spaces.Dict:
    """The observation space (module docstring): the robot's state, and the camera's images with sensors."""
    hw = (cam.height, cam.width)
    ids = spaces.Box(0, _INT32_MAX, hw, np.int32)
    state: dict[str, spaces.Space[Any]] = {
        "robot_pose": spaces.Box(
            np.array([-_COORD_LIMIT_M, -_COORD_LIMIT_M, -math.pi]),
            np.array([_COORD_LIMIT_M, _COORD_LIMIT_M, math.pi]),
            (3,),
            np.float64,
        ),
        "held": spaces.Box(0, _INT32_MAX, (), np.int32),
    }
    if not sensors:
        return spaces.Dict(state)
    images: dict[str, spaces.Space[Any]] = {
        "rgb": spaces.Box(0, 255, (*hw, 3), np.uint8),
        "depth": spaces.Box(0.0, cam.max_range_m, hw, np.float32),
        "semantic": ids,
        "instance": ids,
        "pose": spaces.Box(-_COORD_LIMIT_M, _COORD_LIMIT_M, (4, 4), np.float64),
        "intrinsics": spaces.Box(0.0, _COORD_LIMIT_M, (3, 3), np.float64),
    }
    return spaces.Dict({**images, **state})


class MoreAgentEnv(gym.Env[dict[str, np.ndarray], dict[str, Any]]):
    """Rearrangement in the embedded BEHAVIOR-1K world with ground-truth RGB-D-semantic perception."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        task: str | None = None,
        scene: str | None = None,
        *,
        render_mode: str | None = None,
        max_steps: int | None = 1000,
        camera: Camera | None = None,
        path_frame_spacing_m: float = 1.0,
        sensors: bool = True,
        privileged_info: bool = False,
    ) -> None:
        """``task`` / ``scene``: what reset loads when its options name nothing; ``max_steps``: truncation
        limit in env steps (None: none); ``path_frame_spacing_m``: spacing of the views along a
        navigation path (0: none); ``sensors``: render observations; ``privileged_info``: add the goal
        status to ``info``."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"unsupported render_mode {render_mode!r}; supported: {self.metadata['render_modes']}")
        self.render_mode = render_mode
        self.task, self.scene, self.max_steps = task, scene, max_steps
        self.path_frame_spacing_m = path_frame_spacing_m
        self.sensors, self.privileged_info = sensors, privileged_info
        self.renderer = Renderer(camera)
        self.observation_space = _observation_space(self.renderer.camera, sensors)  # type: ignore[assignment]  # a Dict space
        self.action_space = spaces.Dict(
            {
                "type": spaces.Discrete(len(ACTION_TYPES)),
                "amount": spaces.Box(0.0, np.float32(math.pi), (), np.float32),
                "target": spaces.Text(max_length=128, min_length=0, charset=TARGET_CHARSET),
            }
        )
        self.world: World | None = None
        self.labels = InstanceLabels()
        """What the robot calls the objects it has seen (the instance's, else the injected ones)."""
        self.instance: TaskInstance | None = None
        self._goal: GoalChecker | None = None
        self._progress = 0.0
        self._steps = 0
        self._low_level_steps = 0
        self._last_rgb: np.ndarray | None = None

    # -- episode ---------------------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        options = options or {}
        world = options.get("world")
        self.instance = self._load(options) if world is None else None
        if self.instance is not None:
            self.world, self.labels = self.instance.world, self.instance.labels
            self._goal = GoalChecker(self.instance)
        elif world is not None:
            self.world, self._goal = world, None
            self.labels = options["labels"] if options.get("labels") is not None else InstanceLabels()
        else:
            self.world = World.from_scene(get_scene(options.get("scene") or self.scene or DEFAULT_SCENE, 0))
            self._goal, self.labels = None, InstanceLabels()
            self._spawn()
        self._steps, self._low_level_steps = 0, 0
        turn_frames = self._turn_around() if self.sensors else [self._record()]
        status = self._status()
        self._progress = status.progress if status is not None else 0.0
        obs = {k: v.copy() for k, v in turn_frames[0]["obs"].items()}  # the turn ends where it began
        self._last_rgb = obs.get("rgb")
        feedback = "turned around in place" if self.sensors else "ready"
        info = self._info(status, "reset", True, None, feedback, self._low_level_steps, [], turn_frames[0]["instances"])
        info.update(
            turn_frames=turn_frames if self.sensors else [],
            path_frames=[],
            class_names=list(self.world.class_names),
            task=self.instance.task if self.instance else None,
            task_description=self.instance.description if self.instance else None,
        )
        return obs, info

    def step(
        self, action: Mapping[str, Any]
    ) -> tuple[dict[str, np.ndarray], SupportsFloat, bool, bool, dict[str, Any]]:
        if self.world is None:
            raise RuntimeError("call reset() before step()")
        self._steps += 1
        kind, amount, target, error = _parse(action)
        path: list[tuple[float, float]] = []
        blocking = None
        if error is not None:
            ok, reason, feedback, steps = False, "invalid_action", error, 0
        elif kind == "done":
            ok, reason, feedback, steps = True, None, "episode ended", 0
        elif kind in MOTIONS:
            res = self._move(kind, amount)
            ok, reason, feedback, steps = (
                res.ok,
                res.reason.value if res.reason else None,
                res.feedback,
                res.low_level_steps,
            )
        else:
            name = self.resolve(target)
            if name is None:
                ok, reason, feedback, steps = False, "unknown_object", f"unknown object {target!r}", 0
            else:
                assert kind is not None  # parsed without error
                act = (
                    actions.navigate_to(self.world, name, self.labels)
                    if kind == "navigate_to"
                    else actions.go_to_and(self.world, kind, name, self.labels)
                )
                ok, reason, feedback, steps = (
                    act.ok,
                    act.reason.value if act.reason else None,
                    act.feedback,
                    act.low_level_steps,
                )
                path, blocking = list(act.path), act.blocking
        self._low_level_steps += steps
        record = self._record()
        status = self._status()
        progress = status.progress if status is not None else 0.0
        reward, self._progress = progress - self._progress, progress
        self._last_rgb = record["obs"].get("rgb")
        info = self._info(status, kind or "invalid", ok, reason, feedback, steps, path, record["instances"])
        info.update(blocking=blocking, path_frames=self._path_frames(path))
        truncated = self.max_steps is not None and self._steps >= self.max_steps and kind != "done"
        return record["obs"], float(reward), kind == "done", truncated, info

    def resolve(self, target: str) -> str | None:
        """World name of the object a target names: its name, or its label (exactly, else ignoring case)."""
        if self.world is None:
            raise RuntimeError("call reset() before resolve()")
        key = target.strip()
        if key in self.world.objects:
            return key
        return self.labels.find(key, ignore_case=True)

    def render(self) -> np.ndarray | None:
        """The RGB frame of the latest observation (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array" or self._last_rgb is None:
            return None
        return self._last_rgb.copy()

    # -- helpers ---------------------------------------------------------------------------------
    def _load(self, options: Mapping[str, Any]) -> TaskInstance | None:
        """The task instance the options (or the constructor) ask for, or None for a scene without task."""
        if options.get("instance") is not None:
            return options["instance"]
        task = options.get("task") or (self.task if not options.get("scene") else None)
        if task is None:
            return None
        task_seed = options.get("task_seed")
        if task_seed is None:
            task_seed = int(self.np_random.integers(2**31 - 1))
        return instantiate(task, options.get("scene") or self.scene, seed=int(task_seed))

    def _spawn(self) -> None:
        """Put the robot at a free navigation cell and heading drawn from ``np_random``."""
        assert self.world is not None
        grid = nav_grid(self.world)
        cells = free_cells(grid.free)
        if len(cells) == 0:
            raise ValueError(f"scene {self.world.scene.name} has no free space for the robot")
        x, y = grid.centre(cells[int(self.np_random.integers(len(cells)))])
        self.world.set_robot_pose(x, y, float(self.np_random.uniform(-math.pi, math.pi)))

    def _turn_around(self) -> list[dict[str, Any]]:
        """The full turn in place every episode starts with (S.3): the records of its distinct views."""
        assert self.world is not None
        start = self.world.robot
        x, y, yaw = start.x, start.y, start.yaw
        turn_frames = [self._record()]
        angles = full_turn_angles()
        for angle in angles[:-1]:
            motion.turn(self.world, angle)
            turn_frames.append(self._record())
        self.world.set_robot_pose(x, y, yaw)  # the last turn closes the circle (without rounding drift)
        self._low_level_steps = len(angles)
        return turn_frames

    def _move(self, kind: str, amount: float) -> motion.MotionResult:
        assert self.world is not None
        if kind == "move_forward":
            return motion.move_forward(self.world, amount)
        if amount < 0:
            return motion.MotionResult(
                False, motion.MotionFailure.INVALID_AMOUNT, f"turn amount must be >= 0, got {amount}", 0.0
            )
        return motion.turn(self.world, amount if kind == "turn_left" else -amount)

    def _status(self) -> GoalStatus | None:
        return self._goal.check(self.world) if self._goal is not None else None

    def _record(self, pose: tuple[float, float, float] | None = None) -> dict[str, Any]:
        """{"obs": observation, "instances": instance table} at the robot's pose or at ``pose`` (x, y, yaw);
        without sensors only the robot's state and no instances."""
        assert self.world is not None
        r = self.world.robot
        x, y, yaw = pose if pose is not None else (r.x, r.y, r.yaw)
        held = self.world.objects[r.held].instance_id if r.held is not None else 0
        state = {"robot_pose": np.array([x, y, yaw], dtype=np.float64), "held": np.array(held, dtype=np.int32)}
        if not self.sensors:
            return {"obs": state, "instances": {}}
        frame = self.renderer.render_at(self.world, self.renderer.camera.pose(x, y, yaw))
        obs = {
            "rgb": frame.rgb,
            "depth": np.nan_to_num(frame.depth, nan=0.0),
            "semantic": frame.semantic,
            "instance": frame.instance,
            "pose": frame.T_world_cam,
            "intrinsics": frame.K,
            **state,
        }
        return {"obs": obs, "instances": self.labels.table(self.world, frame.instance, frame.instance_pixels)}

    def _path_frames(self, path: list[tuple[float, float]]) -> list[dict[str, Any]]:
        """Views every ``path_frame_spacing_m`` along a path, facing along it (none when disabled)."""
        if not self.sensors or self.path_frame_spacing_m <= 0 or len(path) < 2:
            return []
        out = []
        for (x0, y0), (x1, y1) in zip(path[:-1], path[1:], strict=True):
            length = math.hypot(x1 - x0, y1 - y0)
            heading = math.atan2(y1 - y0, x1 - x0)
            for s in np.arange(0.0, length, self.path_frame_spacing_m):
                out.append(self._record((x0 + (x1 - x0) * s / length, y0 + (y1 - y0) * s / length, heading)))
        return out

    def _info(
        self,
        status: GoalStatus | None,
        kind: str,
        ok: bool,
        reason: str | None,
        feedback: str,
        steps: int,
        path: list[tuple[float, float]],
        instances: dict[int, dict[str, Any]],
    ) -> dict[str, Any]:
        info = {
            "action": kind,
            "action_ok": ok,
            "reason": reason,
            "feedback": feedback,
            "low_level_steps": steps,
            "total_low_level_steps": self._low_level_steps,
            "steps": self._steps,
            "path": [tuple(map(float, p)) for p in path],
            "instances": instances,
        }
        if self.privileged_info:
            info["goal_status"] = status
        return info


class SimRobot:
    """The robot of a simulated episode as a planner drives it (:class:`~more_agent.robot.Robot`).

    Built by the episode runner on the episode's world; the world, the env and the renderer are its
    own and private. Perception is ground truth as in the paper (S.2): instance attributes, open state
    and how an object rests (inside / on top of what) are read from the world for the instances in
    view. ``observed`` (world names of everything seen) is for the runner's rTP metric.
    """

    def __init__(
        self,
        world: World,
        *,
        labels: InstanceLabels | None = None,
        renderer: Renderer | None = None,
        on_frame: Callable[[Frame], None] | None = None,
        on_sensed: Callable[[Observation], None] | None = None,
    ) -> None:
        """``labels``: what the robot calls objects (the task instance's, with those its description names
        reserved; else afresh); ``on_frame`` is called with every rendered frame (the episode folder
        writes them), ``on_sensed`` with every observation made of one (a bag recorder writes them)."""
        self._world = world
        self._labels = labels if labels is not None else InstanceLabels()
        self._env = MoreAgentEnv(sensors=False, max_steps=None)
        self._env.reset(options={"world": world, "labels": self._labels})
        self._renderer = renderer or Renderer()
        self._on_frame, self._on_sensed = on_frame, on_sensed
        self._held: str | None = None
        """The held item at the last sensing (to report one released since)."""
        self._infos: dict[tuple[object, ...], InstanceInfo] = {}
        """Each distinct report of an instance, once (``_info``)."""
        self._steps = 0
        self._trajectory: list[XY] = [self.pose[:2]]
        self._reported_steps, self._reported_path = 0, 1
        self.observed: set[str] = set()
        """World names of every object seen so far."""

    @property
    def class_names(self) -> Sequence[str]:
        return self._world.class_names

    @property
    def pose(self) -> tuple[float, float, float]:
        r = self._world.robot
        return float(r.x), float(r.y), float(r.yaw)

    @property
    def held(self) -> int | None:
        name = self._world.robot.held
        return None if name is None else self._world.objects[name].instance_id

    @property
    def trajectory(self) -> Sequence[XY]:
        return self._trajectory

    @property
    def low_level_steps(self) -> int:
        return self._steps

    def sense(self, acted_on: Sequence[str] = (), head: tuple[float, float] | None = None) -> Observation:
        """Render a frame from the current pose with what perception says of it.

        The robot knows what it did: an item released since the last frame is reported as no longer
        held, resting where it was put, even when no camera sees it (``Observation.placed`` keeps it,
        and what rode on or in it, at their boxes), and the objects in ``acted_on`` are reported with
        their new state even when out of view, what lies inside those that are open with them
        (``Observation.revealed``). ``head`` (pan left, tilt down; radians) renders from the head pointed
        away from its driving pose.
        """
        world = self._world
        if head is None:
            frame = self._renderer.render(world)
        else:
            r, camera = world.robot, self._renderer.camera
            pose = camera_pose(r.x, r.y, r.yaw + head[0], height_m=camera.height_m, pitch_rad=head[1])
            frame = self._renderer.render_at(world, pose)
        if self._on_frame is not None:
            self._on_frame(frame)
        table = self._labels.table(world, frame.instance, frame.instance_pixels)
        infos = {
            i: self._info(d["label"], d["category"], d["open"], d["held"], self._rests(d["name"]))
            for i, d in table.items()
        }
        released = self._held if self._held is not None and self._held != world.robot.held else None
        acted = [name for name in map(self._env.resolve, acted_on) if name is not None]
        inner = [obj for name in acted for obj in world.shown_by_opening(name)]
        self._labels.observe(inner)
        for obj in [*map(world.get, acted), *([world.get(released)] if released is not None else []), *inner]:
            if obj.instance_id not in infos:
                infos[obj.instance_id] = self._info(
                    self._labels.label(obj.name),
                    obj.category,
                    obj.is_open if obj.openable else None,
                    world.robot.held == obj.name,
                    self._rests(obj.name),
                )
        placed = {}
        if released is not None:  # with what rode on it
            placed = {obj.instance_id: obj.box() for obj in [world.get(released), *world.descendants(released)]}
        self._held = world.robot.held
        self.observed.update([*(d["name"] for d in table.values()), *(obj.name for obj in inner)])
        seen = Observation(
            frame=frame, instances=infos, placed=placed, revealed={obj.instance_id: obj.box() for obj in inner}
        )
        if self._on_sensed is not None:
            self._on_sensed(seen)
        return seen

    def _info(
        self, label: str, category: str, is_open: bool | None, held: bool, rests: tuple[Relation, str | None] | None
    ) -> InstanceInfo:
        """What perception says of an instance, as one frozen model per distinct report: most instances in view
        are reported alike frame after frame, and a frame shows dozens."""
        key = (label, category, is_open, held, rests)
        info = self._infos.get(key)
        if info is None:
            info = self._infos[key] = InstanceInfo(label=label, category=category, open=is_open, held=held, rests=rests)
        return info

    def _rests(self, name: str) -> tuple[Relation, str | None] | None:
        """How a seen object rests, as perception reports it: the world's support link (what the last
        placement did), the support named by its label (None for a floor); None while held."""
        obj = self._world.get(name)
        if obj.parent is None or obj.relation is None:
            return None if self._world.robot.held == name else ("ontop", None)
        parent = self._world.get(obj.parent)
        return obj.relation, self._labels.label(parent.name) if parent.kind != "floor" else None

    def move_forward(self, distance: float) -> bool:
        ok = bool(self._step("move_forward", amount=distance)["action_ok"])
        self._steps += 1
        if ok:
            self._trajectory.append(self.pose[:2])
        return ok

    def turn(self, angle: float) -> None:
        self._step("turn_left" if angle >= 0 else "turn_right", amount=abs(angle))
        self._steps += 1

    def act(self, action: str, target: str = "") -> ActionResult:
        """One magic action of the env on ``target`` (a world name or label); its motion joins the odometry.
        A door in the way is named as ``target`` was: by its label (None while it has none) for a target
        named by label, by its world name for one named so (the privileged oracle)."""
        info = self._step(action, target=target)
        blocking = info["blocking"]
        if blocking is not None and target.strip() not in self._world.objects:
            blocking = self._labels.label(blocking) or None
        result = ActionResult(
            ok=info["action_ok"],
            reason=FailureReason(info["reason"]) if info["reason"] else None,
            feedback=info["feedback"],
            low_level_steps=info["low_level_steps"],
            path=info["path"],
            blocking=blocking,
        )
        self._steps += result.low_level_steps
        self._trajectory.extend((float(x), float(y)) for x, y in result.path[1:])
        return result

    def reach_distance(self, target: str) -> float | None:
        name = self._env.resolve(target)
        return None if name is None else actions.distance_to_footprint(self._world, name)

    def floor_here(self) -> str | None:
        room = self._world.room_at(*self.pose[:2])
        return None if room is None else floor_name(room)

    def since_last_report(self, result: ActionResult) -> ActionResult:
        """``result`` with the low-level steps and path the robot made since the previous call (the first
        call's include the initial full turn): what one high-level step reports to the episode loop."""
        steps, self._reported_steps = self._steps - self._reported_steps, self._steps
        path = self._trajectory[self._reported_path - 1 :] if len(self._trajectory) > self._reported_path else []
        self._reported_path = len(self._trajectory)
        return ActionResult(
            ok=result.ok,
            reason=result.reason,
            feedback=result.feedback,
            low_level_steps=steps,
            path=path,
            blocking=result.blocking,
        )

    def _step(self, kind: str, *, target: str = "", amount: float | None = None) -> dict[str, Any]:
        """``env.step`` of action type ``kind`` (:data:`ACTION_TYPES`); its info."""
        action: dict[str, object] = {"type": ACTION_TYPES.index(kind), "target": target}
        if amount is not None:
            action["amount"] = amount  # a Python float: the env keeps its full precision
        return self._env.step(action)[-1]


def _parse(action: Any) -> tuple[str | None, float, str, str | None]:
    """(type name, amount, target, error): the error says why an action is malformed."""
    if not isinstance(action, Mapping):
        return None, 0.0, "", f"action must be a dict with type / amount / target, got {type(action).__name__}"
    try:
        index = int(action.get("type"))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None, 0.0, "", f"action type must be an integer, got {action.get('type')!r}"
    if not 0 <= index < len(ACTION_TYPES):
        return None, 0.0, "", f"action type {index} is not one of 0..{len(ACTION_TYPES) - 1}"
    kind = ACTION_TYPES[index]
    default = make_action(kind)["amount"]
    try:
        amount = float(np.asarray(action.get("amount", default), dtype=np.float64).reshape(()))
    except (TypeError, ValueError):
        return kind, 0.0, "", f"action amount must be a number, got {action.get('amount')!r}"
    target = action.get("target", "")
    if not isinstance(target, str):
        return kind, amount, "", f"action target must be a string, got {type(target).__name__}"
    return kind, amount, target, None
