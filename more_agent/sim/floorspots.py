"""Free floor spots: where an item (or the robot) can stand on a room's floor without overlapping anything.

A spot is drawn uniformly among the positions where a box of given half extents overlaps no wall,
furniture, door opening (kept clear by ``DOOR_KEEPOUT_M``) or item already on a floor, and, for an
item, leaves every passage around it open to the robot's base (``keeps_passages``): the world's base
drives over floor items, but the robot's map (like a real one's) shows them as obstacles, and a room
strewn with dishes whose gaps the base cannot pass sealed a restaurant kitchen on the map
(putting_out_condiments seed 0), where the paper's scenes keep their dishes on shelves.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from more_agent.robot_spec import ROBOT
from more_agent.sim.motion import fixed_obstacles
from more_agent.sim.navgrid import DEFAULT_NAV
from more_agent.sim.world import World, WorldObject

DOOR_KEEPOUT_M = 0.6
"""Floor items stay this far from door openings so doors stay passable."""

SAMPLE_TRIES = 400
"""Random draws before falling back to a raster scan of the room."""

RASTER_STEP_M = 0.05

PASSAGE_CLEARANCE_M = ROBOT.radius_m + 0.15
"""Clearance a floor item leaves along every passage around it: the base's radius and two cells of the
robot's map (0.075 m each), so that the gap stays open on a map that rasterises both its sides."""

PASSAGE_CELL_M = 0.075
"""Cell size of the local raster ``keeps_passages`` checks (the paper's map resolution)."""


def free_floor_spot(
    world: World,
    room_id: str | None,
    half: np.ndarray,
    rng: np.random.Generator,
    near: WorldObject | None = None,
    exclude: str | None = None,
    bounds: tuple[float, float, float, float] | None = None,
    *,
    keep_passages: bool = True,
    ground: bool = False,
) -> tuple[float, float] | None:
    """A random (x, y) in a room (or in ``bounds``) where a box of half extents ``half`` overlaps no
    furniture, wall, door opening or floor item; with ``near``, close beside that object's box. With
    ``keep_passages`` (an item; not the robot), also one where the box closes no passage (``keeps_passages``).
    A ``ground`` item (a rug: its class is one the map reads as free space, and the base drives over items)
    closes no passage and keeps no distance from door openings."""
    room = world.scene.room(room_id) if room_id else world.scene.rooms[0]
    x0, y0, x1, y1 = bounds or room.bounds
    lo, hi = np.array([x0, y0]) + half, np.array([x1, y1]) - half
    if np.any(lo >= hi):
        return None
    boxes = _floor_obstacles(world, exclude, 0.0 if ground else DOOR_KEEPOUT_M)
    if near is not None:
        nlo = np.maximum(lo, near.center[:2] - near.size[:2] / 2 - 2 * half - 0.1)
        nhi = np.minimum(hi, near.center[:2] + near.size[:2] / 2 + 2 * half + 0.1)
        if np.all(nlo < nhi):
            lo, hi = nlo, nhi
    walls = _passage_obstacles(world, exclude) if keep_passages and not ground else None

    def fits(p: np.ndarray) -> bool:
        return walls is None or keeps_passages(walls, p, half)

    for _ in range(SAMPLE_TRIES):
        p = rng.uniform(lo, hi)
        if not _overlaps(boxes, p - half, p + half).any() and fits(p):
            return float(p[0]), float(p[1])
    # Crowded room: scan a raster of candidate centres and draw among the free ones.
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0], RASTER_STEP_M), np.arange(lo[1], hi[1], RASTER_STEP_M))
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    item_lo, item_hi = (pts - half).T, (pts + half).T
    blocked = np.zeros(len(pts), dtype=bool)
    for box in boxes:
        blocked |= _overlaps(box, item_lo, item_hi)
    free = pts[~blocked]
    p = next((free[i] for i in rng.permutation(len(free)) if fits(free[i])), None)
    return None if p is None else (float(p[0]), float(p[1]))


