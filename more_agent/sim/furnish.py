"""Furniture placement inside one rectangular room, with a reachability check on a raster.

Rules that keep every piece reachable by a robot disc: a piece against a wall keeps a walkway from
the other walls and from anything not on its own wall; a free-standing piece keeps a walkway from
everything; nothing enters the zone in front of a door. The result is then verified on a free-space
grid (robot disc inflated, flood fill from the doors) and the room is refurnished if it fails.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import ndimage

from more_agent.sim.catalog import SUPPORT_CATEGORIES, VEHICLE_CATEGORIES, WALL_MOUNTED_CATEGORIES

Rect = tuple[float, float, float, float]
Vec3 = tuple[float, float, float]

_SIDES = ("S", "N", "W", "E")
_DOOR = "door"  # tag of a door zone: it is walkway itself, so pieces may come up to it
_GAP_M = 0.05
_TRIES = 40
_MOUNT_LEVELS = 3
_LEVEL_STEP_M = 0.45
_MAX_MOUNT_TOP_M = 2.5
_EDGE_INSET_M = 0.05
_WALL_CLEAR_M = 0.01  # between a wall face and the furniture against it


class _Obstacles:
    """Footprints placed so far, each tagged with the wall it stands against ('' if none). Plain floats:
    a room holds a few dozen, and ``clear`` is asked tens of thousands of times per scene, where a loop
    that stops at the first overlap beats numpy's per-call overhead (3x at 20 pieces)."""

    def __init__(self) -> None:
        self.boxes: list[tuple[float, float, float, float]] = []
        self.sides: list[int] = []  # index in _SIDES + 1, 0 = free-standing, -2 = a door zone

    def add(self, rect: Rect, side: str) -> None:
        self.boxes.append((float(rect[0]), float(rect[1]), float(rect[2]), float(rect[3])))
        self.sides.append(_SIDES.index(side) + 1 if side in _SIDES else (-2 if side == _DOOR else 0))

    def clear(self, rect: Rect, side: str, walk: float) -> bool:
        """True if ``rect`` keeps ``_GAP_M`` from same-wall pieces and ``walk`` from all others."""
        code = _SIDES.index(side) + 1 if side else -1
        x0, y0, x1, y1 = rect
        for (b0, b1, b2, b3), c in zip(self.boxes, self.sides):
            gap = _GAP_M if c in (code, -2) else walk
            if x0 < b2 + gap and x1 > b0 - gap and y0 < b3 + gap and y1 > b1 - gap:
                return False
        return True


def furnish_room(
    rect: Rect,
    items: list,
    keepouts: list,
    rng: np.random.Generator,
    *,
    driveway: Rect | None,
    k: dict,
    attempts: int = 6,
) -> list[tuple[Any, Vec3, Vec3]] | None:
    """Place ``items`` in the room; returns (item, centre, rotated size) per item, or None on failure."""
    m = k["t"] / 2 + _WALL_CLEAR_M
    inner = (rect[0] + m, rect[1] + m, rect[2] - m, rect[3] - m)
    for _ in range(attempts):
        placed = _try_furnish(inner, items, keepouts, rng, driveway, k)
        if placed is not None and _reachable(inner, placed, keepouts, k):
            return placed
    return None


def _try_furnish(inner, items, keepouts, rng, driveway, k):
    floor = _Obstacles()
    for ko in keepouts:
        if ko.is_door:
            floor.add(ko.rect, _DOOR)
    out: list[tuple[object, Vec3, Vec3]] = []
    for it in items:
        if it.role in ("floor", "free"):
            region = driveway if it.category in VEHICLE_CATEGORIES else None
            got = _place_floor(inner, it, floor, rng, k["walk"], region)
            if got is None:
                return None
            out.append(got)
    supports = [(i, c, s) for i, c, s in out if i.category in SUPPORT_CATEGORIES]
    tops: dict[int, _Obstacles] = {}
    levels: list[_Obstacles] = []
    for it in items:
        if it.role == "surface":
            got = _place_on_support(inner, it, supports, tops, rng)
            if got is None:
                got = _place_floor(inner, it, floor, rng, k["walk"], None)
            if got is None:
                return None
            out.append(got)
        elif it.role == "wall":
            got = _place_mounted(inner, it, levels, keepouts, out, rng)
            if got is None:
                return None
            out.append(got)
        elif it.role == "carpet":
            out.append(_place_carpet(inner, it, rng))
    return out


def _wall_rect(inner: Rect, side: str, along: float, depth: float, pos: float) -> Rect:
    x0, y0, x1, y1 = inner
    if side == "S":
        return (pos, y0, pos + along, y0 + depth)
    if side == "N":
        return (pos, y1 - depth, pos + along, y1)
    if side == "W":
        return (x0, pos, x0 + depth, pos + along)
    return (x1 - depth, pos, x1, pos + along)


