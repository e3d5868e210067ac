"""``write_rerun``: an episode folder as a Rerun recording (``more-agent view DIR --rerun out.rrd``, the
``rerun`` extra).

Timelines ``step`` (high-level step) and ``frame`` (rendered frame). Per step: the camera frames the
step rendered (``camera/rgb``, ``camera/depth``, ``camera/semantic``; folders run with ``--save-frames``
or ``--viewer``), the BEV occupancy as a 2.5D voxel map (``world/map``: occupied cells as 1 m boxes),
the scene graph (``world/graph/objects`` boxes, ``world/graph/regions``, ``world/graph/places`` and their
``world/graph/nav_edges``, region -> object ``world/graph/edges``; folders with ``--save-graph`` /
``--viewer``), the robot path (``world/robot/path``) and position (``world/robot``), and the chosen action
with its outcome as text (``action``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from more_agent.errors import UserError
from more_agent.eval.episode_folder import EPISODE_FILE, EpisodeFolder
from more_agent.eval.viewer import _read_jsonl as read_jsonl  # the viewer reads the same lines
from more_agent.records import EpisodeRecord
from more_agent.sim.grid import Grid

OCCUPIED = 2
"""Occupancy cell value of an occupied cell (``scene_graph.model.OccupancyMap``)."""
WALL_HEIGHT_M = 1.0
"""Height of the boxes standing for occupied cells."""
FRAME_KINDS = ("rgb", "depth", "semantic")


@dataclass(frozen=True)
class RerunSummary:
    """What went into the recording."""

    path: Path
    steps: int
    frames: int
    graphs: int


def _rerun() -> Any:
    try:
        import rerun
    except ImportError as e:
        raise UserError(f"rerun-sdk is not installed: pip install 'more-agent[rerun]' ({e})") from None
    return rerun


def write_rerun(episode_dir: Path, out: Path) -> RerunSummary:
    """Write ``out`` (a ``.rrd`` file) from the episode folder ``episode_dir``."""
    rr = _rerun()
    folder = EpisodeFolder(Path(episode_dir))
    if not folder.record_path.is_file():
        raise UserError(f"{episode_dir} is not an episode folder (no {EPISODE_FILE}); 'more-agent run' writes one")
    record = EpisodeRecord.model_validate_json(folder.record_path.read_text(encoding="utf-8"))
    timeline = {t["step"]: t for t in read_jsonl(folder.timeline_path)}
    rec = rr.RecordingStream("more-agent", recording_id=f"{record.task}-{record.scene}-{record.seed}-{record.planner}")
    rec.save(str(out))
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    first_frame, frames, graphs = 0, 0, 0
    for action in record.actions:
        t = timeline.get(action.step, {})
        end_frame = t.get("frames", first_frame)
        for i in range(first_frame, end_frame):
            rec.set_time("frame", sequence=i)
            frames += _log_frame(rr, rec, folder, i)
        first_frame = end_frame
        rec.set_time("step", sequence=action.step)
        path = record.trajectory[: t.get("path_len", len(record.trajectory))]
        if path:
            rec.log("world/robot/path", rr.LineStrips3D([[(x, y, 0.05) for x, y in path]]))
            rec.log("world/robot", rr.Points3D([(*path[-1], 0.05)], radii=0.15, labels=["robot"]))
        graphs += _log_graph(rr, rec, folder, action.step)
        status = "success" if action.ok else "failure"
        rec.log(
            "action",
            rr.TextLog(
                f"step {action.step}: {action.name}({', '.join(action.arguments)}) -> {status}; {action.feedback}",
                level="INFO" if action.ok else "WARN",
            ),
        )
    rec.flush()
    return RerunSummary(path=Path(out), steps=len(record.actions), frames=frames, graphs=graphs)


def _log_frame(rr: Any, rec: Any, folder: EpisodeFolder, index: int) -> int:
    """The frame's pictures (1 when it had any, else 0)."""
    logged = 0
    for kind in FRAME_KINDS:
        path = folder.frame_path(index, kind)
        if path.is_file():
            with Image.open(path) as im:
                rec.log(f"camera/{kind}", rr.Image(np.asarray(im.convert("RGB"))))
            logged = 1
    return logged


def _log_graph(rr: Any, rec: Any, folder: EpisodeFolder, step: int) -> int:
    """The step's scene graph and voxel map (1 when the folder has the graph, else 0)."""
    path = folder.graph_path(step)
    if not path.is_file():
        return 0
    g = json.loads(path.read_text(encoding="utf-8"))
    objects = list(g["objects"].values())
    lo = np.array([o["bbox"]["min"] for o in objects]).reshape(-1, 3)
    hi = np.array([o["bbox"]["max"] for o in objects]).reshape(-1, 3)
    rec.log(
        "world/graph/objects",
        rr.Boxes3D(centers=(lo + hi) / 2, half_sizes=(hi - lo) / 2, labels=[o["label"] for o in objects]),
    )
    regions = sorted(g["regions"].values(), key=lambda r: r["id"])
    centroid = {r["id"]: (*r["centroid"], 0.0) for r in regions}
    rec.log(
        "world/graph/regions",
        rr.Points3D(
            [centroid[r["id"]] for r in regions], radii=0.2, labels=[r["room_label"] or r["id"] for r in regions]
        ),
    )
    nodes = np.array(g["nav"]["node_xy"], dtype=float).reshape(-1, 2)
    rec.log("world/graph/places", rr.Points3D(np.c_[nodes, np.zeros(len(nodes))], radii=0.05))
    rec.log(
        "world/graph/nav_edges", rr.LineStrips3D([[(*nodes[a], 0.0), (*nodes[b], 0.0)] for a, b in g["nav"]["edges"]])
    )
    rec.log(
        "world/graph/edges",
        rr.LineStrips3D(
            [[centroid[o["region_id"]], tuple(o["position"])] for o in objects if o["region_id"] in centroid]
        ),
    )
    occupancy = folder.graph_path(step, "_occupancy.png")
    if occupancy.is_file():
        rec.log("world/map", _voxels(rr, occupancy))
    return 1


def _voxels(rr: Any, path: Path) -> Any:
    """The occupied cells of an occupancy PNG (``viz.graph_plot.occupancy_png``) as boxes."""
    with Image.open(path) as im:
        origin, res = json.loads(im.text["origin_xy"]), float(im.text["resolution_m"])  # type: ignore[attr-defined]
        cells = np.asarray(im).T  # the file's rows run along y: back to grid[ix, iy]
    xy = Grid(origin_xy=tuple(origin), resolution_m=res).xy_of(np.argwhere(cells == OCCUPIED))
    centres = np.c_[xy, np.full(len(xy), WALL_HEIGHT_M / 2)]
    return rr.Boxes3D(
        centers=centres, half_sizes=np.tile([res / 2, res / 2, WALL_HEIGHT_M / 2], (len(xy), 1)), colors=[(90, 90, 90)]
    )
