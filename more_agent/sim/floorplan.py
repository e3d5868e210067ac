"""Deterministic floor-plan generator: a BEHAVIOR-1K room list -> a ``Scene``.

Rooms get an area from their type and their furniture; indoor rooms tile the house rectangle
(squarified treemap), gardens are bands along the house sides. Walls run along every room edge,
doors sit on shared walls along a random spanning tree of the indoor rooms' adjacency graph (plus a few
extra), and a garden gets the doors its inventory lists on walls it shares with the house; windows sit in
exterior walls. Furniture goes against walls or free-standing with walkways, and each room is checked
on a raster so that a robot disc reaches every piece; a room that fails is refurnished, and if it still
fails the scene is laid out again with that room larger. Same (name, seed) -> same plan.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import networkx as nx
import numpy as np

from more_agent.sim import catalog
from more_agent.sim.furnish import furnish_room
from more_agent.sim.scene import Door, Furniture, GroundPatch, Room, Scene, Wall, Window
from more_agent.vocabulary import OUTDOOR_ROOM_TYPES, room_type

Rect = tuple[float, float, float, float]

TYPICAL_AREA_M2: dict[str, tuple[float, float]] = {
    "kitchen": (12, 20),
    "bathroom": (5, 8),
    "bedroom": (12, 16),
    "childs_room": (10, 14),
    "living_room": (20, 35),
    "dining_room": (14, 22),
    "television_room": (14, 22),
    "corridor": (6, 12),
    "entryway": (5, 9),
    "closet": (2.5, 5),
    "pantry_room": (3, 6),
    "storage_room": (6, 12),
    "utility_room": (6, 10),
    "garage": (30, 42),
    "garden": (60, 150),
    "staircase": (6, 10),
    "private_office": (10, 16),
    "shared_office": (25, 45),
    "meeting_room": (16, 30),
    "copy_room": (6, 10),
    "phone_room": (3, 5),
    "break_room": (12, 20),
    "conference_hall": (80, 150),
    "lobby": (40, 80),
    "grocery_store": (150, 300),
    "classroom": (50, 70),
    "biology_lab": (50, 70),
    "chemistry_lab": (50, 70),
    "computer_lab": (50, 70),
    "infirmary": (20, 30),
    "gym": (80, 150),
    "bar": (30, 60),
    "spa": (20, 40),
    "sauna": (6, 10),
    "hammam": (20, 35),
    "locker_room": (20, 35),
    "exercise_room": (20, 35),
    "playroom": (12, 20),
    "empty_room": (10, 20),
}
"""Plausible (min, max) floor area per BEHAVIOR room type; others get (10, 20)."""

FURNISH_RADIUS_M = 0.3
"""Robot radius rooms are furnished for: the robot's (``RobotSpec.radius_m``, 0.2 m) plus a 0.1 m margin."""

FURNISH_REACH_M = 1.0
"""Reach every piece of furniture must be within from the free floor: 0.5 m short of the robot's
(``RobotSpec.reach_m``), so that every generated piece is comfortably reachable."""

DOOR_HEIGHT_M = 2.1
WINDOW_SILL_M, WINDOW_TOP_M = 0.9, 2.0
FENCE_HEIGHT_M = 1.0
DRIVEWAY_DEPTH_M = 4.0
_END_MARGIN_M = 0.35  # door/window distance from a wall run's ends

DOOR_CATEGORIES = frozenset({"door", "sliding_door", "garage_door"})
"""Inventory categories of doors between rooms (elevator doors lead nowhere in a one-floor plan)."""


@dataclass(frozen=True)
class _Item:
    category: str
    model: str
    size: tuple[float, float, float]
    role: str


@dataclass(frozen=True)
class _Run:
    """A straight piece of wall line with the same room on each side; axis = the wall's direction."""

    axis: str
    coord: float
    lo: float
    hi: float
    neg: str | None
    pos: str | None


