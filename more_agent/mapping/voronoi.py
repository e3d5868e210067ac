"""Generalized Voronoi diagram of the free space of a BEV occupancy grid, as a ``NavGraph``.

Grid convention used throughout ``mapping``: ``occupancy[ix, iy]`` on a
:class:`~more_agent.sim.grid.Grid` (x east, y north).

The GVD is computed in time linear in the grid area: one Euclidean distance transform with
feature indices (the ESDF), then a cell pair straddles the GVD when the nearest obstacle cells of
two 4-neighbours lie far apart (brushfire criterion); the resulting band, two or three pixels
wide, is thinned to one pixel by Zhang-Suen thinning over the band's pixels only. Obstacles are
every non-free cell (occupied or unknown), so the diagram never leaves the observed free space.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy import ndimage

from more_agent.mapping.graph import NavGraph
from more_agent.mapping.occupancy import FREE
from more_agent.sim.grid import Grid


@numba.njit(cache=True)
def _clearance_mask(feat_r: np.ndarray, feat_c: np.ndarray, resolution: float, inflation: float) -> np.ndarray:
    """Cells whose distance to their nearest obstacle cell (EDT feature indices) times
    ``resolution`` exceeds ``inflation``; the distance is computed as scipy's EDT computes it."""
    h, w = feat_r.shape
    out = np.zeros((h, w), dtype=np.bool_)
    for r in range(h):
        for c in range(w):
            a = float(feat_r[r, c] - r)
            b = float(feat_c[r, c] - c)
            out[r, c] = np.sqrt(a * a + b * b) * resolution > inflation
    return out


@numba.njit(cache=True)
def _gvd_band(domain: np.ndarray, feat_r: np.ndarray, feat_c: np.ndarray, min_sep2: float) -> np.ndarray:
    """Mark both cells of every 4-neighbour pair inside ``domain`` whose nearest obstacle cells are
    more than sqrt(min_sep2) cells apart."""
    h, w = domain.shape
    band = np.zeros((h, w), dtype=np.bool_)
    for r in range(h):
        for c in range(w):
            if not domain[r, c]:
                continue
            for dr, dc in ((1, 0), (0, 1)):
                r2, c2 = r + dr, c + dc
                if r2 >= h or c2 >= w or not domain[r2, c2]:
                    continue
                a = feat_r[r, c] - feat_r[r2, c2]
                b = feat_c[r, c] - feat_c[r2, c2]
                if a * a + b * b > min_sep2:
                    band[r, c] = True
                    band[r2, c2] = True
    return band


@numba.njit(cache=True)
def _thin(band: np.ndarray) -> np.ndarray:
    """Zhang-Suen thinning that visits only the band's pixels (cost linear in the band size)."""
    img = band.copy()
    h, w = img.shape
    rr, cc = np.nonzero(img)
    alive = np.ones(rr.size, dtype=np.bool_)
    nb = np.zeros(9, dtype=np.int64)
    delete = np.zeros(rr.size, dtype=np.bool_)
    changed = True
    while changed:
        changed = False
        for sub in range(2):
            delete[:] = False
            for i in range(rr.size):
                if not alive[i]:
                    continue
                r, c = rr[i], cc[i]
                # P2..P9 clockwise from north; out-of-image counts as background
                for k, (dr, dc) in enumerate(((-1, 0), (-1, 1), (0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1))):
                    r2, c2 = r + dr, c + dc
                    nb[k] = 1 if (0 <= r2 < h and 0 <= c2 < w and img[r2, c2]) else 0
                nb[8] = nb[0]
                b = nb[:8].sum()
                a = 0
                for k in range(8):
                    if nb[k] == 0 and nb[k + 1] == 1:
                        a += 1
                if b < 2 or b > 6 or a != 1:
                    continue
                p2, p4, p6, p8 = nb[0], nb[2], nb[4], nb[6]
                if sub == 0 and p2 * p4 * p6 == 0 and p4 * p6 * p8 == 0:
                    delete[i] = True
                elif sub == 1 and p2 * p4 * p8 == 0 and p2 * p6 * p8 == 0:
                    delete[i] = True
            for i in range(rr.size):
                if delete[i]:
                    img[rr[i], cc[i]] = False
                    alive[i] = False
                    changed = True
    return img


