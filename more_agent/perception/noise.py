"""Perception errors as array operations on one posed frame (depth, semantic, instance) and on the pose.

Every function here is pure numpy over whole frames: per-instance quantities are ``np.bincount``
sums indexed by instance id, and per-pixel changes are look-ups of per-instance tables by the
instance frame, so a frame costs the same whatever the number of objects in view. What is decided
once per episode (which instances are confused, fragmented, merged) lives in :class:`InstanceTables`;
what is drawn per frame (misses, depth noise) comes from the episode's generator, so the same
episode replays the same errors. The kinds and their rates: :class:`~more_agent.perception_spec.PerceptionSpec`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

TYPICAL_RANGE_M = 2.5
"""Range at which the miss rate is quoted."""
TYPICAL_SIZE_M = 0.3
"""Size (largest extent) at which the miss rate is quoted."""
MAX_MISS = 0.95
"""No instance is missed surely: a frame that sees it whole and close has at least 5 % to detect it."""
MERGE_DEPTH_M = 0.5
"""Two instances merge only when their mean depths differ by less than this ..."""
MERGE_PIXELS = 48.0
"""... and their pixel centroids lie closer than this."""
MIN_FRAGMENT_PIXELS = 8
"""An instance is split only when it covers at least this many pixels."""


@dataclass(frozen=True)
class InstanceTables:
    """Per-instance facts and per-episode draws, indexed by instance id (0: walls, ground, nothing)."""

    size_m: np.ndarray
    """(n,) float: largest extent of the object's box, m."""
    eligible: np.ndarray
    """(n,) bool: items and furniture (doors and the ground are never mis-detected: they are the map's structure)."""
    seen_class: np.ndarray
    """(n,) int: the semantic class the instance is seen as for the episode (its own, or a confused relative's)."""
    confused: np.ndarray
    """(n,) bool: ``seen_class`` is not its own."""
    fragment: np.ndarray
    """(n,) bool: the instance is seen as two."""
    merge: np.ndarray
    """(n,) bool: the instance is seen as part of a close neighbour."""


@dataclass(frozen=True)
class Detections:
    """What a detector with errors reports for one frame."""

    semantic: np.ndarray
    """(H, W) semantic frame as perceived."""
    instance: np.ndarray
    """(H, W) instance frame as perceived; the second piece of a fragmented instance ``i`` is ``n + i``
    (``n``: the length of the instance tables)."""
    whole: np.ndarray
    """(H, W) the same before fragmenting: each fragment under the id of its whole instance."""
    split: np.ndarray
    """(k,) ids of the instances seen in two pieces in this frame."""
    in_view: np.ndarray
    """(n,) bool: the instance was in the true frame."""
    kept: np.ndarray
    """(n,) bool: in view and reported under its own id (not missed, not merged)."""


class DepthNoise:
    """Unit Gaussian noise for depth frames, drawn once per episode into a bank and read from a random
    offset per frame: a frame costs one slice and one multiply instead of a fresh draw per pixel."""

    BANK = 1 << 20

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.bank = rng.standard_normal(self.BANK, dtype=np.float32)

    def apply(self, depth: np.ndarray, sigma_per_m: float) -> np.ndarray:
        """z-depth with error of standard deviation ``sigma_per_m`` x range (NaN stays NaN).

        >>> d = np.full((2, 2), 2.0, dtype=np.float32); d[0, 0] = np.nan
        >>> out = DepthNoise(np.random.default_rng(0)).apply(d, 0.0); bool(np.isnan(out[0, 0])), float(out[1, 1])
        (True, 2.0)
        """
        if sigma_per_m <= 0:
            return depth
        start = int(self.rng.integers(self.BANK - depth.size))
        noise = self.bank[start : start + depth.size].reshape(depth.shape)
        return depth * (np.float32(1.0) + np.float32(sigma_per_m) * noise)


