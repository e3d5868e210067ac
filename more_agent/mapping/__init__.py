"""Mapping: voxel map and BEV occupancy, Voronoi graph, sparsification (Alg. 1), door-separated
regions, object-to-region assignment (Eq. 1), frontiers, and ``region_graph`` chaining them on one
BEV grid. Pure functions on arrays, except the stateful ``VoxelMap`` that accumulates frames.
Arrays are ``[ix, iy]`` on a :class:`Grid` (re-exported from :mod:`more_agent.sim.grid`)."""

from more_agent.mapping.assignment import assign_objects, line_of_sight
from more_agent.mapping.config import MappingConfig
from more_agent.mapping.frontiers import frontier_points, visible_unknown_area
from more_agent.mapping.graph import NavGraph
from more_agent.mapping.occupancy import FREE, OCCUPIED, UNKNOWN, VoxelMap, depth_to_points
from more_agent.mapping.pipeline import RegionGraph, region_graph
from more_agent.mapping.regions import (
    DoorKernel,
    door_crossing_edges,
    door_field,
    doorway_mask,
    fit_door_kernel,
    merge_subregions,
    segment_regions,
)
from more_agent.mapping.sparsify import sparsify
from more_agent.mapping.voronoi import voronoi_graph
from more_agent.sim.grid import Grid

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "DoorKernel",
    "Grid",
    "MappingConfig",
    "NavGraph",
    "RegionGraph",
    "VoxelMap",
    "assign_objects",
    "depth_to_points",
    "door_crossing_edges",
    "door_field",
    "doorway_mask",
    "fit_door_kernel",
    "frontier_points",
    "line_of_sight",
    "merge_subregions",
    "region_graph",
    "segment_regions",
    "sparsify",
    "visible_unknown_area",
    "voronoi_graph",
]
