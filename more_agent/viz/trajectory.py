"""The episode map: the world's floor plan at the end of an episode with the robot's path drawn on it.

``draw_world`` draws rooms, walls, doors (in their current state), furniture and items from a
``World`` (``more_agent.viz.plan`` draws a static ``Scene`` into a file and has no axes-level
entry point to reuse here); ``draw_trajectory`` adds a path to axes (start and end marked);
``save_trajectory_map`` writes an episode's ``map.png``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from more_agent.sim.world import World  # noqa: E402

PATH_COLOR = "#d62728"
"""Colour of the robot's path."""

_COLOURS = {"floor": "#efe6d2", "carpet": "#c9a0a0", "lawn": "#9fd38a", "driveway": "#a9a9a9", "wall": "#303030",
            "open door": "#2ca02c", "closed door": "#b2182b", "furniture": "#8c6d46"}


def _box(ax: Axes, b: tuple[float, float, float, float], colour: str, z: float, **kw: object) -> None:
    ax.add_patch(Rectangle((b[0], b[1]), b[2] - b[0], b[3] - b[1], facecolor=colour, zorder=z, **kw))


def draw_world(ax: Axes, world: World) -> None:
    """Rooms by ground class, walls, doors coloured by their current state, furniture, items with labels."""
    scene = world.scene
    for room in scene.rooms:
        _box(ax, room.bounds, _COLOURS[room.ground], 0, edgecolor="none")
    for wall in scene.walls:
        if wall.z_min <= 0:
            _box(ax, wall.bounds, _COLOURS["wall"], 3, edgecolor="none")
    for obj in world.objects.values():
        lo, hi = obj.box()
        b = (lo[0], lo[1], hi[0], hi[1])
        if obj.kind == "door":
            _box(ax, b, _COLOURS["open door" if obj.is_open else "closed door"], 4, edgecolor="none")
        elif obj.kind == "furniture":
            _box(ax, b, _COLOURS["furniture"], 2, edgecolor="black", linewidth=0.3, alpha=0.6)
    for room in scene.rooms:
        ax.text((room.bounds[0] + room.bounds[2]) / 2, (room.bounds[1] + room.bounds[3]) / 2, room.id,
                fontsize=6, ha="center", va="center", alpha=0.6, zorder=5)
    _draw_items(ax, world)
    ax.set_xlim(scene.bounds[0], scene.bounds[2])
    ax.set_ylim(scene.bounds[1], scene.bounds[3])
    ax.set_aspect("equal")


def draw_trajectory(ax: Axes, trajectory: Sequence[tuple[float, float]], *, color: str = PATH_COLOR) -> None:
    """Draw the robot's base path on ``ax``: a line, a circle at the start and a square at the end."""
    if not trajectory:
        return
    xs, ys = zip(*trajectory)
    ax.plot(xs, ys, "-", color=color, lw=1.5, alpha=0.9, zorder=10, label="robot path")
    ax.plot(xs[0], ys[0], "o", color=color, ms=7, zorder=11, label="start")
    ax.plot(xs[-1], ys[-1], "s", color=color, ms=7, zorder=11, label="end")


def _draw_items(ax: Axes, world: World) -> None:
    """Items as small dots with their labels, so the map shows where things ended up."""
    for obj in world.items():
        if world.robot.held == obj.name:
            continue
        ax.plot(obj.center[0], obj.center[1], ".", color="black", ms=4, zorder=9)
        ax.annotate(obj.label, (obj.center[0], obj.center[1]), fontsize=5, zorder=9, xytext=(2, 2), textcoords="offset points")


def save_trajectory_map(
    world: World, trajectory: Sequence[tuple[float, float]], path: Path, *, title: str = "", dpi: int = 120
) -> None:
    """Write the plan of ``world`` with items and the robot's path to ``path`` (PNG)."""
    x0, y0, x1, y1 = world.scene.bounds
    width = 8.0
    fig, ax = plt.subplots(figsize=(width, max(3.0, width * (y1 - y0) / max(x1 - x0, 1e-6))))
    try:
        draw_world(ax, world)
        draw_trajectory(ax, trajectory)
        ax.set_title(title, fontsize=9)
        ax.legend(loc="upper right", fontsize=6)
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
