"""Magic actions on the world: navigate, open, close, grasp, place inside / on top.

They follow the paper (S.3) and OmniGibson's symbolic primitives: grasp needs an empty hand;
open / close need an empty hand and an openable object in the other state; placing inside needs
the target open. Every manipulation needs the object observable (not shut inside a closed
container) and within ``REACH_M`` of the robot base, measured to the object's footprint (for an
item resting in / on furniture, to that furniture's footprint). Each
failure returns a typed ``FailureReason`` and the short feedback a planner sees ("hand is full",
"must open fridge A first"), naming objects as the robot knows them (``labels``: the label once
observed, else the bare category; a world name such as 'apple_o17' would reveal an unseen instance).

``navigate_to`` samples base poses on a circle around the object (radius = footprint half-diagonal
plus ``CLEARANCE_M``), falls back to a ring around its supporting furniture, keeps the free poses
within reach and drives the ground-truth shortest path to the nearest one; it counts low-level
steps as 7.5 cm forward moves and turns of at most 35 degrees, and ends facing the object.
``go_to_and`` chains navigation and one manipulation as the paper's subpolicies do.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from more_agent.records import FailureReason
from more_agent.robot import ActionResult
from more_agent.robot_spec import FORWARD_STEP_M, MAX_TURN_RAD, ROBOT
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.navgrid import DEFAULT_NAV, XY, NavConfig, NavGrid, blocking_door, nav_grid, shortest_path
from more_agent.sim.world import World, WorldObject

REACH_M = ROBOT.reach_m
"""Largest horizontal distance from the robot base to an object's footprint for a manipulation (``RobotSpec.reach_m``)."""

CLEARANCE_M = 0.45
"""Distance added to an object's half-diagonal for the navigation circle."""

RING_OFFSETS_M = (0.35, 0.6, 0.9)
"""Offsets from a support's footprint edge of the fallback rings of navigation poses."""

POSES_PER_RING = 32
"""Candidate base poses sampled on the navigation circle."""

RING_SPACING_M = 0.25
"""Spacing of the candidate base poses along a fallback ring."""

FLOOR_POSE_SPACING_M = 0.5
"""Spacing of the candidate positions inside a room when navigating to its floor."""


def _ok(feedback: str, steps: int = 1, path: list[XY] | None = None) -> ActionResult:
    return ActionResult(ok=True, reason=None, feedback=feedback, low_level_steps=steps, path=path or [])


def _fail(reason: FailureReason, feedback: str, blocking: str | None = None) -> ActionResult:
    return ActionResult(ok=False, reason=reason, feedback=feedback, blocking=blocking)


def reach_box(world: World, name: str) -> tuple[float, float, float, float]:
    """The footprint reach is measured to: the furniture an item rests in / on, else the object's own.

    Reaching into any part of a car or along a long shelf from its side is part of the magic.
    """
    obj = world.get(name)
    anchor = _anchor(world, obj)
    return (anchor if anchor.kind == "furniture" else obj).footprint()


def distance_to_footprint(world: World, name: str) -> float:
    """Horizontal distance from the robot base to the reach footprint of ``name`` (0 when above it)."""
    return float(_gap_to_box(np.array([world.robot.x]), np.array([world.robot.y]), reach_box(world, name))[0])


def _check_target(world: World, name: str, labels: InstanceLabels) -> WorldObject | ActionResult:
    """The object, or the failure for an unknown, held-away or hidden one."""
    if name not in world.objects:
        return _fail(FailureReason.UNKNOWN_OBJECT, f"there is no {name}")
    obj = world.get(name)
    hider = world.enclosing_closed_container(name)
    if hider is not None:
        return _fail(
            FailureReason.HIDDEN,
            f"{labels.display(obj)} is inside closed {labels.display(hider)}; must open {labels.display(hider)} first",
        )
    return obj


def _check_reach(world: World, obj: WorldObject, labels: InstanceLabels) -> ActionResult | None:
    if world.robot.held == obj.name or distance_to_footprint(world, obj.name) <= REACH_M:
        return None
    return _fail(FailureReason.TOO_FAR, f"{labels.display(obj)} is too far away")


