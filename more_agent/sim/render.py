"""Headless ray caster: depth, semantic, instance and flat-shaded RGB frames from a World.

Everything in the world is an axis-aligned box, so a frame is cast on the CPU (numpy + numba, no
OpenGL / X / EGL / GPU): boxes are bucketed in a uniform 2D grid of ~1 m cells, and each pixel's ray
walks that grid (2D DDA), slab-testing the boxes of each cell and stopping at the first cell that
holds the nearest hit. One core (no parallel loops).

What is drawn (docs/sensors.md):
- room ground as its thin floor slab (semantic = the room's ground class, instance 0);
- walls with their z ranges (class "wall", instance 0); windows are the gaps between wall pieces,
  see-through and unlabelled;
- per door its frame, a lintel above the opening and a jamb on each side of it (class "door", the
  door's instance id), plus the leaf filling the opening while the door is closed; open leaves are
  not drawn. The jambs make an open doorway recognisable from close by, where the lintel is above
  the camera's field of view;
- furniture and items as boxes with their category and instance id; items only while
  ``world.is_observable`` (not held, not inside a closed container). An open container, or a
  non-openable one with something inside (or on an inner shelf level), is a cage: bottom and top slabs of
  ``SLAB_FRACTION * height`` and four thin corner posts, so its contents show while its observed
  extent stays its full box. A non-openable container that is not a shelf (a bag, a basket, a shopping
  cart, a bowl, a skiff) has no top slab: nothing covers it in BEHAVIOR-1K's meshes, so its contents show
  from above too. A closed container is solid, which hides its contents.
No ceiling; no robot body.
"""

from __future__ import annotations

import zlib
from colorsys import hsv_to_rgb
from dataclasses import dataclass

import numpy as np
from numba import njit

from more_agent.robot import Frame
from more_agent.sim.camera import Camera
from more_agent.sim.grid import Grid
from more_agent.sim.packing import LEVELLED_CATEGORIES, SLAB_FRACTION
from more_agent.sim.world import World, WorldObject

GRID_CELL_M = 1.0
"""Side of the acceleration grid's cells in metres."""

CAGE_POST_M = 0.03
"""Side of the corner posts of an open container's cage (at most 15% of its footprint)."""

DOOR_JAMB_M = 0.05
"""Width of a door frame's jambs, inside the opening on each side."""

DOOR_INSET_M = 0.002
"""How far door boxes stand proud of their wall on each side (so the door wins ties with the wall)."""

PATCH_TOP_M = 0.001
"""Top of a ground patch (carpet, driveway) slab: just above the room floor so that it shows."""

_STRUCTURAL_COLORS: dict[str, tuple[int, int, int]] = {
    "unlabeled": (0, 0, 0),
    "floor": (196, 170, 130),
    "carpet": (150, 70, 80),
    "lawn": (90, 160, 70),
    "driveway": (120, 120, 120),
    "wall": (225, 225, 215),
    "door": (140, 90, 50),
    "window": (150, 200, 230),
}


@dataclass(frozen=True, eq=False)
class SceneGeometry:
    """The boxes a world draws (float64 corners, int32 class / instance ids) bucketed in a 2D grid.

    ``cell_start[c]:cell_start[c + 1]`` indexes ``cell_items``, the boxes overlapping cell c, with
    c = iy * nx + ix. ``palette`` is the (n_classes, 3) float64 colour of each semantic class.
    """

    lo: np.ndarray
    hi: np.ndarray
    semantic: np.ndarray
    instance: np.ndarray
    grid: Grid
    """The bucket grid (cells of ``GRID_CELL_M``); the kernels repeat ``Grid.cell_of`` inline."""
    shape: tuple[int, int]
    cell_start: np.ndarray
    cell_items: np.ndarray
    palette: np.ndarray

    @property
    def n_boxes(self) -> int:
        return len(self.semantic)