@dataclass(frozen=True)
class _Keepout:
    rect: Rect
    side: str  # the room wall it touches: 'S', 'N', 'W', 'E'
    is_door: bool


class _Retry(Exception):
    """This layout attempt cannot hold one room's furniture; lay out again with that room larger."""

    def __init__(self, room: str) -> None:
        super().__init__(room)
        self.room = room


def generate_floorplan(
    name: str,
    rooms: dict[str, dict[str, int]],
    *,
    rng: np.random.Generator,
    seed: int = 0,
    wall_thickness_m: float = 0.1,
    wall_height_m: float = 2.6,
    door_width_m: float = 0.9,
    closed_door_fraction: float = 0.3,
    extra_door_probability: float = 0.2,
    clearance_factor: float = 2.5,
    walkway_m: float = 0.8,
    door_clear_m: float = 1.0,
    robot_radius_m: float = FURNISH_RADIUS_M,
    reach_m: float = FURNISH_REACH_M,
    resolution_m: float = 0.075,
    max_attempts: int = 12,
) -> Scene:
    """Lay out ``rooms`` (room id -> {'category-model': count}, as in bddl) as a Scene.

    ``seed`` is only recorded in the scene; all randomness comes from ``rng``. Knobs are in metres.
    """
    k = dict(
        t=wall_thickness_m,
        walk=walkway_m,
        door_w=door_width_m,
        door_clear=door_clear_m,
        r=robot_radius_m,
        reach=reach_m,
        res=resolution_m,
    )
    items = {room: _room_items(objs) for room, objs in rooms.items()}
    growth = dict.fromkeys(rooms, 1.0)
    for _ in range(max_attempts):
        plan, growth = _try_layout(
            rooms, items, growth, rng, clearance_factor, closed_door_fraction, extra_door_probability, wall_height_m, k
        )
        if plan is not None:
            return _scene(name, seed, rooms, plan, wall_height_m, wall_thickness_m)
    raise RuntimeError(f"could not lay out scene {name!r} in {max_attempts} attempts")


@dataclass
class _Plan:
    """A laid-out, furnished floor plan: what a ``Scene`` is made of."""

    rects: dict[str, Rect]
    walls: list[Wall]
    doors: list[Door]
    windows: list[Window]
    furniture: list[Furniture]
    patches: list[GroundPatch]


def _try_layout(
    rooms: dict[str, dict[str, int]],
    items: dict[str, list[_Item]],
    growth: dict[str, float],
    rng: np.random.Generator,
    clearance_factor: float,
    closed_door_fraction: float,
    extra_door_probability: float,
    wall_height_m: float,
    k: dict[str, float],
) -> tuple[_Plan | None, dict[str, float]]:
    """One attempt: rooms laid out at ``growth`` times their size, doors, windows, furniture, walls.

    Returns the plan, or None and the growth to try next: every room a little larger when the doors
    did not fit, otherwise the room whose furniture did not fit (``_grown``).
    """
    rects = _layout(rooms, items, rng, clearance_factor, growth, k)
    runs = _wall_runs(rects)
    listed = {rid: _listed_doors(objs) for rid, objs in rooms.items() if room_type(rid) in OUTDOOR_ROOM_TYPES}
    doors = _place_doors(runs, rects, rng, closed_door_fraction, extra_door_probability, k, listed)
    if doors is None:
        return None, {r: g * 1.1 for r, g in growth.items()}
    windows = _place_windows(runs, doors, rng, k)
    try:
        furniture, patches = _furnish_all(rects, items, doors, windows, rng, k)
    except _Retry as e:
        return None, _grown(growth, e.room)
    walls = _walls(runs, doors, windows, wall_height_m, k)
    return _Plan(rects, walls, doors, windows, furniture, patches), growth


