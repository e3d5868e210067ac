"""Voronoi graph sparsification, Alg. 1 of the MORE paper: one pass over the degree-2 nodes."""

from __future__ import annotations

import numba
import numpy as np

from more_agent.mapping.graph import NavGraph


@numba.njit(cache=True)
def _sparsify(nbr: np.ndarray, wt: np.ndarray, deg: np.ndarray, threshold: float) -> np.ndarray:
    """In-place Alg. 1 on fixed-width adjacency rows; returns the mask of kept nodes."""
    n = nbr.shape[0]
    keep = np.ones(n, dtype=np.bool_)
    for x in range(n):
        if deg[x] != 2:
            continue
        u, v = nbr[x, 0], nbr[x, 1]
        w = wt[x, 0] + wt[x, 1]
        if u == v or w >= threshold:
            continue
        adjacent = False
        for k in range(deg[u]):
            if nbr[u, k] == v:
                adjacent = True
        if adjacent:  # bridging would merge two edges and lower degrees; keep x (graph stays simple)
            continue
        for a, b in ((u, v), (v, u)):
            for k in range(deg[a]):
                if nbr[a, k] == x:
                    nbr[a, k] = b
                    wt[a, k] = w
        keep[x] = False
        deg[x] = 0
    return keep


def sparsify(graph: NavGraph, *, threshold_m: float) -> tuple[NavGraph, np.ndarray]:
    """Remove every degree-2 node whose two edges sum below ``threshold_m`` and bridge its
    neighbours with one edge of the summed weight (Alg. 1), in O(|V|).

    Removing a node never changes another node's degree, and edge weights only grow, so one pass
    leaves a minimal graph: no remaining degree-2 node has two non-adjacent neighbours and an edge
    sum below the threshold. A node whose neighbours are already adjacent is kept, so the graph
    stays simple; shortest-path lengths and connectivity between kept nodes are unchanged.

    Parameters
    ----------
    graph : NavGraph
        The dense graph.
    threshold_m : float
        A degree-2 node goes when its two edges sum below this.

    Returns
    -------
    sparse : NavGraph
        The kept nodes and the bridged edges.
    kept : ndarray of int, shape (n_kept,)
        Index in ``graph`` of each node of ``sparse``.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import NavGraph, sparsify
    >>> xy = np.array([[0.0, 0.0], [0.1, 0.0], [0.2, 0.0], [0.3, 0.0]])
    >>> path = NavGraph(xy, np.array([[0, 1], [1, 2], [2, 3]]), np.full(3, 0.1))
    >>> sparse, kept = sparsify(path, threshold_m=0.5)
    >>> kept, sparse.edges, sparse.weights.round(3)
    (array([0, 3]), array([[0, 1]]), array([0.3]))
    """
    n = graph.n_nodes
    if n == 0:
        return graph, np.zeros(0, dtype=np.int64)
    deg = graph.degrees().astype(np.int64)
    width = max(int(deg.max()), 1)
    nbr = np.full((n, width), -1, dtype=np.int64)
    wt = np.zeros((n, width))
    # fill adjacency rows: half-edges sorted by source, slot = rank within the source
    src = np.concatenate([graph.edges[:, 0], graph.edges[:, 1]])
    dst = np.concatenate([graph.edges[:, 1], graph.edges[:, 0]])
    w = np.concatenate([graph.weights, graph.weights])
    order = np.argsort(src, kind="stable")
    src, dst, w = src[order], dst[order], w[order]
    slot = np.arange(len(src)) - np.searchsorted(src, src)
    nbr[src, slot] = dst
    wt[src, slot] = w
    keep = _sparsify(nbr, wt, deg.copy(), float(threshold_m))
    kept = np.flatnonzero(keep)
    rows = np.repeat(kept, width)
    cols = nbr[kept].ravel()
    ws = wt[kept].ravel()
    ok = cols > rows  # each edge once; -1 slots fail this test
    new_index = np.cumsum(keep) - 1
    edges = np.stack([new_index[rows[ok]], new_index[cols[ok]]], axis=1)
    return NavGraph(graph.xy[keep], edges, ws[ok]), kept