@cache
def _pixel_coords(shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Column and row of every ``STATS_STRIDE``-th pixel of a frame of ``shape``, flattened, float64."""
    rows, cols = np.indices(shape, dtype=np.float64)[:, ::STATS_STRIDE, ::STATS_STRIDE]
    return cols.ravel(), rows.ravel()


@cache
def _columns(shape: tuple[int, int]) -> np.ndarray:
    """(1, W) column index of a frame of ``shape``."""
    return np.arange(shape[1], dtype=np.float64)[None, :]


STATS_STRIDE = 4
"""Mean depth and centroids are taken over every fourth pixel in each direction (a sixteenth of the cost of
bincount sums with weights, within a few pixels for anything a detector can see); an instance no sampled
pixel hits counts as at the far end of the range."""
FAR_M = 5.0
"""Range given to an instance in view that no sampled pixel hits (a sliver): the camera's range."""


def instance_stats(
    instance: np.ndarray, depth: np.ndarray, n: int, rows: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per instance id < ``n``: pixel count (full frame), mean depth (NaN pixels count as 0 m; ``FAR_M`` for a
    sliver no sampled pixel hits, inf when unseen) and pixel centroid (n, 2) as (column, row), these two over
    every ``STATS_STRIDE``-th pixel; the row is 0 unless ``rows``."""
    counts = np.bincount(instance.ravel(), minlength=n)[:n].astype(np.float64)
    sub = instance[::STATS_STRIDE, ::STATS_STRIDE].ravel()
    cols, rws = _pixel_coords(instance.shape)
    sampled = np.bincount(sub, minlength=n)[:n]
    safe = np.maximum(sampled, 1.0)
    mean_depth = (
        np.bincount(sub, weights=np.nan_to_num(depth[::STATS_STRIDE, ::STATS_STRIDE].ravel()), minlength=n)[:n] / safe
    )
    centroid = np.zeros((n, 2))
    centroid[:, 0] = np.bincount(sub, weights=cols, minlength=n)[:n] / safe
    if rows:
        centroid[:, 1] = np.bincount(sub, weights=rws, minlength=n)[:n] / safe
    mean_depth = np.where(sampled > 0, mean_depth, FAR_M)
    return counts, np.where(counts > 0, mean_depth, np.inf), centroid


def miss_probability(rate: float, range_m: np.ndarray, visible: np.ndarray, size_m: np.ndarray) -> np.ndarray:
    """Chance that an instance in view goes undetected in one frame.

    ``rate`` is the chance for a typical item: ``TYPICAL_SIZE_M`` large, half visible, ``TYPICAL_RANGE_M``
    away. It grows linearly with range, with the hidden share (``1.25 - visible``: a fully visible object
    keeps a third of the half-hidden chance) and as ``TYPICAL_SIZE_M / size`` for small objects (at most 2x,
    below 0.15 m; at least 1/4, over 1.2 m); capped at ``MAX_MISS``.

    >>> miss_probability(0.2, np.array([2.5, 5.0]), np.array([0.5, 0.5]), np.array([0.3, 0.3])).round(3)
    array([0.2, 0.4])
    """
    size_term = np.clip(TYPICAL_SIZE_M / np.maximum(size_m, 1e-3), 0.25, 2.0)
    p = rate * (range_m / TYPICAL_RANGE_M) * ((1.25 - np.clip(visible, 0.0, 1.0)) / 0.75) * size_term
    return np.clip(p, 0.0, MAX_MISS)


def visible_share(counts: np.ndarray, range_m: np.ndarray, size_m: np.ndarray, fx: float) -> np.ndarray:
    """Share of an object's expected image area that shows: pixels / (fx size / range)^2 / 2, clipped to [0, 1]
    (half the square of its largest extent: a box seen from a typical side)."""
    expected = 0.5 * (fx * size_m / np.maximum(range_m, 0.05)) ** 2
    return np.clip(counts / np.maximum(expected, 1.0), 0.0, 1.0)


def merge_partners(counts: np.ndarray, mean_depth: np.ndarray, centroid: np.ndarray, movers: np.ndarray) -> np.ndarray:
    """(n,) the instance each id in ``movers`` is merged into: the instance with ``counts`` > 0 whose pixel
    centroid is nearest, when within ``MERGE_PIXELS`` and ``MERGE_DEPTH_M``; every other id maps to itself."""
    partner = np.arange(len(counts))
    shown = np.flatnonzero(counts > 0)
    if len(movers) == 0 or len(shown) < 2:
        return partner
    pix = np.linalg.norm(centroid[movers, None, :] - centroid[None, shown, :], axis=2)
    pix[movers[:, None] == shown[None, :]] = np.inf
    pix[np.abs(mean_depth[movers, None] - mean_depth[None, shown]) >= MERGE_DEPTH_M] = np.inf
    best = np.argmin(pix, axis=1)
    ok = pix[np.arange(len(movers)), best] < MERGE_PIXELS
    partner[movers[ok]] = shown[best[ok]]
    return partner


def perturb_instances(
    depth: np.ndarray,
    semantic: np.ndarray,
    instance: np.ndarray,
    fx: float,
    tables: InstanceTables,
    miss_rate: float,
    rng: np.random.Generator,
) -> Detections:
    """The semantic and instance frames a detector with these errors reports for one frame.

    Missed instances become unlabelled (semantic 0, instance 0: their depth stays, as an unknown
    obstacle); merged ones take their partner's id and class; a fragmented one's pixels right of its
    centroid column take id ``n + i`` (``n`` instance ids in the tables); confused ones keep their id and show their episode's
    relative's class. Decisions are made per instance id (one draw each per frame, whatever is in view)
    and applied to the frames as look-ups of per-instance tables.
    """
    n, inst = len(tables.size_m), instance  # the world's ids: all below n
    counts, mean_depth, centroid = instance_stats(inst, depth, n, rows=bool(tables.merge.any()))
    in_view = counts > 0
    counts[0] = 0
    shown = (counts > 0) & tables.eligible
    missed = np.zeros(n, dtype=bool)
    draw = rng.random(n)
    if miss_rate > 0:
        visible = visible_share(counts, mean_depth, tables.size_m, fx)
        missed = shown & (draw < miss_probability(miss_rate, mean_depth, visible, tables.size_m))
    targets = np.where(missed | ~tables.eligible, 0, counts)
    lut = merge_partners(targets, mean_depth, centroid, np.flatnonzero(shown & ~missed & tables.merge))
    lut[missed] = 0
    moved = lut != np.arange(n)
    out_inst, out_sem = inst, semantic
    if (moved | tables.confused)[in_view].any():
        out_inst = lut[inst]
        relabel = np.where(moved | tables.confused, np.where(lut > 0, tables.seen_class[lut], 0), -1)
        new_class = relabel[inst]
        out_sem = np.where(new_class >= 0, new_class, semantic).astype(semantic.dtype, copy=False)
    whole = out_inst.astype(instance.dtype, copy=False)
    split = shown & ~moved & tables.fragment & (counts >= MIN_FRAGMENT_PIXELS)
    pieces = whole
    if split.any():
        right = _columns(inst.shape) > np.where(split, centroid[:, 0], np.inf)[whole]
        pieces = np.where(right, whole + n, whole).astype(instance.dtype, copy=False)
    return Detections(
        semantic=out_sem,
        instance=pieces,
        whole=whole,
        split=np.flatnonzero(split),
        in_view=in_view,
        kept=in_view & ~moved,
    )


def drift_step(
    drift: np.ndarray, xy: tuple[float, float], distance_m: float, sigma: float, rng: np.random.Generator
) -> np.ndarray:
    """The odometry drift (3x3 homogeneous 2D transform, true -> believed) after driving ``distance_m`` more
    from true position ``xy``: a random walk, position std ``sigma`` sqrt(d) per axis and heading std
    ``sigma / 2`` sqrt(d) rad, the heading error turning about where the robot believes it stands."""
    if sigma <= 0 or distance_m <= 0:
        return drift
    dx, dy = rng.normal(0.0, sigma * math.sqrt(distance_m), 2)
    dyaw = rng.normal(0.0, 0.5 * sigma * math.sqrt(distance_m))
    px, py, _ = drift @ np.array([xy[0], xy[1], 1.0])
    c, s = math.cos(dyaw), math.sin(dyaw)
    turn = np.array([[c, -s, px - c * px + s * py + dx], [s, c, py - s * px - c * py + dy], [0.0, 0.0, 1.0]])
    return turn @ drift


def drifted_pose(drift: np.ndarray, T_world_cam: np.ndarray) -> np.ndarray:
    """The 4x4 camera pose the robot believes in: the 2D drift applied in the ground plane."""
    lift = np.eye(4)
    lift[:2, :2], lift[:2, 3] = drift[:2, :2], drift[:2, 2]
    return lift @ T_world_cam
