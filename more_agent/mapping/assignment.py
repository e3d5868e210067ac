"""Object-to-region assignment, Eq. 1 of the MORE paper.

For object O seen from viewpoint v_p, S_O and S_vp are the graph nodes near O and near v_p; the
object goes to the region holding the pair (v, u) in S_O x S_vp that minimises
d_V(v, u) + d_E(O, v)^lambda + d_E(v_p, u) (d_V: shortest path without door-crossing edges,
infinite between regions). When no pair shares a region (e.g. an object seen through a window),
it goes to its closest region, the one of argmin_v d_E(O, v).
"Near" also requires a line of sight in the BEV that crosses no structural cell (wall, window,
door): a node behind a wall is not near the object however close it is.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from more_agent.mapping.graph import NavGraph
from more_agent.sim.grid import Grid


def line_of_sight(p: np.ndarray, targets: np.ndarray, blocked: np.ndarray, grid: Grid) -> np.ndarray:
    """Which targets see point ``p`` without crossing a ``blocked`` cell.

    The segments are sampled every half cell; a blocked run at ``p`` itself (the object stands in a
    wall, or is a door) is skipped. Samples off the grid never block.

    Parameters
    ----------
    p : ndarray, shape (2,)
        The point, metres.
    targets : ndarray, shape (k, 2)
        The points it may see, metres.
    blocked : ndarray of bool, shape (nx, ny)
        Cells that break the line of sight (walls, windows, doors), ``[ix, iy]``.
    grid : Grid
        Where ``blocked`` lies.

    Returns
    -------
    seen : ndarray of bool, shape (k,)

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import Grid, line_of_sight
    >>> blocked = np.zeros((4, 4), dtype=bool)
    >>> blocked[2, :] = True  # a wall at 1.0 <= x < 1.5
    >>> line_of_sight(np.array([0.25, 0.25]), np.array([[0.25, 1.75], [1.75, 0.25]]), blocked,
    ...               Grid(resolution_m=0.5))
    array([ True, False])
    """
    length = np.linalg.norm(targets - p, axis=1).max(initial=0.0)
    n = max(2, int(np.ceil(length / (grid.resolution_m / 2))) + 1)
    s = np.linspace(0.0, 1.0, n)
    pts = p + s[None, :, None] * (targets - p)[:, None, :]
    cells = grid.cell_of(pts)
    inside = (cells >= 0).all(-1) & (cells[..., 0] < blocked.shape[0]) & (cells[..., 1] < blocked.shape[1])
    cells = np.where(inside[..., None], cells, 0)
    hit = blocked[cells[..., 0], cells[..., 1]] & inside
    started = np.logical_or.accumulate(~hit, axis=1)
    return ~(hit & started).any(axis=1)


def assign_objects(
    graph: NavGraph,
    labels: np.ndarray,
    objects_xy: np.ndarray,
    viewpoints_xy: np.ndarray,
    *,
    cut: np.ndarray | None = None,
    blocked: np.ndarray | None = None,
    grid: Grid | None = None,
    lam: float = 1.3,
    radius_m: float = 2.5,
    k: int = 8,
) -> np.ndarray:
    """Region label per object by Eq. 1 (see the module docstring).

    Parameters
    ----------
    graph : NavGraph
        The sparse Voronoi graph.
    labels : ndarray of int, shape (n_nodes,)
        Region per node, -1 for none.
    objects_xy : ndarray, shape (n, 2)
        Object positions, metres.
    viewpoints_xy : ndarray, shape (n, 2)
        Each object's closest viewpoint, metres.
    cut : ndarray of bool, shape (n_edges,), optional
        Door-crossing edges, left out of d_V.
    blocked : ndarray of bool, shape (nx, ny), optional
        Structural cells for the line-of-sight test (omitted: no test); needs ``grid``.
    grid : Grid, optional
        Where ``blocked`` lies.
    lam : float, optional
        The exponent lambda on d_E(O, v).
    radius_m : float, optional
        "Near": within this distance, or the closest node when none is.
    k : int, optional
        At most this many nearest nodes are considered near.

    Returns
    -------
    regions : ndarray of int, shape (n,)
        Region label per object, -1 when the graph has no labelled node.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import NavGraph, assign_objects
    >>> two = NavGraph(np.array([[0.5, 0.5], [3.5, 0.5]]), np.zeros((0, 2), dtype=np.int64), np.zeros(0))
    >>> assign_objects(two, np.array([0, 1]), np.array([[1.0, 0.5]]), np.array([[0.8, 0.5]]))
    array([0])
    """
    if blocked is not None and grid is None:
        raise ValueError("assign_objects: 'blocked' needs the grid it lies on")
    out = np.full(len(objects_xy), -1, dtype=np.int64)
    cand = np.flatnonzero(labels >= 0)
    if cand.size == 0 or len(objects_xy) == 0:
        return out
    tree = cKDTree(graph.xy[cand])
    kk = min(k, cand.size)
    adjacency = graph.csr(None if cut is None else ~cut)

    def near(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, i = tree.query(p, k=kk)
        d, i = np.atleast_1d(d), np.atleast_1d(i)
        if blocked is not None and grid is not None:  # both or neither (checked above)
            seen = line_of_sight(p, graph.xy[cand[i]], blocked, grid)
            if seen.any():
                d, i = d[seen], i[seen]
        within = d <= max(radius_m, d[0])
        return cand[i[within]], d[within]

    for j, (obj, vp) in enumerate(zip(np.asarray(objects_xy, float), np.asarray(viewpoints_xy, float))):
        s_o, d_o = near(obj)
        s_vp, d_vp = near(vp)
        common = np.intersect1d(labels[s_o], labels[s_vp])
        if common.size == 0:
            out[j] = labels[s_o[0]]
        elif common.size == 1:
            out[j] = common[0]
        else:
            dv = csgraph.dijkstra(adjacency, directed=False, indices=s_vp)[:, s_o]  # (|S_vp|, |S_O|)
            cost = dv + d_o[None, :] ** lam + d_vp[:, None]
            out[j] = labels[s_o[np.unravel_index(np.argmin(cost), cost.shape)[1]]]
    return out
