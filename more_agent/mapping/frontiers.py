"""Frontiers: clusters of free cells bordering unknown cells, one representative point each."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from more_agent.mapping.occupancy import FREE, UNKNOWN


def frontier_points(
    occupancy: np.ndarray,
    *,
    resolution_m: float,
    origin_xy: tuple[float, float] = (0.0, 0.0),
    min_length_m: float = 0.3,
) -> tuple[np.ndarray, np.ndarray]:
    """Frontier points (k, 2) in metres and cluster lengths (k,) in metres (cells x resolution).

    A frontier cell is FREE with an UNKNOWN 4-neighbour (outside the grid counts as unknown);
    8-connected frontier cells form a cluster; clusters shorter than ``min_length_m`` are dropped;
    each cluster is represented by its cell closest to the cluster centroid.
    """
    unknown = np.pad(occupancy == UNKNOWN, 1, constant_values=True)
    touches = unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2] | unknown[1:-1, 2:]
    frontier = (occupancy == FREE) & touches
    lab, n = ndimage.label(frontier, structure=np.ones((3, 3)))
    if n == 0:
        return np.zeros((0, 2)), np.zeros(0)
    cells = np.argwhere(lab)
    ids = lab[cells[:, 0], cells[:, 1]] - 1
    sizes = np.bincount(ids, minlength=n)
    centroid = np.stack([np.bincount(ids, weights=cells[:, a], minlength=n) for a in (0, 1)], 1) / sizes[:, None]
    d2 = ((cells - centroid[ids]) ** 2).sum(1)
    order = np.lexsort((d2, ids))
    first = order[np.searchsorted(ids[order], np.arange(n))]
    keep = sizes * resolution_m >= min_length_m
    pts = np.asarray(origin_xy) + (cells[first[keep]] + 0.5) * resolution_m
    return pts, sizes[keep] * resolution_m