# -- navigation ---------------------------------------------------------------------------------


def _anchor(world: World, obj: WorldObject) -> WorldObject:
    """The furniture (or floor) an item ultimately rests on; the object itself otherwise."""
    chain = world.ancestors(obj.name)
    fixed = [parent for parent, _ in chain if not parent.movable]
    return fixed[0] if fixed else obj


def _ring(x0: float, y0: float, x1: float, y1: float, offset: float) -> list[XY]:
    """Points evenly spaced (about ``RING_SPACING_M``) along a rectangle grown by ``offset``."""
    x0, y0, x1, y1 = x0 - offset, y0 - offset, x1 + offset, y1 + offset
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    points: list[XY] = []
    for (ax, ay), (bx, by) in zip(corners, corners[1:]):
        n = max(1, math.ceil(math.dist((ax, ay), (bx, by)) / RING_SPACING_M))
        points += [(ax + (bx - ax) * k / n, ay + (by - ay) * k / n) for k in range(n)]
    return points


def candidate_poses(world: World, name: str) -> list[list[XY]]:
    """Base positions to try around an object, in rounds: the paper's circle first, then rings around its support.

    For a floor (going to a room) the positions are a grid over the room instead.
    """
    obj = world.get(name)
    x0, y0, x1, y1 = obj.footprint()
    if obj.kind == "floor":
        xs, ys = np.arange(x0 + 0.25, x1, FLOOR_POSE_SPACING_M), np.arange(y0 + 0.25, y1, FLOOR_POSE_SPACING_M)
        return [[(float(x), float(y)) for y in ys for x in xs]]
    radius = math.hypot(x1 - x0, y1 - y0) / 2 + CLEARANCE_M
    angles = np.linspace(0, 2 * np.pi, POSES_PER_RING, endpoint=False)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    rounds = [[(float(cx + radius * math.cos(a)), float(cy + radius * math.sin(a))) for a in angles]]
    anchor = _anchor(world, obj)
    if anchor.kind != "floor":
        rounds += [_ring(*anchor.footprint(), offset) for offset in RING_OFFSETS_M]
    return rounds


def _heading(a: XY, b: XY) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def _turns(delta: float) -> int:
    delta = abs(math.atan2(math.sin(delta), math.cos(delta)))
    return math.ceil(delta / MAX_TURN_RAD - 1e-9)


def count_low_level_steps(yaw: float, waypoints: list[XY], final_yaw: float) -> int:
    """Forward moves of 7.5 cm plus turns of at most 35 degrees to follow ``waypoints`` and end at ``final_yaw``."""
    steps = 0
    for a, b in zip(waypoints, waypoints[1:]):
        length = math.dist(a, b)
        if length < 1e-9:
            continue
        heading = _heading(a, b)
        steps += _turns(heading - yaw) + math.ceil(length / FORWARD_STEP_M - 1e-9)
        yaw = heading
    return steps + _turns(final_yaw - yaw)


def approach_rounds(world: World, name: str, config: NavConfig = DEFAULT_NAV) -> list[list[XY]]:
    """Free base positions within reach of ``name``, in rounds (circle first, then support rings)."""
    grid = nav_grid(world, config)
    box = reach_box(world, name)
    rounds = [
        [(float(x), float(y)) for x, y in within_reach(poses, box, grid)] for poses in candidate_poses(world, name)
    ]
    return [r for r in rounds if r]


def within_reach(poses: Sequence[XY], box: tuple[float, float, float, float], grid: NavGrid) -> np.ndarray:
    """Of ``poses``, in order (k x 2), those where the base may stand on ``grid`` with ``box`` (a
    :func:`reach_box`) within ``REACH_M``: all at once, a garden's floor gives thousands."""
    xy = np.asarray(poses, dtype=float).reshape(-1, 2)
    return xy[(_gap_to_box(xy[:, 0], xy[:, 1], box) <= REACH_M) & grid.free_at(xy)]


