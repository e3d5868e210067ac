"""Free floor spots: where an item (or the robot) can stand on a room's floor without overlapping anything.

A spot is drawn uniformly among the positions where a box of given half extents overlaps no wall,
furniture, door opening (kept clear by ``DOOR_KEEPOUT_M``) or item already on a floor.
"""

from __future__ import annotations

import numpy as np

from more_agent.sim.world import World, WorldObject

DOOR_KEEPOUT_M = 0.6
"""Floor items stay this far from door openings so doors stay passable."""

SAMPLE_TRIES = 400
"""Random draws before falling back to a raster scan of the room."""

RASTER_STEP_M = 0.05


def free_floor_spot(
    world: World,
    room_id: str | None,
    half: np.ndarray,
    rng: np.random.Generator,
    near: WorldObject | None = None,
    exclude: str | None = None,
    bounds: tuple[float, float, float, float] | None = None,
) -> tuple[float, float] | None:
    """A random (x, y) in a room (or in ``bounds``) where a box of half extents ``half`` overlaps no
    furniture, wall, door opening or floor item; with ``near``, close beside that object's box."""
    room = world.scene.room(room_id) if room_id else world.scene.rooms[0]
    x0, y0, x1, y1 = bounds or room.bounds
    lo, hi = np.array([x0, y0]) + half, np.array([x1, y1]) - half
    if np.any(lo >= hi):
        return None
    boxes = _floor_obstacles(world, exclude)
    if near is not None:
        nlo = np.maximum(lo, near.center[:2] - near.size[:2] / 2 - 2 * half - 0.1)
        nhi = np.minimum(hi, near.center[:2] + near.size[:2] / 2 + 2 * half + 0.1)
        if np.all(nlo < nhi):
            lo, hi = nlo, nhi
    for _ in range(SAMPLE_TRIES):
        p = rng.uniform(lo, hi)
        if not np.any(np.all((boxes[:, :2] < p + half) & (boxes[:, 2:] > p - half), axis=1)):
            return float(p[0]), float(p[1])
    # Crowded room: scan a raster of candidate centres and draw among the free ones.
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0], RASTER_STEP_M), np.arange(lo[1], hi[1], RASTER_STEP_M))
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    blocked = np.zeros(len(pts), dtype=bool)
    for box in boxes:
        blocked |= np.all((box[:2] < pts + half) & (box[2:] > pts - half), axis=1)
    free = pts[~blocked]
    if len(free) == 0:
        return None
    p = free[rng.integers(len(free))]
    return float(p[0]), float(p[1])


def _floor_obstacles(world: World, exclude: str | None) -> np.ndarray:
    """(n, 4) array of footprints (xmin, ymin, xmax, ymax) a floor spot must avoid."""
    rows = [w.bounds for w in world.scene.walls]
    for obj in world.objects.values():
        if obj.name == exclude or obj.kind == "floor":
            continue
        if obj.kind == "item" and not (obj.parent and world.objects[obj.parent].kind == "floor"):
            continue
        x0, y0, x1, y1 = obj.footprint()
        pad = DOOR_KEEPOUT_M if obj.kind == "door" else 0.0
        rows.append((x0 - pad, y0 - pad, x1 + pad, y1 + pad))
    return np.asarray(rows, dtype=float).reshape(-1, 4)
