"""The episode map: the floor plan (``more_agent.viz.plan``) with the robot's path drawn on it.

``draw_trajectory`` adds a path to existing axes (start and end marked); ``save_trajectory_map``
writes ``map.png`` for an episode: plan, path, and the task objects' current positions.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

from more_agent.sim.world import World  # noqa: E402

PATH_COLOR = "#d62728"
"""Colour of the robot's path."""


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
    from more_agent.viz.plan import draw_plan

    x0, y0, x1, y1 = world.scene.bounds
    width = 8.0
    fig, ax = plt.subplots(figsize=(width, max(3.0, width * (y1 - y0) / max(x1 - x0, 1e-6))))
    try:
        draw_plan(world.scene, ax)
        _draw_items(ax, world)
        draw_trajectory(ax, trajectory)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9)
        ax.legend(loc="upper right", fontsize=6)
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
