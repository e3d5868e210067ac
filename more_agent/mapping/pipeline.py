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
    *,
    door_points: Sequence[np.ndarray],
    objects_xy: np.ndarray,
    viewpoints_xy: np.ndarray,
    blocked: np.ndarray | None = None,
    origin_xy: tuple[float, float] = (0.0, 0.0),
    config: MappingConfig | None = None,
) -> RegionGraph:
    """Run the graph pipeline on a BEV grid (``grid[ix, iy]``, see ``voronoi``).

    ``door_points``: the observed (k, 2) xy points of each door, one kernel each;
    ``objects_xy`` / ``viewpoints_xy`` (n, 2): objects and their closest viewpoints for Eq. 1;
    ``blocked``: grid of cells that break the line of sight in Eq. 1 (None: no test).
    """
    cfg = config or MappingConfig()
    res = cfg.resolution_m
    marks = [time.perf_counter()]
    dense = voronoi_graph(occupancy, resolution_m=res, origin_xy=origin_xy, inflation_m=cfg.inflation_m,
                          min_separation_m=cfg.gvd_min_separation_m)
    marks.append(time.perf_counter())
    graph, _ = sparsify(dense, threshold_m=cfg.sparsify_threshold_m)
    marks.append(time.perf_counter())
    doors = [fit_door_kernel(p, min_sigma_m=cfg.door_min_sigma_m) for p in door_points]
    cut = door_crossing_edges(graph, doors, threshold_m=cfg.door_cut_threshold_m)
    labels = segment_regions(graph, cut, doors, doorway_value=cfg.door_mask_value)
    if cfg.merge_subregions and graph.n_nodes:
        cells = np.floor((graph.xy - origin_xy) / res).astype(int)
        doorway = doorway_mask(occupancy.shape, doors, resolution_m=res, origin_xy=origin_xy,
                               value=cfg.door_mask_value)
        labels = merge_subregions(labels, cells, occupancy, doorway)
    marks.append(time.perf_counter())
    assigned = assign_objects(
        graph, labels, objects_xy, viewpoints_xy, cut=cut, blocked=blocked, resolution_m=res, origin_xy=origin_xy,
        lam=cfg.assignment_lambda, radius_m=cfg.assignment_radius_m, k=cfg.assignment_k,
    )
    marks.append(time.perf_counter())
    frontier_xy, _ = frontier_points(occupancy, resolution_m=res, origin_xy=origin_xy, min_length_m=cfg.min_frontier_m)
    marks.append(time.perf_counter())
    return RegionGraph(dense=dense, graph=graph, cut=cut, labels=labels, assigned=assigned, frontier_xy=frontier_xy,
                       timings_s=dict(zip(STAGES, np.diff(marks).tolist())))