def scene_geometry(world: World, *, cell_m: float = GRID_CELL_M) -> SceneGeometry:
    """Every box the world draws in its current state, with the grid that accelerates ray casting."""
    boxes: list[tuple[np.ndarray, np.ndarray, int, int]] = []
    for door in (o for o in world.objects.values() if o.kind == "door"):
        boxes.extend(_door_boxes(world, door))
    wall = world.semantic_id("wall")
    for w in world.scene.walls:
        x0, y0, x1, y1 = w.bounds
        boxes.append((np.array([x0, y0, w.z_min]), np.array([x1, y1, w.z_max]), wall, 0))
    for patch in world.scene.ground_patches:
        x0, y0, x1, y1 = patch.bounds
        boxes.append((np.array([x0, y0, -0.01]), np.array([x1, y1, PATCH_TOP_M]), world.semantic_id(patch.ground), 0))
    holds_inside = {  # in it, or on one of its inner levels (world.LEVELLED_CATEGORIES)
        o.parent
        for o in world.objects.values()
        if o.parent is not None and (o.relation == "inside" or o.bottom < world.objects[o.parent].top - 1e-6)
    }
    for obj in world.objects.values():
        sem = world.semantic_id(obj.category)
        lo, hi = obj.box()
        if obj.kind == "floor":
            boxes.append((lo, hi, sem, 0))
        elif obj.kind == "furniture" or (obj.kind == "item" and world.is_observable(obj.name)):
            see_through = obj.is_open if obj.openable else obj.name in holds_inside
            covered = obj.openable or obj.category in LEVELLED_CATEGORIES
            parts = _cage(lo, hi, top=covered) if see_through else [(lo, hi)]
            boxes.extend((a, b, sem, obj.instance_id) for a, b in parts)
    lo = np.array([b[0] for b in boxes], dtype=np.float64).reshape(-1, 3)
    hi = np.array([b[1] for b in boxes], dtype=np.float64).reshape(-1, 3)
    x0, y0, x1, y1 = world.scene.bounds
    x0, y0 = min(x0, lo[:, 0].min()) - cell_m, min(y0, lo[:, 1].min()) - cell_m
    nx = int(np.ceil((max(x1, hi[:, 0].max()) + cell_m - x0) / cell_m))
    ny = int(np.ceil((max(y1, hi[:, 1].max()) + cell_m - y0) / cell_m))
    start, items = _build_grid(lo, hi, x0, y0, cell_m, nx, ny)
    return SceneGeometry(
        lo=lo,
        hi=hi,
        semantic=np.array([b[2] for b in boxes], dtype=np.int32),
        instance=np.array([b[3] for b in boxes], dtype=np.int32),
        grid=Grid(origin_xy=(float(x0), float(y0)), resolution_m=cell_m),
        shape=(nx, ny),
        cell_start=start,
        cell_items=items,
        palette=class_colors(world.class_names).astype(np.float64),
    )


def _door_boxes(world: World, door: WorldObject) -> list[tuple[np.ndarray, np.ndarray, int, int]]:
    """A door's frame (lintel above the opening, a jamb on each side) and its leaf while closed.

    All are thickened by ``DOOR_INSET_M`` across the wall so that they, not the wall piece that
    may share the lintel's box, are what the camera sees (doors are listed first, too).
    """
    lo, hi = door.box()
    across = 1 if door.size[1] < door.size[0] else 0
    lo[across] -= DOOR_INSET_M
    hi[across] += DOOR_INSET_M
    sem, top = world.semantic_id(door.category), world.scene.wall_height
    out = []
    if top > hi[2]:
        out.append((np.array([lo[0], lo[1], hi[2]]), np.array([hi[0], hi[1], top]), sem, door.instance_id))
    along = 1 - across
    for start in (lo[along], hi[along] - DOOR_JAMB_M):
        jamb_lo, jamb_hi = lo.copy(), hi.copy()
        jamb_lo[along], jamb_hi[along] = start, start + DOOR_JAMB_M
        out.append((jamb_lo, jamb_hi, sem, door.instance_id))
    if not door.is_open:
        out.append((lo, hi, sem, door.instance_id))
    return out


def _cage(lo: np.ndarray, hi: np.ndarray, *, top: bool = True) -> list[tuple[np.ndarray, np.ndarray]]:
    """Bottom slab, top slab (unless not ``top``) and four corner posts of a see-through container's box."""
    slab = SLAB_FRACTION * (hi[2] - lo[2])
    post = np.minimum(CAGE_POST_M, 0.15 * (hi[:2] - lo[:2]))
    parts = [(lo, np.array([hi[0], hi[1], lo[2] + slab]))]
    post_top = hi[2]
    if top:
        post_top = hi[2] - slab
        parts.append((np.array([lo[0], lo[1], post_top]), hi))
    for px in (lo[0], hi[0] - post[0]):
        for py in (lo[1], hi[1] - post[1]):
            parts.append((np.array([px, py, lo[2] + slab]), np.array([px + post[0], py + post[1], post_top])))
    return parts


