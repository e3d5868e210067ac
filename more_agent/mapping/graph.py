"""``NavGraph``: an undirected metric graph whose nodes carry world coordinates (x, y) in metres."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph


@dataclass(frozen=True)
class NavGraph:
    """Undirected graph on plain arrays: ``xy`` (n, 2) node positions in metres, ``edges`` (m, 2)
    node index pairs with i < j, ``weights`` (m,) edge lengths in metres."""

    xy: np.ndarray
    edges: np.ndarray
    weights: np.ndarray

    @property
    def n_nodes(self) -> int:
        return int(self.xy.shape[0])

    @property
    def n_edges(self) -> int:
        return int(self.edges.shape[0])

    @staticmethod
    def empty() -> NavGraph:
        return NavGraph(np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64), np.zeros(0))

    def csr(self, edge_mask: np.ndarray | None = None) -> sparse.csr_matrix:
        """Symmetric sparse adjacency (weights as entries), optionally only the edges in ``edge_mask``."""
        e, w = (self.edges, self.weights) if edge_mask is None else (self.edges[edge_mask], self.weights[edge_mask])
        rows = np.concatenate([e[:, 0], e[:, 1]])
        cols = np.concatenate([e[:, 1], e[:, 0]])
        return sparse.csr_matrix((np.concatenate([w, w]), (rows, cols)), shape=(self.n_nodes, self.n_nodes))

    def components(self, edge_mask: np.ndarray | None = None) -> np.ndarray:
        """Connected-component label per node (0..k-1)."""
        if self.n_nodes == 0:
            return np.zeros(0, dtype=np.int64)
        return csgraph.connected_components(self.csr(edge_mask), directed=False)[1].astype(np.int64)

    def degrees(self) -> np.ndarray:
        return np.bincount(self.edges.ravel(), minlength=self.n_nodes)
