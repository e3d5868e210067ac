"""Tiny test renderer: axis-aligned boxes ray-cast into depth / semantic / instance frames with
the renderer's contract (z-depth, NaN beyond range, OpenCV camera, world z up)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from more_agent.sim.scene import STRUCTURAL_CLASSES

CLASSES = [*STRUCTURAL_CLASSES, "table", "cabinet", "apple", "basket"]
CID = {name: i for i, name in enumerate(CLASSES)}


@dataclass(frozen=True)
class Box:
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    cls: str
    instance: int = 0


def intrinsics(size: int) -> np.ndarray:
    """90-degree field of view."""
    f = size / 2
    return np.array([[f, 0, size / 2], [0, f, size / 2], [0, 0, 1.0]])


def camera_pose(x: float, y: float, yaw: float, *, height: float = 1.3, pitch_deg: float = 15.0) -> np.ndarray:
    """T_world_cam for a camera at (x, y, height) looking along yaw, tilted down by pitch."""
    p = np.deg2rad(pitch_deg)
    fwd = np.array([np.cos(yaw) * np.cos(p), np.sin(yaw) * np.cos(p), -np.sin(p)])
    right = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
    down = np.cross(fwd, right)
    T = np.eye(4)
    T[:3, :3] = np.stack([right, down, fwd], axis=1)
    T[:3, 3] = [x, y, height]
    return T


def render(boxes: list[Box], K: np.ndarray, T: np.ndarray, size: int, max_range: float = 5.0):
    """(depth, semantic, instance) of the boxes seen from pose T: slab tests one box at a time over the
    pixels its corners project to (all of them when a corner is behind the camera), the nearest hit
    kept (the first box on ties)."""
    v, u = np.mgrid[0:size, 0:size]
    cam = np.stack([(u + 0.5 - K[0, 2]) / K[0, 0], (v + 0.5 - K[1, 2]) / K[1, 1], np.ones((size, size))], -1).reshape(-1, 3)
    dirs = cam @ T[:3, :3].T
    o = T[:3, 3]
    tz = np.full(len(dirs), np.inf)
    best = np.zeros(len(dirs), dtype=np.intp)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.ascontiguousarray((1.0 / dirs).T)  # (3, pixels): each axis a row, so the slab joins rows
        for i, b in enumerate(boxes):
            pix = _pixels_of(b, K, T, size)
            if pix is not None and len(pix) == 0:
                continue
            lo, hi = np.subtract(b.lo, o)[:, None], np.subtract(b.hi, o)[:, None]
            d = inv if pix is None else inv[:, pix]
            t1, t2 = lo * d, hi * d
            near, far = np.minimum(t1, t2), np.maximum(t1, t2)
            tn = np.fmax(np.fmax(near[0], near[1]), near[2])  # fmax / fmin skip the NaN of 0 * inf, like nanmax
            tf = np.fmin(np.fmin(far[0], far[1]), far[2])
            t = np.where((tn <= tf) & (tf > 0), np.maximum(tn, 0), np.inf)
            idx = np.arange(len(dirs)) if pix is None else pix
            closer = t < tz[idx]
            tz[idx[closer]], best[idx[closer]] = t[closer], i
    ok = np.isfinite(tz) & (tz * np.linalg.norm(cam, axis=1) <= max_range)  # along cam, whose z is 1: tz is z-depth
    depth = np.where(ok, tz, np.nan).astype(np.float32).reshape(size, size)
    sem = np.where(ok, np.array([CID[b.cls] for b in boxes])[best], 0).astype(np.int32).reshape(size, size)
    inst = np.where(ok, np.array([b.instance for b in boxes])[best], 0).astype(np.int32).reshape(size, size)
    return depth, sem, inst


def _pixels_of(box: Box, K: np.ndarray, T: np.ndarray, size: int) -> np.ndarray | None:
    """Flat indices of the pixels inside the image rectangle around the box's projected corners (one
    pixel of margin); None when a corner lies at or behind the camera plane (test every pixel)."""
    corners = np.array([[x, y, z] for x in (box.lo[0], box.hi[0]) for y in (box.lo[1], box.hi[1]) for z in (box.lo[2], box.hi[2])])
    c = (corners - T[:3, 3]) @ T[:3, :3]
    if (c[:, 2] <= 1e-6).any():
        return None
    uv = (c[:, :2] / c[:, 2:]) * [K[0, 0], K[1, 1]] + [K[0, 2], K[1, 2]]
    u0, v0 = np.clip(np.floor(uv.min(0)).astype(int) - 1, 0, size)
    u1, v1 = np.clip(np.ceil(uv.max(0)).astype(int) + 1, 0, size)
    v, u = np.mgrid[v0:v1, u0:u1]
    return (v * size + u).ravel()


def walls_x(x: float, y0: float, y1: float, *, openings=(), thick: float = 0.15, height: float = 2.6) -> list[Box]:
    """A wall across x = x..x+thick from y0 to y1 with full-height openings [(ya, yb), ...]."""
    out, y = [], y0
    for a, b in sorted(openings):
        out.append(Box((x, y, 0), (x + thick, a, height), "wall"))
        y = b
    out.append(Box((x, y, 0), (x + thick, y1, height), "wall"))
    return out


def walls_y(y: float, x0: float, x1: float, *, thick: float = 0.15, height: float = 2.6) -> list[Box]:
    return [Box((x0, y, 0), (x1, y + thick, height), "wall")]