@njit(cache=True)
def _build_grid(
    lo: np.ndarray, hi: np.ndarray, x0: float, y0: float, cell: float, nx: int, ny: int
) -> tuple[np.ndarray, np.ndarray]:
    """CSR lists of the boxes overlapping each grid cell (counting pass, then filling pass)."""
    n = lo.shape[0]
    ranges = np.empty((n, 4), dtype=np.int64)
    count = np.zeros(nx * ny + 1, dtype=np.int32)
    for b in range(n):
        ix0 = max(0, min(nx - 1, int(np.floor((lo[b, 0] - x0) / cell))))
        ix1 = max(0, min(nx - 1, int(np.floor((hi[b, 0] - x0) / cell))))
        iy0 = max(0, min(ny - 1, int(np.floor((lo[b, 1] - y0) / cell))))
        iy1 = max(0, min(ny - 1, int(np.floor((hi[b, 1] - y0) / cell))))
        ranges[b, 0], ranges[b, 1], ranges[b, 2], ranges[b, 3] = ix0, ix1, iy0, iy1
        for iy in range(iy0, iy1 + 1):
            for ix in range(ix0, ix1 + 1):
                count[iy * nx + ix + 1] += 1
    start = np.cumsum(count).astype(np.int32)
    fill = start[:-1].copy()
    items = np.empty(start[-1], dtype=np.int32)
    for b in range(n):
        for iy in range(ranges[b, 2], ranges[b, 3] + 1):
            for ix in range(ranges[b, 0], ranges[b, 1] + 1):
                c = iy * nx + ix
                items[fill[c]] = b
                fill[c] += 1
    return start, items


@njit(cache=True, error_model="numpy")
def _ray_direction(rot: np.ndarray, rays: np.ndarray, r: int) -> tuple[float, float, float]:
    """World-frame direction ``rot @ rays[r]`` (camera z = 1), no component exactly zero."""
    dx = rot[0, 0] * rays[r, 0] + rot[0, 1] * rays[r, 1] + rot[0, 2]
    dy = rot[1, 0] * rays[r, 0] + rot[1, 1] * rays[r, 1] + rot[1, 2]
    dz = rot[2, 0] * rays[r, 0] + rot[2, 1] * rays[r, 1] + rot[2, 2]
    if dx == 0.0:
        dx = 1e-12
    if dy == 0.0:
        dy = 1e-12
    if dz == 0.0:
        dz = 1e-12
    return dx, dy, dz


@njit(cache=True, error_model="numpy")
def _clip(a: float, b: float, o: float, inv: float, tn: float, tf: float) -> tuple[float, float]:
    """The ray interval [tn, tf] narrowed to the slab a <= o + t / inv <= b along one axis."""
    ta, tb = (a - o) * inv, (b - o) * inv
    return max(tn, min(ta, tb)), min(tf, max(ta, tb))


@njit(cache=True, error_model="numpy")
def _box_entry(
    lo: np.ndarray, hi: np.ndarray, b: int, o: np.ndarray, inv: tuple[float, float, float]
) -> tuple[float, float, int]:
    """Slab test of box ``b``: (entry t, exit t, axis of the face entered: 0 x, 1 y, 2 z)."""
    ta, tb = (lo[b, 0] - o[0]) * inv[0], (hi[b, 0] - o[0]) * inv[0]
    t0, t1, f = min(ta, tb), max(ta, tb), 0
    ta, tb = (lo[b, 1] - o[1]) * inv[1], (hi[b, 1] - o[1]) * inv[1]
    if min(ta, tb) > t0:
        t0, f = min(ta, tb), 1
    t1 = min(t1, max(ta, tb))
    ta, tb = (lo[b, 2] - o[2]) * inv[2], (hi[b, 2] - o[2]) * inv[2]
    if min(ta, tb) > t0:
        t0, f = min(ta, tb), 2
    t1 = min(t1, max(ta, tb))
    return t0, t1, f


