"""Where the robot starts, and how far that is from the task: the paper places the agent at random.

``random_start`` draws a pose uniformly over the reachable free space of the whole scene: the cells
of the ground-truth navigation grid (every door counted open, as the robot can open them) that lie
in a connected component holding a base pose from which the magic actions reach some task object,
indoors or outdoors; the position is uniform within the drawn cell and the heading uniform. Floor
items count as obstacles there (``clear_of_floor_items``): the world's base drives over them, but the
robot's map shows them, and a start among them (putting_away_tools seed 1: in a corner behind a
pillow on the floor, 0.46 x 0.56 m) left the robot sealed in on its own map from its first step.
``start_facts`` measures the start against the task: the rooms holding task objects, and the
shortest path on that grid from the start to the nearest such pose.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from more_agent.sim.actions import candidate_poses, reach_box, within_reach
from more_agent.sim.floorspots import PASSAGE_CLEARANCE_M
from more_agent.sim.navgrid import NavGrid, free_cells, nav_grid, shortest_path
from more_agent.sim.world import World

MIN_ROOM_FREE_M2 = 1.0
"""A room counts for the per-room start draw when it has at least this much reachable free floor."""


@dataclass(frozen=True)
class StartFacts:
    """How far from the task the robot starts (the ``WorldStats`` of an episode record, less the counts)."""

    start_room: str
    task_rooms: list[str] = field(default_factory=list)
    start_to_task_m: float | None = None
    """Path length from the start to within reach of the nearest task object; None when none is reachable."""


def approach_cells(world: World, grid: NavGrid, targets: Iterable[str]) -> list[tuple[int, int]]:
    """Free cells of ``grid`` at the base poses the magic actions would use to reach any target."""
    cells: list[tuple[int, int]] = []
    for t in targets:
        box = reach_box(world, t)
        for poses in candidate_poses(world, t):
            cells += [(int(i), int(j)) for i, j in grid.cell_of(within_reach(poses, box, grid))]
    return cells


def random_start(
    world: World,
    targets: list[str],
    rng: np.random.Generator,
    *,
    by_room: bool = False,
) -> tuple[float, float, float] | None:
    """A uniformly drawn (x, y, yaw) on the free space connected to a pose that reaches a task object
    (anywhere free when there is no target); None if there is none.

    With ``by_room`` the room is drawn first, uniformly among the rooms with at least
    ``MIN_ROOM_FREE_M2`` of such free space, then the position uniformly within it.
    """
    grid = nav_grid(world, all_doors_open=True)
    goals = approach_cells(world, grid, targets)
    free = _reachable(grid.free & clear_of_floor_items(world, grid), goals, targets)
    if not free.any():  # floor items close every way to the task: the furniture's free space alone
        free = _reachable(grid.free, goals, targets)
    if by_room:
        min_cells = MIN_ROOM_FREE_M2 / grid.resolution_m**2
        xy = grid.xy_of(np.stack(list(np.indices(grid.shape)), axis=-1))
        x, y = xy[..., 0], xy[..., 1]
        in_room = [
            free & (x >= r.bounds[0]) & (x <= r.bounds[2]) & (y >= r.bounds[1]) & (y <= r.bounds[3])
            for r in world.scene.rooms
        ]
        rooms = [m for m in in_room if m.sum() >= min_cells]
        if rooms:
            free = rooms[rng.integers(len(rooms))]
    cells = free_cells(free)
    if len(cells) == 0:
        return None
    cx, cy = grid.centre(cells[rng.integers(len(cells))])
    jitter = rng.uniform(-0.5, 0.5, size=2) * grid.resolution_m
    return float(cx + jitter[0]), float(cy + jitter[1]), float(rng.uniform(-np.pi, np.pi))


def _reachable(free: np.ndarray, goals: list[tuple[int, int]], targets: list[str]) -> np.ndarray:
    """The cells of ``free`` connected to one of ``goals`` (all of them when there is no target)."""
    components, _ = ndimage.label(free, structure=np.ones((3, 3)))
    keep = np.unique([components[c] for c in goals]) if targets else np.unique(components)
    return np.isin(components, keep[keep > 0])


def clear_of_floor_items(world: World, grid: NavGrid) -> np.ndarray:
    """Cells of ``grid`` farther than ``PASSAGE_CLEARANCE_M`` from every item on a floor (the clearance a
    floor item leaves along a passage, ``floorspots``)."""
    items = np.zeros(grid.shape, dtype=bool)
    for obj in world.objects.values():
        if world.on_floor(obj):
            x0, y0, x1, y1 = obj.footprint()
            (i0, j0), (i1, j1) = grid.cell_at(x0, y0), grid.cell_at(x1, y1)
            items[i0 : i1 + 1, j0 : j1 + 1] = True
    if not items.any():
        return np.ones(grid.shape, dtype=bool)
    return ndimage.distance_transform_edt(~items) * grid.resolution_m > PASSAGE_CLEARANCE_M


def start_to_task_m(world: World, targets: list[str]) -> float | None:
    """Path length (doors open) from the robot to the nearest pose from which a task object is within reach."""
    grid = nav_grid(world, all_doors_open=True)
    goals = [grid.centre(c) for c in approach_cells(world, grid, targets)]
    path = shortest_path(grid, (world.robot.x, world.robot.y), goals)
    return round(path.length_m, 3) if path.found else None


def task_rooms(world: World, targets: Iterable[str]) -> list[str]:
    """The rooms holding task objects now (where an item rests, a piece of furniture stands), sorted."""
    return sorted({room for t in targets if (room := world.get(t).room) is not None})


def start_facts(world: World, targets: list[str]) -> StartFacts:
    """The start room, task rooms and start-to-task path length of the world as it is now."""
    return StartFacts(
        start_room=world.room_at(world.robot.x, world.robot.y) or "",
        task_rooms=task_rooms(world, targets),
        start_to_task_m=start_to_task_m(world, targets),
    )
