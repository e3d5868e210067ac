"""Posed depth + semantics -> world points -> 3D voxel grid -> 2D BEV occupancy.

``VoxelMap`` keeps, per voxel, the semantic class and instance id of the last point that fell in
it. Each frame first clears the voxels its rays pass through (so moved objects and opened doors
disappear), then writes the frame's hits. The BEV takes the highest occupied voxel per column
below ``bev_max_height_m`` (it may lie below the ground, e.g. a pool): a free-space class there
(floor, carpet, lawn, driveway) makes the cell FREE, any other class OCCUPIED, none UNKNOWN.
Voxels of free-space classes are never cleared by passing rays: grazing rays would otherwise
erase the ground they skim. (Rays grazing a table top on their way to the floor behind do erode
some of its voxels; the holes are single cells, narrower than the inflation, so the graph is not
affected.) Depth is z-depth in the OpenCV camera frame (x right, y down, z fwd).
Grid layout: ``grid[ix, iy]`` on ``VoxelMap.grid`` (:class:`~more_agent.sim.grid.Grid`); the
compiled kernels repeat ``Grid.cell_of`` inline, in z as well, on the voxel map's corner.
"""

from __future__ import annotations

import mmap
from collections.abc import Iterable

import numba
import numpy as np

from more_agent.sim.grid import Grid

UNKNOWN, FREE, OCCUPIED = 0, 1, 2
"""BEV cell values (also used by the synthetic benchmark maps)."""

_MAX_CLASSES = 65535


