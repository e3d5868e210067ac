"""One PNG of a scene graph: BEV occupancy, sparse Voronoi graph coloured by region, doors,
objects, frontiers and the robot; and the occupancy grid as a lossless PNG (``--save-graph``)."""

from __future__ import annotations

import io
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from PIL import Image  # noqa: E402
from PIL.PngImagePlugin import PngInfo  # noqa: E402

from more_agent.scene_graph.model import OccupancyMap, SceneGraph  # noqa: E402

_OCC_CMAP = ListedColormap(["#d9d9d9", "#ffffff", "#303030"])  # unknown, free, occupied


def draw_occupancy(ax: Axes, occ: OccupancyMap) -> None:
    """The BEV grid on ``ax`` in world coordinates: unknown grey, free white, occupied dark."""
    x0, y0, x1, y1 = occ.frame.bounds(occ.grid.shape)
    ax.imshow(
        occ.grid.T, origin="lower", extent=(x0, x1, y0, y1), cmap=_OCC_CMAP, vmin=0, vmax=2, interpolation="nearest"
    )  # imshow draws [row, col]: y up the rows


def scene_graph_png(graph: SceneGraph, *, title: str | None = None, dpi: int = 120) -> bytes:
    """The picture as PNG bytes. World x is to the right, y up."""
    fig, ax = plt.subplots(figsize=(8, 8))
    occ = graph.occupancy
    if occ is not None:
        draw_occupancy(ax, occ)
        known = np.argwhere(occ.grid != 0)
        if len(known):  # show the explored part, with a metre around it
            margin = occ.resolution_m / 2 + 1.0
            lo = occ.frame.xy_of(known.min(0)) - margin
            hi = occ.frame.xy_of(known.max(0)) + margin
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
    colours = plt.get_cmap("tab10")
    region_colour = {rid: colours(i % 10) for i, rid in enumerate(sorted(graph.regions))}
    xy = graph.nav.node_xy
    if len(graph.nav.edges):
        segs = xy[graph.nav.edges]
        edge_colour = [
            "#ff00ff" if door else region_colour.get(graph.nav.node_region[a] or "", "#999999")
            for (a, _), door in zip(graph.nav.edges, graph.nav.door_edges)
        ]
        ax.add_collection(LineCollection(segs, colors=edge_colour, linewidths=1.2))
    for rid, region in graph.regions.items():
        pts = xy[region.nav_nodes]
        name = rid if region.room_label is None else f"{rid} ({region.room_label})"
        ax.scatter(pts[:, 0], pts[:, 1], s=10, color=region_colour[rid], label=name, zorder=3)
        if region.frontiers:
            f = np.array(region.frontiers)
            ax.scatter(f[:, 0], f[:, 1], marker="*", s=90, color=region_colour[rid], edgecolors="k", zorder=4)
    for obj in graph.objects.values():
        low, high = obj.bbox.min, obj.bbox.max
        door = obj.category == "door"
        ax.add_patch(
            plt.Rectangle(
                (low[0], low[1]),
                high[0] - low[0],
                high[1] - low[1],
                fill=False,
                edgecolor="#ff00ff" if door else "#1f77b4",
                linewidth=1.5,
                zorder=4,
            )
        )
        ax.annotate(obj.label, (obj.position[0], obj.position[1]), fontsize=7, zorder=5)
    rx, ry = graph.robot.position
    ax.scatter([rx], [ry], marker="^", s=120, color="#d62728", edgecolors="k", label="robot", zorder=6)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right", fontsize=7)
    ax.set_title(title or f"scene graph, step {graph.step}")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()


def occupancy_png(occupancy: OccupancyMap) -> bytes:
    """The occupancy grid as a lossless greyscale PNG of its cell values (row 0 = lowest y), with its
    origin and resolution in the PNG's text chunks; a few kB, read by the episode viewer."""
    info = PngInfo()
    info.add_text("origin_xy", json.dumps(list(occupancy.origin_xy)))
    info.add_text("resolution_m", repr(occupancy.resolution_m))
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(occupancy.grid.T.astype(np.uint8))).save(buf, format="PNG", pnginfo=info)
    return buf.getvalue()