@njit(cache=True, error_model="numpy")
def _walk_grid(
    r: int,
    o: np.ndarray,
    d: tuple[float, float, float],
    inv: tuple[float, float, float],
    tn: float,
    tf: float,
    x0: float,
    y0: float,
    cell: float,
    nx: int,
    ny: int,
    start: np.ndarray,
    items: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    mailbox: np.ndarray,
) -> tuple[float, int, int]:
    """Nearest box hit by ray ``r`` within [tn, tf]: (t, box, face axis), box -1 on a miss.

    Walks the grid cells the ray crosses in order (Amanatides-Woo) and stops once the nearest hit
    lies before the next cell; each box is tested once per ray (``mailbox``).
    """
    cx = min(nx - 1, max(0, int((o[0] + tn * d[0] - x0) / cell)))
    cy = min(ny - 1, max(0, int((o[1] + tn * d[1] - y0) / cell)))
    sx = 1 if d[0] > 0 else -1
    sy = 1 if d[1] > 0 else -1
    tmx = (x0 + (cx + (1 if sx > 0 else 0)) * cell - o[0]) * inv[0]
    tmy = (y0 + (cy + (1 if sy > 0 else 0)) * cell - o[1]) * inv[1]
    tdx, tdy = cell * abs(inv[0]), cell * abs(inv[1])
    best, best_b, best_f = np.inf, -1, -1
    while True:
        c = cy * nx + cx
        for k in range(start[c], start[c + 1]):
            b = items[k]
            if mailbox[b] == r:
                continue
            mailbox[b] = r
            t0, t1, f = _box_entry(lo, hi, b, o, inv)
            if t0 <= t1 and t0 >= 0.0 and t0 < best:
                best, best_b, best_f = t0, b, f
        t_exit = min(tmx, tmy)
        if best <= t_exit or t_exit >= tf:
            break
        if tmx < tmy:
            cx += sx
            tmx += tdx
            if cx < 0 or cx >= nx:
                break
        else:
            cy += sy
            tmy += tdy
            if cy < 0 or cy >= ny:
                break
    return best, best_b, best_f


@njit(cache=True, error_model="numpy")
def _cast(
    origin: np.ndarray,
    rot: np.ndarray,
    rays: np.ndarray,
    reach: np.ndarray,
    max_t: float,
    x0: float,
    y0: float,
    cell: float,
    nx: int,
    ny: int,
    start: np.ndarray,
    items: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    box_sem: np.ndarray,
    box_inst: np.ndarray,
    palette: np.ndarray,
    depth: np.ndarray,
    sem: np.ndarray,
    inst: np.ndarray,
    rgb: np.ndarray,
) -> None:
    """Nearest hit of each ray origin + t * rot @ rays[r], t in [0, reach[r]]; NaN / 0 / 0 / black on a miss.

    Camera-frame rays have z = 1, so t is the z-depth; ``reach[r]`` is the z-depth at which ray r is ``max_t``
    metres from the camera (the sensor range of paper S.2 is a distance, as the mapper applies it:
    :func:`ray_reach`). The colour is the class's palette entry dimmed by the face hit and by depth.
    """
    mailbox = np.full(lo.shape[0], -1, dtype=np.int64)
    zlo, zhi = np.inf, -np.inf
    for b in range(lo.shape[0]):
        zlo, zhi = min(zlo, lo[b, 2]), max(zhi, hi[b, 2])
    for r in range(rays.shape[0]):
        depth[r], sem[r], inst[r] = np.nan, 0, 0
        rgb[r, 0], rgb[r, 1], rgb[r, 2] = 0, 0, 0
        d = _ray_direction(rot, rays, r)
        inv = (1.0 / d[0], 1.0 / d[1], 1.0 / d[2])
        # clip the ray to the grid's xy extent, the boxes' z extent and the range
        tn, tf = _clip(x0, x0 + nx * cell, origin[0], inv[0], 0.0, reach[r])
        tn, tf = _clip(y0, y0 + ny * cell, origin[1], inv[1], tn, tf)
        tn, tf = _clip(zlo, zhi, origin[2], inv[2], tn, tf)
        if tn > tf:
            continue
        best, best_b, best_f = _walk_grid(
            r, origin, d, inv, tn, tf, x0, y0, cell, nx, ny, start, items, lo, hi, mailbox
        )
        if best_b >= 0 and best <= reach[r]:
            depth[r], sem[r], inst[r] = best, box_sem[best_b], box_inst[best_b]
            shade = (0.80 if best_f == 0 else 0.65 if best_f == 1 else 1.0) * (1.0 - 0.35 * best / max_t)
            for ch in range(3):
                rgb[r, ch] = np.uint8(palette[sem[r], ch] * shade + 0.5)


