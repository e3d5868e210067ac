"""Frontiers: clusters of free cells bordering unknown cells, one representative point each."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from more_agent.mapping.occupancy import FREE, OCCUPIED, UNKNOWN
from more_agent.sim.grid import Grid


def frontier_points(
    occupancy: np.ndarray,
    grid: Grid,
    *,
    min_length_m: float = 0.3,
    max_length_m: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Frontier points and cluster lengths of a BEV grid.

    A frontier cell is FREE with an UNKNOWN 4-neighbour (outside the grid counts as unknown);
    8-connected frontier cells form a cluster; a cluster longer than ``max_length_m`` is cut into
    pieces by square tiles of that side (:func:`_pieces`); clusters (pieces) shorter than
    ``min_length_m`` are dropped; each is represented by its cell closest to its centroid.

    Parameters
    ----------
    occupancy : ndarray of int, shape (nx, ny)
        UNKNOWN / FREE / OCCUPIED per cell, ``[ix, iy]``.
    grid : Grid
        Where ``occupancy`` lies.
    min_length_m : float, optional
        Shortest cluster kept, as cells x resolution.
    max_length_m : float, optional
        Longest cluster kept whole; None keeps every cluster whole.

    Returns
    -------
    points : ndarray, shape (k, 2)
        One point per kept cluster, metres.
    lengths : ndarray, shape (k,)
        Cluster lengths (cells x resolution), metres.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import FREE, OCCUPIED, UNKNOWN, Grid, frontier_points
    >>> occ = np.full((6, 5), OCCUPIED, dtype=np.int8)
    >>> occ[1:5, 1:4] = FREE     # a room seen from inside ...
    >>> occ[5, 1:4] = UNKNOWN    # ... whose east side is not seen yet
    >>> frontier_points(occ, Grid(resolution_m=0.5), min_length_m=1.0)
    (array([[2.25, 1.25]]), array([1.5]))
    """
    unknown = np.pad(occupancy == UNKNOWN, 1, constant_values=True)
    touches = unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2] | unknown[1:-1, 2:]
    frontier = (occupancy == FREE) & touches
    lab, n = ndimage.label(frontier, structure=np.ones((3, 3)))
    if n == 0:
        return np.zeros((0, 2)), np.zeros(0)
    cells = np.argwhere(lab)
    ids = lab[cells[:, 0], cells[:, 1]] - 1
    if max_length_m is not None:
        ids, n = _pieces(grid.xy_of(cells), ids, max_length_m, grid.resolution_m)
    sizes = np.bincount(ids, minlength=n)
    centroid = np.stack([np.bincount(ids, weights=cells[:, a], minlength=n) for a in (0, 1)], 1) / sizes[:, None]
    d2 = ((cells - centroid[ids]) ** 2).sum(1)
    order = np.lexsort((d2, ids))
    first = order[np.searchsorted(ids[order], np.arange(n))]
    keep = sizes * grid.resolution_m >= min_length_m
    return grid.xy_of(cells[first[keep]]), sizes[keep] * grid.resolution_m


def _pieces(xy: np.ndarray, ids: np.ndarray, side_m: float, resolution_m: float) -> tuple[np.ndarray, int]:
    """Cluster ids of the frontier cells at ``xy`` with each cluster longer than ``side_m`` cut by the squares of
    side ``side_m`` of a lattice fixed in the world (not in the grid, whose corner moves as the map grows). One
    point for a 30 m edge of unseen lawn sits at its middle, and once the robot has looked from there
    (``visited_frontier_m``) the rest of the edge, still unseen, would have no point."""
    long = np.bincount(ids)[ids] * resolution_m > side_m
    tiles = np.floor(xy / side_m).astype(np.int64)
    key = np.stack([ids, np.where(long, tiles[:, 0], 0), np.where(long, tiles[:, 1], 0)], axis=1)
    _, pieces = np.unique(key, axis=0, return_inverse=True)
    pieces = pieces.reshape(-1)
    return pieces, int(pieces.max()) + 1


def visible_unknown_area(
    occupancy: np.ndarray,
    grid: Grid,
    points: np.ndarray,
    *,
    range_m: float,
    rays: int = 48,
) -> np.ndarray:
    """Unknown floor area (m^2) in sensor range of each point that no known obstacle hides.

    The information gain of driving to a frontier: rays are cast from each point in ``rays``
    directions up to ``range_m``, each stops at the first OCCUPIED cell, and the UNKNOWN cells it
    crosses count with the area of their ring sector (cells outside the grid are unknown). Unknown
    cells do not stop a ray: what is unseen may be open.

    Parameters
    ----------
    occupancy : ndarray of int, shape (nx, ny)
        UNKNOWN / FREE / OCCUPIED per cell, ``[ix, iy]``.
    grid : Grid
        Where ``occupancy`` lies.
    points : ndarray, shape (k, 2)
        Viewpoints, metres.
    range_m : float
        Sensor range.
    rays : int, optional
        Directions cast per point.

    Returns
    -------
    area : ndarray, shape (k,)
        Square metres per point.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import FREE, OCCUPIED, UNKNOWN, Grid, visible_unknown_area
    >>> occ = np.full((40, 20), FREE, dtype=np.int8)
    >>> occ[20:, :] = UNKNOWN    # the east half is unseen ...
    >>> occ[10, :] = OCCUPIED    # ... and a wall stands west of x = 1.1 m
    >>> west, east = visible_unknown_area(occ, Grid(resolution_m=0.1), np.array([[1.5, 1.0], [1.95, 1.0]]), range_m=1.0)
    >>> bool(west < east)        # nearer the unseen half, more of it in range
    True
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    step = grid.resolution_m
    radii = (np.arange(int(range_m / step)) + 0.5) * step  # ring midpoints: the sectors tile the disc
    angles = np.linspace(0.0, 2 * np.pi, rays, endpoint=False)
    offsets = radii[None, :, None] * np.stack([np.cos(angles), np.sin(angles)], axis=1)[:, None, :]
    padded = np.pad(occupancy, 1, constant_values=UNKNOWN)  # a cell beyond the grid reads as its unknown rim
    cells = grid.cell_of(points[:, None, None, :] + offsets[None]) + 1
    for axis in (0, 1):
        np.clip(cells[..., axis], 0, padded.shape[axis] - 1, out=cells[..., axis])
    value = padded[cells[..., 0], cells[..., 1]]  # (points, rays, radii)
    visible = np.cumsum(value == OCCUPIED, axis=2) == 0
    sector = radii * step * (2 * np.pi / rays)
    return (((value == UNKNOWN) & visible) @ sector).sum(axis=1)
