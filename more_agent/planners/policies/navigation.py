"""Paths on the agent's own map: the BEV occupancy of the scene graph, inflated, as a navigation grid.

Only cells the robot has seen free count as traversable, kept ``plan_inflation_m`` away from mapped
obstacles (unknown space is not traversable but does not inflate), plus the unknown cells close to
where the robot has stood: the pitched camera never sees the floor right around the robot, and
without them the robot's own spot is a hole that cuts it off from the map it has seen. With
``retrace``, the cells its centre has passed through are traversable too, inflation or not, unless mapped
occupied since: a magic action's final approach drives on the ground truth with the robot's real radius
and may leave it inside the inflation margin of its map (a gap between a counter and a table), where no
path with the full margin leads out. Shortest paths use the same
8-connected geometric search as the ground-truth grid (:func:`more_agent.sim.paths.shortest_path`,
an optimal search like A* with an admissible heuristic), here on what the agent knows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from scipy import ndimage

from more_agent.mapping import FREE, OCCUPIED
from more_agent.robot import XY
from more_agent.scene_graph import OccupancyMap, SceneGraph
from more_agent.sim.paths import NavGrid, PathResult, shortest_path


def agent_nav_grid(
    occupancy: OccupancyMap,
    *,
    inflation_m: float,
    stood_xy: Sequence[XY] = (),
    blind_radius_m: float = 0.0,
    bumped_xy: Sequence[XY] = (),
    retrace: bool = False,
) -> NavGrid:
    """The traversable raster of the agent's map: seen-free cells, and unknown cells within
    ``blind_radius_m`` of a position in ``stood_xy``, at least ``inflation_m`` from obstacles (mapped
    ones, and the points in ``bumped_xy`` where a move was blocked by something the camera missed);
    with ``retrace``, also the cells of ``stood_xy`` themselves (the robot's path, a polyline) that are not
    obstacles."""
    grid = np.array(occupancy.grid)
    bumps = _cells(occupancy, bumped_xy)
    grid[bumps[:, 0], bumps[:, 1]] = OCCUPIED
    res = occupancy.resolution_m
    known_free = grid == FREE
    path = _path_cells(occupancy, stood_xy)
    if len(path) and blind_radius_m > 0:
        seeds = np.zeros(grid.shape, dtype=bool)
        seeds[path[:, 0], path[:, 1]] = True
        near = _within(seeds, blind_radius_m, res, around=seeds)
        known_free |= near & (grid != OCCUPIED)
    occupied = grid == OCCUPIED
    # with no obstacle at all, scipy's transform measures to the grid's rim: keep that on the whole grid
    free = known_free & ~_within(occupied, inflation_m, res, around=known_free if occupied.any() else None)
    if retrace:
        free[path[:, 0], path[:, 1]] |= grid[path[:, 0], path[:, 1]] != OCCUPIED
    return NavGrid(
        origin_xy=occupancy.origin_xy,
        resolution_m=occupancy.resolution_m,
        free=free,
        closed_doors=frozenset(),
        door_cells={},
    )


def _within(targets: np.ndarray, radius_m: float, res: float, *, around: np.ndarray | None) -> np.ndarray:
    """Whether each cell lies within ``radius_m`` of a ``targets`` cell (the Euclidean distance transform's
    test, to the bit), evaluated only in the box of the ``around`` cells grown by the radius (False outside;
    the whole grid when None). A target within the radius of a cell in the box lies in the grown box, so
    the box's transform answers like the whole grid's: most of a growing map is unknown rim, never asked."""
    out = np.zeros(targets.shape, dtype=bool)
    box = _grown_box(around, math.ceil(radius_m / res) + 1) if around is not None else (slice(None), slice(None))
    if box is None:
        return out
    crop = targets[box]
    if around is None or crop.any():
        out[box] = ndimage.distance_transform_edt(~crop) * res <= radius_m
    return out


def _grown_box(mask: np.ndarray, margin: int) -> tuple[slice, slice] | None:
    """The bounding box of the True cells of ``mask`` grown by ``margin`` cells (clipped), None when none."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return None
    return (
        slice(max(rows[0] - margin, 0), rows[-1] + margin + 1),
        slice(max(cols[0] - margin, 0), cols[-1] + margin + 1),
    )


def _path_cells(occupancy: OccupancyMap, path: Sequence[XY]) -> np.ndarray:
    """(n, 2) cells the polyline ``path`` passes through (``Grid.passed``)."""
    return _cells(occupancy, occupancy.frame.passed(path))


def _cells(occupancy: OccupancyMap, points: Sequence[XY] | np.ndarray) -> np.ndarray:
    """(n, 2) integer (ix, iy) cells of the points that lie on the occupancy grid."""
    if not len(points):
        return np.zeros((0, 2), dtype=int)
    cells = occupancy.frame.cell_of(points)
    return cells[((cells >= 0) & (cells < occupancy.grid.shape)).all(axis=1)]


def snap_goals(grid: NavGrid, goals: Sequence[XY], max_m: float, sight: np.ndarray | None = None) -> list[XY | None]:
    """Each goal moved to its nearest traversable cell centre, or None when that is farther than ``max_m``.
    With ``sight`` (a boolean raster of the cells a line of sight crosses, on ``grid``), to the nearest
    traversable cell within ``max_m`` from which the straight line to the goal crosses only such cells or
    traversable ones, where there is one."""
    clear = None if sight is None else sight | grid.free
    out: list[XY | None] = []
    for g in goals:
        seeing = None if clear is None else nearest_in_sight(grid, clear, g, max_m)
        if seeing is not None:
            out.append(seeing)
            continue
        cell = grid.snap(*g)
        xy = grid.centre(cell) if cell is not None else None
        out.append(xy if xy is not None and math.dist(xy, g) <= max_m else None)
    return out


def nearest_in_sight(grid: NavGrid, clear: np.ndarray, goal: XY, max_m: float) -> XY | None:
    """The centre of the traversable cell nearest to ``goal`` within ``max_m`` from which the straight line
    to it crosses only ``clear`` cells, None when there is none: a frontier seen through a doorway lies a
    hand's breadth beyond a wall that the camera never saw, and the cell nearest to it, on this side of that
    wall, shows nothing of what lies beyond. Rays cast from the goal in half-cell steps, as many as cells on
    the circle of ``max_m``, each ending at its first cell that is not clear (or off the grid)."""
    res = grid.resolution_m
    radii = np.arange(int(math.ceil(2 * max_m / res)) + 1) * (res / 2)
    angles = np.linspace(0.0, 2 * np.pi, max(8, int(math.ceil(2 * np.pi * max_m / res))), endpoint=False)
    directions = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    points = np.asarray(goal, dtype=float) + radii[None, :, None] * directions[:, None, :]
    cells = grid.cell_of(points)  # (rays, radii, 2)
    inside = ((cells >= 0) & (cells < grid.shape)).all(axis=2)
    ix, iy = (np.clip(cells[..., a], 0, grid.shape[a] - 1) for a in (0, 1))
    seen = np.cumprod(inside & clear[ix, iy], axis=1).astype(bool)  # clear all the way from the goal
    ray, step = np.nonzero(seen & grid.free[ix, iy])
    centres = grid.xy_of(np.stack([ix[ray, step], iy[ray, step]], axis=1))
    distance = np.hypot(centres[:, 0] - goal[0], centres[:, 1] - goal[1])
    if not len(distance) or distance.min() > max_m:
        return None
    x, y = centres[int(np.argmin(distance))]
    return float(x), float(y)


def reachable_part(grid: NavGrid, start: XY) -> NavGrid:
    """The grid reduced to the 8-connected free component the robot (snapped) stands in, so that goals
    snap to cells it can drive to, never to an island of free space cut off by unknown cells."""
    cell = grid.snap(*start)
    if cell is None:
        return grid
    return replace(grid, free=grid.components == grid.components[cell])


def path_to_nearest(
    grid: NavGrid, start: XY, goals: Sequence[XY], *, snap_m: float, sight: np.ndarray | None = None
) -> tuple[PathResult, int | None]:
    """Shortest path from ``start`` to the nearest reachable goal (goals snapped first, to the robot's
    free component; in sight of them through ``sight``'s cells when given, :func:`snap_goals`) and that
    goal's index."""
    grid = reachable_part(grid, start)
    snapped = snap_goals(grid, goals, snap_m, sight)
    usable = [i for i, g in enumerate(snapped) if g is not None]
    if not usable:
        return shortest_path(grid, start, []), None
    result = shortest_path(grid, start, [snapped[i] for i in usable])  # type: ignore[misc]
    return result, (usable[result.goal_index] if result.goal_index is not None else None)


def object_goal(graph: SceneGraph, object_id: str) -> XY | None:
    """The Voronoi node of the object's region closest to it (paper: navigate(room, object)): a wall
    cabinet's nearest node may lie behind the wall, in the next room; any node when the object has no
    region. None on an empty graph."""
    if len(graph.nav.node_xy) == 0:
        return None
    obj = graph.objects[object_id]
    region = graph.regions.get(obj.region_id) if obj.region_id is not None else None
    nodes = np.asarray(region.nav_nodes if region is not None and region.nav_nodes else range(len(graph.nav.node_xy)))
    xy = np.asarray(graph.nav.node_xy)[nodes]
    best = xy[int(np.argmin(np.hypot(xy[:, 0] - obj.position[0], xy[:, 1] - obj.position[1])))]
    return (float(best[0]), float(best[1]))
