"""``more-agent ingest BAG --out DIR``: a ROS 2 bag through MORE's mapping -> scene graph, map, scene text.

Writes ``DIR/scene_graph.json`` (the versioned scene-graph JSON that ``plan`` and ``serve`` read),
``DIR/map.png`` (the graph over its occupancy grid), ``DIR/scene.txt`` (MORE's scene text, rooms named
``unknown_room_<k>`` until an LLM labels them) and ``DIR/ingest.json`` (frames, timings, topics).
The message contract: docs/ros.md.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from more_agent.commands._common import console, user_errors_exit_2
from more_agent.errors import check_writable_dir

GRAPH_FILE = "scene_graph.json"
MAP_FILE = "map.png"
SCENE_FILE = "scene.txt"
SUMMARY_FILE = "ingest.json"


@user_errors_exit_2
def ingest(
    bag: Annotated[
        Path, typer.Argument(help="rosbag2 folder (metadata.yaml + .mcap / .db3) or a single .mcap / .db3 file.")
    ],
    out: Annotated[Path, typer.Option(help="Output folder.")],
    depth_topic: Annotated[str, typer.Option(help="Depth image (32FC1 m / 16UC1 mm).")] = "/camera/depth/image_raw",
    rgb_topic: Annotated[
        str, typer.Option(help="Colour image (rgb8 / bgr8); used when the bag has it.")
    ] = "/camera/color/image_raw",
    semantic_topic: Annotated[str, typer.Option(help="Semantic class id image.")] = "/camera/semantic/image_raw",
    instance_topic: Annotated[str, typer.Option(help="Instance id image.")] = "/camera/instance/image_raw",
    camera_info_topic: Annotated[
        str, typer.Option(help="CameraInfo of the depth camera.")
    ] = "/camera/depth/camera_info",
    labels_topic: Annotated[str, typer.Option(help="Label table (std_msgs/String JSON).")] = "/more/labels",
    pose_topic: Annotated[
        str | None, typer.Option(help="PoseStamped of the camera optical frame (default: /tf).")
    ] = None,
    world_frame: Annotated[str, typer.Option(help="Fixed frame of the map.")] = "map",
    camera_frame: Annotated[
        str | None, typer.Option(help="Camera optical frame (default: the depth header's).")
    ] = None,
    base_frame: Annotated[
        str, typer.Option(help="Robot base frame (default: the camera's position when absent).")
    ] = "base_link",
) -> None:
    """Build MORE's scene graph from a ROS 2 bag, frame by frame, and write it with its map and scene text."""
    from more_agent.interop.bag_contract import BagTopics
    from more_agent.interop.ingest import ingest_bag
    from more_agent.planners.language import scene_view
    from more_agent.planners.llm_planner import PLANNER_CONFIGS
    from more_agent.viz.graph_plot import scene_graph_png

    check_writable_dir(out)
    topics = BagTopics(
        depth=depth_topic,
        rgb=rgb_topic,
        semantic=semantic_topic,
        instance=instance_topic,
        camera_info=camera_info_topic,
        labels=labels_topic,
        pose=pose_topic,
        world_frame=world_frame,
        camera_frame=camera_frame,
        base_frame=base_frame,
    )
    with console.status(f"ingesting {bag} ..."):
        result = ingest_bag(bag, topics)
    graph = result.graph
    out.mkdir(parents=True, exist_ok=True)
    (out / GRAPH_FILE).write_text(graph.model_dump_json(), encoding="utf-8")
    (out / MAP_FILE).write_bytes(scene_graph_png(graph, title=f"{bag.name}: {result.frames} frames"))
    (out / SCENE_FILE).write_text(scene_view(graph, PLANNER_CONFIGS["more"].language).text() + "\n", encoding="utf-8")
    summary = {
        "bag": str(bag),
        "frames": result.frames,
        "skipped_stamps": result.skipped,
        "fuse_s": round(result.fuse_s, 3),
        "build_s": round(result.build_s, 3),
        "frames_per_s": round(result.frames / max(result.fuse_s, 1e-9), 2),
        "regions": len(graph.regions),
        "objects": len(graph.objects),
        "topics": topics.model_dump(),
    }
    (out / SUMMARY_FILE).write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    console.print(
        f"{result.frames} frames ({summary['frames_per_s']} frames/s), {len(graph.regions)} regions, "
        f"{len(graph.objects)} objects -> {out}/{{{GRAPH_FILE}, {MAP_FILE}, {SCENE_FILE}, {SUMMARY_FILE}}}",
        highlight=False,
        markup=False,
    )