def _pixel_graph(skel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """8-connected pixel graph of a one-pixel skeleton; a diagonal step is dropped when an
    orthogonal two-step path through a skeleton pixel exists (avoids corner triangles)."""
    cells = np.argwhere(skel)
    index = np.full(skel.shape, -1, dtype=np.int64)
    index[cells[:, 0], cells[:, 1]] = np.arange(len(cells))
    padded = np.pad(index, 1, constant_values=-1)
    r, c = cells[:, 0] + 1, cells[:, 1] + 1
    edges, weights = [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        other = padded[r + dr, c + dc]
        ok = other >= 0
        if dr and dc:
            ok &= (padded[r + dr, c] < 0) & (padded[r, c + dc] < 0)
        edges.append(np.stack([np.arange(len(cells))[ok], other[ok]], axis=1))
        weights.append(np.full(int(ok.sum()), np.hypot(dr, dc)))
    e = np.concatenate(edges)
    return cells, np.sort(e, axis=1), np.concatenate(weights)


def voronoi_graph(
    occupancy: np.ndarray,
    grid: Grid,
    *,
    inflation_m: float = 0.15,
    min_separation_m: float = 0.3,
) -> NavGraph:
    """Voronoi graph of the free cells (``occupancy == FREE``) of a BEV grid.

    Parameters
    ----------
    occupancy : ndarray of int, shape (nx, ny)
        UNKNOWN / FREE / OCCUPIED per cell, ``[ix, iy]``; every non-free cell is an obstacle.
    grid : Grid
        Where ``occupancy`` lies.
    inflation_m : float, optional
        Cells closer than this to any non-free cell are excluded (ESDF inflation, robot clearance).
    min_separation_m : float, optional
        Two neighbours straddle the GVD when their nearest obstacles are farther apart than this;
        smaller values keep more wall-corner spurs.

    Returns
    -------
    graph : NavGraph
        Nodes at skeleton cell centres (metres), 8-connected edges weighted by metric length.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import FREE, Grid, voronoi_graph
    >>> occ = np.zeros((12, 5), dtype=np.int8)
    >>> occ[1:11, 1:4] = FREE  # a corridor three cells wide along x
    >>> g = voronoi_graph(occ, Grid(resolution_m=0.1), inflation_m=0.05)
    >>> g.xy.round(2).tolist()  # its centre line
    [[0.35, 0.25], [0.45, 0.25], [0.55, 0.25], [0.65, 0.25], [0.75, 0.25], [0.85, 0.25]]
    >>> g.weights.round(2)
    array([0.1, 0.1, 0.1, 0.1, 0.1])
    """
    free = occupancy == FREE
    if not free.any():
        return NavGraph.empty()
    rows, cols = np.nonzero(free.any(axis=1))[0], np.nonzero(free.any(axis=0))[0]
    r0, c0 = rows[0] - 1, cols[0] - 1  # one non-free ring around the crop
    crop = np.zeros((rows[-1] - rows[0] + 3, cols[-1] - cols[0] + 3), dtype=bool)
    crop[1:-1, 1:-1] = free[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    # feature indices only (int32): the distances follow from them without scipy's float temporaries
    feat_r, feat_c = ndimage.distance_transform_edt(crop, return_distances=False, return_indices=True)
    res = grid.resolution_m
    domain = _clearance_mask(feat_r, feat_c, float(res), float(inflation_m))
    band = _gvd_band(domain, feat_r, feat_c, (min_separation_m / res) ** 2)
    if not band.any():
        return NavGraph.empty()
    skel = _thin(band)
    cells, edges, steps = _pixel_graph(skel)
    return NavGraph(grid.xy_of(cells + (r0, c0)), edges, steps * res)
