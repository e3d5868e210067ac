"""BUMBLE's visual memory: a buffer of camera frames kept while the robot moves, and the questions asked of it.

The paper's BUMBLE adaptation (supplementary "BUMBLE Implementation") samples frames continuously
during execution so the VLM can pick a frame showing a previously seen object (landmark step) or an
unexplored area (exploration). Here every frame the robot senses (at the episode's ``--sensing``
cadence on the way) is offered to the buffer, which keeps it when the camera has moved or turned far
enough since the last kept frame, by the rule of :class:`~more_agent.sensing_spec.SensingCadence` at
0.5 m or 30 degrees (:data:`BUMBLE_KEEP`); the initial full turn keeps every view (its turns are about
33 degrees).

A kept frame holds its pose and its RGB, instance and coarse depth images compressed (about 12 kB
per frame); the PNG a request sends is encoded the first time the frame is sent. Which objects a
frame shows is its set of instance ids; which unexplored areas it shows is decided when asked,
against the frontiers of the current scene graph (:func:`shows_points`).
"""

from __future__ import annotations

import functools
import math
import zlib
from collections.abc import Callable, Collection, Sequence, Set
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from more_agent.llm.images import png_bytes
from more_agent.planners.policies.sensing import SensingSchedule
from more_agent.robot import Frame
from more_agent.sensing_spec import SensingCadence
from more_agent.sim.camera import project

BUMBLE_KEEP = SensingCadence(distance_m=0.5, angle_deg=30.0)
"""The buffer's rule: a frame once the camera moved 0.5 m or turned 30 degrees since the last kept one."""

DEPTH_STRIDE = 4
"""Kept depth images are subsampled by this factor per axis (64x64 for 256x256 frames)."""


class MemoryConfig(BaseModel):
    """When a frame enters the buffer, and how many go into one request."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    keep: SensingCadence = Field(
        default=BUMBLE_KEEP,
        description="Keep a frame once the camera moved or turned this far since the last kept one (the mapper's rule).",
    )
    max_images: int = Field(default=8, ge=1, description="Most buffer frames in one VLM request (subsampled beyond).")
    occlusion_margin_m: float = Field(
        default=0.3,
        ge=0,
        description="A point counts as seen in a frame if the frame's depth there reaches within this of it.",
    )


@dataclass(frozen=True, eq=False)
class MemoryFrame:
    """One kept frame (see module docstring)."""

    index: int
    """Position in the buffer (0 = first kept frame)."""
    step: int
    """High-level step during which it was captured."""
    pose: tuple[float, float, float]
    """Camera (x, y, yaw) in the world frame."""
    instance_ids: frozenset[int]
    """Instance ids visible in it (background 0 excluded)."""
    K: np.ndarray
    T_world_cam: np.ndarray
    shape: tuple[int, int]
    _rgb: bytes
    _instance: bytes
    _depth: bytes

    def rgb(self) -> np.ndarray:
        """The (H, W, 3) uint8 image."""
        return np.frombuffer(zlib.decompress(self._rgb), dtype=np.uint8).reshape(*self.shape, 3)

    def instance(self) -> np.ndarray:
        """The (H, W) int32 instance image."""
        return np.frombuffer(zlib.decompress(self._instance), dtype=np.int32).reshape(self.shape)

    def depth(self) -> np.ndarray:
        """The depth image subsampled by ``DEPTH_STRIDE`` (float16, NaN where nothing was hit)."""
        h, w = self.shape
        return np.frombuffer(zlib.decompress(self._depth), dtype=np.float16).reshape(
            -(-h // DEPTH_STRIDE), -(-w // DEPTH_STRIDE)
        )

    @functools.cached_property
    def png(self) -> bytes:
        """The RGB image as PNG, encoded on first use (most kept frames are never sent)."""
        return png_bytes(self.rgb())


def camera_pose(T_world_cam: np.ndarray) -> tuple[float, float, float]:
    """(x, y, yaw) of a camera pose: its position and the heading of its optical axis."""
    forward = T_world_cam[:3, 2]
    return float(T_world_cam[0, 3]), float(T_world_cam[1, 3]), math.atan2(float(forward[1]), float(forward[0]))


def _packed(array: np.ndarray, dtype: type) -> bytes:
    return zlib.compress(np.ascontiguousarray(array, dtype=dtype).tobytes(), 1)


def memory_frame(frame: Frame, *, index: int, step: int) -> MemoryFrame:
    """A buffer entry for ``frame`` (arrays zlib-compressed: about 1.5 ms and a few tens of kB per frame)."""
    counts = frame.instance_pixels
    return MemoryFrame(
        index=index,
        step=step,
        pose=camera_pose(frame.T_world_cam),
        instance_ids=frozenset(int(i) for i in np.flatnonzero(counts) if i != 0),
        K=frame.K.copy(),
        T_world_cam=frame.T_world_cam.copy(),
        shape=frame.instance.shape,
        _rgb=_packed(frame.rgb, np.uint8),
        _instance=_packed(frame.instance, np.int32),
        _depth=_packed(frame.depth[::DEPTH_STRIDE, ::DEPTH_STRIDE], np.float16),
    )


class VisualMemory:
    """The frame buffer of one episode; ``offer`` every rendered frame, it keeps some (module docstring)."""

    def __init__(self, config: MemoryConfig | None = None) -> None:
        self.config = config or MemoryConfig()
        self.schedule = SensingSchedule(self.config.keep)
        """When the next frame is kept: the rule the embodiment's mapper fuses frames on the way by."""
        self.frames: list[MemoryFrame] = []
        self.step = 0
        """The high-level step frames are captured in now (the planner advances it)."""

    def offer(self, frame: Frame) -> MemoryFrame | None:
        """Keep ``frame`` if the camera moved or turned enough since the last kept frame; the new entry or None."""
        pose = camera_pose(frame.T_world_cam)
        if not self.schedule.due(*pose):
            return None
        self.schedule.fused(*pose)
        kept = memory_frame(frame, index=len(self.frames), step=self.step)
        self.frames.append(kept)
        return kept

    def since(self, index: int) -> list[MemoryFrame]:
        """Frames kept at or after buffer position ``index``."""
        return self.frames[index:]