def _grown(growth: dict[str, float], failed: str) -> dict[str, float]:
    """The growth after ``failed``'s furniture did not fit: that room 1.4 times, the rest of its tiling 5 %.

    Indoor rooms tile the house, so one room's growth reshapes its neighbours, and they grow a little
    too. A garden is a band outside, sized by its own furniture: it grows only when that did not fit,
    never for a closet's (house_single_floor's garden grew 1.7 times from other rooms' retries).
    """
    outdoor = room_type(failed) in OUTDOOR_ROOM_TYPES

    def factor(room: str) -> float:
        if room == failed:
            return 1.4
        return 1.0 if outdoor or room_type(room) in OUTDOOR_ROOM_TYPES else 1.05

    return {r: g * factor(r) for r, g in growth.items()}


def _scene(
    name: str, seed: int, rooms: dict[str, dict[str, int]], plan: _Plan, wall_height_m: float, pad: float
) -> Scene:
    """The ``Scene`` of a plan: its rooms in the order given, bounds ``pad`` beyond the outer walls."""
    rects = plan.rects
    allx = [v for r in rects.values() for v in (r[0], r[2])]
    ally = [v for r in rects.values() for v in (r[1], r[3])]
    return Scene(
        name=name,
        seed=seed,
        wall_height=wall_height_m,
        bounds=_round((min(allx) - pad, min(ally) - pad, max(allx) + pad, max(ally) + pad)),
        rooms=[
            Room(
                id=rid,
                type=room_type(rid),
                bounds=rects[rid],
                ground="lawn" if room_type(rid) in OUTDOOR_ROOM_TYPES else "floor",
                outdoor=room_type(rid) in OUTDOOR_ROOM_TYPES,
            )
            for rid in rooms
        ],
        walls=plan.walls,
        doors=plan.doors,
        windows=plan.windows,
        furniture=plan.furniture,
        ground_patches=plan.patches,
    )


def scene_rng(name: str, seed: int) -> np.random.Generator:
    """The generator's random stream for one (scene, seed): stable across runs and platforms."""
    return np.random.default_rng([seed, zlib.crc32(name.encode())])


def _rect(v: tuple[float, ...]) -> Rect:
    """``v`` as a rectangle (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = v
    return (x0, y0, x1, y1)


def _round(v: tuple[float, ...], nd: int = 3) -> tuple[float, ...]:
    return tuple(round(float(x), nd) for x in v)


def _room_items(objs: dict[str, int], wall_top_m: float = 2.5) -> list[_Item]:
    """The room's kept objects, one per instance, largest footprint first."""
    out: list[_Item] = []
    kept: dict[str, int] = {}
    for key, count in objs.items():
        category, model = key.rsplit("-", 1)
        role = catalog.furniture_role(category)
        if role == "skip":
            continue
        size = catalog.model_size(model) or catalog.category_size(category)
        if category == "countertop":
            size = (size[0], size[1], catalog.COUNTER_HEIGHT_M)
        if role == "wall" and catalog.WALL_MOUNTED_CATEGORIES[category] + size[2] > wall_top_m:
            role = "floor"  # too tall to hang: a floor-standing unit
        cap = catalog.ROLE_CAPS.get(category, catalog.MAX_PER_CATEGORY)
        n = min(count, cap - kept.get(category, 0))
        kept[category] = kept.get(category, 0) + max(n, 0)
        out += [_Item(category, model, size, role)] * max(n, 0)
    return sorted(out, key=lambda it: (-it.size[0] * it.size[1], it.category, it.model))


def _room_area(room_id: str, items: list[_Item], rng: np.random.Generator, clearance: float, k: dict) -> float:
    lo, hi = TYPICAL_AREA_M2.get(room_type(room_id), (10.0, 20.0))
    floor = [it for it in items if it.role in ("floor", "free")]
    footprint = sum(it.size[0] * it.size[1] for it in floor)
    # random sequential packing fills about half the plane with walkway-inflated free pieces
    free = sum((it.size[0] + k["walk"]) * (it.size[1] + k["walk"]) for it in floor if it.role == "free")
    walled = sum(max(it.size[:2]) * (min(it.size[:2]) + k["walk"]) for it in floor if it.role == "floor")
    need = max(clearance * footprint, 2.0 * free + 1.3 * walled) + 4.0
    if room_type(room_id) in OUTDOOR_ROOM_TYPES and any(it.category in catalog.VEHICLE_CATEGORIES for it in items):
        need += 30.0
    return max(float(rng.uniform(lo, hi)), need)


