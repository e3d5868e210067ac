"""Sim episode -> ROS 2 bag -> ingest: the same regions and objects as the live robot's scene graph."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from rosbags.rosbag2 import Reader, StoragePlugin
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.interop.bag_contract import BagTopics
from more_agent.interop.bag_writer import POSE_TOPIC
from more_agent.interop.compare import compare_graphs
from more_agent.interop.ingest import ingest_bag
from tests.interop.bags import rewrite_bag

pytestmark = pytest.mark.slow  # a recorded episode, ingested whole several times

ROUND_TRIP_TOL_M = 1e-9
"""Positions and boxes after the round trip (measured: 0.0; depth is float32 either way, poses float64)."""


def test_the_bag_holds_the_contract_topics_one_message_per_frame(recorded):
    with Reader(recorded.bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        types = {c.topic: c.msgtype for c in reader.connections}
    t = BagTopics()
    for topic in (t.depth, t.rgb, t.semantic, t.instance, t.camera_info, t.labels, "/tf", POSE_TOPIC):
        assert counts[topic] == recorded.frames > 50
    assert "/tf_static" not in counts  # the head moves: base -> camera travels on /tf with every frame
    assert types[t.depth] == "sensor_msgs/msg/Image" and types[t.labels] == "std_msgs/msg/String"


def test_ingest_gives_the_live_graph_through_tf_and_through_the_pose_topic(recorded):
    for topics in (BagTopics(), BagTopics(pose=POSE_TOPIC)):
        result = ingest_bag(recorded.bag, topics)
        diff = compare_graphs(recorded.live, result.graph)
        assert result.frames == recorded.frames and result.skipped == 0
        assert diff.same_within(ROUND_TRIP_TOL_M), diff
        assert {o.id for o in result.graph.objects.values() if o.open} == {
            o.id for o in recorded.live.objects.values() if o.open} != set()
        assert result.graph.relations == recorded.live.relations
        assert np.allclose(result.graph.nav.node_xy, recorded.live.nav.node_xy)


def test_ingest_reads_sqlite3_bags_too(recorded, tmp_path):
    bag = rewrite_bag(recorded.bag, tmp_path / "sqlite", storage=StoragePlugin.SQLITE3)
    assert next(bag.glob("*.db3"))
    assert compare_graphs(recorded.live, ingest_bag(bag).graph).same_within(ROUND_TRIP_TOL_M)


def test_ingest_command_writes_graph_map_and_scene_text(recorded, tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["ingest", str(recorded.bag), "--out", str(out)])
    assert result.exit_code == 0, result.output
    graph = json.loads((out / "scene_graph.json").read_text())
    assert set(graph["objects"]) == set(recorded.live.objects)
    assert (out / "map.png").read_bytes()[:4] == b"\x89PNG"
    scene = (out / "scene.txt").read_text()
    assert re.search(r"unknown_room_0( \(unexplored areas\))?: floor, ", scene) and "fridge A [" in scene
    summary = json.loads((out / "ingest.json").read_text())
    assert summary["frames"] == recorded.frames and summary["objects"] == len(recorded.live.objects)


def test_run_bag_refuses_an_existing_path_or_an_unknown_storage_before_any_work(tmp_path):
    (tmp_path / "bag").mkdir()
    result = CliRunner().invoke(app, ["run", "putting_shopping_away", "--planner", "oracle", "--out", str(tmp_path / "o"),
                                      "--bag", str(tmp_path / "bag")])
    assert result.exit_code == 2 and "exists; a bag is written to a new folder" in result.output
    result = CliRunner().invoke(app, ["run", "putting_shopping_away", "--planner", "oracle", "--out", str(tmp_path / "o"),
                                      "--bag", str(tmp_path / "new"), "--bag-storage", "rosbag1"])
    assert result.exit_code == 2 and "use one of mcap, sqlite3" in result.output
    assert not (tmp_path / "o" / "episode.json").exists() and not (tmp_path / "new").exists()
