"""Tiny test renderer: axis-aligned boxes ray-cast into depth / semantic / instance frames with
the renderer's contract (z-depth, NaN beyond range, OpenCV camera, world z up)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from more_agent.sim.scene import STRUCTURAL_CLASSES

CLASSES = [*STRUCTURAL_CLASSES, "table", "cabinet", "apple"]
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
    """(depth, semantic, instance) of the boxes seen from pose T."""
    v, u = np.mgrid[0:size, 0:size]
    cam = np.stack([(u + 0.5 - K[0, 2]) / K[0, 0], (v + 0.5 - K[1, 2]) / K[1, 1], np.ones((size, size))], -1).reshape(-1, 3)
    dirs = cam @ T[:3, :3].T
    o = T[:3, 3]
    lo = np.array([b.lo for b in boxes])
    hi = np.array([b.hi for b in boxes])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo[None] - o) / dirs[:, None, :]
        t2 = (hi[None] - o) / dirs[:, None, :]
    tn = np.nanmax(np.minimum(t1, t2), axis=2)
    tf = np.nanmin(np.maximum(t1, t2), axis=2)
    hit = (tn <= tf) & (tf > 0)
    t = np.where(hit, np.maximum(tn, 0), np.inf)
    best = np.argmin(t, axis=1)
    tz = t[np.arange(len(t)), best]  # along cam, whose z component is 1: tz is z-depth
    ok = np.isfinite(tz) & (tz * np.linalg.norm(cam, axis=1) <= max_range)
    depth = np.where(ok, tz, np.nan).astype(np.float32).reshape(size, size)
    sem = np.where(ok, np.array([CID[b.cls] for b in boxes])[best], 0).astype(np.int32).reshape(size, size)
    inst = np.where(ok, np.array([b.instance for b in boxes])[best], 0).astype(np.int32).reshape(size, size)
    return depth, sem, inst


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