def navigate_to(world: World, name: str, labels: InstanceLabels, config: NavConfig = DEFAULT_NAV) -> ActionResult:
    """Drive to the nearest free pose within reach of ``name`` and face it.

    Fails with NOT_REACHABLE when no such pose can be reached, or PATH_BLOCKED_BY_DOOR naming the
    closed door on the way (``ActionResult.blocking``) when opening it would make one reachable.
    """
    checked = _check_target(world, name, labels)
    if isinstance(checked, ActionResult):
        return checked
    obj = checked
    if world.robot.held == name:
        return _fail(FailureReason.INVALID_TARGET, f"already holding {labels.display(obj)}")
    grid = nav_grid(world, config)
    start = (world.robot.x, world.robot.y)
    x0, y0, x1, y1 = obj.footprint()
    center = ((x0 + x1) / 2, (y0 + y1) / 2)
    rounds = approach_rounds(world, name, config)
    for poses in rounds:
        path = shortest_path(grid, start, poses)
        if path.found:
            goal = path.waypoints[-1]
            final_yaw = _heading(goal, center) if math.dist(goal, center) > 1e-6 else world.robot.yaw
            steps = count_low_level_steps(world.robot.yaw, path.waypoints, final_yaw)
            world.set_robot_pose(goal[0], goal[1], final_yaw)
            return _ok(f"reached {labels.display(obj)}", steps=steps, path=path.waypoints)
    door = blocking_door(world, start, [p for poses in rounds for p in poses], config)
    if door is not None:
        return _fail(
            FailureReason.PATH_BLOCKED_BY_DOOR,
            f"the way to {labels.display(obj)} is blocked by closed {labels.display(world.get(door))}",
            blocking=door,
        )
    return _fail(FailureReason.NOT_REACHABLE, f"cannot reach {labels.display(obj)}")