def shows_points(frame: MemoryFrame, points_xy: np.ndarray, *, z_m: float = 0.0, margin_m: float = 0.3) -> np.ndarray:
    """(N,) bool: which ground points (x, y at height ``z_m``) the frame saw: in view, in front of the
    camera and not hidden (its depth there reaches within ``margin_m`` of the point, or saw nothing)."""
    if len(points_xy) == 0:
        return np.zeros(0, dtype=bool)
    pts = np.column_stack([np.asarray(points_xy, dtype=float), np.full(len(points_xy), z_m)])
    uv, z = project(pts, frame.K, frame.T_world_cam)
    h, w = frame.shape
    inside = (z > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
    out = np.zeros(len(pts), dtype=bool)
    if not inside.any():
        return out
    depth = frame.depth()
    cols = (uv[inside, 0] // DEPTH_STRIDE).astype(int)
    rows = (uv[inside, 1] // DEPTH_STRIDE).astype(int)
    seen = depth[rows, cols].astype(np.float32)
    out[inside] = np.isnan(seen) | (seen >= z[inside] - margin_m)
    return out


def covering_frames(
    frames: Sequence[MemoryFrame],
    wanted: Collection[int],
    limit: int,
    *,
    shown: Callable[[MemoryFrame], Set[int]] = lambda f: f.instance_ids,
) -> list[MemoryFrame]:
    """At most ``limit`` frames that together show as many ``wanted`` things as possible (greedy set
    cover: each pick adds the most not yet shown, ties to the most recent frame), in buffer order.
    ``shown(frame)`` is what a frame shows: its instance ids by default."""
    remaining = set(wanted)
    candidates = [f for f in frames if shown(f) & remaining]
    picked: list[MemoryFrame] = []
    while remaining and candidates and len(picked) < limit:
        best = max(candidates, key=lambda f: (len(shown(f) & remaining), f.index))
        if not shown(best) & remaining:
            break
        picked.append(best)
        remaining -= shown(best)
        candidates.remove(best)
    return sorted(picked, key=lambda f: f.index)


def spread(frames: Sequence[MemoryFrame], limit: int) -> list[MemoryFrame]:
    """At most ``limit`` frames evenly spaced over ``frames`` (first and last kept)."""
    if len(frames) <= limit:
        return list(frames)
    picks = np.unique(np.round(np.linspace(0, len(frames) - 1, limit)).astype(int))
    return [frames[i] for i in picks]