def _squarify(areas: list[float], rect: Rect) -> list[Rect]:
    """Squarified treemap (Bruls et al.): tiles of the given areas (summing to the rect's) in order."""
    x0, y0, x1, y1 = rect
    out: list[Rect] = []
    i, n = 0, len(areas)

    def worst(row: list[float], short: float) -> float:
        s = sum(row)
        return max(max(short * short * a / (s * s), s * s / (short * short * a)) for a in row)

    while i < n:
        w, h = x1 - x0, y1 - y0
        short = min(w, h)
        row, j = [areas[i]], i + 1
        while j < n and worst(row + [areas[j]], short) <= worst(row, short):
            row.append(areas[j])
            j += 1
        last_row = j == n
        s = sum(row)
        if w >= h:
            cx = x1 if last_row else x0 + s / h
            yy = y0
            for m, a in enumerate(row):
                ny = y1 if m == len(row) - 1 else yy + a / (cx - x0)
                out.append((x0, yy, cx, ny))
                yy = ny
            x0 = cx
        else:
            cy = y1 if last_row else y0 + s / w
            xx = x0
            for m, a in enumerate(row):
                nx_ = x1 if m == len(row) - 1 else xx + a / (cy - y0)
                out.append((xx, y0, nx_, cy))
                xx = nx_
            y0 = cy
        i = j
    return out


def _layout(rooms, items, rng, clearance, growth: dict[str, float], k) -> dict[str, Rect]:
    """Room rectangles: indoor rooms tile the house, outdoor ones are bands along its sides."""
    areas = {rid: _room_area(rid, items[rid], rng, clearance, k) * growth[rid] for rid in rooms}
    indoor = [rid for rid in rooms if room_type(rid) not in OUTDOOR_ROOM_TYPES]
    outdoor = [rid for rid in rooms if room_type(rid) in OUTDOOR_ROOM_TYPES]
    rects: dict[str, Rect] = {}
    w = h = 0.0
    if indoor:
        total = sum(areas[r] for r in indoor)
        aspect = float(rng.uniform(1.0, 1.7))
        w, h = (total * aspect) ** 0.5, (total / aspect) ** 0.5
        if rng.random() < 0.5:
            w, h = h, w
        jitter = rng.uniform(0.85, 1.15, size=len(indoor))
        order = sorted(range(len(indoor)), key=lambda i: -areas[indoor[i]] * jitter[i])
        tiles = _squarify([areas[indoor[i]] for i in order], (0.0, 0.0, w, h))
        rects = {indoor[i]: _rect(_round(t, 2)) for i, t in zip(order, tiles)}
    long_sides, short_sides = (["S", "N"], ["E", "W"]) if w >= h else (["E", "W"], ["S", "N"])
    sides = [str(s) for s in rng.permutation(long_sides)] + [str(s) for s in rng.permutation(short_sides)]
    offset = dict.fromkeys(sides, 0.0)
    for i, rid in enumerate(outdoor):
        side = sides[i % 4]
        length = w if side in "SN" else h
        if length <= 0:  # a scene of gardens only: square bands side by side
            length = areas[rid] ** 0.5
        depth = max(areas[rid] / length, 7.0)
        o = offset[side]
        rects[rid] = _rect(
            _round(
                {
                    "S": (0, -o - depth, length, -o),
                    "N": (0, h + o, length, h + o + depth),
                    "W": (-o - depth, 0, -o, length),
                    "E": (w + o, 0, w + o + depth, length),
                }[side],
                2,
            )
        )
        offset[side] = o + depth
    return rects


