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
from numba import njit
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
    return lines_of_sight(np.asarray(p, dtype=float)[None], np.asarray(targets, dtype=float)[None], blocked, grid)[0]


def lines_of_sight(points: np.ndarray, targets: np.ndarray, blocked: np.ndarray, grid: Grid) -> np.ndarray:
    """:func:`line_of_sight` of many points at once: ``seen[j, t]`` for point j and its target t.

    Parameters
    ----------
    points : ndarray, shape (m, 2)
    targets : ndarray, shape (m, k, 2)
        The targets of each point.
    blocked, grid
        As for :func:`line_of_sight`.

    Returns
    -------
    seen : ndarray of bool, shape (m, k)
    """
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    targets = np.ascontiguousarray(targets, dtype=np.float64).reshape(len(points), -1, 2)
    seen = np.empty(targets.shape[:2], dtype=np.bool_)
    _sight(
        points,
        targets,
        np.ascontiguousarray(blocked, dtype=np.bool_),
        float(grid.origin_xy[0]),
        float(grid.origin_xy[1]),
        float(grid.resolution_m),
        seen,
    )
    return seen


@njit(cache=True)
def _sight(points, targets, blocked, x0, y0, res, seen):  # pragma: no cover - compiled
    """Each point's segments to its targets, sampled every half cell (n samples, the same for all
    targets of a point, from the farthest; ``i / (n - 1)`` as ``np.linspace`` spaces them); a target is
    seen unless a blocked cell follows an unblocked sample. ``Grid.cell_of`` is repeated inline."""
    nx, ny = blocked.shape
    for j in range(points.shape[0]):
        px, py = points[j, 0], points[j, 1]
        length = 0.0
        for t in range(targets.shape[1]):
            dx, dy = targets[j, t, 0] - px, targets[j, t, 1] - py
            length = max(length, np.sqrt(dx * dx + dy * dy))
        n = max(2, int(np.ceil(length / (res / 2))) + 1)
        step = 1.0 / (n - 1)
        for t in range(targets.shape[1]):
            dx, dy = targets[j, t, 0] - px, targets[j, t, 1] - py
            started, ok = False, True
            for i in range(n):
                s = 1.0 if i == n - 1 else i * step
                cx = int(np.floor((px + s * dx - x0) / res))
                cy = int(np.floor((py + s * dy - y0) / res))
                if 0 <= cx < nx and 0 <= cy < ny and blocked[cx, cy]:
                    if started:
                        ok = False
                        break
                else:
                    started = True
            seen[j, t] = ok


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
    objects_xy, viewpoints_xy = np.asarray(objects_xy, float), np.asarray(viewpoints_xy, float)
    nodes_o, d_o, near_o = _near_nodes(objects_xy, tree, cand, kk, graph, blocked, grid, radius_m)
    nodes_vp, d_vp, near_vp = _near_nodes(viewpoints_xy, tree, cand, kk, graph, blocked, grid, radius_m)
    lab_o, lab_vp = labels[nodes_o], labels[nodes_vp]  # every candidate node has a region (>= 0)
    shared = (lab_o[:, :, None] == lab_vp[:, None, :]) & near_o[:, :, None] & near_vp[:, None, :]
    common = np.sort(np.where(shared.any(axis=2), lab_o, -1), axis=1)  # the regions S_O and S_vp share, -1 pads
    distinct = np.ones(common.shape, dtype=bool)
    distinct[:, 1:] = common[:, 1:] != common[:, :-1]  # sorted: a region's first entry in its row
    n_common = (distinct & (common >= 0)).sum(axis=1)
    rows = np.arange(len(objects_xy))
    out[:] = np.where(n_common == 0, lab_o[rows, np.argmax(near_o, axis=1)], common[:, -1])  # none: the closest
    for j in np.flatnonzero(n_common > 1).tolist():
        s_o, s_vp = nodes_o[j, near_o[j]], nodes_vp[j, near_vp[j]]
        dv = csgraph.dijkstra(adjacency, directed=False, indices=s_vp)[:, s_o]  # (|S_vp|, |S_O|)
        cost = dv + d_o[j, near_o[j]][None, :] ** lam + d_vp[j, near_vp[j]][:, None]
        out[j] = labels[s_o[np.unravel_index(np.argmin(cost), cost.shape)[1]]]
    return out


def _near_nodes(
    points: np.ndarray,
    tree: cKDTree,
    cand: np.ndarray,
    kk: int,
    graph: NavGraph,
    blocked: np.ndarray | None,
    grid: Grid | None,
    radius_m: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """S_p of Eq. 1 for each point: its ``kk`` nearest candidate nodes, those it sees if it sees any, within
    ``radius_m`` (or the closest); as (node indices, distances, whether near), each (n, kk), nearest first."""
    d, i = tree.query(points, k=kk)
    d, i = d.reshape(len(points), kk), i.reshape(len(points), kk)
    keep = np.ones(d.shape, dtype=bool)
    if blocked is not None and grid is not None:  # both or neither (checked by the caller)
        seen = lines_of_sight(points, graph.xy[cand[i]], blocked, grid)
        keep = seen | ~seen.any(axis=1, keepdims=True)
    first = np.take_along_axis(d, np.argmax(keep, axis=1)[:, None], axis=1)
    keep &= d <= np.maximum(radius_m, first)
    return cand[i], d, keep
