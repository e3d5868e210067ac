"""A scene's floor plan seen from above: ground classes, walls, windows, doors (open / closed), furniture.

``draw_plan`` draws on given axes (the episode map adds items and the robot's path on top);
``plot_plan`` writes one PNG for ``more-agent scene render``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from more_agent.sim.scene import Scene  # noqa: E402

GROUND_COLOURS: dict[str, str] = {"floor": "#efe6d2", "carpet": "#c9a0a0", "lawn": "#9fd38a", "driveway": "#a9a9a9"}
_WALL, _FENCE, _WINDOW = "#303030", "#7a5c3a", "#4fa3e0"
_OPEN_DOOR, _CLOSED_DOOR = "#2ca02c", "#d62728"
_FURNITURE, _OPENABLE = "#8c6d46", "#c7822b"


def _rects(bounds, **kw) -> PolyCollection:
    """Axis-aligned boxes (x0, y0, x1, y1) as one collection of corner arrays: a store's hundreds of boxes draw
    in one call, and no patch object is made per box (they cost a tenth of an episode map; the same pixels)."""
    b = np.asarray(bounds, dtype=float).reshape(-1, 4)
    corners = np.stack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]], axis=1)
    return PolyCollection(corners, **kw)  # type: ignore[arg-type]  # an (n, 4, 2) array: matplotlib takes it whole


def draw_plan(
    ax: Axes,
    scene: Scene,
    *,
    open_state: Mapping[str, bool] | None = None,
    label_furniture: bool = False,
    legend: bool = True,
) -> None:
    """Draw ``scene`` seen from above on ``ax`` (x right, y up).

    ``open_state`` maps door / furniture ids to their current state (an episode's world); ids it
    leaves out are drawn in the scene's initial state.
    """
    state = open_state or {}
    layers: list[tuple[float, tuple[float, float, float, float], str]] = []  # (zorder, bounds, colour)
    layers += [(0, r.bounds, GROUND_COLOURS[r.ground]) for r in scene.rooms]
    layers += [(1, p.bounds, GROUND_COLOURS[p.ground]) for p in scene.ground_patches]
    # lintels and window tops (z_min > 0) are left out: the gap below is drawn instead
    layers += [(3, w.bounds, _FENCE if w.z_max < 2.0 else _WALL) for w in scene.walls if w.z_min <= 0]
    layers += [(4, w.bounds, _WINDOW) for w in scene.windows]
    layers += [(4, d.bounds(), _OPEN_DOOR if state.get(d.id, d.open) else _CLOSED_DOOR) for d in scene.doors]
    for z in sorted({z for z, _, _ in layers}):
        rects = [(b, c) for zz, b, c in layers if zz == z]
        ax.add_collection(_rects([b for b, _ in rects], facecolor=[c for _, c in rects], edgecolor="none", zorder=z))
    furniture = sorted(scene.furniture, key=lambda f: f.center[2])  # higher pieces drawn over lower ones
    if furniture:
        ax.add_collection(
            _rects(
                [
                    (
                        f.center[0] - f.size[0] / 2,
                        f.center[1] - f.size[1] / 2,
                        f.center[0] + f.size[0] / 2,
                        f.center[1] + f.size[1] / 2,
                    )
                    for f in furniture
                ],
                facecolor=[_OPENABLE if f.openable else _FURNITURE for f in furniture],
                edgecolor="black",
                linewidth=0.3,
                alpha=0.85,
                zorder=2,
            )
        )
    for f in scene.furniture if label_furniture else ():
        ax.text(f.center[0], f.center[1], f.id, fontsize=4, ha="center", va="center", zorder=6)
    for r in scene.rooms:
        cx, cy = (r.bounds[0] + r.bounds[2]) / 2, (r.bounds[1] + r.bounds[3]) / 2
        ax.text(
            cx,
            cy,
            r.id,
            fontsize=8,
            ha="center",
            va="center",
            zorder=7,
            bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.7, linewidth=0),
        )
    if legend:
        handles = [Patch(color=c, label=g) for g, c in GROUND_COLOURS.items()] + [
            Patch(color=_WALL, label="wall"),
            Patch(color=_FENCE, label="fence"),
            Patch(color=_WINDOW, label="window"),
            Patch(color=_OPEN_DOOR, label="open door"),
            Patch(color=_CLOSED_DOOR, label="closed door"),
            Patch(color=_FURNITURE, label="furniture"),
            Patch(color=_OPENABLE, label="openable furniture"),
        ]
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_xlim(scene.bounds[0], scene.bounds[2])
    ax.set_ylim(scene.bounds[1], scene.bounds[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


PLAN_MARGINS = (0.8, 0.55, 2.1, 0.4)
"""Inches around the plan (left, bottom, right, top): tick labels and axis names, the legend on the right,
the title. A fixed layout draws a figure once; ``bbox_inches="tight"`` drew it twice to crop it."""


def plan_figure(scene: Scene) -> tuple[Figure, Axes]:
    """A figure holding the plan at 7.5 inches on its long side, with fixed margins for labels and legend."""
    w, h = scene.bounds[2] - scene.bounds[0], scene.bounds[3] - scene.bounds[1]
    scale = 7.5 / max(w, h)
    left, bottom, right, top = PLAN_MARGINS
    aw, ah = w * scale, max(h * scale, 2.4)  # the legend's eleven rows need about 2.4 inches
    fig = plt.figure(figsize=(left + aw + right, bottom + ah + top))
    fw, fh = fig.get_size_inches()
    return fig, fig.add_axes((left / fw, bottom / fh, aw / fw, ah / fh))


def plot_plan(scene: Scene, path: str | Path, *, dpi: int = 110, label_furniture: bool = False) -> Path:
    """Draw ``scene`` seen from above into ``path`` (PNG) and return the path."""
    path = Path(path)
    fig, ax = plan_figure(scene)
    try:
        draw_plan(ax, scene, label_furniture=label_furniture)
        ax.set_title(f"{scene.name} (seed {scene.seed})")
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)
    return path