def _wall_runs(rects: dict[str, Rect]) -> list[_Run]:
    """Split every room edge line into runs with the same rooms on both sides."""
    lines: dict[tuple[str, float], list[tuple[float, float, str, str]]] = {}
    for rid, (x0, y0, x1, y1) in rects.items():
        lines.setdefault(("x", y0), []).append((x0, x1, "pos", rid))
        lines.setdefault(("x", y1), []).append((x0, x1, "neg", rid))
        lines.setdefault(("y", x0), []).append((y0, y1, "pos", rid))
        lines.setdefault(("y", x1), []).append((y0, y1, "neg", rid))
    runs: list[_Run] = []
    for (axis, coord), segs in sorted(lines.items()):
        cuts = sorted({v for s in segs for v in s[:2]})
        cur: list = []
        for a, b in zip(cuts, cuts[1:]):
            m = (a + b) / 2
            neg = next((s[3] for s in segs if s[2] == "neg" and s[0] < m < s[1]), None)
            pos = next((s[3] for s in segs if s[2] == "pos" and s[0] < m < s[1]), None)
            if cur and cur[3] == neg and cur[4] == pos and cur[1] == a:
                cur[1] = b
                continue
            if cur and (cur[3] or cur[4]):
                runs.append(_Run(axis, coord, cur[0], cur[1], cur[3], cur[4]))
            cur = [a, b, None, neg, pos]
        if cur and (cur[3] or cur[4]):
            runs.append(_Run(axis, coord, cur[0], cur[1], cur[3], cur[4]))
    return runs


def _listed_doors(objs: dict[str, int]) -> int:
    """Door instances a room's inventory lists (bddl counts a door in the room its centre lies in)."""
    return sum(n for key, n in objs.items() if key.rsplit("-", 1)[0] in DOOR_CATEGORIES)


def _place_doors(runs, rects, rng, closed_fraction, extra_p, k, outdoor_doors) -> list[Door] | None:
    """Doors on a random spanning tree of the indoor rooms' adjacency graph, so the house's rooms connect
    without going outdoors; each outdoor room (``outdoor_doors``: room -> doors its inventory lists) on
    that many random walls it shares with another room (at least one, at most one per wall); and an extra
    door between indoor rooms with probability ``extra_p``. None if the rooms are not connected so."""
    need = k["door_w"] + 2 * _END_MARGIN_M
    best: dict[tuple[str, str], _Run] = {}
    for run in runs:
        if run.neg and run.pos and run.hi - run.lo >= need:
            key = tuple(sorted((run.neg, run.pos)))
            if key not in best or run.hi - run.lo > best[key].hi - best[key].lo:
                best[key] = run
    g = nx.Graph()
    g.add_nodes_from(rects)
    for key in sorted(best):
        g.add_edge(*key, weight=float(rng.random()))
    house = g.subgraph(r for r in rects if r not in outdoor_doors)
    if not nx.is_connected(g) or (house and not nx.is_connected(house)):
        return None
    chosen = {tuple(sorted(e)) for e in nx.minimum_spanning_edges(house, data=False)}
    for room, listed in sorted(outdoor_doors.items()):
        spare = [key for key in sorted(best) if room in key and key not in chosen]
        wanted = min(max(listed, 1), len(spare))
        if wanted > 0:
            chosen.update(spare[i] for i in rng.choice(len(spare), size=wanted, replace=False))
    doors: list[Door] = []
    for key in sorted(best):
        outdoor = any(r in outdoor_doors for r in key)
        if key not in chosen and (outdoor or rng.random() >= extra_p):
            continue
        run = best[key]
        slack = max(run.hi - run.lo - 2 * _END_MARGIN_M - k["door_w"], 0.0)
        c = run.lo + _END_MARGIN_M + k["door_w"] / 2 + float(rng.random()) * slack
        center = (c, run.coord) if run.axis == "x" else (run.coord, c)
        doors.append(
            Door(
                id=f"door_{len(doors)}",
                rooms=(run.neg, run.pos),
                center=_round(center),
                width=k["door_w"],
                axis=run.axis,
                thickness=k["t"],
                height=DOOR_HEIGHT_M,
                open=bool(rng.random() >= closed_fraction),
            )
        )
    return doors


