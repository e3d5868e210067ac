"""Alg. 1 invariants: connectivity and kept-pair path lengths preserved, result minimal."""

import numpy as np
import pytest
from scipy.sparse import csgraph

from more_agent.mapping import Grid, NavGraph, sparsify, voronoi_graph
from more_agent.mapping.occupancy import FREE, OCCUPIED


def _random_graph(rng: np.random.Generator, n: int) -> NavGraph:
    """Random tree plus a few chords, with chains (many degree-2 nodes) and random weights."""
    parent = np.array([rng.integers(max(i - 3, 0), i) for i in range(1, n)])
    edges = {(int(p), i) for p, i in zip(parent, range(1, n))}
    for _ in range(n // 10):
        a, b = sorted(rng.choice(n, 2, replace=False).tolist())
        edges.add((a, b))
    e = np.array(sorted(edges))
    return NavGraph(rng.uniform(0, 10, (n, 2)), e, rng.uniform(0.05, 0.6, len(e)))


def _check_invariants(graph: NavGraph, threshold: float) -> None:
    sparse, kept = sparsify(graph, threshold_m=threshold)
    # connectivity: same partition of kept nodes
    comp_old, comp_new = graph.components()[kept], sparse.components()
    assert len(np.unique(comp_old)) == len(np.unique(comp_new))
    assert all(len(set(comp_new[comp_old == c])) == 1 for c in np.unique(comp_old))
    # path lengths between kept nodes
    d_old = csgraph.dijkstra(graph.csr(), directed=False)[np.ix_(kept, kept)]
    d_new = csgraph.dijkstra(sparse.csr(), directed=False)
    np.testing.assert_allclose(d_new, d_old)
    # minimal: no remaining node is removable by Alg. 1
    nbrs: dict[int, list[tuple[int, float]]] = {}
    for (a, b), w in zip(sparse.edges.tolist(), sparse.weights.tolist()):
        nbrs.setdefault(a, []).append((b, w))
        nbrs.setdefault(b, []).append((a, w))
    adjacent = {tuple(sorted(e)) for e in sparse.edges.tolist()}
    for lst in nbrs.values():
        if len(lst) == 2:
            (u, w1), (v, w2) = lst
            assert w1 + w2 >= threshold or tuple(sorted((u, v))) in adjacent
    # only degree-2 nodes are removed (removal never changes another node's degree)
    removed = np.setdiff1d(np.arange(graph.n_nodes), kept)
    assert (graph.degrees()[removed] == 2).all()
    assert (np.diff(kept) > 0).all()


@pytest.mark.parametrize("seed", range(8))
def test_invariants_on_random_graphs(seed: int) -> None:
    rng = np.random.default_rng(seed)
    _check_invariants(_random_graph(rng, 300), threshold=float(rng.uniform(0.3, 2.0)))


def test_invariants_on_a_voronoi_graph_and_strong_reduction() -> None:
    occ = np.full((120, 160), OCCUPIED, dtype=np.int8)
    occ[5:115, 5:155] = FREE
    occ[40:80, 60:100] = OCCUPIED  # a pillar makes a cycle
    dense = voronoi_graph(occ, Grid(resolution_m=0.075))
    _check_invariants(dense, threshold=1.0)
    sparse, _ = sparsify(dense, threshold_m=1.0)
    assert sparse.n_nodes < dense.n_nodes / 5


def test_cycle_of_degree_two_nodes_stays_simple() -> None:
    # a triangle: removing any node would need an edge that already exists
    g = NavGraph(np.zeros((3, 2)), np.array([[0, 1], [1, 2], [0, 2]]), np.full(3, 0.1))
    sparse, kept = sparsify(g, threshold_m=5.0)
    assert sparse.n_nodes == 3 and sparse.n_edges == 3


def test_chain_collapses_to_endpoints_when_threshold_is_large() -> None:
    n = 50
    g = NavGraph(np.stack([np.arange(n) * 0.1, np.zeros(n)], 1), np.stack([np.arange(n - 1), np.arange(1, n)], 1),
                 np.full(n - 1, 0.1))
    sparse, kept = sparsify(g, threshold_m=100.0)
    assert kept.tolist() == [0, n - 1]
    assert sparse.weights.tolist() == pytest.approx([0.1 * (n - 1)])