def _gap_to_box(x: np.ndarray, y: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    """Horizontal distance from each point (``x``, ``y``) to the footprint ``box`` (0 inside it)."""
    x0, y0, x1, y1 = box
    return np.hypot(np.maximum(np.maximum(x0 - x, 0.0), x - x1), np.maximum(np.maximum(y0 - y, 0.0), y - y1))


# -- manipulation -------------------------------------------------------------------------------


def _set_open(world: World, name: str, labels: InstanceLabels, want_open: bool) -> ActionResult:
    checked = _check_target(world, name, labels)
    if isinstance(checked, ActionResult):
        return checked
    obj = checked
    verb = "open" if want_open else "close"
    if world.robot.held is not None:
        return _fail(FailureReason.HAND_FULL, f"hand is full; cannot {verb} {labels.display(obj)}")
    if not obj.openable:
        return _fail(FailureReason.NOT_OPENABLE, f"{labels.display(obj)} cannot be opened or closed")
    if obj.is_open == want_open:
        reason = FailureReason.ALREADY_OPEN if want_open else FailureReason.ALREADY_CLOSED
        return _fail(reason, f"{labels.display(obj)} is already {'open' if want_open else 'closed'}")
    far = _check_reach(world, obj, labels)
    if far is not None:
        return far
    world.set_open(name, want_open)
    return _ok(f"{'opened' if want_open else 'closed'} {labels.display(obj)}")


def open_(world: World, name: str, labels: InstanceLabels) -> ActionResult:
    """Open a closed openable object (container or door) within reach, with an empty hand."""
    return _set_open(world, name, labels, True)


def close(world: World, name: str, labels: InstanceLabels) -> ActionResult:
    """Close an open openable object within reach, with an empty hand."""
    return _set_open(world, name, labels, False)


def grasp(world: World, name: str, labels: InstanceLabels) -> ActionResult:
    """Pick up a movable, observable item within reach, with an empty hand (what rests on / in it comes along)."""
    checked = _check_target(world, name, labels)
    if isinstance(checked, ActionResult):
        return checked
    obj = checked
    if world.robot.held is not None:
        return _fail(FailureReason.HAND_FULL, f"hand is full; holding {labels.display(world.get(world.robot.held))}")
    if not obj.movable:
        return _fail(FailureReason.NOT_GRASPABLE, f"{labels.display(obj)} cannot be picked up")
    far = _check_reach(world, obj, labels)
    if far is not None:
        return far
    world.pick(name)
    return _ok(f"grasped {labels.display(obj)}")


def _place(world: World, name: str, labels: InstanceLabels, relation: str) -> ActionResult:
    held = world.robot.held
    if held is None:
        return _fail(FailureReason.HAND_EMPTY, "hand is empty")
    checked = _check_target(world, name, labels)
    if isinstance(checked, ActionResult):
        return checked
    target = checked
    item = world.get(held)
    if target.kind == "door" or name == held or any(d.name == name for d in world.descendants(held)):
        return _fail(
            FailureReason.INVALID_TARGET, f"cannot place {labels.display(item)} {relation} {labels.display(target)}"
        )
    if relation == "inside" and target.kind == "floor":
        return _fail(FailureReason.INVALID_TARGET, f"cannot place {labels.display(item)} inside the floor")
    if relation == "inside" and target.openable and not target.is_open:
        return _fail(FailureReason.TARGET_CLOSED, f"must open {labels.display(target)} first")
    far = _check_reach(world, target, labels)
    if far is not None:
        return far
    if target.kind == "floor":
        ahead = (world.robot.x + 0.4 * math.cos(world.robot.yaw), world.robot.y + 0.4 * math.sin(world.robot.yaw))
        fx0, fy0, fx1, fy1 = target.footprint()
        world.place_on_floor_at(held, name, (min(max(ahead[0], fx0), fx1), min(max(ahead[1], fy0), fy1)))
    else:
        world.place(held, name, relation)  # type: ignore[arg-type]
    return _ok(f"placed {labels.display(item)} {'inside' if relation == 'inside' else 'on'} {labels.display(target)}")


def place_inside(world: World, name: str, labels: InstanceLabels) -> ActionResult:
    """Put the held item inside ``name``, which must be open if it is openable."""
    return _place(world, name, labels, "inside")


def place_ontop(world: World, name: str, labels: InstanceLabels) -> ActionResult:
    """Put the held item on top of ``name`` (a floor: just in front of the robot)."""
    return _place(world, name, labels, "ontop")


MANIPULATIONS: dict[str, Callable[[World, str, InstanceLabels], ActionResult]] = {
    "open": open_,
    "close": close,
    "grasp": grasp,
    "place_inside": place_inside,
    "place_ontop": place_ontop,
}
"""The world's binding of the skill table's manipulations (:data:`more_agent.skills.MANIPULATION_VERBS`)
to the functions that carry them out; each takes the world, one object name and the labels its
feedback names objects by."""


def go_to_and(
    world: World, verb: str, name: str, labels: InstanceLabels, config: NavConfig = DEFAULT_NAV
) -> ActionResult:
    """The paper's ``go_to_and_<verb>`` subpolicy: navigate next to ``name`` unless within reach, then act.

    Preconditions that do not depend on position are checked before moving, so a doomed action
    (hand full, target closed, ...) costs no motion. Steps and path of both parts are summed.
    """
    if verb not in MANIPULATIONS:
        raise ValueError(f"unknown manipulation {verb!r}; known: {', '.join(MANIPULATIONS)}")
    act = MANIPULATIONS[verb]
    trial = act(world, name, labels)
    if trial.ok or trial.reason is not FailureReason.TOO_FAR:
        return trial
    nav = navigate_to(world, name, labels, config)
    if not nav.ok:
        return nav
    result = act(world, name, labels)
    return ActionResult(
        ok=result.ok,
        reason=result.reason,
        feedback=result.feedback,
        low_level_steps=nav.low_level_steps + result.low_level_steps,
        path=nav.path,
        blocking=result.blocking,
    )
