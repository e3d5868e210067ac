"""Frontier clusters and the voxel map -> BEV update."""

import numpy as np
import pytest

from more_agent.mapping import Grid, VoxelMap, depth_to_points, frontier_points, visible_unknown_area
from more_agent.mapping.occupancy import FREE, OCCUPIED, UNKNOWN, zeroed
from tests.scene_graph.boxworld import CID, Box, camera_pose, intrinsics, render


def test_frontier_points_one_per_long_cluster() -> None:
    occ = np.full((60, 60), OCCUPIED, dtype=np.int8)
    occ[5:55, 5:30] = FREE
    occ[20:40, 30:55] = UNKNOWN  # opening of 20 cells onto unknown space
    occ[5:7, 30] = UNKNOWN  # 2-cell crack: too short
    pts, lengths = frontier_points(occ, Grid(origin_xy=(1.0, 2.0), resolution_m=0.1), min_length_m=0.5)
    assert len(pts) == 1
    assert lengths[0] >= 2.0
    assert 1.0 + 20 * 0.1 <= pts[0, 0] <= 1.0 + 40 * 0.1 and abs(pts[0, 1] - (2.0 + 29.5 * 0.1)) < 1e-9


def test_a_frontier_longer_than_the_sensor_range_is_cut_into_pieces_each_with_a_point() -> None:
    occ = np.full((142, 40), OCCUPIED, dtype=np.int8)
    occ[1:141, 1:20] = FREE
    occ[1:141, 20:] = UNKNOWN  # a 14 m straight edge of unseen lawn along y = 1.95 m
    occ[5:9, 5] = UNKNOWN  # and a pocket: under 1.5 m of frontier, shorter than a piece
    grid = Grid(resolution_m=0.1)
    whole, whole_lengths = frontier_points(occ, grid, min_length_m=0.3)
    pts, lengths = frontier_points(occ, grid, min_length_m=0.3, max_length_m=5.0)
    assert len(whole) == 2 and len(pts) == 4  # the edge: one point at its middle, or one per 5 m tile
    edge = pts[np.abs(pts[:, 1] - 1.95) < 1e-9]
    assert sorted((edge[:, 0] // 5.0).tolist()) == [0.0, 1.0, 2.0] and all(lengths <= 5.0 + 1e-9)
    assert abs(lengths.sum() - whole_lengths.sum()) < 1e-9  # the pieces partition the clusters
    grown = np.pad(occ, ((7, 0), (0, 0)), constant_values=OCCUPIED)  # the map grew 0.7 m west: its corner moved
    moved, _ = frontier_points(grown, Grid(origin_xy=(-0.7, 0.0), resolution_m=0.1), min_length_m=0.3, max_length_m=5.0)
    assert np.allclose(np.sort(moved, axis=0), np.sort(pts, axis=0))  # the pieces lie where they lay


def test_visible_unknown_area_is_the_unseen_floor_in_range_that_no_wall_hides() -> None:
    grid = Grid(resolution_m=0.1)
    unseen = np.full((100, 100), UNKNOWN, dtype=np.int8)
    (alone,) = visible_unknown_area(unseen, grid, np.array([[5.0, 5.0]]), range_m=2.0)
    assert abs(alone - np.pi * 2.0**2) < 0.5  # the whole disc in range
    half = unseen.copy()
    half[:50, :] = FREE  # the west half is seen
    west, edge, east = visible_unknown_area(half, grid, np.array([[3.0, 5.0], [5.0, 5.0], [7.0, 5.0]]), range_m=2.0)
    assert west == 0.0 and abs(edge - alone / 2) < 0.5 and abs(east - alone) < 0.5
    walled = half.copy()
    walled[50, :] = OCCUPIED  # a wall along the seen half's edge hides the rest
    assert visible_unknown_area(walled, grid, np.array([[4.5, 5.0]]), range_m=2.0)[0] == 0.0
    assert visible_unknown_area(half, grid, np.zeros((0, 2)), range_m=2.0).shape == (0,)


def _vmap() -> VoxelMap:
    return VoxelMap(free_class_ids=[CID["floor"], CID["lawn"]], initial_extent_m=12.0, carve_stride_px=1)


def test_depth_to_points_inverts_projection() -> None:
    K = intrinsics(32)
    T = camera_pose(1.0, 2.0, 0.3)
    boxes = [Box((-10, -10, -0.1), (10, 10, 0.0), "floor")]
    depth, _, _ = render(boxes, K, T, 32)
    pts, idx = depth_to_points(depth, K, T)
    assert len(pts) == np.isfinite(depth).sum() and len(idx) == len(pts)
    np.testing.assert_allclose(pts[:, 2], 0.0, atol=1e-4)


def test_floor_is_free_objects_occupied_and_moved_objects_are_cleared() -> None:
    K = intrinsics(96)
    floor = Box((-10, -10, -0.05), (10, 10, 0.0), "floor")
    crate = Box((2.0, -0.3, 0.0), (2.5, 0.3, 0.6), "cabinet", 7)
    vmap = _vmap()
    poses = [camera_pose(0, 0, yaw) for yaw in (-0.3, 0.0, 0.3)]
    for T in poses:
        vmap.integrate(*render([floor, crate], K, T, 96), K, T)
    occ = vmap.occupancy()
    cell = lambda x, y: tuple(vmap.grid.cell_of((x, y)))  # noqa: E731
    assert occ[cell(2.1, 0.0)] == OCCUPIED
    assert occ[cell(1.0, 0.0)] == FREE
    assert occ[cell(-3.0, 0.0)] == UNKNOWN  # behind the camera
    assert 7 in vmap.instance_voxels()
    for T in poses:  # the crate was taken away
        vmap.integrate(*render([floor], K, T, 96), K, T)
    assert vmap.occupancy()[cell(2.1, 0.0)] == FREE
    assert 7 not in vmap.instance_voxels()


def test_grid_grows_and_keeps_content_and_ignored_instances_are_not_mapped() -> None:
    K = intrinsics(64)
    floor = Box((-40, -40, -0.05), (40, 40, 0.0), "floor")
    crate = Box((1.5, -0.3, 0.0), (2.0, 0.3, 0.6), "cabinet", 9)
    vmap = _vmap()
    T = camera_pose(0, 0, 0.0)
    vmap.integrate(*render([floor, crate], K, T, 64), K, T, ignore_instances=[9])
    assert 9 not in vmap.instance_voxels()
    vmap.integrate(*render([floor, crate], K, T, 64), K, T)
    shape = vmap.shape
    T2 = camera_pose(25.0, 0, np.pi)
    vmap.integrate(*render([floor], K, T2, 64), K, T2)
    assert vmap.shape[0] > shape[0]
    assert 9 in vmap.instance_voxels()
    vmap.clear_instance(9)
    assert 9 not in vmap.instance_voxels()
    with pytest.raises(ValueError, match="instance ids are positive"):
        vmap.clear_instance(0)  # would have cleared every voxel of no object: floor, walls


def test_growth_in_every_direction_keeps_the_map_and_brings_in_only_unknown_cells() -> None:
    """Growths that widen the view into spare buffer room and growths that copy into a new buffer both
    keep what was mapped where it was and add unknown columns only: the sky-pointed camera sees nothing."""
    K = intrinsics(32)
    floor = Box((-1, -1, -0.05), (1, 1, 0.0), "floor")
    crate = Box((0.3, -0.3, 0.0), (0.8, 0.3, 0.6), "cabinet", 9)
    vmap = _vmap()
    T = camera_pose(0, 0, 0.0)
    vmap.integrate(*render([floor, crate], K, T, 32), K, T)
    crate_voxels, seen, filled = vmap.instance_voxels()[9], int((vmap.top_class >= 0).sum()), int((vmap.cls > 0).sum())
    for x, y in [(20, 0), (-20, 0), (0, 25), (0, -25), (45, 0), (0, 60)]:
        shape = vmap.shape
        T2 = camera_pose(x, y, 0.0)
        vmap.integrate(np.full((32, 32), np.nan), np.zeros((32, 32), int), np.zeros((32, 32), int), K, T2)
        assert vmap.shape != shape
        assert np.allclose(vmap.instance_voxels()[9], crate_voxels, rtol=0, atol=1e-9)
        assert int((vmap.top_class >= 0).sum()) == seen and int((vmap.cls > 0).sum()) == filled


def test_zeroed_buffers_are_empty_writable_and_their_own() -> None:
    """The voxel buffers' allocation: zeros of the asked shape and type, writable, sharing no memory with
    another buffer; an empty shape works too."""
    a, b = zeroed((300, 200, 53), np.uint16), zeroed((300, 200, 53), np.uint16)
    assert a.shape == (300, 200, 53) and a.dtype == np.uint16 and not a.any()
    a[7, 9, 11] = 5
    assert a[7, 9, 11] == 5 and not b.any() and not np.shares_memory(a, b)
    assert zeroed((0, 0, 53), np.int32).shape == (0, 0, 53)


def test_bev_ignores_lintels_and_keeps_negative_tops() -> None:
    K = intrinsics(96)
    floor = Box((-10, -10, -0.05), (10, 10, 0.0), "floor")
    lintel = Box((2.0, -0.5, 2.1), (2.15, 0.5, 2.6), "door", 3)
    pool = Box((3.0, 1.0, -0.9), (4.0, 2.0, -0.8), "table", 0)  # an obstacle below ground level
    vmap = _vmap()
    for yaw in (0.0, 0.4):
        T = camera_pose(0, 0, yaw, pitch_deg=0.0)
        vmap.integrate(*render([floor, lintel, pool], K, T, 96), K, T)
    cell = tuple(vmap.grid.cell_of((2.07, 0.0)))
    assert vmap.occupancy()[cell] == FREE
    assert 3 in vmap.instance_voxels()


def test_instance_voxels_groups_every_instance_voxel_in_grid_order() -> None:
    """The compiled pass of instance_voxels keeps numpy's selection: voxels with an instance id and a
    class, in flat grid order, in the marked columns (those ever given an instance voxel), of one id when
    asked; on a view into a larger buffer too (how the voxel map holds its grid)."""
    from more_agent.mapping.occupancy import _instance_cells

    rng = np.random.default_rng(1)
    cls = rng.integers(0, 3, (9, 7, 5)).astype(np.uint16)
    inst = rng.integers(-1, 4, (9, 7, 5)).astype(np.int32)
    every = np.ones(cls.shape[:2], dtype=np.bool_)
    flat, ids = _instance_cells(cls, inst, every, 0)
    expected = np.flatnonzero((inst > 0) & (cls > 0))
    assert np.array_equal(flat, expected) and np.array_equal(ids, inst.ravel()[expected])
    flat, ids = _instance_cells(
        np.pad(cls, ((2, 1), (0, 3), (0, 0)))[2:-1, :-3],
        np.pad(inst, ((2, 1), (0, 3), (0, 0)))[2:-1, :-3],
        np.pad(every, ((2, 1), (0, 3)))[2:-1, :-3],
        0,
    )
    assert np.array_equal(flat, expected) and np.array_equal(ids, inst.ravel()[expected])
    some = rng.random(every.shape) < 0.5
    flat, ids = _instance_cells(cls, inst, some, 2)
    expected = np.flatnonzero((inst == 2) & (cls > 0) & some[:, :, None])
    assert np.array_equal(flat, expected) and (ids == 2).all() and expected.size > 0
