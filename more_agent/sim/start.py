"""Where the robot starts, and how far that is from the task: the paper places the agent at random.

``random_start`` draws a pose uniformly over the reachable free space of the whole scene: the cells
of the ground-truth navigation grid (every door counted open, as the robot can open them) that lie
in a connected component from which some task object can be reached, indoors or outdoors; the
position is uniform within the drawn cell and the heading uniform. ``start_facts`` measures the
start against the task: the rooms holding task objects, and the shortest path on that grid from the
start to within reach of the nearest task object.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from more_agent.errors import UserError
from more_agent.sim.actions import REACH_M, reach_box
from more_agent.sim.navgrid import NavGrid, nav_grid
from more_agent.sim.world import World

START_MODES = ("random", "task-room")
"""``random``: anywhere reachable (the paper's protocol, default); ``task-room``: a free spot in the room
of the task's ``(ontop agent floor)`` literal (the behaviour before random starts)."""


def check_start(start: str) -> None:
    """Raise a UserError naming the valid values when ``start`` is not one of ``START_MODES``."""
    if start not in START_MODES:
        raise UserError(f"unknown start {start!r}; use --start with one of: {', '.join(START_MODES)}")


@dataclass(frozen=True)
class StartFacts:
    """How far from the task the robot starts (the ``WorldStats`` of an episode record, less the counts)."""

    start_room: str
    task_rooms: list[str] = field(default_factory=list)
    start_to_task_m: float | None = None
    """Path length from the start to within reach of the nearest task object; None when none is reachable."""


def _cell_centres(grid: NavGrid) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) of every cell centre, each of the grid's shape."""
    rows, cols = np.indices(grid.shape)
    return grid.origin[0] + (cols + 0.5) * grid.resolution_m, grid.origin[1] + (rows + 0.5) * grid.resolution_m


def _box_distance(grid: NavGrid, box: tuple[float, float, float, float]) -> np.ndarray:
    """Horizontal distance of every cell centre to a footprint (0 inside it)."""
    x, y = _cell_centres(grid)
    x0, y0, x1, y1 = box
    return np.hypot(np.maximum(np.maximum(x0 - x, x - x1), 0.0), np.maximum(np.maximum(y0 - y, y - y1), 0.0))


def _reach_masks(world: World, grid: NavGrid, targets: Iterable[str]) -> list[np.ndarray]:
    """Per target, the free cells from which it is within reach."""
    return [grid.free & (_box_distance(grid, reach_box(world, t)) <= REACH_M) for t in targets]


def random_start(world: World, targets: list[str], rng: np.random.Generator) -> tuple[float, float, float] | None:
    """A uniformly drawn (x, y, yaw) on the free space connected to some task object; None if there is none."""
    grid = nav_grid(world, all_doors_open=True)
    components, _ = ndimage.label(grid.free, structure=np.ones((3, 3)))
    reach = np.zeros(grid.shape, dtype=bool)
    for mask in _reach_masks(world, grid, targets):
        reach |= mask
    keep = np.unique(components[reach])
    keep = keep[keep > 0]
    if not targets:  # nothing to reach: anywhere free
        keep = np.unique(components[components > 0])
    cells = np.flatnonzero(np.isin(components, keep))
    if len(cells) == 0:
        return None
    r, c = np.unravel_index(cells[rng.integers(len(cells))], grid.shape)
    x, y = grid.to_xy(int(r), int(c))
    jitter = rng.uniform(-0.5, 0.5, size=2) * grid.resolution_m
    return float(x + jitter[0]), float(y + jitter[1]), float(rng.uniform(-np.pi, np.pi))


def start_to_task_m(world: World, targets: list[str]) -> float | None:
    """Path length (doors open) from the robot to the nearest cell within reach of a task object."""
    if not targets:
        return None
    grid = nav_grid(world, all_doors_open=True)
    start = grid.snap(world.robot.x, world.robot.y)
    if start is None:
        return None
    costs = np.where(grid.free, 1.0, np.inf)
    cum, _ = MCP_Geometric(costs).find_costs([start])
    best = min((float(cum[m].min()) for m in _reach_masks(world, grid, targets) if m.any()), default=np.inf)
    return round(best * grid.resolution_m, 3) if np.isfinite(best) else None


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
