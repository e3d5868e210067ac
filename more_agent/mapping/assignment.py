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


def line_of_sight(
    p: np.ndarray, targets: np.ndarray, blocked: np.ndarray, *, origin_xy: np.ndarray, resolution_m: float
) -> np.ndarray:
    """Which targets (k, 2) see point p without crossing a ``blocked`` grid cell; a blocked run at
    p itself (the object stands in a wall, or is a door) is skipped."""
    res = resolution_m
    length = np.linalg.norm(targets - p, axis=1).max(initial=0.0)
    n = max(2, int(np.ceil(length / (res / 2))) + 1)
    s = np.linspace(0.0, 1.0, n)
    pts = p + s[None, :, None] * (targets - p)[:, None, :]
    cells = np.floor((pts - origin_xy) / res).astype(int)
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
    resolution_m: float = 0.075,
    origin_xy: tuple[float, float] = (0.0, 0.0),
    lam: float = 1.3,
    radius_m: float = 2.5,
    k: int = 8,
) -> np.ndarray:
    """Region label per object (n,), -1 when the graph has no labelled node.

    ``labels``: region per node (-1 = none); ``viewpoints_xy`` (n, 2): each object's closest
    viewpoint; ``cut``: door-crossing edge mask excluded from d_V; ``blocked``: BEV grid of
    structural cells for the line-of-sight test (omitted: no test).
    """
    out = np.full(len(objects_xy), -1, dtype=np.int64)
    cand = np.flatnonzero(labels >= 0)
    if cand.size == 0 or len(objects_xy) == 0:
        return out
    tree = cKDTree(graph.xy[cand])
    kk = min(k, cand.size)
    origin = np.asarray(origin_xy, dtype=float)
    adjacency = graph.csr(None if cut is None else ~cut)

    def near(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, i = tree.query(p, k=kk)
        d, i = np.atleast_1d(d), np.atleast_1d(i)
        if blocked is not None:
            seen = line_of_sight(p, graph.xy[cand[i]], blocked, origin_xy=origin, resolution_m=resolution_m)
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