def _place_floor(inner, it, obstacles: _Obstacles, rng, walk, region):
    """Against a wall (unless free-standing) or free-standing, keeping the walkway rules."""
    sx, sy, sz = it.size
    long_, short = max(sx, sy), min(sx, sy)
    x0, y0, x1, y1 = inner
    for n in range(_TRIES):
        against_wall = (it.role != "free") == (n < 3 * _TRIES // 4)
        if region is None and against_wall:
            side = _SIDES[int(rng.integers(4))]
            lo_a, hi_a = (x0, x1) if side in "SN" else (y0, y1)
            room_depth = (y1 - y0) if side in "SN" else (x1 - x0)
            if short > room_depth - walk - 0.6:
                continue
            span = hi_a - lo_a - long_
            if span < 0:
                continue
            r = _wall_rect(inner, side, long_, short, lo_a + float(rng.random()) * span)
            if obstacles.clear(r, side, walk):
                obstacles.add(r, side)
                return it, _center(r, sz), (r[2] - r[0], r[3] - r[1], sz)
        else:
            w, h = (long_, short) if rng.random() < 0.5 else (short, long_)
            bx0, by0, bx1, by1 = region if region is not None else (x0 + walk, y0 + walk, x1 - walk, y1 - walk)
            if bx1 - bx0 < w or by1 - by0 < h:
                continue
            px = bx0 + float(rng.random()) * (bx1 - bx0 - w)
            py = by0 + float(rng.random()) * (by1 - by0 - h)
            r = (px, py, px + w, py + h)
            if obstacles.clear(r, "", walk):
                obstacles.add(r, "")
                return it, _center(r, sz), (w, h, sz)
    return None


def _center(r: Rect, sz: float, z0: float = 0.0) -> Vec3:
    return ((r[0] + r[2]) / 2, (r[1] + r[3]) / 2, z0 + sz / 2)


def _place_on_support(inner, it, supports, tops: dict[int, _Obstacles], rng):
    """On top of a random support piece whose top holds the item's footprint."""
    sx, sy, sz = it.size
    centre = ((inner[0] + inner[2]) / 2, (inner[1] + inner[3]) / 2)
    if not supports:
        return None
    for _ in range(_TRIES // 2):
        idx = int(rng.integers(len(supports)))
        _, (cx, cy, cz), (wx, wy, wz) = supports[idx]
        w, h = (sx, sy) if rng.random() < 0.5 else (sy, sx)
        if w > wx or h > wy:
            continue
        px = cx - wx / 2 + float(rng.random()) * (wx - w)
        py = cy - wy / 2 + float(rng.random()) * (wy - h)
        # near the edge of the top that faces the room centre, within the robot's reach
        mids = [(cx - wx / 2, cy), (cx + wx / 2, cy), (cx, cy - wy / 2), (cx, cy + wy / 2)]
        edge = min(range(4), key=lambda e: np.hypot(mids[e][0] - centre[0], mids[e][1] - centre[1]))
        inset = min(_EDGE_INSET_M, (wx - w) / 2 if edge < 2 else (wy - h) / 2)
        if edge < 2:
            px = cx - wx / 2 + inset if edge == 0 else cx + wx / 2 - inset - w
        else:
            py = cy - wy / 2 + inset if edge == 2 else cy + wy / 2 - inset - h
        r = (px, py, px + w, py + h)
        top = tops.setdefault(idx, _Obstacles())
        if top.clear(r, "", 0.02):
            top.add(r, "")
            return it, _center(r, sz, cz + wz / 2), (w, h, sz)
    return None


def _place_mounted(inner, it, levels: list[_Obstacles], keepouts, placed, rng):
    """Hung on a wall at the category's height (or one to three shelf levels higher), clear of
    openings, other hung pieces and tall furniture."""
    sx, sy, sz = it.size
    long_, short = max(sx, sy), min(sx, sy)
    for n in range(_TRIES):
        level = n * _MOUNT_LEVELS // _TRIES
        z0 = WALL_MOUNTED_CATEGORIES[it.category] + _LEVEL_STEP_M * level
        if z0 + sz > _MAX_MOUNT_TOP_M and level > 0:
            break
        z0 = max(min(z0, _MAX_MOUNT_TOP_M - sz), 0.0)
        while len(levels) <= level:
            levels.append(_Obstacles())
            for ko in keepouts:
                levels[-1].add(ko.rect, ko.side)
        side = _SIDES[int(rng.integers(4))]
        lo_a, hi_a = (inner[0], inner[2]) if side in "SN" else (inner[1], inner[3])
        span = hi_a - lo_a - 0.2 - long_
        if span < 0:
            continue
        r = _wall_rect(inner, side, long_, short, lo_a + 0.1 + float(rng.random()) * span)
        tall = any(
            cz + wz / 2 > z0 and _overlap(r, _footprint((cx, cy, cz), (wx, wy, wz)))
            for _, (cx, cy, cz), (wx, wy, wz) in placed
        )
        if not tall and levels[level].clear(r, side, 0.02):
            levels[level].add(r, side)
            return it, _center(r, sz, z0), (r[2] - r[0], r[3] - r[1], sz)
    return None


def _overlap(a: Rect, b: Rect) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _place_carpet(inner, it, rng):
    sx, sy, sz = it.size
    w, h = (sx, sy) if rng.random() < 0.5 else (sy, sx)
    w, h = min(w, inner[2] - inner[0] - 0.4), min(h, inner[3] - inner[1] - 0.4)
    px = inner[0] + 0.2 + float(rng.random()) * (inner[2] - inner[0] - 0.4 - w)
    py = inner[1] + 0.2 + float(rng.random()) * (inner[3] - inner[1] - 0.4 - h)
    return it, (px + w / 2, py + h / 2, sz / 2), (w, h, sz)


def reach_grid(inner: Rect, boxes: list[Rect], *, robot_radius_m: float, resolution_m: float):
    """Cell centres (xs, ys) and the robot-free mask of a rectangle with box obstacles.

    A cell is free when a disc of ``robot_radius_m`` centred there touches no box and stays
    inside ``inner``.
    """
    res = resolution_m
    nx_ = max(int(np.ceil((inner[2] - inner[0]) / res)), 1)
    ny_ = max(int(np.ceil((inner[3] - inner[1]) / res)), 1)
    xs = inner[0] + (np.arange(nx_) + 0.5) * res
    ys = inner[1] + (np.arange(ny_) + 0.5) * res
    occ = np.zeros((ny_ + 2, nx_ + 2), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    for b in boxes:
        i0, i1 = np.searchsorted(xs, b[0]), np.searchsorted(xs, b[2])
        j0, j1 = np.searchsorted(ys, b[1]), np.searchsorted(ys, b[3])
        occ[j0 + 1 : j1 + 1, i0 + 1 : i1 + 1] = True
    dist = ndimage.distance_transform_edt(~occ)[1:-1, 1:-1] * res
    return xs, ys, dist > robot_radius_m + res / 2


def box_distance(xs: np.ndarray, ys: np.ndarray, b: Rect) -> np.ndarray:
    """Distance (m) from every grid cell centre to the rectangle ``b`` (0 inside)."""
    dx = np.maximum(np.maximum(b[0] - xs, xs - b[2]), 0.0)
    dy = np.maximum(np.maximum(b[1] - ys, ys - b[3]), 0.0)
    return np.hypot(dy[:, None], dx[None, :])


def _reachable(inner, placed, keepouts, k) -> bool:
    """Every door zone in one free component, and every piece within reach of that component."""
    boxes = [_footprint(c, s) for it, c, s in placed if it.role in ("floor", "free")]
    xs, ys, free = reach_grid(inner, boxes, robot_radius_m=k["r"], resolution_m=k["res"])
    labels, n = ndimage.label(free)
    if n == 0:
        return False
    common: set[int] | None = None
    for ko in keepouts:
        if ko.is_door:
            m = box_distance(xs, ys, ko.rect) == 0
            found = set(np.unique(labels[m & free]).tolist())
            common = found if common is None else common & found
    if common is None:
        common = {int(np.argmax(np.bincount(labels.ravel())[1:])) + 1}
    if not common:
        return False
    reach = labels == min(common)
    return all(within_reach(xs, ys, reach, _footprint(c, s), k["reach"]) for it, c, s in placed if it.role != "carpet")


def within_reach(xs: np.ndarray, ys: np.ndarray, mask: np.ndarray, b: Rect, reach_m: float) -> bool:
    """True if some cell of ``mask`` (on the grid ``xs`` x ``ys``) lies within ``reach_m`` of rectangle ``b``."""
    i0, i1 = np.searchsorted(xs, b[0] - reach_m), np.searchsorted(xs, b[2] + reach_m)
    j0, j1 = np.searchsorted(ys, b[1] - reach_m), np.searchsorted(ys, b[3] + reach_m)
    near = box_distance(xs[i0:i1], ys[j0:j1], b) <= reach_m
    return bool((mask[j0:j1, i0:i1] & near).any())


def _footprint(c: Vec3, s: Vec3) -> Rect:
    return (c[0] - s[0] / 2, c[1] - s[1] / 2, c[0] + s[0] / 2, c[1] + s[1] / 2)
