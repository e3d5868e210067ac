"""Headless renderer: depth, semantic, instance and flat-shaded RGB frames from a World.

Everything in the world is an axis-aligned box, so a frame is drawn on the CPU (numpy + numba, no
OpenGL / X / EGL / GPU) in object order, as a z-buffer rasteriser draws, with a ray caster's exact hit
test: each box within sensor range projects to a rectangle of the image (its clipped corners' bounds),
every pixel in that rectangle slab-tests the box with its own ray, and each pixel keeps the nearest
entry; a tie goes to the box listed first. A pixel so sees exactly what its ray would hit first, while
only the pixels a box can cover test it. One core (no parallel loops).

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
from more_agent.sim.packing import LEVELLED_CATEGORIES, SLAB_FRACTION
from more_agent.sim.world import World, WorldObject

CAGE_POST_M = 0.03
"""Side of the corner posts of an open container's cage (at most 15% of its footprint)."""

DOOR_JAMB_M = 0.05
"""Width of a door frame's jambs, inside the opening on each side."""

DOOR_INSET_M = 0.002
"""How far door boxes stand proud of their wall on each side (so the door wins ties with the wall)."""

PATCH_TOP_M = 0.001
"""Top of a ground patch (carpet, driveway) slab: just above the room floor so that it shows."""

NEAR_M = 1e-3
"""Depth of the plane that clips a box's corners before they are projected (those behind it would project
through infinity). No ray can hit a box nearer than this in depth unless the box lies within
``2 * NEAR_M`` of the camera (the image's corner rays are 1.33 times their depth long); such a box tests
every pixel."""

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
    """The boxes a world draws (float64 corners, int32 class / instance ids), doors first.

    ``palette`` is the (n_classes, 3) float64 colour of each semantic class.
    """

    lo: np.ndarray
    hi: np.ndarray
    semantic: np.ndarray
    instance: np.ndarray
    palette: np.ndarray

    @property
    def n_boxes(self) -> int:
        return len(self.semantic)


