"""``region_graph``: the whole graph pipeline on one BEV occupancy grid, as one pure function.

BEV -> Voronoi graph -> sparsification (Alg. 1) -> door kernels and door-crossing edges ->
regions (+ sub-region merging) -> Eq. 1 object assignment -> frontiers, each stage timed.
``SceneGraphBuilder.build`` adds stable region ids, the reduction to the robot's component and
the data model on top; ``benchmarks/mapping.py`` reports the stage timings.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from more_agent.mapping.assignment import assign_objects
from more_agent.mapping.config import MappingConfig
from more_agent.mapping.frontiers import frontier_points
from more_agent.mapping.graph import NavGraph
from more_agent.mapping.regions import (
    door_crossing_edges,
    doorway_mask,
    fit_door_kernel,
    merge_subregions,
    segment_regions,
)
from more_agent.mapping.sparsify import sparsify
from more_agent.mapping.voronoi import voronoi_graph
from more_agent.sim.grid import Grid

STAGES = ("voronoi_s", "sparsify_s", "regions_s", "assignment_s", "frontiers_s")
"""Keys of ``RegionGraph.timings_s``, in pipeline order."""


@dataclass(frozen=True)
class RegionGraph:
    """What the graph pipeline makes of one occupancy grid."""

    dense: NavGraph
    """Voronoi graph before sparsification."""
    graph: NavGraph
    """Sparse Voronoi graph (Alg. 1)."""
    cut: np.ndarray
    """(m,) True for the edges of ``graph`` that cross a door kernel."""
    labels: np.ndarray
    """(n,) region label per node of ``graph`` (0..k-1), -1 for doorway-only nodes."""
    assigned: np.ndarray
    """(objects,) region label per object (Eq. 1), -1 when no node is labelled."""
    frontier_xy: np.ndarray
    """(f, 2) frontier points, metres."""
    timings_s: dict[str, float]
    """Seconds per stage, keyed by ``STAGES``."""


def region_graph(
    occupancy: np.ndarray,
    grid: Grid,
    *,
    door_points: Sequence[np.ndarray],
    objects_xy: np.ndarray,
    viewpoints_xy: np.ndarray,
    blocked: np.ndarray | None = None,
    config: MappingConfig | None = None,
) -> RegionGraph:
    """Run the graph pipeline on a BEV grid.

    Parameters
    ----------
    occupancy : ndarray of int, shape (nx, ny)
        UNKNOWN / FREE / OCCUPIED per cell, ``[ix, iy]``.
    grid : Grid
        Where ``occupancy`` lies (its resolution, not ``config.resolution_m``, is used here).
    door_points : sequence of ndarray, each (k, 2)
        The observed points of each door, one kernel each.
    objects_xy, viewpoints_xy : ndarray, shape (n, 2)
        Objects and their closest viewpoints, for Eq. 1.
    blocked : ndarray of bool, shape (nx, ny), optional
        Cells that break the line of sight in Eq. 1 (None: no test).
    config : MappingConfig, optional

    Returns
    -------
    RegionGraph

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import FREE, OCCUPIED, UNKNOWN, Grid, region_graph
    >>> occ = np.full((24, 14), OCCUPIED, dtype=np.int8)
    >>> occ[2:22, 2:12] = FREE     # one 2 m x 1 m room ...
    >>> occ[22, 4:10] = UNKNOWN    # ... with an unseen gap in its east wall
    >>> obj = np.array([[1.0, 0.7]])
    >>> rg = region_graph(occ, Grid(resolution_m=0.1), door_points=[], objects_xy=obj, viewpoints_xy=obj)
    >>> rg.labels, rg.assigned, rg.frontier_xy
    (array([0, 0, 0]), array([0]), array([[2.15, 0.65]]))
    """
    cfg = config or MappingConfig()
    marks = [time.perf_counter()]
    dense = voronoi_graph(occupancy, grid, inflation_m=cfg.inflation_m, min_separation_m=cfg.gvd_min_separation_m)
    marks.append(time.perf_counter())
    graph, _ = sparsify(dense, threshold_m=cfg.sparsify_threshold_m)
    marks.append(time.perf_counter())
    doors = [fit_door_kernel(p, min_sigma_m=cfg.door_min_sigma_m) for p in door_points]
    cut = door_crossing_edges(graph, doors, threshold_m=cfg.door_cut_threshold_m)
    labels = segment_regions(graph, cut, doors, doorway_value=cfg.door_mask_value)
    if cfg.merge_subregions and graph.n_nodes:
        doorway = doorway_mask(occupancy.shape, grid, doors, value=cfg.door_mask_value)
        labels = merge_subregions(labels, grid.cell_of(graph.xy), occupancy, doorway)
    marks.append(time.perf_counter())
    assigned = assign_objects(
        graph,
        labels,
        objects_xy,
        viewpoints_xy,
        cut=cut,
        blocked=blocked,
        grid=grid,
        lam=cfg.assignment_lambda,
        radius_m=cfg.assignment_radius_m,
        k=cfg.assignment_k,
    )
    marks.append(time.perf_counter())
    frontier_xy, _ = frontier_points(occupancy, grid, min_length_m=cfg.min_frontier_m, max_length_m=cfg.max_frontier_m)
    marks.append(time.perf_counter())
    return RegionGraph(
        dense=dense,
        graph=graph,
        cut=cut,
        labels=labels,
        assigned=assigned,
        frontier_xy=frontier_xy,
        timings_s=dict(zip(STAGES, np.diff(marks).tolist())),
    )
