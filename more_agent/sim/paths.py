"""Shortest paths on a free-space raster: what the ground-truth grid (``sim.navgrid``) and the agent's
own map (``planners.policies.navigation``) both plan with.

Rasters are ``free[ix, iy]`` on a :class:`~more_agent.sim.grid.Grid`. The searches (nearest free
cell, shortest path, its simplification) run on the raster transposed to ``[iy, ix]``: how they
break ties between equally good cells depends on the layout, and every recorded episode was made
with that one. Cells go in and come out as (ix, iy). Paths are 8-connected geometric shortest paths
(``skimage.graph.MCP_Geometric``), simplified to polylines (``simplify_polyline``, Douglas-Peucker).
This module knows no world: a raster is all it reads.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike
from scipy import ndimage
from skimage.graph import MCP_Geometric

from more_agent.robot import XY
from more_agent.sim.grid import Grid


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
        return bool(self.free_at([(x, y)])[0])

    def free_at(self, xy: ArrayLike) -> np.ndarray:
        """Per point of ``xy`` (n x 2), whether the robot base may stand there (off the grid: no)."""
        ix, iy = self.cell_of(np.asarray(xy, dtype=float).reshape(-1, 2)).T
        inside = (ix >= 0) & (ix < self.shape[0]) & (iy >= 0) & (iy < self.shape[1])
        ok = np.zeros(len(ix), dtype=bool)
        ok[inside] = self.free[ix[inside], iy[inside]]
        return ok

    @cached_property
    def _mcp(self) -> tuple[MCP_Geometric, np.ndarray]:
        """The path search over this raster (y-major, see the module docstring), built once, and the (ix, iy)
        of its first cell. It covers only the free cells' bounding box, with a rim of blocked cells: a search
        never enters a blocked cell, so it pushes and pops the same cells in the same order as one over the
        whole raster and finds the same path, while setting up its arrays costs as much as a search (12 ms on a
        store's map, of which the free box is a third). Built once, as a magic action searches one world grid
        many times; ``find_costs`` starts afresh on each call."""
        rows, cols = np.flatnonzero(self.free.any(axis=1)), np.flatnonzero(self.free.any(axis=0))  # one at least
        lo = np.array([max(rows[0] - 1, 0), max(cols[0] - 1, 0)])
        box = self.free[lo[0] : rows[-1] + 2, lo[1] : cols[-1] + 2]
        return MCP_Geometric(np.where(box.T, 1.0, np.inf)), lo

    @cached_property
    def components(self) -> np.ndarray:
        """The connected components of the free cells (0 elsewhere), with the eight neighbours the path search
        steps to: two free cells are joined by a path exactly when they share a label. Labelled once a grid."""
        return ndimage.label(self.free, structure=np.ones((3, 3), dtype=bool))[0]

    @cached_property
    def _nearest_free(self) -> tuple[np.ndarray, np.ndarray]:
        # y-major, see the module docstring
        iys, ixs = ndimage.distance_transform_edt(~self.free.T, return_distances=False, return_indices=True)
        return ixs.T, iys.T

    def snap(self, x: float, y: float) -> tuple[int, int] | None:
        """The free cell nearest to (x, y), or None when the grid has no free cell. A free cell is its own
        nearest (what the distance transform would say too), so only off-free points pay for the transform."""
        cell = self.cell_at(x, y)
        if self.free[cell]:
            return cell
        if not self.free.any():
            return None
        ixs, iys = self._nearest_free
        return int(ixs[cell]), int(iys[cell])


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


def reaches(grid: NavGrid, start: XY, goals: Sequence[XY]) -> bool:
    """Whether :func:`shortest_path` finds a path from ``start`` to one of ``goals``, without searching for it:
    the snapped start and a free goal lie in one component of the free cells. A privileged planner asks this
    of a world's grid many times (is a closed door in the way?), and a search costs milliseconds."""
    start_cell = grid.snap(*start)
    if start_cell is None:
        return False
    components = grid.components
    label = components[start_cell[0], start_cell[1]]
    cells = [grid.cell_at(*goals[i]) for i in np.flatnonzero(grid.free_at(goals)).tolist()]
    return any(components[ix, iy] == label for ix, iy in cells)


def shortest_path(grid: NavGrid, start: XY, goals: Sequence[XY]) -> PathResult:
    """Shortest 8-connected path over free cells from ``start`` to the nearest of ``goals``.

    The start snaps to its nearest free cell (the robot may stand in a spot the inflated grid
    forbids after a non-physical step); goals must be free themselves or are ignored.
    """
    start_cell = grid.snap(*start)
    goal_index = np.flatnonzero(grid.free_at(goals)).tolist()
    goal_cells = [grid.cell_at(*goals[i]) for i in goal_index]
    if start_cell is None or not goal_cells:
        return _NO_PATH
    mcp, (x0, y0) = grid._mcp
    goals_yx = [(iy - y0, ix - x0) for ix, iy in goal_cells]
    cum, _ = mcp.find_costs([(start_cell[1] - y0, start_cell[0] - x0)], goals_yx, find_all_ends=False)
    reached = [(float(cum[yx]), i) for i, yx in enumerate(goals_yx) if np.isfinite(cum[yx])]
    if not reached:
        return _NO_PATH
    cost, k = min(reached)
    path_yx = np.asarray(mcp.traceback(goals_yx[k])) + (y0, x0)
    cells = [(int(ix), int(iy)) for iy, ix in path_yx]
    simplified = simplify_polyline(path_yx.astype(float), tolerance=1.0)
    waypoints = [(float(start[0]), float(start[1]))]
    waypoints += [grid.centre((int(round(ix)), int(round(iy)))) for iy, ix in simplified[1:-1]]
    waypoints.append((float(goals[goal_index[k]][0]), float(goals[goal_index[k]][1])))
    return PathResult(goal_index=goal_index[k], length_m=cost * grid.resolution_m, waypoints=waypoints, cells=cells)