def _on_run(run: _Run, center: tuple[float, float]) -> float | None:
    """Position along the run of an opening centred at ``center``, or None if not on it."""
    along, across = (center[0], center[1]) if run.axis == "x" else (center[1], center[0])
    return along if abs(across - run.coord) < 1e-6 and run.lo < along < run.hi else None


def _place_windows(runs, doors, rng, k) -> list[Window]:
    """One window per exterior wall run of an indoor room (to the void or a garden), clear of doors."""
    out: list[Window] = []
    for run in runs:
        sides = [r for r in (run.neg, run.pos) if r]
        indoor = [r for r in sides if room_type(r) not in OUTDOOR_ROOM_TYPES]
        if len(indoor) != 1 or run.hi - run.lo < 1.8:
            continue
        busy = [a for a in (_on_run(run, d.center) for d in doors) if a is not None]
        width = min(1.5, run.hi - run.lo - 2 * _END_MARGIN_M)
        slack = max(run.hi - run.lo - 2 * _END_MARGIN_M - width, 0.0)
        for _ in range(10):  # keep clear of the run's doors
            c = run.lo + _END_MARGIN_M + width / 2 + float(rng.random()) * slack
            if all(abs(c - a) > width / 2 + 0.45 + _END_MARGIN_M for a in busy):
                break
        else:
            continue
        b = (c - width / 2, run.coord - k["t"] / 2, c + width / 2, run.coord + k["t"] / 2)
        bounds = b if run.axis == "x" else (b[1], b[0], b[3], b[2])
        out.append(
            Window(
                id=f"window_{len(out)}",
                bounds=_round(bounds),
                sill=WINDOW_SILL_M,
                top=WINDOW_TOP_M,
                rooms=tuple(indoor + [r for r in sides if r not in indoor]),
            )
        )
    return out


def _walls(runs, doors, windows, height, k) -> list[Wall]:
    """Wall boxes along every run, with door gaps (lintel above) and window gaps (sill below, top above)."""
    out: list[Wall] = []
    t = k["t"]
    for run in runs:
        indoor = any(r and room_type(r) not in OUTDOOR_ROOM_TYPES for r in (run.neg, run.pos))
        top = height if indoor else FENCE_HEIGHT_M
        gaps = []
        for d in doors:
            a = _on_run(run, d.center)
            if a is not None:
                gaps.append((a - d.width / 2, a + d.width / 2, [(DOOR_HEIGHT_M, top)]))
        for w in windows:
            ctr = ((w.bounds[0] + w.bounds[2]) / 2, (w.bounds[1] + w.bounds[3]) / 2)
            a = _on_run(run, ctr)
            if a is not None:
                half = (w.bounds[2] - w.bounds[0] if run.axis == "x" else w.bounds[3] - w.bounds[1]) / 2
                gaps.append((a - half, a + half, [(0.0, w.sill), (w.top, top)]))
        gaps.sort()
        pieces: list[tuple[float, float, float, float]] = []
        start = run.lo - t / 2
        for g0, g1, spans in gaps:
            pieces.append((start, g0, 0.0, top))
            pieces += [(g0, g1, z0, z1) for z0, z1 in spans if z1 > z0]
            start = g1
        pieces.append((start, run.hi + t / 2, 0.0, top))
        for a0, a1, z0, z1 in pieces:
            if a1 - a0 < 1e-3:
                continue
            b = (a0, run.coord - t / 2, a1, run.coord + t / 2)
            out.append(Wall(bounds=_round(b if run.axis == "x" else (b[1], b[0], b[3], b[2])), z_min=z0, z_max=z1))
    return out


