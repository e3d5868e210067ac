"""Ground-truth navigation: a free-space raster of the world and shortest paths on it.

The raster covers the scene at ``NavConfig.resolution_m`` (0.075 m, the paper's map resolution).
A cell is free when it lies in a room (or a door's passage) and is at least ``robot_radius_m`` from
every wall, closed door and piece of furniture. Items are not obstacles: the paper takes
non-physical steps where collisions would be unavoidable (S.2). The radius (0.2 m by default,
smaller than Fetch's ~0.28 m base) is chosen so that 0.9 m doors and 0.8 m corridors stay passable.

Grids depend only on the world's fixed geometry and on which doors are closed, so they are cached
per (world, closed doors, config). Paths are 8-connected geometric shortest paths (``skimage.graph.MCP_Geometric``),
simplified to polylines (``simplify_polyline``, Douglas-Peucker). ``blocking_door`` names the closed door on the way when a goal is only
reachable with doors open: the magic actions report it so that a planner knows what to open.

Rasters are ``free[ix, iy]`` on a :class:`~more_agent.sim.grid.Grid`. The searches (nearest free
cell, shortest path, its simplification) run on the raster transposed to ``[iy, ix]``: how they
break ties between equally good cells depends on the layout, and every recorded episode was made
with that one. Cells go in and come out as (ix, iy).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from more_agent.robot_spec import ROBOT
from more_agent.sim.grid import Grid
from more_agent.sim.scene import Bounds2D, Door
from more_agent.sim.world import World

XY = tuple[float, float]


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


@dataclass(frozen=True, eq=False, kw_only=True)
class NavGrid(Grid):
    """Boolean free-space raster on a :class:`~more_agent.sim.grid.Grid`: ``free[ix, iy]``."""

    free: np.ndarray
    closed_doors: frozenset[str]
    door_cells: dict[str, np.ndarray] = field(repr=False)
    """Per door id, a boolean mask of its passage strip (used to name a blocking door)."""

    __eq__ = object.__eq__  # a raster is itself, not its Grid's placement
    __hash__ = object.__hash__

    @property
    def shape(self) -> tuple[int, int]:
        return self.free.shape

    def cell_at(self, x: float, y: float) -> tuple[int, int]:
        """The (ix, iy) of the cell containing (x, y), clipped to the grid."""
        ix, iy = self.cell_of((x, y))
        return min(max(int(ix), 0), self.shape[0] - 1), min(max(int(iy), 0), self.shape[1] - 1)

    def centre(self, cell: tuple[int, int]) -> XY:
        """World coordinates of a cell's centre, as plain floats."""
        x, y = self.xy_of(cell)
        return float(x), float(y)

    def is_free(self, x: float, y: float) -> bool:
        """Whether the robot base may stand at (x, y)."""
        ix, iy = self.cell_of((x, y))
        return bool(0 <= ix < self.shape[0] and 0 <= iy < self.shape[1] and self.free[ix, iy])

    @cached_property
    def _nearest_free(self) -> tuple[np.ndarray, np.ndarray]:
        # y-major, see the module docstring
        _, (iys, ixs) = ndimage.distance_transform_edt(~self.free.T, return_indices=True)
        return ixs.T, iys.T

    def snap(self, x: float, y: float) -> tuple[int, int] | None:
        """The free cell nearest to (x, y), or None when the grid has no free cell."""
        if not self.free.any():
            return None
        cell = self.cell_at(x, y)
        ixs, iys = self._nearest_free
        return int(ixs[cell]), int(iys[cell])


def free_cells(mask: np.ndarray) -> np.ndarray:
    """(k, 2) cells (ix, iy) of the True cells of a ``[ix, iy]`` mask, row by row (iy, then ix):
    the order in which seeded draws of a cell pick, kept so that a seed gives the same cell."""
    return np.argwhere(mask.T)[:, ::-1]


def _mask_box(grid: Grid, shape: tuple[int, int], box: Bounds2D) -> tuple[slice, slice]:
    """Slices of the cells whose centres lie inside ``box``."""
    lo, hi = grid.centre_range(box[:2], box[2:])
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
        blocked[_mask_box(grid, shape, wall.bounds)] = True
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
            blocked[_mask_box(grid, shape, obj.footprint())] = True

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