def depth_to_points(depth: np.ndarray, K: np.ndarray, T_world_cam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World points of the finite depth pixels, and which pixels they are.

    Parameters
    ----------
    depth : ndarray, shape (h, w)
        Z-depth, metres; non-finite where nothing was hit.
    K : ndarray, shape (3, 3)
        Camera intrinsics (pixel centres at +0.5).
    T_world_cam : ndarray, shape (4, 4)
        Camera-to-world pose (OpenCV camera frame).

    Returns
    -------
    points : ndarray, shape (N, 3)
        World points, metres.
    pixels : ndarray of int, shape (N,)
        Flat index of each point's pixel.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import depth_to_points
    >>> K = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])
    >>> depth_to_points(np.array([[2.0, np.inf]]), K, np.eye(4))
    (array([[-1.,  0.,  2.]]), array([0]))
    """
    h, w = depth.shape
    v, u = np.mgrid[0:h, 0:w]
    valid = np.isfinite(depth).ravel()
    d = depth.ravel()[valid]
    x = (u.ravel()[valid] + 0.5 - K[0, 2]) / K[0, 0] * d
    y = (v.ravel()[valid] + 0.5 - K[1, 2]) / K[1, 1] * d
    cam = np.stack([x, y, d], axis=1)
    return cam @ T_world_cam[:3, :3].T + T_world_cam[:3, 3], np.flatnonzero(valid)


@numba.njit(cache=True)
def _widen(box, ix, iy):
    """Grow the column box [x0, x1) x [y0, y1) (``box``: x0, x1, y0, y1) to hold column (ix, iy)."""
    box[0], box[1] = min(box[0], ix), max(box[1], ix + 1)
    box[2], box[3] = min(box[2], iy), max(box[3], iy + 1)


@numba.njit(cache=True)
def _carve(depth, intr, rot, trans, cls, changed, origin, res, max_range, stride, free_lut):
    """Clear the non-free-space voxels that rays pass through (sampled every ``res``) before
    their hit (or max range), widening ``changed`` (:func:`_widen`) over their columns. Each voxel index
    is monotone along a ray, so a ray that has left the grid never comes back: its march stops there. A
    sample ``res`` further along a unit direction lies one voxel of that direction further: its voxel
    coordinates are summed, not divided out per sample (a third of a frame's mapping; the maps of two
    recorded episodes, 1,038 frames, byte-identical)."""
    h, w = depth.shape
    nx, ny, nz = cls.shape
    x0, y0, z0 = (trans[0] - origin[0]) / res, (trans[1] - origin[1]) / res, (trans[2] - origin[2]) / res
    for v in range(stride // 2, h, stride):
        for u in range(stride // 2, w, stride):
            a = (u + 0.5 - intr[2]) / intr[0]
            b = (v + 0.5 - intr[3]) / intr[1]
            norm = np.sqrt(a * a + b * b + 1.0)
            d = depth[v, u]
            length = max_range if not np.isfinite(d) else min(d * norm, max_range)
            dx = (rot[0, 0] * a + rot[0, 1] * b + rot[0, 2]) / norm
            dy = (rot[1, 0] * a + rot[1, 1] * b + rot[1, 2]) / norm
            dz = (rot[2, 0] * a + rot[2, 1] * b + rot[2, 2]) / norm
            t, inside = 0.0, False
            fx, fy, fz = x0, y0, z0
            while t < length - res:
                ix = int(np.floor(fx))
                iy = int(np.floor(fy))
                iz = int(np.floor(fz))
                fx += dx
                fy += dy
                fz += dz
                t += res
                if not (0 <= ix < nx and 0 <= iy < ny and 0 <= iz < nz):
                    if inside:
                        break
                    continue
                inside = True
                c = cls[ix, iy, iz]
                if c != 0 and not free_lut[c - 1]:
                    cls[ix, iy, iz] = 0
                    _widen(changed, ix, iy)


@numba.njit(cache=True)
def _insert(depth, semantic, instance, use, intr, rot, trans, cls, inst, marked, changed, origin, res, max_range):
    """Write every valid pixel's hit into the grid (class + 1, instance id); mark the columns that get an
    instance id > 0 (``VoxelMap.marked``), widen ``changed`` over those whose classes change."""
    h, w = depth.shape
    nx, ny, nz = cls.shape
    for v in range(h):
        for u in range(w):
            d = depth[v, u]
            if not use[v, u] or not np.isfinite(d):
                continue
            a = (u + 0.5 - intr[2]) / intr[0] * d
            b = (v + 0.5 - intr[3]) / intr[1] * d
            if a * a + b * b + d * d > max_range * max_range:
                continue
            px = rot[0, 0] * a + rot[0, 1] * b + rot[0, 2] * d + trans[0]
            py = rot[1, 0] * a + rot[1, 1] * b + rot[1, 2] * d + trans[1]
            pz = rot[2, 0] * a + rot[2, 1] * b + rot[2, 2] * d + trans[2]
            ix = int(np.floor((px - origin[0]) / res))
            iy = int(np.floor((py - origin[1]) / res))
            iz = int(np.floor((pz - origin[2]) / res))
            if 0 <= ix < nx and 0 <= iy < ny and 0 <= iz < nz:
                if cls[ix, iy, iz] != semantic[v, u] + 1:
                    cls[ix, iy, iz] = semantic[v, u] + 1
                    _widen(changed, ix, iy)
                inst[ix, iy, iz] = instance[v, u]
                if instance[v, u] > 0:
                    marked[ix, iy] = True


@numba.njit(cache=True)
def _instance_cells(cls, inst, marked, only):
    """Flat indices (ascending, C order of the grid's shape) and ids of the occupied voxels with an
    instance id > 0 (``only`` > 0: with that id), in the ``marked`` columns only: about 1 % of a house's
    columns hold an object, and a pass over the whole grid (tens of millions of voxels, a view into a
    larger buffer, see ``VoxelMap._ensure_covers``) cost every scene-graph build 18 ms in a grocery store, 31 ms
    on average over the test suite's builds (docs/benchmarks.md)."""
    nx, ny, nz = inst.shape
    n = 0
    for ix in range(nx):
        for iy in range(ny):
            if marked[ix, iy]:
                for iz in range(nz):
                    i = inst[ix, iy, iz]
                    if i > 0 and (only <= 0 or i == only) and cls[ix, iy, iz] > 0:
                        n += 1
    flat = np.empty(n, dtype=np.int64)
    ids = np.empty(n, dtype=inst.dtype)
    n = 0
    for ix in range(nx):
        for iy in range(ny):
            if marked[ix, iy]:
                for iz in range(nz):
                    i = inst[ix, iy, iz]
                    if i > 0 and (only <= 0 or i == only) and cls[ix, iy, iz] > 0:
                        flat[n], ids[n] = (ix * ny + iy) * nz + iz, i
                        n += 1
    return flat, ids


@numba.njit(cache=True)
def _update_top(cls, top, x0, x1, y0, y1, top_level):
    """Recompute the BEV class (highest occupied voxel at or below ``top_level``) in a window."""
    for ix in range(x0, x1):
        for iy in range(y0, y1):
            top[ix, iy] = -1
            for k in range(top_level, -1, -1):
                c = cls[ix, iy, k]
                if c != 0:
                    top[ix, iy] = c - 1
                    break


def zeroed(shape: tuple[int, ...], dtype: type[np.generic]) -> np.ndarray:
    """A zero-filled array on fresh anonymous memory with transparent huge pages advised (Linux), like
    ``np.zeros``: pages still come on first use, but 2 MB at a time. The voxel grid is hundreds of
    megabytes, mostly written once, and first touch of 4 kB pages dominated its cost on virtual machines
    (docs/benchmarks.md: 50 MB filled in 0.22 s with ``np.zeros``, 0.04 s with huge pages)."""
    size = int(np.prod(shape)) * np.dtype(dtype).itemsize
    if size == 0 or not hasattr(mmap, "MADV_HUGEPAGE"):
        return np.zeros(shape, dtype=dtype)
    pages = mmap.mmap(-1, size)
    pages.madvise(mmap.MADV_HUGEPAGE)
    return np.frombuffer(pages, dtype=dtype).reshape(shape)


class VoxelMap:
    """Growing dense voxel grid of semantic class and instance id, with its BEV kept up to date."""

    def __init__(
        self,
        *,
        free_class_ids: Iterable[int],
        resolution_m: float = 0.075,
        z_min_m: float = -1.0,
        z_max_m: float = 3.0,
        bev_max_height_m: float = 2.0,
        max_range_m: float = 5.0,
        carve_stride_px: int = 2,
        initial_extent_m: float = 20.0,
    ) -> None:
        self.grid = Grid(resolution_m=resolution_m)
        """Where the voxel columns and the BEV lie; the corner moves when the map grows."""
        self.max_range_m = max_range_m
        self.carve_stride_px = carve_stride_px
        self.initial_extent_m = initial_extent_m
        self._free_lut = np.zeros(_MAX_CLASSES + 1, dtype=np.bool_)
        self._free_lut[list(free_class_ids)] = True
        self._nz = int(np.ceil((z_max_m - z_min_m) / resolution_m))
        self._z_min = z_min_m
        self._top_level = min(self._nz - 1, int(np.ceil((bev_max_height_m - z_min_m) / resolution_m - 0.5)) - 1)
        self.cls = np.zeros((0, 0, self._nz), dtype=np.uint16)
        self.inst = np.zeros((0, 0, self._nz), dtype=np.int32)
        self.top_class = np.full((0, 0), -1, dtype=np.int32)
        """BEV: semantic class of the highest occupied voxel per column, -1 where none."""
        self.marked = np.zeros((0, 0), dtype=np.bool_)
        """Columns that were ever given a voxel of an instance id > 0 (a superset of those holding one now)."""

    @property
    def shape(self) -> tuple[int, int]:
        return self.top_class.shape

    def _ensure_covers(self, lo: np.ndarray, hi: np.ndarray) -> None:
        """Grow the grid (whole cells, existing content kept) so that [lo, hi] in xy lies inside: by the
        cells missing plus half the initial extent on each side that lacks them. The arrays are views into
        buffers with room for as much again on every side, the first one too, so most growths only widen
        the view (a copy of a house's grid is tens of megabytes), and every view is strided alike: the
        numba kernels that take them compile once, not again for a whole-buffer (C-contiguous) view."""
        res = self.grid.resolution_m
        if self.cls.shape[0] == 0:
            half = max(self.initial_extent_m / 2, float(np.max(hi - lo)) / 2 + res)
            centre = (lo + hi) / 2
            self._move_corner(np.round((centre - half) / res) * res)
            n = int(np.ceil(2 * half / res))
            self._allocate((3 * n, 3 * n))
            self._view(np.array([n, n]), np.array([2 * n, 2 * n]))
            return
        size = np.array(self.shape)
        low, high = self.grid.cell_range(lo, hi)
        if (low >= 0).all() and (high <= size).all():
            return
        margin = int(np.ceil(self.initial_extent_m / 2 / res))
        pad_lo = np.where(low < 0, -low + margin, 0)
        pad_hi = np.where(high > size, high - size + margin, 0)
        start, stop = self._view_start - pad_lo, self._view_start + size + pad_hi
        if (start < 0).any() or (stop > self._top_buf.shape).any():
            start = size.copy()  # room for as much again on every side: few copies
            stop = start + pad_lo + size + pad_hi
            old = self.cls, self.inst, self.top_class, self.marked
            self._allocate(tuple(stop + size))
            kept = (slice(start[0] + pad_lo[0], stop[0] - pad_hi[0]), slice(start[1] + pad_lo[1], stop[1] - pad_hi[1]))
            self._cls_buf[kept], self._inst_buf[kept], self._top_buf[kept], self._mark_buf[kept] = old
        self._view(start, stop)
        self._move_corner(np.asarray(self.grid.origin_xy) - pad_lo * res)

    def _allocate(self, shape: tuple[int, ...]) -> None:
        """Fresh empty buffers of ``shape`` columns. What lies outside the view is never written, so it is
        still empty when a growth brings it in; untouched, it takes no memory (zeroed pages come on use)."""
        self._cls_buf = zeroed((*shape, self._nz), np.uint16)
        self._inst_buf = zeroed((*shape, self._nz), np.int32)
        self._top_buf = np.full(shape, -1, dtype=np.int32)
        self._mark_buf = np.zeros(shape, dtype=np.bool_)

    def _view(self, start: np.ndarray, stop: np.ndarray) -> None:
        """Point ``cls``, ``inst``, ``top_class`` and ``marked`` at the buffers' columns [start, stop)."""
        window = (slice(int(start[0]), int(stop[0])), slice(int(start[1]), int(stop[1])))
        self._view_start = np.asarray(start)
        self.cls, self.inst = self._cls_buf[window], self._inst_buf[window]
        self.top_class, self.marked = self._top_buf[window], self._mark_buf[window]

    def _move_corner(self, origin_xy: np.ndarray) -> None:
        self.grid = Grid(origin_xy=(float(origin_xy[0]), float(origin_xy[1])), resolution_m=self.grid.resolution_m)

    def integrate(
        self,
        depth: np.ndarray,
        semantic: np.ndarray,
        instance: np.ndarray,
        K: np.ndarray,
        T_world_cam: np.ndarray,
        *,
        ignore_instances: Iterable[int] = (),
    ) -> None:
        """Fuse one frame: clear traversed voxels, write hits (except of ``ignore_instances``,
        e.g. held objects), refresh the BEV of the columns whose classes changed."""
        rot = np.ascontiguousarray(T_world_cam[:3, :3], dtype=np.float64)
        trans = np.ascontiguousarray(T_world_cam[:3, 3], dtype=np.float64)
        r = self.max_range_m
        self._ensure_covers(trans[:2] - r, trans[:2] + r)
        intr = np.array([K[0, 0], K[1, 1], K[0, 2], K[1, 2]], dtype=np.float64)
        origin = np.array([*self.grid.origin_xy, self._z_min])
        depth = np.ascontiguousarray(depth, dtype=np.float32)
        ignore = np.fromiter(ignore_instances, dtype=np.int64)
        use = ~np.isin(instance, ignore) if ignore.size else np.ones(depth.shape, dtype=np.bool_)
        res = self.grid.resolution_m
        changed = np.array([self.shape[0], 0, self.shape[1], 0], dtype=np.int64)  # empty: no column yet
        _carve(depth, intr, rot, trans, self.cls, changed, origin, res, r, self.carve_stride_px, self._free_lut)
        _insert(
            depth,
            semantic.astype(np.int32, copy=False),
            instance.astype(np.int32, copy=False),
            use,
            intr,
            rot,
            trans,
            self.cls,
            self.inst,
            self.marked,
            changed,
            origin,
            res,
            r,
        )
        x0, x1, y0, y1 = changed.tolist()  # the columns whose classes changed
        _update_top(self.cls, self.top_class, x0, x1, y0, y1, self._top_level)

    def occupancy(self) -> np.ndarray:
        """BEV grid (int8): UNKNOWN, FREE (top voxel of a free-space class) or OCCUPIED."""
        out = np.full(self.shape, UNKNOWN, dtype=np.int8)
        seen = self.top_class >= 0
        free = np.zeros(self.shape, dtype=bool)
        free[seen] = self._free_lut[self.top_class[seen]]
        out[seen] = OCCUPIED
        out[free] = FREE
        return out

    def instance_voxels(self) -> dict[int, np.ndarray]:
        """World coordinates (k, 3) of the occupied voxel centres of every instance id > 0."""
        flat, ids = _instance_cells(self.cls, self.inst, self.marked, 0)
        if flat.size == 0:
            return {}
        order = np.argsort(ids, kind="stable")
        flat, ids = flat[order], ids[order]
        pts = self._centres(*np.unravel_index(flat, self.inst.shape))
        uniq, starts = np.unique(ids, return_index=True)
        return {int(i): p for i, p in zip(uniq, np.split(pts, starts[1:]))}

    def clear_instance(self, instance_id: int) -> np.ndarray:
        """Remove every voxel of one instance (id > 0, e.g. when it is picked up), refresh the BEV, and
        return the world coordinates (k, 3) of the removed voxel centres."""
        if instance_id <= 0:
            raise ValueError(f"instance ids are positive, got {instance_id}")
        flat, _ = _instance_cells(self.cls, self.inst, self.marked, instance_id)
        ix, iy, iz = np.unravel_index(flat, self.inst.shape)
        self.cls[ix, iy, iz] = 0
        self.inst[ix, iy, iz] = 0
        if ix.size:
            _update_top(self.cls, self.top_class, ix.min(), ix.max() + 1, iy.min(), iy.max() + 1, self._top_level)
        return self._centres(ix, iy, iz)

    def _centres(self, ix: np.ndarray, iy: np.ndarray, iz: np.ndarray) -> np.ndarray:
        """World coordinates (k, 3) of voxel centres."""
        z = self._z_min + (iz + 0.5) * self.grid.resolution_m
        return np.column_stack([self.grid.xy_of(np.stack([ix, iy], axis=1)), z])
