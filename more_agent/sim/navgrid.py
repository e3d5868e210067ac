"""Ground-truth navigation: a free-space raster of the world and shortest paths on it.

The raster covers the scene at ``NavConfig.resolution_m`` (0.075 m, the paper's map resolution).
A cell is free when it lies in a room (or a door's passage) and is at least ``robot_radius_m`` from
every wall, closed door and piece of furniture. Items are not obstacles: the paper takes
non-physical steps where collisions would be unavoidable (S.2). The radius (0.2 m by default,
smaller than Fetch's ~0.28 m base) is chosen so that 0.9 m doors and 0.8 m corridors stay passable.

Grids depend only on the world's fixed geometry and on which doors are closed, so they are cached
per (world, closed doors, config). Shortest paths on them are :mod:`more_agent.sim.paths`' (the
planners search their own maps with it too, without the world). ``blocking_door`` names the closed
door on the way when a goal is only reachable with doors open: the magic actions report it so that a
planner knows what to open.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from more_agent.robot import XY
from more_agent.robot_spec import ROBOT
from more_agent.sim.grid import Grid
from more_agent.sim.paths import NavGrid, reaches, shortest_path
from more_agent.sim.scene import Bounds2D, Door
from more_agent.sim.world import World


@dataclass(frozen=True)
class NavConfig:
    """Knobs of the ground-truth navigation grid."""

    resolution_m: float = 0.075
    """Cell size in metres (the paper's map resolution)."""

    robot_radius_m: float = ROBOT.radius_m
    """Clearance kept from walls, closed doors and furniture (the robot's radius, ``RobotSpec.radius_m``)."""

    door_passage_m: float = 0.3
    """How far a door's passage strip reaches into the rooms on either side (bridges wall thickness)."""

    obstacle_max_bottom_m: float = 1.2
    """Furniture whose box starts above this height (wall cabinets) does not block the base."""


DEFAULT_NAV = NavConfig()

_CACHE_SIZE = 16


def free_cells(mask: np.ndarray) -> np.ndarray:
    """(k, 2) cells (ix, iy) of the True cells of a ``[ix, iy]`` mask, row by row (iy, then ix):
    the order in which seeded draws of a cell pick, kept so that a seed gives the same cell."""
    return np.argwhere(mask.T)[:, ::-1]


def _mask_box(grid: Grid, shape: tuple[int, int], box: Bounds2D) -> tuple[slice, slice]:
    """Slices of the cells whose centres lie inside ``box``."""
    return _clipped(*grid.centre_range(box[:2], box[2:]), shape)


def _obstacle_box(grid: Grid, shape: tuple[int, int], box: Bounds2D) -> tuple[slice, slice]:
    """Slices of the cells an obstacle's ``box`` blocks: those whose centres lie inside it and, along an axis where
    no centre does, those it overlaps. A room divider 1-4 cm thick lies between two rows of centres: it blocked
    no cell, and the magic actions' paths (the oracle's among them) crossed it where the base's own moves, checked
    against the footprints (``motion.move_forward``), are refused."""
    lo, hi = grid.centre_range(box[:2], box[2:])
    over_lo, over_hi = grid.cell_range(box[:2], box[2:])
    thin = hi <= lo
    return _clipped(np.where(thin, over_lo, lo), np.where(thin, over_hi, hi), shape)


def _clipped(lo: np.ndarray, hi: np.ndarray, shape: tuple[int, int]) -> tuple[slice, slice]:
    """Slices of the cells from ``lo`` to one before ``hi`` (each (ix, iy)) within a grid of ``shape``."""
    lo, hi = np.maximum(lo, 0), np.maximum(np.minimum(hi, shape), 0)
    return slice(int(lo[0]), int(hi[0])), slice(int(lo[1]), int(hi[1]))


def _door_strip(door: Door, reach: float) -> Bounds2D:
    """A door's opening extended along the wall normal by ``reach`` on either side."""
    x0, y0, x1, y1 = door.bounds()
    return (x0, y0 - reach, x1, y1 + reach) if door.axis == "x" else (x0 - reach, y0, x1 + reach, y1)


def _build(world: World, closed: frozenset[str], config: NavConfig) -> NavGrid:
    scene, res = world.scene, config.resolution_m
    bx0, by0, bx1, by1 = scene.bounds
    grid = Grid(origin_xy=(bx0 - res, by0 - res), resolution_m=res)
    shape = (int(np.ceil((bx1 - bx0) / res)) + 2, int(np.ceil((by1 - by0) / res)) + 2)

    region = np.zeros(shape, dtype=bool)
    for room in scene.rooms:
        region[_mask_box(grid, shape, room.bounds)] = True
    blocked = np.zeros(shape, dtype=bool)
    for wall in scene.walls:
        blocked[_obstacle_box(grid, shape, wall.bounds)] = True
    door_cells: dict[str, np.ndarray] = {}
    for door in scene.doors:
        passage = np.zeros(shape, dtype=bool)
        passage[_mask_box(grid, shape, _door_strip(door, config.door_passage_m))] = True
        door_cells[door.id] = passage
        region |= passage
        # The opening is a gap in its wall whatever the wall list says; a closed leaf fills it.
        opening = _mask_box(grid, shape, _door_strip(door, door.thickness / 2 + res))
        blocked[opening] = door.id in closed
    for obj in world.objects.values():
        if obj.kind == "furniture" and obj.bottom < config.obstacle_max_bottom_m:
            blocked[_obstacle_box(grid, shape, obj.footprint())] = True

    passable = region & ~blocked
    clearance = ndimage.distance_transform_edt(passable) * res
    return NavGrid(
        origin_xy=grid.origin_xy,
        resolution_m=res,
        free=clearance > config.robot_radius_m,
        closed_doors=closed,
        door_cells=door_cells,
    )


_cache: OrderedDict[tuple[int, int, frozenset[str], NavConfig], tuple[World, NavGrid]] = OrderedDict()


def closed_doors(world: World) -> frozenset[str]:
    """Names of the world's doors that are closed now."""
    return frozenset(o.name for o in world.objects.values() if o.kind == "door" and not o.is_open)


def nav_grid(world: World, config: NavConfig = DEFAULT_NAV, *, all_doors_open: bool = False) -> NavGrid:
    """The free-space raster for the world's current door states (or with every door open); cached.

    Furniture never moves, so a grid only depends on the world (its furniture) and its closed doors.
    """
    closed = frozenset() if all_doors_open else closed_doors(world)
    n_furniture = sum(o.kind == "furniture" for o in world.objects.values())
    key = (id(world), n_furniture, closed, config)
    hit = _cache.get(key)
    if hit is not None and hit[0] is world:
        _cache.move_to_end(key)
        return hit[1]
    grid = _build(world, closed, config)
    _cache[key] = (world, grid)
    while len(_cache) > _CACHE_SIZE:
        _cache.popitem(last=False)
    return grid


def blocking_door(world: World, start: XY, goals: Sequence[XY], config: NavConfig = DEFAULT_NAV) -> str | None:
    """The first closed door along the way to the nearest goal, when only open doors would make it reachable."""
    closed = closed_doors(world)
    if not closed:
        return None
    open_grid = nav_grid(world, config, all_doors_open=True)
    path = shortest_path(open_grid, start, goals)
    for cell in path.cells:
        for door_id in sorted(closed):
            if open_grid.door_cells[door_id][cell]:
                return door_id
    return None


def reachable(world: World, start: XY, goal: XY, config: NavConfig = DEFAULT_NAV) -> bool:
    """Whether the robot can drive from ``start`` to ``goal`` with the doors as they are."""
    return reaches(nav_grid(world, config), start, [goal])
