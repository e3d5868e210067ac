"""``Grid``: the one cell <-> metre convention of every raster over the floor plane.

A grid has a corner ``origin_xy`` (metres, x east, y north) and square cells of ``resolution_m``.
Arrays on a grid are indexed ``[ix, iy]`` (x first); cell ``(ix, iy)`` covers
``origin_xy + [ix, ix + 1) x [iy, iy + 1) * resolution_m`` and its centre lies at
``origin_xy + (ix + 0.5, iy + 0.5) * resolution_m``. The agent's voxel map and BEV
(:mod:`more_agent.mapping`), the ground-truth and the agent's navigation rasters
(:mod:`more_agent.sim.navgrid`, :mod:`more_agent.planners.policies.navigation`) and the map
pictures all use it. The grid holds no extent: the arrays on it do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True, kw_only=True)
class Grid:
    """Placement of a raster in the world: corner and cell size; arrays on it are ``[ix, iy]``.

    Examples
    --------
    >>> grid = Grid(origin_xy=(1.0, 2.0), resolution_m=0.5)
    >>> grid.cell_of([[1.2, 2.9], [0.9, 2.0]])
    array([[ 0,  1],
           [-1,  0]])
    >>> grid.xy_of([0, 1])
    array([1.25, 2.75])
    """

    origin_xy: tuple[float, float] = (0.0, 0.0)
    """World position (x, y) of the corner of cell (0, 0), metres."""

    resolution_m: float
    """Cell size, metres."""

    def cell_of(self, xy: ArrayLike) -> np.ndarray:
        """Integer cells (..., 2) holding the points ``xy`` (..., 2); not clipped to any extent.

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            Points in metres.

        Returns
        -------
        cells : ndarray of int, shape (..., 2)
            ``floor((xy - origin_xy) / resolution_m)``, i.e. (ix, iy) per point.

        Examples
        --------
        >>> Grid(resolution_m=0.1).cell_of((0.35, -0.05))
        array([ 3, -1])
        """
        return np.floor((np.asarray(xy, dtype=float) - self.origin_xy) / self.resolution_m).astype(int)

    def xy_of(self, cells: ArrayLike) -> np.ndarray:
        """Centres (..., 2), metres, of the cells (..., 2).

        Parameters
        ----------
        cells : array_like of int, shape (..., 2)
            (ix, iy) per cell.

        Returns
        -------
        xy : ndarray of float, shape (..., 2)
            ``origin_xy + (cells + 0.5) * resolution_m``.

        Examples
        --------
        >>> Grid(origin_xy=(-1.0, 0.0), resolution_m=0.5).xy_of([[0, 0], [2, 1]])
        array([[-0.75,  0.25],
               [ 0.25,  0.75]])
        """
        return np.asarray(self.origin_xy) + (np.asarray(cells) + 0.5) * self.resolution_m

    def cell_range(self, lo_xy: ArrayLike, hi_xy: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """First cell and one past the last cell (each (ix, iy)) of the cells that the box
        ``[lo_xy, hi_xy]`` overlaps; not clipped.

        Examples
        --------
        >>> Grid(resolution_m=1.0).cell_range((0.5, 1.0), (2.5, 3.0))
        (array([0, 1]), array([3, 3]))
        """
        lo = np.floor((np.asarray(lo_xy, dtype=float) - self.origin_xy) / self.resolution_m).astype(int)
        hi = np.ceil((np.asarray(hi_xy, dtype=float) - self.origin_xy) / self.resolution_m).astype(int)
        return lo, hi

    def centre_range(self, lo_xy: ArrayLike, hi_xy: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """First cell and one past the last cell (each (ix, iy)) of the cells whose centres lie in
        the box ``[lo_xy, hi_xy]``; not clipped.

        Examples
        --------
        >>> Grid(resolution_m=1.0).centre_range((0.5, 1.0), (2.5, 3.0))
        (array([0, 1]), array([3, 3]))
        >>> Grid(resolution_m=1.0).centre_range((0.6, 1.0), (2.4, 3.0))
        (array([1, 1]), array([2, 3]))
        """
        lo = np.ceil((np.asarray(lo_xy, dtype=float) - self.origin_xy) / self.resolution_m - 0.5).astype(int)
        hi = np.floor((np.asarray(hi_xy, dtype=float) - self.origin_xy) / self.resolution_m - 0.5).astype(int) + 1
        return lo, hi

    def bounds(self, shape: tuple[int, int]) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1), metres, of an array of ``shape`` (nx, ny) on the grid.

        Examples
        --------
        >>> Grid(origin_xy=(1.0, 2.0), resolution_m=0.5).bounds((4, 2))
        (1.0, 2.0, 3.0, 3.0)
        """
        (x0, y0), res = self.origin_xy, self.resolution_m
        return float(x0), float(y0), float(x0 + shape[0] * res), float(y0 + shape[1] * res)

    def passed(self, path: ArrayLike) -> np.ndarray:
        """The points (n x 2) a polyline ``path`` passes within a cell of: its vertices, then, for each segment
        longer than a cell (in segment order), points at most a cell apart between its ends. A magic action's
        approach adds only its waypoints to a path, metres apart, and the robot passed every point between them.
        Only the long segments are visited: a robot's path has a vertex for every step it drove.

        Examples
        --------
        >>> Grid(resolution_m=0.5).passed([[0.0, 0.0], [0.2, 0.0], [1.2, 0.0]])
        array([[0. , 0. ],
               [0.2, 0. ],
               [1.2, 0. ],
               [0.7, 0. ]])
        """
        points = np.asarray(path, dtype=float).reshape(-1, 2)
        steps = np.diff(points, axis=0)
        counts = np.ceil(np.abs(steps).max(axis=1) / self.resolution_m).astype(int)
        inner = np.maximum(counts - 1, 0)  # points strictly between a segment's ends
        segment = np.repeat(np.arange(len(steps)), inner)
        k = np.arange(len(segment)) - np.repeat(np.cumsum(inner) - inner, inner) + 1  # 1, 2, ... within a segment
        between = points[segment] + steps[segment] * (k / counts[segment])[:, None]
        return np.concatenate([points, between])
