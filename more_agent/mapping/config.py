"""``MappingConfig``: every knob of the mapping and scene-graph pipeline, in physical units."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class MappingConfig(BaseModel):
    """Parameters of the voxel map, Voronoi graph, regions, object assignment and frontiers.
    Defaults follow the MORE paper where it gives a value (0.075 m, 5 m range, lambda 1.3)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    resolution_m: float = Field(0.075, gt=0, description="Voxel and BEV cell size in metres (paper: 0.075).")
    max_range_m: float = Field(5.0, gt=0, description="Sensor range; rays without a hit are cleared up to here.")
    z_min_m: float = Field(-1.0, description="Lowest mapped height (negative for pools or sunken areas).")
    z_max_m: float = Field(3.0, description="Highest mapped height; points above are dropped.")
    bev_max_height_m: float = Field(
        2.0, description="Voxels centred above this height (door lintels, ceilings) are ignored by the BEV."
    )
    carve_stride_px: int = Field(
        2, ge=1, description="Free-space clearing casts one ray per this many pixels in u and v."
    )
    initial_extent_m: float = Field(20.0, gt=0, description="Side of the first voxel grid; it grows as needed.")
    inflation_m: float = Field(
        0.15, ge=0, description="ESDF inflation: free cells closer than this to a non-free cell are excluded."
    )
    gvd_min_separation_m: float = Field(
        0.3, gt=0, description="Neighbouring cells straddle the GVD when their nearest obstacles are farther apart."
    )
    sparsify_threshold_m: float = Field(
        1.0, gt=0, description="Alg. 1 threshold c on the sum of a degree-2 node's two edges."
    )
    door_min_sigma_m: float = Field(0.15, gt=0, description="Lower bound on a door kernel's standard deviations.")
    door_cut_threshold_m: float = Field(
        0.15,
        gt=0,
        description="An edge whose line integral of the door kernels exceeds this is cut (metres x unit peak).",
    )
    door_mask_value: float = Field(
        0.05, gt=0, lt=1, description="Cells where a door kernel exceeds this count as doorway (not merged across)."
    )
    merge_subregions: bool = Field(
        True, description="Merge graph components that share one door-free connected patch of free space (paper S.5)."
    )
    assignment_lambda: float = Field(1.3, gt=0, description="Exponent lambda on the object-node distance in Eq. 1.")
    assignment_radius_m: float = Field(
        2.5, gt=0, description="Nodes within this radius of an object / viewpoint form S_O / S_vp."
    )
    assignment_k: int = Field(8, ge=1, description="At most this many nearest nodes per set in Eq. 1.")
    relation_tol_m: float = Field(
        0.08, ge=0, description="Vertical gap tolerated between a supported object and its support."
    )
    inside_fraction: float = Field(
        0.7, gt=0, le=1, description="Share of an object's box inside another's box for 'inside'."
    )
    min_frontier_m: float = Field(
        0.3, ge=0, description="Frontier clusters shorter than this (cells x resolution) are dropped."
    )
    max_frontier_m: float = Field(
        5.0,
        gt=0,
        description="Frontier clusters longer than this are cut into pieces of at most this extent, one point each "
        "(the sensor range: what one look from a point shows).",
    )
    viewpoint_spacing_m: float = Field(
        0.25, gt=0, description="Viewpoints closer than this are stored once per object."
    )