def scene_geometry(world: World) -> SceneGeometry:
    """Every box the world draws in its current state."""
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
    return SceneGeometry(
        lo=np.array([b[0] for b in boxes], dtype=np.float64).reshape(-1, 3),
        hi=np.array([b[1] for b in boxes], dtype=np.float64).reshape(-1, 3),
        semantic=np.array([b[2] for b in boxes], dtype=np.int32),
        instance=np.array([b[3] for b in boxes], dtype=np.int32),
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
def _inverse_directions(rot: np.ndarray, rays: np.ndarray) -> np.ndarray:
    """(n, 3) reciprocals of each pixel's world-frame ray direction: what a slab test multiplies by."""
    inv = np.empty((rays.shape[0], 3))
    for r in range(rays.shape[0]):
        d = _ray_direction(rot, rays, r)
        inv[r, 0], inv[r, 1], inv[r, 2] = 1.0 / d[0], 1.0 / d[1], 1.0 / d[2]
    return inv


@njit(cache=True, error_model="numpy")
def _squared_distance(lo: np.ndarray, hi: np.ndarray, b: int, o: np.ndarray) -> float:
    """Squared distance from point ``o`` to box ``b`` (0 inside it)."""
    dd = 0.0
    for a in range(3):
        gap = max(lo[b, a] - o[a], 0.0, o[a] - hi[b, a])
        dd += gap * gap
    return dd


@njit(cache=True, error_model="numpy")
def _image_bounds(
    lo: np.ndarray, hi: np.ndarray, b: int, o: np.ndarray, rot: np.ndarray, cam: np.ndarray
) -> tuple[float, float, float, float, bool]:
    """Bounds (x min, x max, y min, y max) of box ``b``'s projection on the plane z = 1 of the camera at
    ``o`` with axes ``rot``, of its part beyond the ``NEAR_M`` plane: its corners there and where its edges
    cross that plane. False (and no bounds) when no corner lies beyond it. ``cam`` (8 x 3) is scratch space
    for the corners in the camera frame (one array for every box of a frame)."""
    for k in range(8):
        qx = (hi[b, 0] if k & 1 else lo[b, 0]) - o[0]
        qy = (hi[b, 1] if k & 2 else lo[b, 1]) - o[1]
        qz = (hi[b, 2] if k & 4 else lo[b, 2]) - o[2]
        for a in range(3):
            cam[k, a] = rot[0, a] * qx + rot[1, a] * qy + rot[2, a] * qz
    x0, x1, y0, y1, seen = np.inf, -np.inf, np.inf, -np.inf, False
    for k in range(8):
        if cam[k, 2] > NEAR_M:
            x, y, seen = cam[k, 0] / cam[k, 2], cam[k, 1] / cam[k, 2], True
            x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
        for a in range(3):  # the edges to the corners that differ in one coordinate, each once
            m = k ^ (1 << a)
            if m > k and (cam[k, 2] > NEAR_M) != (cam[m, 2] > NEAR_M):
                s = (NEAR_M - cam[k, 2]) / (cam[m, 2] - cam[k, 2])
                x = (cam[k, 0] + s * (cam[m, 0] - cam[k, 0])) / NEAR_M
                y = (cam[k, 1] + s * (cam[m, 1] - cam[k, 1])) / NEAR_M
                x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
    return x0, x1, y0, y1, seen


@njit(cache=True, error_model="numpy")
def _pixel_rect(
    lo: np.ndarray,
    hi: np.ndarray,
    b: int,
    o: np.ndarray,
    rot: np.ndarray,
    K: np.ndarray,
    width: int,
    height: int,
    max_t: float,
    cam: np.ndarray,
) -> tuple[int, int, int, int]:
    """Columns u0..u1 and rows v0..v1 (inclusive; empty when u0 > u1) holding every pixel whose ray can hit
    box ``b`` within ``max_t`` of the camera: none for a box beyond that range (where a pixel shows nothing
    anyway), the whole image for a box at the camera, else its projection's bounds widened by a pixel."""
    dd = _squared_distance(lo, hi, b, o)
    if dd > max_t * max_t * (1.0 + 1e-4):
        return 0, -1, 0, -1
    if dd <= (2 * NEAR_M) ** 2:
        return 0, width - 1, 0, height - 1
    x0, x1, y0, y1, seen = _image_bounds(lo, hi, b, o, rot, cam)
    u0, u1 = x0 * K[0, 0] + K[0, 2] - 1.0, x1 * K[0, 0] + K[0, 2] + 1.0
    v0, v1 = y0 * K[1, 1] + K[1, 2] - 1.0, y1 * K[1, 1] + K[1, 2] + 1.0
    if not seen or u1 < 0 or v1 < 0 or u0 > width - 1 or v0 > height - 1:
        return 0, -1, 0, -1
    return max(0, int(u0)), min(width - 1, int(u1) + 1), max(0, int(v0)), min(height - 1, int(v1) + 1)


@njit(cache=True, error_model="numpy")
def _nearest_entries(
    origin: np.ndarray,
    rot: np.ndarray,
    rays: np.ndarray,
    K: np.ndarray,
    width: int,
    max_t: float,
    lo: np.ndarray,
    hi: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pixel, the depth at which its ray first enters a box, the box (-1 on a miss) and the axis of the
    face entered (0 x, 1 y, 2 z): every box is slab-tested by the pixels of its :func:`_pixel_rect` (none
    beyond ``max_t``), in the boxes' order, a nearer entry replacing the one kept."""
    n = rays.shape[0]
    inv = _inverse_directions(rot, rays)
    best = np.full(n, np.inf)
    box = np.full(n, -1, dtype=np.int32)
    face = np.zeros(n, dtype=np.int8)
    cam = np.empty((8, 3))
    for b in range(lo.shape[0]):
        u0, u1, v0, v1 = _pixel_rect(lo, hi, b, origin, rot, K, width, n // width, max_t, cam)
        l0, l1, l2 = lo[b, 0] - origin[0], lo[b, 1] - origin[1], lo[b, 2] - origin[2]
        h0, h1, h2 = hi[b, 0] - origin[0], hi[b, 1] - origin[1], hi[b, 2] - origin[2]
        for v in range(v0, v1 + 1):
            for r in range(v * width + u0, v * width + u1 + 1):
                ta, tb = l0 * inv[r, 0], h0 * inv[r, 0]
                t0, t1, f = min(ta, tb), max(ta, tb), 0
                ta, tb = l1 * inv[r, 1], h1 * inv[r, 1]
                if min(ta, tb) > t0:
                    t0, f = min(ta, tb), 1
                t1 = min(t1, max(ta, tb))
                ta, tb = l2 * inv[r, 2], h2 * inv[r, 2]
                if min(ta, tb) > t0:
                    t0, f = min(ta, tb), 2
                t1 = min(t1, max(ta, tb))
                if t0 <= t1 and t0 >= 0.0 and t0 < best[r]:
                    best[r], box[r], face[r] = t0, b, f
    return best, box, face


@njit(cache=True, error_model="numpy")
def _draw(
    origin: np.ndarray,
    rot: np.ndarray,
    rays: np.ndarray,
    reach: np.ndarray,
    max_t: float,
    K: np.ndarray,
    width: int,
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
    best, box, face = _nearest_entries(origin, rot, rays, K, width, max_t, lo, hi)
    for r in range(rays.shape[0]):
        depth[r], sem[r], inst[r] = np.nan, 0, 0
        rgb[r, 0], rgb[r, 1], rgb[r, 2] = 0, 0, 0
        b = box[r]
        if b >= 0 and best[r] <= reach[r]:
            depth[r], sem[r], inst[r] = best[r], box_sem[b], box_inst[b]
            shade = (0.80 if face[r] == 0 else 0.65 if face[r] == 1 else 1.0) * (1.0 - 0.35 * best[r] / max_t)
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
    """Renders frames of a world through one camera; rebuilds the boxes only when ``world.layout_version`` changes."""

    def __init__(self, camera: Camera | None = None) -> None:
        self.camera = camera or Camera()
        self._rays = self.camera.pixel_rays()
        self._reach = ray_reach(self._rays, self.camera.max_range_m)
        self._K = self.camera.intrinsics()
        self._world: World | None = None
        self._version = -1
        self._geometry: SceneGeometry | None = None

    def geometry(self, world: World) -> SceneGeometry:
        """The world's current drawable boxes (cached per world object and version)."""
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
        _draw(
            np.ascontiguousarray(T[:3, 3]),
            np.ascontiguousarray(T[:3, :3]),
            self._rays,
            self._reach,
            cam.max_range_m,
            self._K,
            cam.width,
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