def _keepouts(room_id: str, rect: Rect, doors: list[Door], windows: list[Window], k: dict) -> list[_Keepout]:
    """Zones in front of the room's doors (kept clear) and windows (no wall-mounted furniture)."""
    out = []
    x0, y0, x1, y1 = rect
    openings = [(d.center, d.width + 0.4, k["door_clear"], True) for d in doors if room_id in d.rooms]
    for w in windows:
        if room_id in w.rooms:
            ctr = ((w.bounds[0] + w.bounds[2]) / 2, (w.bounds[1] + w.bounds[3]) / 2)
            openings.append((ctr, max(w.bounds[2] - w.bounds[0], w.bounds[3] - w.bounds[1]), 0.4, False))
    for (cx, cy), width, depth, is_door in openings:
        if abs(cy - y0) < 1e-6 and x0 < cx < x1:
            out.append(_Keepout((cx - width / 2, y0, cx + width / 2, y0 + depth), "S", is_door))
        elif abs(cy - y1) < 1e-6 and x0 < cx < x1:
            out.append(_Keepout((cx - width / 2, y1 - depth, cx + width / 2, y1), "N", is_door))
        elif abs(cx - x0) < 1e-6 and y0 < cy < y1:
            out.append(_Keepout((x0, cy - width / 2, x0 + depth, cy + width / 2), "W", is_door))
        elif abs(cx - x1) < 1e-6 and y0 < cy < y1:
            out.append(_Keepout((x1 - depth, cy - width / 2, x1, cy + width / 2), "E", is_door))
    return out


def _furnish_all(rects, items, doors, windows, rng, k) -> tuple[list[Furniture], list[GroundPatch]]:
    furniture: list[Furniture] = []
    patches: list[GroundPatch] = []
    counters: dict[str, int] = {}
    for rid, rect in rects.items():
        keep = _keepouts(rid, rect, doors, windows, k)
        driveway = None
        if room_type(rid) in OUTDOOR_ROOM_TYPES and any(it.category in catalog.VEHICLE_CATEGORIES for it in items[rid]):
            driveway = _driveway(rid, rect, rects, k)
            patches.append(GroundPatch(room=rid, bounds=_round(driveway), ground="driveway"))
        placed = furnish_room(rect, items[rid], keep, rng, driveway=driveway, k=k)
        if placed is None:
            raise _Retry(rid)
        for it, center, size in placed:
            if it.role == "carpet":
                half = (size[0] / 2, size[1] / 2)
                b = (center[0] - half[0], center[1] - half[1], center[0] + half[0], center[1] + half[1])
                patches.append(GroundPatch(room=rid, bounds=_round(b), ground="carpet"))
                continue
            n = counters.get(it.category, 0)
            counters[it.category] = n + 1
            openable = catalog.is_openable(it.category)
            synsets = catalog.category_synsets(it.category)
            furniture.append(
                Furniture(
                    id=f"{it.category}_{n}",
                    category=it.category,
                    synset=synsets[0] if synsets else None,
                    model=it.model,
                    room=rid,
                    center=_round(center),
                    size=_round(size),
                    openable=openable,
                )
            )
    return furniture, patches


def _driveway(rid: str, rect: Rect, rects: dict[str, Rect], k: dict) -> Rect:
    """A driveway strip along the garden's edge farthest from the house."""
    x0, y0, x1, y1 = rect
    inner = k["t"] / 2
    d = DRIVEWAY_DEPTH_M
    others = [r for o, r in rects.items() if o != rid]
    hx0 = min((r[0] for r in others), default=x0)
    hy0 = min((r[1] for r in others), default=y0)
    hy1 = max((r[3] for r in others), default=y1)
    if y1 <= hy0 + 1e-6:
        return (x0 + inner, y0 + inner, x1 - inner, y0 + inner + d)
    if y0 >= hy1 - 1e-6:
        return (x0 + inner, y1 - inner - d, x1 - inner, y1 - inner)
    if x1 <= hx0 + 1e-6:
        return (x0 + inner, y0 + inner, x0 + inner + d, y1 - inner)
    return (x1 - inner - d, y0 + inner, x1 - inner, y1 - inner)