def ray_reach(rays: np.ndarray, max_range_m: float) -> np.ndarray:
    """Per camera-frame ray (z = 1), the z-depth at which it is ``max_range_m`` from the camera."""
    return max_range_m / np.linalg.norm(rays, axis=1)


def class_colors(class_names: list[str]) -> np.ndarray:
    """(n, 3) uint8 colour per semantic class: fixed for structural classes, else from a hash of the name.

    Hashing the name (not the id) keeps a category's colour the same across worlds and runs.
    """
    colors = np.empty((len(class_names), 3), dtype=np.uint8)
    for i, name in enumerate(class_names):
        if name in _STRUCTURAL_COLORS:
            colors[i] = _STRUCTURAL_COLORS[name]
        else:
            h = zlib.crc32(name.encode())
            rgb = hsv_to_rgb((h % 360) / 360, 0.45 + 0.4 * ((h >> 9) % 100) / 100, 0.55 + 0.4 * ((h >> 17) % 100) / 100)
            colors[i] = np.round(np.array(rgb) * 255).astype(np.uint8)
    return colors


class Renderer:
    """Renders frames of a world through one camera; rebuilds the box grid only when ``world.layout_version`` changes."""

    def __init__(self, camera: Camera | None = None) -> None:
        self.camera = camera or Camera()
        self._rays = self.camera.pixel_rays()
        self._reach = ray_reach(self._rays, self.camera.max_range_m)
        self._K = self.camera.intrinsics()
        self._world: World | None = None
        self._version = -1
        self._geometry: SceneGeometry | None = None

    def geometry(self, world: World) -> SceneGeometry:
        """The world's current drawable boxes and grid (cached per world object and version)."""
        if self._geometry is None or self._world is not world or self._version != world.layout_version:
            self._geometry = scene_geometry(world)
            self._world, self._version = world, world.layout_version
        return self._geometry

    def render(self, world: World) -> Frame:
        """A frame from the robot's current pose."""
        r = world.robot
        return self.render_at(world, self.camera.pose(r.x, r.y, r.yaw))

    def render_at(self, world: World, T_world_cam: np.ndarray) -> Frame:
        """A frame from an arbitrary camera pose (4x4, camera to world)."""
        g = self.geometry(world)
        cam = self.camera
        n = cam.width * cam.height
        T = np.asarray(T_world_cam, dtype=np.float64)
        depth = np.empty(n, dtype=np.float32)
        sem = np.empty(n, dtype=np.int32)
        inst = np.empty(n, dtype=np.int32)
        rgb = np.empty((n, 3), dtype=np.uint8)
        _cast(
            np.ascontiguousarray(T[:3, 3]),
            np.ascontiguousarray(T[:3, :3]),
            self._rays,
            self._reach,
            cam.max_range_m,
            *g.grid.origin_xy,
            g.grid.resolution_m,
            g.shape[0],
            g.shape[1],
            g.cell_start,
            g.cell_items,
            g.lo,
            g.hi,
            g.semantic,
            g.instance,
            g.palette,
            depth,
            sem,
            inst,
            rgb,
        )
        hw = (cam.height, cam.width)
        return Frame(
            rgb=rgb.reshape(*hw, 3),
            depth=depth.reshape(hw),
            semantic=sem.reshape(hw),
            instance=inst.reshape(hw),
            K=self._K.copy(),
            T_world_cam=T.copy(),
        )


def render(world: World, camera: Camera | None = None) -> Frame:
    """One frame from the robot's pose (builds the geometry afresh; keep a ``Renderer`` to reuse it)."""
    return Renderer(camera).render(world)
