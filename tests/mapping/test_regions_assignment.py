"""Door kernels cut regions; Eq. 1 assignment respects walls and windows."""

import numpy as np
import pytest

from more_agent.mapping import (
    Grid,
    MappingConfig,
    NavGraph,
    assign_objects,
    door_crossing_edges,
    doorway_mask,
    fit_door_kernel,
    merge_subregions,
    region_graph,
    segment_regions,
    sparsify,
    voronoi_graph,
)
from more_agent.mapping.occupancy import FREE, OCCUPIED
from more_agent.mapping.pipeline import STAGES

RES = 0.075
GRID = Grid(resolution_m=RES)


def _two_rooms() -> np.ndarray:
    """Rooms x in cells [2, 50) and [52, 100), wall rows 50..51 with a 12-cell door at y 24..36."""
    occ = np.full((102, 62), OCCUPIED, dtype=np.int8)
    occ[2:100, 2:60] = FREE
    occ[50:52, :] = OCCUPIED
    occ[50:52, 24:36] = FREE
    return occ


def _door_points() -> np.ndarray:
    y = np.linspace(24, 36, 13) * RES
    return np.stack([np.full_like(y, 51 * RES), y], 1)


def _regions(occ: np.ndarray, doors) -> tuple:
    g, _ = sparsify(voronoi_graph(occ, GRID), threshold_m=1.0)
    cut = door_crossing_edges(g, doors, threshold_m=0.15)
    return g, cut, segment_regions(g, cut, doors)


def test_fit_door_kernel_orientation_and_size() -> None:
    k = fit_door_kernel(_door_points(), min_sigma_m=0.15)
    assert abs(np.cos(k.angle_rad)) < 1e-6  # width axis along y
    assert abs(k.sigma_along_m - 0.45) < 1e-9
    assert k.sigma_across_m == 0.15
    np.testing.assert_allclose(k.center_xy, (51 * RES, 30 * RES))


def test_observed_door_separates_two_rooms_and_unobserved_does_not() -> None:
    occ = _two_rooms()
    g, cut, labels = _regions(occ, [fit_door_kernel(_door_points())])
    assert cut.sum() >= 1
    assert labels.max() == 1
    room = g.xy[:, 0] < 51 * RES
    assert len(set(labels[room & (labels >= 0)])) == 1 and len(set(labels[~room & (labels >= 0)])) == 1
    assert set(labels[room & (labels >= 0)]) != set(labels[~room & (labels >= 0)])
    g2, cut2, labels2 = _regions(occ, [])
    assert not cut2.any() and labels2.max() == 0


def test_merge_subregions_joins_components_of_one_free_patch_only() -> None:
    occ = _two_rooms()
    door = fit_door_kernel(_door_points())
    g, cut, labels = _regions(occ, [door])
    # split room A's component artificially by relabelling half of it
    room_a = labels[np.argmin(g.xy[:, 0])]
    split = labels.copy()
    split[(labels == room_a) & (g.xy[:, 1] > 30 * RES)] = labels.max() + 1
    merged = merge_subregions(split, GRID.cell_of(g.xy), occ, doorway_mask(occ.shape, GRID, [door]))
    assert merged.max() == 1
    np.testing.assert_array_equal(merged >= 0, labels >= 0)


def test_object_goes_to_its_room_not_the_one_behind_the_wall() -> None:
    occ = _two_rooms()
    occ[44:49, 5:12] = OCCUPIED  # cabinet against the wall in room A
    g, cut, labels = _regions(occ, [fit_door_kernel(_door_points())])
    obj = np.array([[46.5 * RES, 8.5 * RES]])
    vp = np.array([[25 * RES, 30 * RES]])  # robot in room A
    label_a = labels[np.argmin(np.linalg.norm(g.xy - vp, axis=1))]
    got = assign_objects(g, labels, obj, vp, cut=cut, blocked=occ == OCCUPIED, grid=GRID)
    assert got[0] == label_a
    # even seen from room B, the wall keeps nodes of B out of S_O
    vp_b = np.array([[75 * RES, 30 * RES]])
    got_b = assign_objects(g, labels, obj, vp_b, cut=cut, blocked=occ == OCCUPIED, grid=GRID)
    assert got_b[0] == label_a
    with pytest.raises(ValueError, match="grid"):  # a blocked mask means nothing without its placement
        assign_objects(g, labels, obj, vp, cut=cut, blocked=occ == OCCUPIED)


def test_an_object_sharing_no_region_with_its_viewpoint_goes_to_the_nearest_node_it_sees() -> None:
    """With no region common to S_O and S_vp, the object goes to the region of its closest node in S_O: the
    closest it sees, not the closest of all, which lies behind the wall."""
    blocked = np.zeros((8, 8), dtype=bool)
    blocked[4, :] = True  # a wall at 2.0 <= x < 2.5
    xy = np.array([[2.75, 1.25], [0.5, 1.25], [0.75, 3.75]])  # behind the wall (region 1), beside (0), far (2)
    g = NavGraph(xy, np.zeros((0, 2), dtype=np.int64), np.zeros(0))
    obj, vp = np.array([[1.75, 1.25]]), np.array([[2.75, 2.25]])  # the viewpoint sees only the node behind the wall
    got = assign_objects(g, np.array([1, 0, 2]), obj, vp, blocked=blocked, grid=Grid(resolution_m=0.5), radius_m=1.3)
    assert got.tolist() == [0]


def test_object_seen_through_a_window_goes_to_the_indoor_region() -> None:
    occ = np.full((102, 62), OCCUPIED, dtype=np.int8)
    occ[2:50, 2:60] = FREE  # house
    occ[52:100, 2:60] = FREE  # garden, separated by a wall whose window is not passable
    occ[44:48, 28:34] = OCCUPIED  # cabinet behind the window
    g, cut, labels = _regions(occ, [])
    assert labels.max() == 1
    obj = np.array([[46 * RES, 31 * RES]])
    vp = np.array([[56 * RES, 31 * RES]])  # garden viewpoint, 0.7 m from the wall
    window_wall = np.zeros_like(occ, dtype=bool)
    window_wall[50:52, :] = True
    got = assign_objects(g, labels, obj, vp, cut=cut, blocked=window_wall, grid=GRID)
    indoor = labels[np.argmin(np.linalg.norm(g.xy - obj, axis=1) + 100 * (g.xy[:, 0] > 50 * RES))]
    assert got[0] == indoor


def test_region_graph_chains_the_stages_and_times_each() -> None:
    occ = _two_rooms()
    obj = np.array([[25 * RES, 10 * RES], [75 * RES, 50 * RES]])
    rg = region_graph(occ, GRID, door_points=[_door_points()], objects_xy=obj, viewpoints_xy=obj,
                      blocked=occ == OCCUPIED, config=MappingConfig(resolution_m=RES))
    g, cut, labels = _regions(occ, [fit_door_kernel(_door_points())])
    np.testing.assert_array_equal(rg.graph.xy, g.xy)
    np.testing.assert_array_equal(rg.cut, cut)
    assert rg.dense.n_nodes > rg.graph.n_nodes
    assert rg.labels.max() == 1
    assert rg.assigned.tolist() == [labels[np.argmin(g.xy[:, 0])], labels[np.argmax(g.xy[:, 0])]]
    assert len(rg.frontier_xy) == 0  # everything outside the rooms is occupied, nothing unknown
    assert tuple(rg.timings_s) == STAGES and all(t >= 0 for t in rg.timings_s.values())