def _overlaps(boxes: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether footprints (``boxes``: (n, 4) or one (4,) of xmin, ymin, xmax, ymax) overlap the box from ``lo`` to
    ``hi`` ((2,) corners, or (2, m) for m boxes). One comparison per side joined with ``&``, not ``np.all`` over
    an axis of 2: with ``packing``'s the same way, instantiation took 23 % less CPU (docs/benchmarks.md)."""
    return (boxes[..., 0] < hi[0]) & (boxes[..., 1] < hi[1]) & (boxes[..., 2] > lo[0]) & (boxes[..., 3] > lo[1])


def keeps_passages(obstacles: np.ndarray, p: np.ndarray, half: np.ndarray) -> bool:
    """Whether a floor item of half extents ``half`` at ``p`` leaves every way the base had through its
    neighbourhood open: on a local raster, the cells with ``PASSAGE_CLEARANCE_M`` from every obstacle
    (``obstacles``: footprints) that the raster's border joined must stay joined once the item lies there."""
    reach = half + 2 * PASSAGE_CLEARANCE_M + PASSAGE_CELL_M
    xs = np.arange(p[0] - reach[0], p[0] + reach[0], PASSAGE_CELL_M)
    ys = np.arange(p[1] - reach[1], p[1] + reach[1], PASSAGE_CELL_M)
    cx, cy = np.meshgrid(xs, ys, indexing="ij")
    item = np.array([[*(p - half), *(p + half)]])
    near = obstacles[
        np.all(obstacles[:, :2] < p + reach + PASSAGE_CLEARANCE_M, axis=1)
        & np.all(obstacles[:, 2:] > p - reach - PASSAGE_CLEARANCE_M, axis=1)
    ]
    before = _clear_of(near, cx, cy)
    after = before & _clear_of(item, cx, cy)
    border = np.ones(before.shape, dtype=bool)
    border[1:-1, 1:-1] = False
    eight = np.ones((3, 3), dtype=bool)
    parts_before, n = ndimage.label(before, structure=eight)
    parts_after, _ = ndimage.label(after, structure=eight)
    for part in range(1, n + 1):
        ends = border & (parts_before == part) & after
        if len(np.unique(parts_after[ends])) > 1:
            return False
    return True


def _clear_of(boxes: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
    """Which raster points lie more than ``PASSAGE_CLEARANCE_M`` from every box."""
    clear = np.ones(cx.shape, dtype=bool)
    for x0, y0, x1, y1 in boxes:
        dx = np.maximum(np.maximum(x0 - cx, cx - x1), 0.0)
        dy = np.maximum(np.maximum(y0 - cy, cy - y1), 0.0)
        clear &= dx * dx + dy * dy > PASSAGE_CLEARANCE_M**2
    return clear


def _floor_obstacles(world: World, exclude: str | None, door_keepout_m: float) -> np.ndarray:
    """(n, 4) array of footprints (xmin, ymin, xmax, ymax) a floor spot must avoid, door openings grown by
    ``door_keepout_m``."""
    rows = [w.bounds for w in world.scene.walls]
    for obj in world.objects.values():
        if obj.name == exclude or obj.kind == "floor":
            continue
        if obj.kind == "item" and not world.on_floor(obj):
            continue
        x0, y0, x1, y1 = obj.footprint()
        pad = door_keepout_m if obj.kind == "door" else 0.0
        rows.append((x0 - pad, y0 - pad, x1 + pad, y1 + pad))
    return np.asarray(rows, dtype=float).reshape(-1, 4)


def _passage_obstacles(world: World, exclude: str | None) -> np.ndarray:
    """(n, 4) footprints of what the base drives around (``motion.fixed_obstacles``: walls below a lintel,
    low furniture) and of the floor items: what a passage runs between. Doors are left out: their openings
    are passages."""
    fixed, _ = fixed_obstacles(world, DEFAULT_NAV)
    items = [o.footprint() for o in world.objects.values() if o.name != exclude and world.on_floor(o)]
    return np.concatenate([fixed, np.asarray(items, dtype=float).reshape(-1, 4)])
