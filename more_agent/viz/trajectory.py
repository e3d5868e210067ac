"""The episode map: the floor plan in its end-of-episode state, the items, and the robot's path.

``draw_trajectory`` adds a path to axes (start and end marked); ``trajectory_map_png`` draws an
episode's ``map.png`` on top of ``more_agent.viz.plan.draw_plan``.
"""

from __future__ import annotations

import io
from collections.abc import Collection, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

from more_agent.sim.labels import InstanceLabels  # noqa: E402
from more_agent.sim.world import World  # noqa: E402
from more_agent.viz.plan import draw_plan, plan_figure  # noqa: E402

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


def draw_items(ax: Axes, world: World, labels: InstanceLabels, labelled: Collection[str] | None = None) -> None:
    """Items as small dots, with their labels (only for ``labelled`` names when given: a store holds
    hundreds of items), so the map shows where things ended up."""
    items = [o for o in world.items() if world.robot.held != o.name]
    if not items:
        return
    ax.plot([o.center[0] for o in items], [o.center[1] for o in items], ".", color="black", ms=4, zorder=9)
    for obj in items:
        if labelled is None or obj.name in labelled:
            ax.annotate(
                labels.display(obj),
                (obj.center[0], obj.center[1]),
                fontsize=5,
                zorder=9,
                xytext=(2, 2),
                textcoords="offset points",
            )


def trajectory_map_png(
    world: World,
    labels: InstanceLabels,
    trajectory: Sequence[tuple[float, float]],
    *,
    title: str = "",
    dpi: int = 120,
    labelled: Collection[str] | None = None,
) -> bytes:
    """The plan of ``world`` (doors and furniture as they are now), its items and the robot's path, as PNG bytes."""
    fig, ax = plan_figure(world.scene)
    try:
        open_state = {o.name: o.is_open for o in world.objects.values() if o.openable}
        draw_plan(ax, world.scene, open_state=open_state)
        draw_items(ax, world, labels, labelled)
        draw_trajectory(ax, trajectory)
        ax.set_title(title, fontsize=9)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi)
        return buf.getvalue()
    finally:
        plt.close(fig)
