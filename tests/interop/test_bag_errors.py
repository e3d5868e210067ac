"""Bags a robot may hand us: other encodings and unnamed instances work; a missing stream, a wrong
encoding, a broken label table or a missing transform gets one error naming the topic."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.interop.bag_contract import BagError, BagTopics, image_array, image_fields
from more_agent.interop.compare import compare_graphs
from more_agent.interop.ingest import ingest_bag, letters
from tests.interop.bags import rewrite_bag

pytestmark = pytest.mark.slow  # a recorded episode, ingested whole several times

T = BagTopics()
SHORT_S = 3.0
"""The broken bags keep the first three seconds (30 frames: the start's full turn, head looks included) of the recording."""


def _drop(topic_to_drop: str):
    return lambda topic, msg: None if topic == topic_to_drop else (topic, msg)


def _reencode(topic_to_change: str, convert):
    def edit(topic, msg):
        if topic != topic_to_change:
            return topic, msg
        pixels, encoding = convert(image_array(msg, topic, (msg.encoding,)))
        return topic, replace(msg, **image_fields(pixels, encoding))
    return edit


@pytest.mark.parametrize("dropped", [T.depth, T.semantic, T.instance, T.camera_info, T.labels, "/tf"])
def test_a_missing_stream_is_one_error_naming_its_topic(recorded, tmp_path, dropped):
    bag = rewrite_bag(recorded.bag, tmp_path / "bag", _drop(dropped), until_s=SHORT_S)
    with pytest.raises(BagError, match=f"no topic {dropped} "):
        ingest_bag(bag)


def test_the_cli_prints_that_error_on_one_line_and_exits_2(recorded, tmp_path):
    bag = rewrite_bag(recorded.bag, tmp_path / "bag", _drop(T.semantic), until_s=SHORT_S)
    result = CliRunner().invoke(app, ["ingest", str(bag), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "error: the bag" in result.output and T.semantic in result.output and "--semantic-topic" in result.output
    assert not (tmp_path / "out" / "scene_graph.json").exists()


def test_a_wrong_encoding_is_one_error_naming_topic_and_encoding(recorded, tmp_path):
    bag = rewrite_bag(recorded.bag, tmp_path / "bag", _reencode(T.depth, lambda d: (np.nan_to_num(d).astype(np.uint8), "8UC1")),
                      until_s=SHORT_S)
    with pytest.raises(BagError, match=f"topic {T.depth}: image encoding '8UC1', expected one of 32FC1, 16UC1"):
        ingest_bag(bag)


def test_millimetre_depth_bgr_colour_and_32_bit_ids_are_read(recorded, tmp_path):
    mm = _reencode(T.depth, lambda d: (np.where(np.isfinite(d), np.round(d * 1000), 0).astype(np.uint16), "16UC1"))
    bgr = _reencode(T.rgb, lambda c: (c[..., ::-1], "bgr8"))
    wide = _reencode(T.instance, lambda i: (i.astype(np.int32), "32SC1"))
    bag = rewrite_bag(recorded.bag, tmp_path / "bag", lambda t, m: wide(*bgr(*mm(t, m))))
    diff = compare_graphs(recorded.live, ingest_bag(bag).graph)
    assert not diff.only_in_a and not diff.only_in_b and not diff.attribute_mismatches
    assert diff.max_position_error_m < 0.075  # depth rounded to millimetres: within a voxel


def test_instances_without_labels_get_categories_from_semantics_and_letters_in_order(recorded, tmp_path):
    def anonymous(topic, msg):
        if topic != T.labels:
            return topic, msg
        table = json.loads(msg.data)
        table["instances"] = {}
        table["placed"] = {}
        return topic, replace(msg, data=json.dumps(table))

    graph = ingest_bag(rewrite_bag(recorded.bag, tmp_path / "bag", anonymous, until_s=SHORT_S)).graph
    categories = sorted(o.category for o in graph.objects.values())
    assert "fridge" in categories and "door" in categories
    for obj in graph.objects.values():
        stem, _, letter = obj.label.rpartition(" ")
        assert stem == obj.category and letter.isalpha() and letter.isupper()
    assert [letters(i) for i in (0, 25, 26, 27, 701, 702)] == ["A", "Z", "AA", "AB", "ZZ", "AAA"]


def test_a_broken_label_table_is_one_error_naming_its_topic(recorded, tmp_path):
    def broken(topic, msg):
        return (topic, replace(msg, data='{"instances": {}}')) if topic == T.labels else (topic, msg)

    with pytest.raises(BagError, match=f"topic {T.labels}: not a label table"):
        ingest_bag(rewrite_bag(recorded.bag, tmp_path / "bag", broken, until_s=SHORT_S))


def test_a_wrong_world_frame_names_the_chain(recorded):
    with pytest.raises(BagError, match="no transform from 'camera_optical_frame' to 'odom'"):
        ingest_bag(recorded.bag, BagTopics(world_frame="odom"))


def test_not_a_bag(tmp_path):
    (tmp_path / "x.txt").write_text("hello")
    with pytest.raises(BagError):
        ingest_bag(tmp_path / "x.txt")
    with pytest.raises(BagError, match="no bag at"):
        ingest_bag(tmp_path / "missing")