@dataclass(frozen=True)
class PathResult:
    """The shortest path from a start to the nearest of several goals (or none)."""

    goal_index: int | None
    """Index into the goals given of the one reached, None when none is reachable."""

    length_m: float
    """Path length in metres (inf when unreachable)."""

    waypoints: list[XY]
    """Simplified polyline from the start to the goal, both included; empty when unreachable."""

    cells: list[tuple[int, int]] = field(repr=False, default_factory=list)
    """The raw 8-connected cell path, (ix, iy) per cell."""

    @property
    def found(self) -> bool:
        return self.goal_index is not None


_NO_PATH = PathResult(goal_index=None, length_m=float("inf"), waypoints=[])


def simplify_polyline(points: np.ndarray, tolerance: float) -> np.ndarray:
    """The points (k, 2) of a polyline that Douglas-Peucker keeps: both ends, and recursively the point
    farthest from the chord between two kept ones while it is more than ``tolerance`` away.

    The distance to a chord is the perpendicular one where the point projects strictly inside it, else
    the distance to its nearer end; ties go to the first point. These are the distances and the tie
    rule of ``skimage.measure.approximate_polygon`` (whose module pulls in ``scipy.signal``, a second
    of import for every command), computed the same way so that every recorded path stays the same.

    >>> simplify_polyline(np.array([[0.0, 0.0], [0.1, 1.0], [0.0, 2.0], [2.0, 2.0]]), 0.5)
    array([[0., 0.],
           [0., 2.],
           [2., 2.]])
    """
    keep = np.zeros(len(points), dtype=bool)
    keep[[0, -1]] = True
    spans = [(0, len(points) - 1)]
    while spans:
        start, end = spans.pop()
        (r0, c0), (r1, c1) = points[start], points[end]
        dr, dc = r1 - r0, c1 - c0
        angle = -np.arctan2(dr, dc)
        offset = c0 * np.sin(angle) + r0 * np.cos(angle)
        inner = points[start + 1 : end]
        dr0, dc0 = inner[:, 0] - r0, inner[:, 1] - c0
        dr1, dc1 = inner[:, 0] - r1, inner[:, 1] - c1
        across = ((dr0 * dr + dc0 * dc) > 0) & ((-dr1 * dr - dc1 * dc) > 0)
        dist = np.where(
            across,
            np.abs(inner[:, 0] * np.cos(angle) + inner[:, 1] * np.sin(angle) - offset),
            np.minimum(np.sqrt(dc0**2 + dr0**2), np.sqrt(dc1**2 + dr1**2)),
        )
        if np.any(dist > tolerance):
            split = start + int(np.argmax(dist)) + 1
            keep[split] = True
            spans += [(split, end), (start, split)]
    return points[keep]


def shortest_path(grid: NavGrid, start: XY, goals: Sequence[XY]) -> PathResult:
    """Shortest 8-connected path over free cells from ``start`` to the nearest of ``goals``.

    The start snaps to its nearest free cell (the robot may stand in a spot the inflated grid
    forbids after a non-physical step); goals must be free themselves or are ignored.
    """
    start_cell = grid.snap(*start)
    goal_index = [i for i, g in enumerate(goals) if grid.is_free(*g)]
    goal_cells = [grid.cell_at(*goals[i]) for i in goal_index]
    if start_cell is None or not goal_cells:
        return _NO_PATH
    mcp = MCP_Geometric(np.where(grid.free.T, 1.0, np.inf))  # y-major: see the module docstring
    goals_yx = [cell[::-1] for cell in goal_cells]
    cum, _ = mcp.find_costs([start_cell[::-1]], goals_yx, find_all_ends=False)
    reached = [(float(cum[yx]), i) for i, yx in enumerate(goals_yx) if np.isfinite(cum[yx])]
    if not reached:
        return _NO_PATH
    cost, k = min(reached)
    path_yx = np.asarray(mcp.traceback(goals_yx[k]))
    cells = [(int(ix), int(iy)) for iy, ix in path_yx]
    simplified = simplify_polyline(path_yx.astype(float), tolerance=1.0)
    waypoints = [(float(start[0]), float(start[1]))]
    waypoints += [grid.centre((int(round(ix)), int(round(iy)))) for iy, ix in simplified[1:-1]]
    waypoints.append((float(goals[goal_index[k]][0]), float(goals[goal_index[k]][1])))
    return PathResult(goal_index=goal_index[k], length_m=cost * grid.resolution_m, waypoints=waypoints, cells=cells)


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
    return shortest_path(nav_grid(world, config), start, [goal]).found
